"""What a scan keeps of its records: filtered, ranked and cut to --top, chunk by chunk, so
memory stays bounded."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np


def take(cols: Mapping[str, np.ndarray], rows: np.ndarray) -> dict[str, np.ndarray]:
    return {k: v[rows] for k, v in cols.items()}


def concat(parts: Sequence[Mapping[str, np.ndarray]]) -> dict[str, np.ndarray]:
    if not parts:
        return {}
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def rank(cols: Mapping[str, np.ndarray], key: str, descending: bool) -> np.ndarray:
    """Row order by ``key``: stable, ties in design order, NaN (and, for text, nothing
    else) last whichever the direction."""
    v = cols[key]
    if v.dtype == object:
        order = np.argsort(v.astype(str), kind="stable")
        return order[::-1] if descending else order
    v = v.astype(float)
    missing = np.isnan(v)
    keyed = np.where(missing, np.inf, -v if descending else v)
    return np.lexsort((cols["design"], missing, keyed))


class Keeper:
    """The records a scan keeps: all of them (streamed on to ``sink`` as they come when
    unsorted), or the first ``top`` (by ``sort``), merged chunk by chunk so memory stays
    bounded. ``show`` caps what is held for a table without changing what is counted."""

    def __init__(self, sort: str | None, descending: bool, top: int | None,
                 sink: Callable[[Mapping[str, np.ndarray]], None] | None, show: int | None = None) -> None:
        self.sort, self.descending, self.top, self.sink = sort, descending, top, sink
        self.limit = top if top is not None else show
        self.kept = 0
        self.held: dict[str, np.ndarray] = {}
        self.parts: list[dict[str, np.ndarray]] = []

    @property
    def full(self) -> bool:
        """True once no later design can change the output (unsorted, top reached)."""
        return self.sort is None and self.top is not None and self.kept >= self.top

    def add(self, cols: dict[str, np.ndarray]) -> None:
        if self.sort is None and self.top is not None:
            cols = take(cols, np.arange(min(self.top - self.kept, len(cols["design"]))))
        self.kept += len(cols["design"])
        if self.sink is not None:
            self.sink(cols)
            return
        if self.limit is None:
            self.parts.append(cols)
            return
        merged = concat([self.held, cols]) if self.held else cols
        order = (rank(merged, self.sort, self.descending) if self.sort is not None
                 else np.arange(len(merged["design"])))
        self.held = take(merged, order[: self.limit])

    def result(self) -> dict[str, np.ndarray]:
        """What is held at the end, in order: the rows a table shows, or every row of a
        sorted file."""
        if self.limit is not None:
            return self.held
        rows = concat(self.parts)
        if self.sort is None or not rows:
            return rows
        return take(rows, rank(rows, self.sort, self.descending))

