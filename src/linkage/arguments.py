"""The checks every public function runs on its arguments, once, at its front door.

Each check returns the value in the form the internals use (a float, an int, a list of
floats) or raises :class:`~linkage.errors.InputError` with one line that names the
argument and shows the offending value, so a misuse never surfaces as a TypeError,
ValueError or IndexError from deep inside, and never runs on with a silently changed
value (``n=2.7`` truncated, ``workers=-1``). The command line reaches the same checks
(its option names are passed as the argument's name).

Decisions recorded here, once:

- A whole number is an ``int`` (or a numpy integer), never a ``bool`` and never a float,
  even an integral one: ``2.7`` is refused, not truncated, and so is ``2.0``.
- A real number is anything ``float()`` accepts except ``bool``, ``str``/``bytes`` and
  complex numbers; it must be finite. :func:`check_number` is that rule for one number and
  every public function's numbers go through it (or :func:`check_reals`, :func:`is_real`
  for a sequence): ``speed=True``, ``ground=True`` or ``{"coupler": "5"}`` is refused.
- Driver values are a sequence (list, tuple, range, 1-D numpy array) of finite reals. A
  generator or iterator is refused: a sweep needs the count first, and reading it would
  consume it.
- Rates in the API are numbers in internal units (rad/s and rad/s^2, or length unit/s and
  /s^2); unit strings such as ``"10rpm"`` belong to the command line's ``--speed`` and are
  refused here with the conversion to use.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from operator import countOf
from typing import Any

from .errors import InputError
from .units import RAD_PER_DEG

MAX_RATE = 1e12
"""The largest |speed| or |accel| accepted (the command line's --speed bound too)."""

MIN_RATE = 1e-12
"""The smallest nonzero |speed| or |accel| accepted: rates are linear in the speed (and
accelerations in its square), so a slower driver's rates are these scaled; below it the
products in a rate's error bound leave double precision's normal range."""


def rate_in_range(value: float) -> bool:
    """0, or a finite size from MIN_RATE to MAX_RATE: the range of a driver's speed or
    acceleration, for the API and the command line alike."""
    size = abs(value)
    return size == 0.0 or MIN_RATE <= size <= MAX_RATE

MAX_THREADS = min(256, 4 * (os.cpu_count() or 1))
"""Local scan workers as threads: 4 per core, at most 256 (each holds a chunk's arrays)."""

MAX_PROCESSES = max(2, os.cpu_count() or 1)
"""Local scan workers as processes: one per core (each is a whole interpreter)."""

MAX_SEED = 2**64 - 1

MAX_INT_FLOAT = 2**1023
"""An int of at most this size converts to a finite float (a larger one may overflow)."""
"""numpy's generators take any whole number >= 0; this bound keeps the message short."""

SCHEDULERS = ("threads", "processes", "synchronous")
"""The local dask schedulers a scan may name (else the address of a cluster)."""


def describe(value: Any) -> str:
    """The offending value for a message: its repr, cut short."""
    try:
        text = repr(value)
    except Exception:  # a user object whose repr fails still gets a message
        text = f"<{type(value).__name__}>"
    text = " ".join(text.split())
    return text if len(text) <= 60 else f"{text[:50]}...({type(value).__name__})"


def is_real(value: Any) -> bool:
    """True for an int, a float or a numpy real scalar (not a bool, a string or a complex)."""
    if isinstance(value, (bool, str, bytes, complex)):
        return False
    if type(value) is float or type(value) is int:
        return True
    kind = getattr(getattr(value, "dtype", None), "kind", None)
    if kind is not None:
        return kind in "iuf" and getattr(value, "ndim", 0) == 0
    try:
        float(value)
    except (TypeError, ValueError, OverflowError):
        return False
    return not hasattr(value, "imag") or getattr(value, "imag", 0) == 0


def finite_real(value: Any) -> float | None:
    """``value`` as a float when it is a finite number by :func:`is_real`, else None (an int
    beyond the float range too)."""
    if not is_real(value):
        return None
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        return None
    return v if math.isfinite(v) else None


def check_number(name: str, value: Any, *, positive: bool = False, allow_zero: bool = True) -> float:
    """A finite float (and > 0 or >= 0 when asked), or an InputError naming the value: the
    one check of a number from Python. A number is what :func:`is_real` says (an int, a
    float, a numpy real scalar), never a bool (``speed=True`` is not a speed of 1), a
    string (``"5"``: the command line parses its text, the API does not) or a complex."""
    if type(value) is not float and not is_real(value):
        kind = "real number" if _complex(value) else "number"
        raise InputError(f"{name} must be a {kind}, got {describe(value)}")
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} must be a finite number, got {describe(value)}") from None
    if not math.isfinite(v):
        raise InputError(f"{name} must be finite, got {v!r}")
    if positive and (v < 0.0 or (v == 0.0 and not allow_zero)):
        raise InputError(f"{name} must be {'>' if not allow_zero else '>='} 0, got {v!r}")
    return v


MAX_FD_STEP = 1.0
"""The largest forward-difference step h accepted (``fd_step``, --fd-step): a difference
quotient is a derivative only for h small beside the unknowns' variation, and angle unknowns
are in radians (one radian is already 57 degrees); the default is sqrt(eps) max(1, |q|)."""


def check_fd_step(name: str, value: Any) -> float:
    """A forward-difference step: a finite number > 0 and at most :data:`MAX_FD_STEP`."""
    h = check_number(name, value, positive=True, allow_zero=False)
    if h > MAX_FD_STEP:
        raise InputError(f"{name} must be at most {MAX_FD_STEP:g} (a difference over a wider step is no "
                         f"derivative; angles are in radians), got {h!r}")
    return h


def check_method(name: str, method: Any, known: Collection[str], scope: str = "") -> str:
    """``method`` if it is one of the ``known`` names (a str), else InputError
    "unknown method 'x' in NAME[ SCOPE]; choose from A, B, C": the one check of a method's
    name, which every front door taking one calls (the command line's --method, the
    library's ``method=``) and :func:`check_method_list` calls for each entry. ``known``
    comes from the caller's registry (``linkage.methods.METHODS``, read when called, so a
    method registered later is known; ``linkage.solve.SYSTEM_METHODS``): this layer knows
    no method. ``scope`` says what the methods apply to ("for a mechanism file")."""
    if isinstance(method, str) and method in known:
        return method
    where = f"{name} {scope}" if scope else name
    raise InputError(f"unknown method {method!r} in {where}; choose from {', '.join(known)}")


def check_method_list(name: str, text: str, known: Sequence[str], every: str = "all") -> list[str]:
    """The methods a comma-separated list names, each known and none twice, or an InputError
    naming the entry at fault; ``every`` ("all": every method that applies) stands alone."""
    names = [m.strip() for m in text.split(",")]
    choose = f"choose from {', '.join(known)}, {every}"
    for m in names:
        check_method(name, m, (*known, every))
    if every in names:
        raise InputError(f"{every!r} stands alone in {name}, got {text!r}")
    if len(set(names)) < len(names):
        raise InputError(f"a method named twice in {name} {text!r}; {choose}")
    return names


def _complex(value: Any) -> bool:
    return isinstance(value, complex) or getattr(getattr(value, "dtype", None), "kind", "") == "c"


def check_fps(name: str, value: Any) -> float:
    """An animation's frames per second: 0.01 to 100, since a GIF stores each frame's delay
    as a whole number of hundredths of a second (at most 655.35 s)."""
    fps = check_number(name, value, positive=True, allow_zero=False)
    if not 0.01 <= fps <= 100:
        raise InputError(f"{name} {fps:g} is out of range (0.01 to 100 frames per second)")
    return fps


def check_whole(name: str, value: Any, lo: int = 1, hi: int | None = None, why: str = "") -> int:
    """An int in [lo, hi] (no bools, no floats), or InputError: "NAME must be a whole
    number from LO to HI, got V" (``why`` says where HI comes from)."""
    import operator

    if hi is None:
        span = f">= {lo:,}"
    else:
        span = f"from {lo:,} to {'2**64 - 1' if hi == MAX_SEED else f'{hi:,}'}"
    if isinstance(value, bool) or isinstance(value, float):
        raise InputError(f"{name} must be a whole number {span}{why}, got {describe(value)}")
    try:
        n = operator.index(value)
    except TypeError:
        raise InputError(f"{name} must be a whole number {span}{why}, got {describe(value)}") from None
    if n < lo or (hi is not None and n > hi):
        shown = str(n) if abs(n) < 10**30 else f"about {'-' if n < 0 else ''}1e{len(str(abs(n))) - 1}"
        raise InputError(f"{name} must be a whole number {span}{why}, got {shown}")
    return n


def check_flag(name: str, value: Any) -> bool:
    """True or False (numpy's bool too), nothing else."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise InputError(f"{name} must be True or False, got {describe(value)}")


def check_text(name: str, value: Any, *, optional: bool = True) -> str | None:
    """A string (or None when ``optional``)."""
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise InputError(f"{name} must be {'None or ' if optional else ''}a string, got {describe(value)}")
    return value


def check_callable(name: str, value: Any, *, optional: bool = True) -> Any:
    """A callable (or None when ``optional``)."""
    if value is None and optional:
        return None
    if not callable(value):
        raise InputError(f"{name} must be {'None or ' if optional else ''}a function, got {describe(value)}")
    return value


def check_reals(name: str, values: Any, length: int | None = None, labels: Sequence[str] = (),
                most: int | None = None, keep_array: bool = False) -> list[float]:
    """A 1-D sequence of finite reals as a list of floats (``length`` of them when given, at
    most ``most``, counted before any is read; ``labels`` name the entries in the message),
    or InputError naming the first bad entry. ``keep_array``: a numpy array (or a long
    list read through one) comes back as a float array, not a list (a million positions
    for the batch engine: 30 ms to make the list and as much to make the array again)."""
    if type(values) is tuple or type(values) is list:
        # the common case (a bracket, x0, a short list of floats) without the abstract-class
        # checks below, which cost microseconds on a solve of a few
        size = len(values)
        if size <= 1000 and (most is None or size <= most) and (length is None or size == length):
            # every entry a float, counted at C speed, and their sum finite: a NaN or an
            # infinity makes it NaN or infinite, so every entry is finite (a sum that
            # overflows only sends finite values to the checks below, which pass them)
            if countOf(map(type, values), float) == size:
                total = sum(values)
                if total - total == 0.0:
                    return list(values)
    if values is None or isinstance(values, (str, bytes, Mapping)) or is_real(values):
        raise InputError(f"{name} must be a sequence of numbers (a list, tuple or 1-D array), "
                         f"got {describe(values)}")
    listed = isinstance(values, Sequence) or hasattr(values, "__array__")
    if isinstance(values, Iterator) or not listed:
        raise InputError(f"{name} must be a sequence of numbers (a list, tuple or 1-D array), got "
                         f"{type(values).__name__}: a generator or iterator is read once and has no "
                         "length; pass list(...) of it")
    ndim = getattr(values, "ndim", 1)
    if ndim != 1:
        raise InputError(f"{name} must be 1-D, got an array of shape {getattr(values, 'shape', '?')}")
    if most is not None and len(values) > most:
        raise InputError(f"{name} has {len(values):,} entries, more than {most:,}")
    if length is not None and len(values) != length:
        what = f" ({', '.join(labels)})" if labels else ""
        raise InputError(f"{name} needs {length} values{what}, got {len(values)}")
    kind = getattr(getattr(values, "dtype", None), "kind", None)
    if kind is None and len(values) > 1000:
        # a long list: numpy reads it at C speed (a short one is checked without it, so a
        # scalar solve never imports numpy); anything but reals falls to the loop below
        import numpy as np

        try:
            probe = np.asarray(values)
        except (ValueError, TypeError):
            probe = None
        if probe is not None and probe.ndim == 1 and probe.dtype.kind in "iuf":
            values, kind = probe, probe.dtype.kind
    if kind is not None and kind in "iuf":
        import numpy as np

        arr = np.asarray(values, dtype=float)
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size == 0:
            return arr if keep_array else arr.tolist()  # type: ignore[no-any-return]
        k = int(bad[0])
        raise InputError(f"{name}[{labels[k] if labels else k}] must be finite, got {float(arr[k])!r}")
    out = []
    for k, v in enumerate(values):
        if type(v) is float and v - v == 0.0:
            out.append(v)
            continue
        if type(v) is int and -MAX_INT_FLOAT <= v <= MAX_INT_FLOAT:
            out.append(float(v))  # range(361) and the like: finite, no check needed
            continue
        where = labels[k] if k < len(labels) else k
        if not is_real(v):
            raise InputError(f"{name}[{where}] must be a real number, got {describe(v)}")
        try:
            x = float(v)
        except OverflowError:  # an int beyond the float range
            raise InputError(f"{name}[{where}] must be finite, got an integer beyond the float "
                             "range") from None
        if not math.isfinite(x):
            raise InputError(f"{name}[{where}] must be finite, got {x!r}")
        out.append(x)
    return out


def check_rate(name: str, value: Any, unit: str) -> float:
    """A driver speed or acceleration: a finite number of internal units (``unit``, e.g.
    rad/s) with |value| <= MAX_RATE. A string such as "10rpm" is refused: units are for the
    command line's --speed/--accel."""
    if isinstance(value, (str, bool)):
        raise InputError(f"{name} must be a number in {unit} (the API takes internal units: "
                         f"rpm x pi/30 = rad/s, deg/s x pi/180 = rad/s), got {describe(value)}")
    v = check_number(name, value)
    if not rate_in_range(v):
        raise InputError(f"{name} must be 0 or from {MIN_RATE:g} to {MAX_RATE:g} in size, got {v!r}")
    return v


def check_motion(speed: Any, accel: Any, driver_kind: str, length_unit: str) -> tuple[float | None, float]:
    """The driver's (speed, accel) for rates: speed None (no rates) or a rate in rad/s (a
    turning driver) or length unit/s (a sliding one), accel in the same per second; an
    acceleration without a speed is refused."""
    per_s = "rad/s" if driver_kind == "angle" else f"{length_unit or 'length unit'}/s"
    if speed is not None:
        speed = check_rate("speed", speed, per_s)
    accel = check_rate("accel", accel, f"{per_s}^2")
    if speed is None and accel != 0.0:
        raise InputError("accel needs speed (the driver's velocity)")
    return speed, accel


def check_workers(name: str, value: Any, scheduler: str | None) -> int | None:
    """Local workers: None (one per core), or a whole number up to MAX_PROCESSES for the
    processes scheduler and MAX_THREADS otherwise."""
    if value is None:
        return None
    if scheduler == "processes":
        return check_whole(name, value, 1, MAX_PROCESSES,
                           f" (one process per core: this machine has {os.cpu_count() or 1})")
    return check_whole(name, value, 1, MAX_THREADS,
                       f" (at most 4 threads per core, and 256: this machine has "
                       f"{os.cpu_count() or 1} cores)")


def check_scan_options(*, seed: Any = 0, samples: Any = None, top: Any = None, chunk: Any = None,
                       workers: Any = None, scheduler: Any = None, max_designs: int,
                       prefix: str = "") -> None:
    """The scan options shared by ``linkage.scan_designs`` and ``linkage scan`` (``prefix``
    is "--" for the command line's names)."""
    check_text(f"{prefix}scheduler", scheduler)
    if scheduler is not None and "://" not in scheduler and scheduler not in SCHEDULERS:
        raise InputError(f"{prefix}scheduler must be threads, processes, synchronous or "
                         f"tcp://HOST:PORT, got {describe(scheduler)}")
    check_whole(f"{prefix}seed", seed, 0, MAX_SEED)
    if samples is not None:
        check_whole(f"{prefix}samples", samples, 1, max_designs)
    if top is not None:
        check_whole(f"{prefix}top", top, 1)
    if chunk is not None:
        check_whole(f"{prefix}chunk", chunk, 1, max_designs)
    check_workers(f"{prefix}workers", workers, scheduler)


def check_vary(vary: Any, max_designs: int) -> list[tuple[str, float, float, int | None]]:
    """``scan_designs``' ``vary``: a mapping of parameter name to (lo, hi) or (lo, hi, n),
    as (name, lo, hi, n) with finite bounds and a whole n."""
    if not isinstance(vary, Mapping):
        raise InputError("vary must be a mapping of parameter name to (lo, hi) or (lo, hi, n), "
                         f"got {describe(vary)}")
    out = []
    for name, spec in vary.items():
        if not isinstance(name, str):
            raise InputError(f"vary's keys must be parameter names (strings), got {describe(name)}")
        label = f"vary[{name!r}]"
        listed = isinstance(spec, Sequence) or hasattr(spec, "__array__")
        if isinstance(spec, (str, bytes, Mapping)) or not listed or len(spec) not in (2, 3):
            raise InputError(f"{label} must be (lo, hi) or (lo, hi, n), got {describe(spec)}")
        lo = check_number(f"{label} lo", spec[0])
        hi = check_number(f"{label} hi", spec[1])
        n = check_whole(f"{label} n", spec[2], 1, max_designs) if len(spec) == 3 else None
        out.append((name, lo, hi, n))
    return out


def check_path(name: str, value: Any) -> Any:
    """A file path: a str or an os.PathLike."""
    if isinstance(value, (str, os.PathLike)):
        return value
    raise InputError(f"{name} must be a path to a mechanism file (a str or os.PathLike), "
                     f"got {describe(value)}")


def real_result(name: str, value: Any, where: str) -> None:
    """InputError unless a user function's return ``value`` is a real number (or a complex
    one, which the solvers report as a domain error)."""
    if not (is_real(value) or isinstance(value, complex)):
        raise InputError(f"{name} must return a real number, got {describe(value)} {where}")


def real_vector(name: str, value: Any, n: int, where: str) -> None:
    """InputError unless ``value`` (a residual F returned) is a sequence of n real numbers
    (not complex: the system solvers work in real arithmetic)."""
    if type(value) is list:
        for v in value:  # the common case, a list of floats: a plain loop, no generator
            if type(v) is not float:
                break
        else:
            return
    try:
        size = len(value)
    except TypeError:
        size = None
    if size is None or isinstance(value, (str, bytes)):
        raise InputError(f"{name} must return a sequence of {n} real numbers, got {describe(value)} {where}")
    if size != n:
        return  # the caller's own check names the count ("the system has 1 equations ...")
    for k, v in enumerate(value):
        if not is_real(v):
            raise InputError(f"{name} must return {n} real numbers; entry {k} is {describe(v)} {where}")


def real_matrix(name: str, value: Any, n: int, where: str) -> None:
    """InputError unless ``value`` (a Jacobian jac returned) is n rows of n numbers."""
    shape = f"a {n} x {n} matrix (a sequence of {n} rows of {n} numbers)"
    try:
        rows = list(value)
    except TypeError:
        raise InputError(f"{name} must return {shape}, got {describe(value)} {where}") from None
    if isinstance(value, (str, bytes)) or len(rows) != n:
        raise InputError(f"{name} must return {shape}, got {describe(value)} {where}")
    for row in rows:
        try:
            cells = list(row)
        except TypeError:
            raise InputError(f"{name} must return {shape}, got a row {describe(row)} {where}") from None
        if len(cells) != n or not all(is_real(c) for c in cells):
            raise InputError(f"{name} must return {shape}, got a row {describe(row)} {where}")


def guarded(call: Callable[[], Any], diagnose: Callable[[], None]) -> Any:
    """``call()``; if it raises TypeError or IndexError (what a user function that returns
    the wrong kind of value causes inside a solver), run ``diagnose``, which raises an
    InputError naming that function when it finds the fault, and otherwise re-raise: on
    valid input this costs nothing."""
    try:
        return call()
    except (TypeError, IndexError):
        diagnose()
        raise


def parse_motion(speed: str | None, accel: str | None, mechanism: Any,
                 names: tuple[str, str] = ("--speed", "--accel")) -> tuple[float | None, float]:
    """--speed and --accel in internal units (rad/s, rad/s^2, or length/s, length/s^2);
    ``names``: the options as the command names them (simulate's speed is --omega0)."""
    from .numbers import parse_quantity

    if speed is None:
        if accel is not None:
            raise InputError(f"{names[1]} needs {names[0]} (the driver's velocity)")
        return None, 0.0
    tables = _rate_units(mechanism)
    out = []
    accel = "0" if accel is None else accel  # an empty --accel '' is refused, not taken as 0
    for option, text, units in ((names[0], speed, tables[0]), (names[1], accel, tables[1])):
        value, _ = parse_quantity(option, text, units)
        if not rate_in_range(value):
            raise InputError(f"{option} {text!r} is out of range "
                             f"(0, or {MIN_RATE:g} to {MAX_RATE:g} in size)")
        out.append(value)
    return out[0], out[1]


def _rate_units(mechanism: Any) -> tuple[dict[str, float], dict[str, float]]:
    """--speed's and --accel's units, each with its factor to the internal unit ("": none
    given, internal)."""
    unit = mechanism.length_unit
    if mechanism.driver.kind == "angle":
        deg, rpm = RAD_PER_DEG, math.pi / 30.0
        return ({"": 1.0, "rad/s": 1.0, "deg/s": deg, "rpm": rpm},
                {"": 1.0, "rad/s^2": 1.0, "rad/s2": 1.0, "deg/s^2": deg, "deg/s2": deg, "rpm/s": rpm})
    return {"": 1.0, f"{unit}/s": 1.0}, {"": 1.0, f"{unit}/s^2": 1.0, f"{unit}/s2": 1.0}


def motion_text(speed: str | None, accel: str | None, mechanism: Any) -> str | None:
    """--speed and --accel as given, for a plot's title: "600 rpm, 0 rpm/s". A bare number
    is in the internal unit (rad/s, or the length unit per second); no --accel is 0 in the
    speed's unit per second. Checked as :func:`parse_motion` checks them."""
    parse_motion(speed, accel, mechanism)
    if speed is None:
        return None
    per = "rad" if mechanism.driver.kind == "angle" else mechanism.length_unit
    from .numbers import split_unit

    number, unit = split_unit(speed)  # type: ignore[misc]
    unit = unit or f"{per}/s"
    if accel is None:
        a_number, a_unit = "0", "rpm/s" if unit == "rpm" else f"{unit}^2"
    else:
        a_number, a_unit = split_unit(accel)  # type: ignore[misc]
        a_unit = a_unit or f"{per}/s^2"
    return f"{float(number):g} {unit}, {float(a_number):g} {a_unit}"


def driver_span(mechanism: Any, start: float | None, stop: float | None,
                turn_end: float = 360.0) -> tuple[float, float]:
    """The driver values a sweep, scan or animation runs between: --from and --to where
    given, else the file's ``[driver] range``, else a turn (0 to ``turn_end``) for an
    angle; a length driver has no natural range and asks for one."""
    given = getattr(mechanism, "driver_range", None)
    lo, hi = given if given is not None else (0.0, turn_end)
    if given is None and mechanism.driver.kind != "angle" and (start is None or stop is None):
        raise InputError(f"{mechanism.driver.name} is a length: give --from and --to "
                         "(or range = [LO, HI] under [driver] in the file)")
    a = check_number("--from", lo if start is None else start)
    b = check_number("--to", hi if stop is None else stop)
    if b < a:
        raise InputError(f"--to ({b:g}) must not be below --from ({a:g})")
    return a, b
