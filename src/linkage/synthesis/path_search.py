"""The search of path synthesis (docs/path_synthesis.md, "Five to eight points"): four-bars
through five to eight points, found through samples of the extra points that make nine
(:mod:`.path_points`), and every defect-free one ranked as function generation's search
ranks its candidates (:mod:`.search`); through nine points, the finite set's real ones.

Samples run one after another: each is a complete nine-point solve whose chunks of paths
are already tasks on the scan's runner (both cores busy, one sample's paths in memory)."""

from __future__ import annotations

from collections.abc import Callable

from ..errors import InputError
from ..records import frozen
from .path import PathFourBar, PathSynthesis, check_points, chunk_runner, path_options, solve_nine
from .path_points import POINTS, check_via, nine_points
from .request import MIN_TRANSMISSION_DEG

MAX_SAMPLES = 1000
"""At about half a minute of two cores a sample, more is a cluster's day."""


@frozen
class RankedDesign:
    """A defect-free four-bar of a search: which sample found it, which real design of that
    sample's (0-based, in the order found) and which of its three Roberts cognates (1 to 3).
    A design whose first cognate has a branch or order defect is judged once (the cognates
    share those: :data:`.path.CIRCUIT_DEFECTS`)."""

    sample: int  # 1-based
    group: int
    cognate: int
    four_bar: PathFourBar


@frozen
class PathSearch:
    points: tuple[complex, ...]  # the given points
    samples: tuple[PathSynthesis, ...]  # a nine-point synthesis per sample of the extra points
    designs: tuple[RankedDesign, ...]  # every defect-free one, best first (:func:`rank`)
    min_transmission: float

    @property
    def real(self) -> int:
        """Real four-bars found over all samples, up to cognates."""
        return sum(len(s.designs) for s in self.samples)


def rank(samples: tuple[PathSynthesis, ...]) -> tuple[RankedDesign, ...]:
    """Every defect-free cognate of every sample, by least transmission angle over the
    motion, largest first (function generation's search key for the same judgement; ties
    in the order found)."""
    found = [RankedDesign(k + 1, g, c + 1, fb) for k, s in enumerate(samples)
             for g, group in enumerate(s.designs) for c, fb in enumerate(group) if not fb.defects]
    return tuple(sorted(found, key=lambda d: -d.four_bar.transmission_min_deg))


def search_path(points: object, samples: int | None = None, via: object = None, seed: int = 0,
                scheduler: str | None = None, workers: int | None = None,
                min_transmission: float = MIN_TRANSMISSION_DEG,
                progress: Callable[[int, str], None] | None = None,
                orbits: int | None = None) -> PathSearch:
    """Four-bars whose coupler point passes through ``points`` (five to nine (x, y) pairs,
    in order), the defect-free ones ranked (:func:`rank`). Through n < 9 points: ``samples``
    sets (default 1) of 9 - n extra points on the curve through them (sample 0 evenly
    spaced, the others moved by the random numbers of ``seed``), or the user's ``via``;
    through nine, the finite set. The other arguments are :func:`.path.synthesize_path`'s;
    ``progress(done, label)`` counts paths over all samples (each sample's routes from 0)."""
    pts = check_points(points)
    extra = check_via(via, pts)
    seed, floor, workers, orbits = path_options(seed, min_transmission, workers, scheduler, orbits)
    if samples is not None:
        from ..arguments import check_whole

        samples = check_whole("samples", samples, 1, MAX_SAMPLES)
        if samples > 1 and (len(pts) == POINTS or extra):
            raise InputError(f"samples: {'nine points' if len(pts) == POINTS else 'via points'} leave no "
                             "extra points to sample (one set of four-bars): give samples=1 or none")
    run = chunk_runner(scheduler, workers)
    out = []
    for k in range(samples or 1):
        nine = nine_points(pts, extra, seed, k)
        told = None if progress is None else _sample_progress(progress, k, samples or 1)
        out.append(solve_nine(nine.points, nine.extra, seed, run, floor, told, orbits, every_cognate=False))
    found = tuple(out)
    return PathSearch(tuple(pts), found, rank(found), floor)


def _sample_progress(progress: Callable[[int, str], None], k: int, total: int) -> Callable[[int, str], None]:
    """A sample's progress(done, label) as the whole search's: paths of the samples before
    it added, the sample named."""
    from ..homotopy.ninepoint_track import PATHS

    def told(done: int, label: str) -> None:
        progress(k * PATHS + done, f"sample {k + 1} of {total}: {label}" if total > 1 else label)

    return told
