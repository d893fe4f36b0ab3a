"""Parameter homotopy and monodromy: every root of one member of a family of systems from
the roots of another.

A family F(x; p) is a list of polynomials in n unknowns x and k parameters p. For a generic
complex p0 every member has the same number of isolated roots, the family's generic count;
tracking those roots from p0 to any p1 along a path of parameters that avoids the
discriminant reaches every isolated root of F(x; p1) (Morgan and Sommese, "Coefficient-
parameter polynomial continuation", Appl. Math. Comput. 29, 1989). The path is p = (1 -
tau) p0 + tau p1 with tau = t / (t + gamma (1 - t)), gamma a random complex number: an arc
of the complex plane from 0 to 1 that misses the finitely many bad values of tau for all
but finitely many gamma (the gamma trick on the parameter path; Sommese and Wampler 2005,
sec. 7.3). Paths are projective in x and classified like any others (:mod:`.solve`).

Monodromy fills the root set of a generic member from one seed root: a loop of parameters
p0 -> p1 -> p2 -> p0 through random complex points permutes the roots, so tracking the
known roots around it finds new ones; loops go on until the count has not grown for
``stable_loops`` loops in a row (Duff, Hill, Jensen, Lee, Leykin and Sommars, "Solving
polynomial systems via homotopy continuation and monodromy", IMA J. Numer. Anal. 39,
2019). A stable count is evidence, not proof, that every root is found: the result says
how many loops it was stable for, and tests compare it with counts known otherwise.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from functools import cached_property
from itertools import pairwise
from typing import Protocol

import numpy as np

from ..records import frozen
from .polynomials import HomogeneousForm, Polynomial, PolySystem
from .solve import Solutions, on_patch, track_all
from .tracker import velocity


@frozen
class Family:
    """F(x; p): each exponent tuple has n entries for x, then k for p."""

    n: int
    k: int
    polynomials: tuple[Polynomial, ...]
    groups: tuple[tuple[int, ...], ...] = ()
    conjugate: tuple[int, ...] = ()

    @cached_property
    def joint(self) -> PolySystem:
        """The polynomials over (x, p) together."""
        return PolySystem(self.n + self.k, self.polynomials)

    @cached_property
    def degrees(self) -> tuple[int, ...]:
        """Each polynomial's degree in x."""
        return tuple(max(sum(e[:self.n]) for e in p) for p in self.polynomials)

    @cached_property
    def form(self) -> JointForm:
        """Homogenised in x only, over the columns (X0, x, p)."""
        return JointForm(HomogeneousForm.of(self.joint, self.degrees, counted=self.n), self.n)

    def at(self, p: Sequence[complex] | np.ndarray) -> PolySystem:
        """The member at p, a system in x."""
        p = np.asarray(p, dtype=complex)
        polys = []
        for poly in self.polynomials:
            out: dict[tuple[int, ...], complex] = {}
            for e, c in poly.items():
                value = complex(c) * complex(np.prod(p ** np.array(e[self.n:])))
                out[e[:self.n]] = out.get(e[:self.n], 0j) + value
            polys.append({e: c for e, c in out.items() if c != 0} or {(0,) * self.n: 0j})
        return PolySystem(self.n, tuple(polys), groups=self.groups, conjugate=self.conjugate)


class ParameterForm(Protocol):
    """What a parameter homotopy needs of a family: F, dF/dX and dF/dp along a direction."""

    def jet(self, X: np.ndarray, p: np.ndarray,
            dp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


class ParameterFamily(Protocol):
    """A family as :func:`track_parameters` and :func:`monodromy` take it (:class:`Family`
    or a family with its own evaluation)."""

    n: int
    k: int

    @property
    def degrees(self) -> tuple[int, ...]: ...

    @property
    def form(self) -> ParameterForm: ...

    def at(self, p: np.ndarray) -> PolySystem: ...


@frozen
class JointForm:
    """A family's polynomials over (X0, x, p) as one HomogeneousForm."""

    form: HomogeneousForm
    n: int

    def jet(self, X: np.ndarray, p: np.ndarray, dp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """F (P, m), dF/dX (P, m, n + 1) and dF/dp . dp (P, m) at (X, p), one row a path."""
        F, J = self.form.both(np.concatenate([X, p], axis=1))
        return F, J[:, :, :self.n + 1], np.einsum("pmk,pk->pm", J[:, :, self.n + 1:], dp)


@frozen
class ParameterHomotopy:
    """H(X, t) = F(X; p(t)), p(t) = p0 + tau(t) (p1 - p0), on the patch a.X = 1."""

    form: ParameterForm
    target: HomogeneousForm
    n: int
    p0: np.ndarray
    p1: np.ndarray
    gamma: complex
    patch: np.ndarray

    def residual_and_jacobians(self, X: np.ndarray,
                               t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.asarray(t, dtype=complex)
        below = t + self.gamma * (1.0 - t)
        tau, dtau = t / below, self.gamma / below ** 2
        p = self.p0[None, :] + tau[:, None] * (self.p1 - self.p0)[None, :]
        F, JX, Ht = self.form.jet(X, p, dtau[:, None] * (self.p1 - self.p0)[None, :])
        P = X.shape[0]
        patch = np.broadcast_to(self.patch, (P, 1, X.shape[1]))
        return (np.concatenate([F, (X @ self.patch - 1.0)[:, None]], axis=1),
                np.concatenate([JX, patch], axis=1),
                np.concatenate([Ht, np.zeros((P, 1), dtype=complex)], axis=1))

    def velocity(self, X: np.ndarray, t: np.ndarray, dt: np.ndarray) -> np.ndarray:
        return velocity(self, X, t, dt)


Parameters = Sequence[complex] | np.ndarray


def track_parameters(family: ParameterFamily, p0: Parameters, p1: Parameters, roots: np.ndarray,
                     seed: int = 0, max_step: float = 0.1) -> Solutions:
    """Every root of F(x; p0) in ``roots`` (affine, one a row) tracked to p1; each endpoint
    classified, refined and checked against F(x; p1) as :func:`.solve.solve` does."""
    began = time.perf_counter()
    rng = np.random.default_rng(seed)
    gamma = complex(np.exp(2j * np.pi * rng.random()))
    patch = rng.normal(size=family.n + 1) + 1j * rng.normal(size=family.n + 1)
    patch /= np.linalg.norm(patch)
    p0, p1 = np.asarray(p0, dtype=complex), np.asarray(p1, dtype=complex)
    system = family.at(p1)
    target = HomogeneousForm.of(system, family.degrees)
    h = ParameterHomotopy(family.form, target, family.n, p0, p1, gamma, patch)
    roots = np.asarray(roots, dtype=complex).reshape(-1, family.n)
    endpoints = track_all(system, h, on_patch(roots, patch), max_step)
    return Solutions(system, tuple(endpoints), gamma, time.perf_counter() - began, PARAMETER)


PARAMETER = "parameter"
SAME = 1e-8
"""Two roots are one when they differ by this against max(1, |x|)."""
GOOD_RESIDUAL = 1e-11
"""A loop's endpoint joins the root set only as a finite, nonsingular root whose relative
residual (:class:`.solve.Endpoint`) is at most this."""


class Loops(Protocol):
    """What :func:`monodromy` needs of a problem to carry its roots around a loop of
    parameters: :class:`FamilyLoops` for a :class:`Family`, or a problem's own (the
    nine-point problem's, which keeps one root per orbit of its symmetries:
    :class:`.ninepoint.NinePointLoops`)."""

    @property
    def n(self) -> int: ...

    def turn(self, p: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """A random complex parameter point, a corner of a loop from ``p``."""
        ...

    def leg(self, a: np.ndarray, b: np.ndarray, roots: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """``roots`` (roots at ``a``, one a row) tracked to ``b``: the endpoints that are good
        roots there (the others are dropped)."""
        ...

    def settle(self, roots: np.ndarray, p: np.ndarray) -> np.ndarray:
        """A loop's endpoints, back at ``p``, in the form the root set keeps (those that do
        not settle are dropped)."""
        ...

    def fresh(self, known: np.ndarray, roots: np.ndarray) -> list[int]:
        """Indices of the rows of ``roots`` that are in neither ``known`` nor an earlier row."""
        ...


@frozen
class FamilyLoops:
    """A family's loops: corners at the scale of ``p``, legs by :func:`track_parameters`
    (an endpoint is kept as a finite root of residual at most GOOD_RESIDUAL), roots equal
    to SAME."""

    family: ParameterFamily

    @property
    def n(self) -> int:
        return self.family.n

    def turn(self, p: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        k = self.family.k
        scale = max(1.0, float(np.linalg.norm(p)) / np.sqrt(max(1, k)))
        return scale * (rng.normal(size=k) + 1j * rng.normal(size=k))

    def leg(self, a: np.ndarray, b: np.ndarray, roots: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        ends = track_parameters(self.family, a, b, roots, seed=int(rng.integers(2**31)))
        good = [e.x for e in ends.endpoints if e.kind == "finite" and e.residual <= GOOD_RESIDUAL]
        return np.array(good).reshape(-1, self.n)

    def settle(self, roots: np.ndarray, p: np.ndarray) -> np.ndarray:
        return roots  # track_parameters refined them at p

    def fresh(self, known: np.ndarray, roots: np.ndarray) -> list[int]:
        seen = list(known)
        out = []
        for i, x in enumerate(roots):
            size = max(1.0, float(np.linalg.norm(x)))
            if all(np.linalg.norm(x - y) > SAME * size for y in seen):
                seen.append(x)
                out.append(i)
        return out


@frozen
class Loop:
    """One monodromy loop: the count after it, the roots it added, the paths it dropped."""

    count: int
    new: int
    dropped: int
    seconds: float


@frozen
class Monodromy:
    """The roots of F(x; p) found from the seeds, and how the count grew."""

    p: np.ndarray
    roots: np.ndarray  # (found, n)
    counts: tuple[int, ...]  # the count after each loop
    stable: int  # loops at the end that found nothing new
    paths: int  # paths tracked, over every leg of every loop
    dropped: int  # paths that did not end at a good root on some leg (that loop lost them)
    seconds: float
    loops: tuple[Loop, ...] = ()


def monodromy(family: ParameterFamily | Loops, p: Parameters, seeds: np.ndarray, stable_loops: int = 5,
              max_loops: int = 200, seed: int | np.random.Generator = 0, max_seconds: float = np.inf,
              on_loop: Callable[[Loop], None] | None = None) -> Monodromy:
    """Loops p -> p1 -> p2 -> p through random complex parameters, each tracking every known
    root, until ``stable_loops`` loops in a row add none, or after ``max_loops`` loops, or
    the first loop to end past ``max_seconds`` (then ``stable`` says how settled it was).
    ``family``: a family (:class:`FamilyLoops` loops it) or a problem's own :class:`Loops`
    (the seeds are settled by it first, as each loop's endpoints are).
    ``seed``: an int, or a generator to draw from (a caller's stream goes on). ``on_loop``
    is called with each loop's record as it ends."""
    began = time.perf_counter()
    loops: Loops = family if hasattr(family, "leg") else FamilyLoops(family)  # type: ignore[assignment]
    rng = np.random.default_rng(seed)
    p = np.asarray(p, dtype=complex)
    seeds = loops.settle(np.asarray(seeds, dtype=complex).reshape(-1, loops.n), p)
    known = seeds[loops.fresh(np.zeros((0, loops.n), dtype=complex), seeds)]
    records: list[Loop] = []
    stable = paths = dropped = 0
    for _ in range(max_loops):
        t0, before, lost = time.perf_counter(), len(known), 0
        turns = [loops.turn(p, rng) for _ in range(2)]
        current = known
        for a, b in pairwise([p, *turns, p]):
            good = loops.leg(a, b, current, rng)
            paths += len(current)
            lost += len(current) - len(good)
            current = good
            if not len(good):
                break
        else:
            settled = loops.settle(current, p)
            lost += len(current) - len(settled)
            known = np.vstack([known, settled[loops.fresh(known, settled)]])
        dropped += lost
        records.append(Loop(len(known), len(known) - before, lost, time.perf_counter() - t0))
        if on_loop is not None:
            on_loop(records[-1])
        stable = 0 if len(known) > before else stable + 1
        if stable >= stable_loops or time.perf_counter() - began > max_seconds:
            break
    return Monodromy(p, known, tuple(r.count for r in records), stable, paths, dropped,
                     time.perf_counter() - began, tuple(records))
