"""What a solve returns: a named stop reason, the iteration history, the answer."""

from __future__ import annotations

import math
from enum import Enum
from typing import Any

from .errors import NotConvergedError
from .records import NamedTuple, frozen


class Status(Enum):
    """Why an iteration stopped. ``value`` is the stable name used in JSON and CSV."""

    CONVERGED_STEP = "converged_step"
    CONVERGED_RESIDUAL = "converged_residual"
    CONVERGED_EXACT = "converged_exact"
    MAX_ITER = "max_iter"
    DIVERGED = "diverged"
    ZERO_DERIVATIVE = "zero_derivative"
    NON_FINITE = "non_finite"
    INVALID_BRACKET = "invalid_bracket"
    DOMAIN_ERROR = "domain_error"
    PRECISION_LIMIT = "precision_limit"
    SINGULAR_JACOBIAN = "singular_jacobian"
    NO_SOLUTION = "no_solution"
    DISCONTINUITY = "discontinuity"
    STALLED = "stalled"
    LOCAL_MINIMUM = "local_minimum"

    @property
    def converged(self) -> bool:
        return self in _CONVERGED

    @property
    def message(self) -> str:
        return _MESSAGES[self]


class StatusMembers:
    """The statuses as the attributes of a plain instance (:data:`STATUS_MEMBERS`)."""

    def __init__(self) -> None:
        for name, member in Status.__members__.items():
            setattr(self, name, member)


STATUS_MEMBERS = StatusMembers()
"""The statuses as plain attributes, for the hot paths (the generated loops read them as
``_S.MAX_ITER``): the same members, read as an instance attribute (a fast read) where an
Enum class attribute is a slow lookup on Python 3.11, made several times per solve. An instance
of a class of its own, not a ``SimpleNamespace``, whose attributes CPython 3.11 reads by
the generic lookup every time (it specialises attribute reads for instances of classes
defined in Python only)."""

_CONVERGED = frozenset({Status.CONVERGED_STEP, Status.CONVERGED_RESIDUAL, Status.CONVERGED_EXACT})

_MESSAGES = {
    Status.CONVERGED_STEP: "converged: the step is within the tolerance",
    Status.CONVERGED_RESIDUAL: "converged: the residual is within the tolerance",
    Status.CONVERGED_EXACT: "converged: the function is exactly zero",
    Status.MAX_ITER: "stopped: iteration cap reached before the tolerance",
    Status.DIVERGED: "diverged: the steps kept growing",
    Status.ZERO_DERIVATIVE: "stalled: the derivative (or slope) is zero",
    Status.NON_FINITE: "failed: a value became infinite or NaN",
    Status.INVALID_BRACKET: "invalid bracket: f has the same sign at both ends",
    Status.DOMAIN_ERROR: "failed: a function was evaluated outside its domain",
    Status.PRECISION_LIMIT: "stopped at the limit of double precision before reaching the tolerance",
    Status.SINGULAR_JACOBIAN: "stalled: the Jacobian is singular",
    Status.NO_SOLUTION: "no solution: the residual stays above the tolerance",
    Status.STALLED: "stalled: the steps fell below the tolerance, but nothing shows a root within it",
    Status.LOCAL_MINIMUM: "no root found from this start: the residual stopped decreasing at a local "
                          "minimum above the tolerance",
    Status.DISCONTINUITY: "stopped: f changes sign here through a jump or a pole (|f| does not "
                          "shrink toward the sign change), not through a root",
}


# A NamedTuple, not a frozen dataclass: built once per class at import, it costs
# 0.1 ms against 0.7 ms, and every command's start pays for its classes.
class Column(NamedTuple):
    """One column of an iteration table: a label template and the kind of quantity.

    ``template`` uses ``{v}`` for the unknown's name (``{v}_i`` becomes ``phi_i``);
    ``kind`` decides the unit: ``x`` (unit of the unknown), ``f`` (unit of the
    function), ``df`` (f per x), ``d2f`` (f per x^2), ``ratio`` (dimensionless), ``index``
    and ``text``.
    """

    template: str
    kind: str

    def label(self, var: str, x_unit: str, f_unit: str = "") -> str:
        name = self.template.format(v=var)
        unit = {
            "x": x_unit,
            "f": f_unit,
            "df": _per(f_unit, x_unit),
            "d2f": _per(f_unit, f"{x_unit}^2" if x_unit else ""),
        }.get(self.kind, "")
        return f"{name} ({unit})" if unit else name


def _per(num: str, den: str) -> str:
    if not den:
        return num
    return f"{num or '1'}/{den}"


@frozen
class History:
    """The recorded iterations: column labels (with units) and one tuple per row.

    ``error_column`` indexes the column holding the method's error measure, which
    the convergence analysis reads; renderers read rows and never recompute them.
    """

    columns: tuple[str, ...]
    rows: tuple[tuple[Any, ...], ...]
    error_column: int
    elided: int = 0
    """Rows left out of a long run (the history keeps its first and last rows)."""
    gap_at: int = 0
    """With ``elided``: the index in ``rows`` of the first row after the gap."""

    @classmethod
    def of(cls, columns: tuple[str, ...], rows: Any, error_column: int) -> History:
        """A History from the loop's rows (a list, or a ceiling-bounded ``Rows``)."""
        elided = gap = 0
        if hasattr(rows, "finish"):
            rows, elided, gap = rows.finish()
        obj = _new(cls)
        # as Result.fast: the frozen dataclass's value without its per-field __setattr__
        _setattr(obj, "__dict__", {"columns": columns, "rows": tuple(rows), "error_column": error_column,
                                   "elided": elided, "gap_at": gap if elided else 0})
        return obj

    @property
    def note(self) -> str:
        if not self.elided:
            return ""
        return (f"({self.elided} rows between i = {self.rows[self.gap_at - 1][0]} and "
                f"i = {self.rows[self.gap_at][0]} are left out: a history keeps its first "
                f"{self.gap_at} and last {len(self.rows) - self.gap_at} rows)")

    def errors(self) -> list[float | None]:
        k = self.error_column
        return [r[k] for r in self.rows]

    def as_dicts(self) -> list[dict[str, Any]]:
        return [dict(zip(self.columns, r)) for r in self.rows]


# A NamedTuple, not a frozen dataclass: built once per class at import, it costs
# 0.1 ms against 0.7 ms, and every command's start pays for its classes.
class IterationRecord(NamedTuple):
    """One row of a history as a mapping, for callers who prefer names to positions."""

    index: int
    values: dict[str, Any]


@frozen
class Result:
    """The outcome of one solve. The same type for every method and every outcome.

    ``x`` is the final estimate (a float for scalar problems, a tuple for systems);
    ``error`` the last error measure the stopping test saw; ``residual`` the function
    value at ``x`` when it was evaluated (``None`` if the method never needed it).
    """

    method: str
    x: Any
    status: Status
    iterations: int
    nfev: int
    error: float
    residual: Any
    detail: str = ""
    history: History | None = None
    njev: int = 0
    meta: dict[str, Any] | None = None

    @classmethod
    def fast(cls, method: str, x: Any, status: Status, iterations: int, nfev: int, error: float,
             residual: Any, detail: str, njev: int, meta: Raw, history: Raw | None = None) -> Result:
        """The same value as ``Result(...)``, made for a solve's hot path: without the frozen
        dataclass's per-field ``object.__setattr__`` (about 1.5 us of a 5 us solve), and with
        ``meta`` and ``history`` kept raw, each as ``(builder, *arguments)``, to be built on
        their first read (:class:`Built`): most callers never read them.

        The fields are stored on a :class:`ResultBuilder` (the same layout, without the
        frozen ``__setattr__``: plain attribute stores, the cheapest Python has) and the
        object then becomes a Result by assigning its ``__class__`` (the language reference,
        "Data model", 3.3.2.1: allowed between classes of the same layout): about 0.2 us
        where the instance's namespace set as one dict took 0.37 us."""
        obj = _new(ResultBuilder)
        obj.method = method
        obj.x = x
        obj.status = status
        obj.iterations = iterations
        obj.nfev = nfev
        obj.error = error
        obj.residual = residual
        obj.raw_meta = meta
        # a field at its default is read from the class (``detail``, ``njev``) or built as
        # its default (``history``): a smaller namespace to carry over to the Result
        if detail:
            obj.detail = detail
        if njev:
            obj.njev = njev
        if history is not None:
            obj.raw_history = history
        obj.__class__ = cls
        return obj  # type: ignore[return-value]

    def __getstate__(self) -> dict[str, Any]:
        """The fields as values (a raw record holds the solve's callables, which need not
        pickle): a copy or a pickle is the Result as every reader sees it."""
        return {name: getattr(self, name) for name in self.__dataclass_fields__}

    @property
    def root(self) -> Any:
        return self.x

    @property
    def converged(self) -> bool:
        return self.status.converged

    @property
    def message(self) -> str:
        detail = self.detail or self._default_detail()
        return f"{self.status.message} ({detail})" if detail else self.status.message

    def _default_detail(self) -> str:
        meta = self.meta or {}
        if self.status is Status.CONVERGED_STEP and "tol" in meta:
            limit = meta["tol"] + meta.get("rtol", 0.0) * _magnitude(self.x)
            return f"error {self.error:.3g} <= {limit:.3g}"
        if self.status is Status.CONVERGED_RESIDUAL and meta.get("ftol") is not None:
            return f"residual {_magnitude(self.residual):.3g} <= {meta['ftol']:.3g}"
        if self.status is Status.MAX_ITER:
            return f"{self.iterations} iterations, last error {self.error:.3g}"
        return ""

    @property
    def records(self) -> list[IterationRecord]:
        if self.history is None:
            return []
        return [IterationRecord(r[0], d) for r, d in zip(self.history.rows, self.history.as_dicts())]

    def raise_for_status(self) -> Result:
        """Return self when converged, raise :class:`NotConvergedError` otherwise."""
        if not self.converged:
            raise NotConvergedError(self, self.message)
        return self


_new = object.__new__
_setattr = object.__setattr__


class ResultBuilder:
    """A :class:`Result` under construction by :meth:`Result.fast` (or :func:`fast_source`):
    an object of Result's layout (a namespace, weak references) whose attributes are set as
    plain stores, and whose class is then set to Result. Nothing else makes or holds one."""


FAST_NAMES = {"_new_result": _new, "_ResultBuilder": ResultBuilder, "_Result": Result}
"""The names :func:`fast_source`'s statements read."""


def fast_source(method: str, x: str, status: str, iterations: str, nfev: str, error: str, residual: str,
                detail: str, meta: str, history: str | None = None, njev: str | None = None) -> list[str]:
    """Statements (unindented source lines) that return what :meth:`Result.fast` returns for
    these expressions (``detail`` and ``njev`` read twice: no side effects; ``history``
    None when not kept, ``njev`` None for 0): for a generated loop, which so builds its Result in its
    own frame instead of calling ``fast`` with eleven arguments (tests/test_result_fields.py holds
    the two equal)."""
    lines = ["_r = _new_result(_ResultBuilder)"]
    lines += [f"_r.{name} = {value}" for name, value in (
        ("method", method), ("x", x), ("status", status), ("iterations", iterations), ("nfev", nfev),
        ("error", error), ("residual", residual), ("raw_meta", meta))]
    lines += [f"if {detail}:", f"    _r.detail = {detail}"]
    if njev is not None:
        lines += [f"if {njev}:", f"    _r.njev = {njev}"]
    if history is not None:
        lines.append(f"_r.raw_history = {history}")
    return [*lines, "_r.__class__ = _Result", "return _r"]

Raw = tuple
"""A field kept raw: ``(builder, *arguments)``, the value being ``builder(*arguments)``."""


class Built:
    """A :class:`Result` field that :meth:`Result.fast` keeps raw (as ``raw_<name>`` in the
    instance's namespace) and that is built on its first read, then kept (as
    ``functools.cached_property`` does). A Result made the ordinary way holds the value
    itself, which is read first: a non-data descriptor yields to the instance's namespace."""

    __slots__ = ("default", "name", "raw")

    def __init__(self, name: str, default: Any) -> None:
        self.name, self.raw, self.default = name, f"raw_{name}", default

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self.default
        namespace = obj.__dict__
        raw = namespace.get(self.raw)
        value = self.default if raw is None else raw[0](*raw[1:])
        namespace[self.name] = value
        return value


def given(value: Any) -> Any:
    """The builder of a raw field whose value is already made: ``(given, value)``."""
    return value


# after the dataclass is made: its __init__ keeps the defaults, the class the builders
Result.meta = Built("meta", None)  # type: ignore[assignment]
Result.history = Built("history", None)  # type: ignore[assignment]


def _magnitude(v: Any) -> float:
    if isinstance(v, (int, float)):
        return abs(v)
    return max((abs(c) for c in v), default=0.0)


def finite_or_none(v: Any) -> Any:
    """JSON has no NaN or infinity: map them to None, keep everything else."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v
