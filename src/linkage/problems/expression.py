"""Equations in x typed by users: parsed safely, compiled once to straight-line code.

The text is parsed with :func:`ast.parse` (which only builds a tree, it runs nothing)
and every node is checked against a whitelist: numbers, the name ``x``, the constants
``pi`` and ``e``, ``+ - * / **`` (``^`` is read as ``**``), unary signs, and calls of the
functions in :data:`FUNCTIONS` with one argument.

The checked tree becomes a list of single operations on numbered temporaries (static
single assignment), walked without recursion, so chains and nestings of any depth the
parser accepts cost time and memory linear in their length. Identical subexpressions
share one temporary (``sin(x)*sin(x)*...`` computes sin(x) once). From that list this
module *generates* Python source, from its own tokens only (temporary names, operator
symbols, ``repr`` of floats, whitelisted function names) and never from user text:

- ``f(x)``: the value;
- ``fprime(x)``, ``fsecond(x)``: exact first and second derivatives by forward-mode
  differentiation (each operation carries its value and derivatives), so their size
  grows linearly with the expression, never exponentially as repeated symbolic
  differentiation of products does;
- ``fbound(x)``: a first-order bound on the rounding error of the computed f(x)
  (each operation adds one rounding of its result and propagates its arguments'
  bounds by the local derivative), used to certify that a tiny |f| is a root.

Only constant folding simplifies: an operation on two numbers is computed once when it
is finite. No identity rule (0*a = 0, a/a = 1, a - a = 0) is ever applied, so a NaN or a
domain restriction in the text (``0/0 + x``, ``0*log(x) + x``) is kept.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping

from ..errors import ParseError
from ..records import frozen
from ..units import RAD_PER_DEG
from .scalar import ScalarProblem

MAX_LENGTH = 2000
MAX_OPERATIONS = 2000
"""Operations one equation may compile to (a 2000-character text stays well below)."""

Fn = Callable[[float], float]

DEG = RAD_PER_DEG
"""pi/180 (:data:`linkage.units.RAD_PER_DEG`): the degree functions' factor and their
derivatives' chain-rule factor."""
EPS = 2.0**-52


def _sign(v: float) -> float:
    return (v > 0.0) - (v < 0.0)


FUNCTIONS: dict[str, Fn] = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan,
    "asin": math.asin, "acos": math.acos, "atan": math.atan,
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh,
    "exp": math.exp, "log": math.log, "log10": math.log10, "sqrt": math.sqrt,
    "abs": abs,
    # the degree functions hold linkage.units' constant (no call in an equation's hot loop)
    "sind": lambda v: math.sin(v * DEG), "cosd": lambda v: math.cos(v * DEG),
    "tand": lambda v: math.tan(v * DEG),
    "asind": lambda v: math.asin(v) / DEG, "acosd": lambda v: math.acos(v) / DEG,
    "atand": lambda v: math.atan(v) / DEG,
}
"""Functions an equation may call. Angles in radians, except the ``*d`` ones (degrees)."""

CONSTANTS = {"pi": math.pi, "e": math.e}

# d/du fn(u) and d2/du2 fn(u) as source templates in u (the argument) and v (fn(u));
# g1 names the first derivative's temporary, usable in the second's template.
_RULES: dict[str, tuple[str, str]] = {
    "sin": ("_cos({u})", "-{v}"),
    "cos": ("-_sin({u})", "-{v}"),
    "tan": ("1.0 + {v} * {v}", "2.0 * {v} * {g1}"),
    "asin": ("1.0 / _sqrt(1.0 - {u} * {u})", "{u} * {g1} * {g1} * {g1}"),
    "acos": ("-1.0 / _sqrt(1.0 - {u} * {u})", "{u} * {g1} * {g1} * {g1}"),
    "atan": ("1.0 / (1.0 + {u} * {u})", "-2.0 * {u} * {g1} * {g1}"),
    "sinh": ("_cosh({u})", "{v}"),
    "cosh": ("_sinh({u})", "{v}"),
    "tanh": ("1.0 - {v} * {v}", "-2.0 * {v} * {g1}"),
    "exp": ("{v}", "{v}"),
    "log": ("1.0 / {u}", "-{g1} * {g1}"),
    "log10": (f"1.0 / ({{u}} * {math.log(10.0)!r})", "-{g1} / {u}"),
    "sqrt": ("0.5 / {v}", "-0.5 * {g1} / {u}"),
    "abs": ("_sign({u})", "0.0"),
    "sind": (f"{DEG!r} * _cos({{u}} * {DEG!r})", f"-{DEG * DEG!r} * {{v}}"),
    "cosd": (f"-{DEG!r} * _sin({{u}} * {DEG!r})", f"-{DEG * DEG!r} * {{v}}"),
    "tand": (f"{DEG!r} * (1.0 + _tan({{u}} * {DEG!r}) ** 2)",
             f"2.0 * {DEG!r} * _tan({{u}} * {DEG!r}) * {{g1}}"),
    "asind": (f"1.0 / ({DEG!r} * _sqrt(1.0 - {{u}} * {{u}}))", f"{DEG * DEG!r} * {{u}} * {{g1}} ** 3"),
    "acosd": (f"-1.0 / ({DEG!r} * _sqrt(1.0 - {{u}} * {{u}}))", f"{DEG * DEG!r} * {{u}} * {{g1}} ** 3"),
    "atand": (f"1.0 / ({DEG!r} * (1.0 + {{u}} * {{u}}))", f"-2.0 * {DEG!r} * {{u}} * {{g1}} * {{g1}}"),
}

def _small(e: float, u: float) -> float:
    """An argument's error bound where a first-order bound through a nonlinear operation
    holds (at most 1e-6 of the argument); infinite otherwise (log(sin(pi)): the argument
    may be zero, and no bound holds)."""
    return e if e <= 1e-6 * abs(u) else math.inf


def _quotient_err(q: float, b: float, eb: float) -> float:
    """How far a / b moves when b moves by up to eb: |q| eb / (|b| - eb), infinite once eb
    reaches |b| (the divisor may be zero: no first-order bound holds)."""
    room = abs(b) - eb
    return abs(q) * eb / room if room > 0.0 else math.inf


_NAMESPACE = {
    **{f"_{k}": v for k, v in FUNCTIONS.items()},
    "_cos": math.cos, "_sin": math.sin, "_tan": math.tan, "_sqrt": math.sqrt,
    "_cosh": math.cosh, "_sinh": math.sinh, "_pow": math.pow, "_log": math.log,
    "_sign": _sign, "_fabs": math.fabs, "_quotient_err": _quotient_err, "_small": _small,
    "__builtins__": {},
}


# --- the operation list -----------------------------------------------------------------

@frozen
class Op:
    """One operation: ``kind`` is ``num``, ``x``, ``neg``, ``+ - * / **`` or a function name;
    ``args`` index earlier operations; ``value`` is the number of a ``num``."""

    kind: str
    args: tuple[int, ...] = ()
    value: float = 0.0
    err: float = 0.0
    """For a ``num``: a bound on how far it is from the exact value it stands for (the
    rounding of a literal such as 0.1 or pi, and of every operation folded into it)."""


BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_FOLD: dict[str, Callable[..., float]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "**": math.pow, "neg": lambda a: -a,
}


class _Builder:
    """Appends operations, sharing identical ones and folding finite constant ones."""

    def __init__(self, what: str = "equation") -> None:
        self.what = what
        self.ops: list[Op] = []
        self.index: dict[tuple[str, tuple[int, ...], float], int] = {}

    def add(self, op: Op) -> int:
        if op.args and all(self.ops[a].kind == "num" for a in op.args):
            fn = _FOLD.get(op.kind) or FUNCTIONS.get(op.kind)
            vals = [self.ops[a].value for a in op.args]
            try:
                v = float(fn(*vals))  # type: ignore[misc]
                err = _folded_error(op.kind, vals, [self.ops[a].err for a in op.args], v)
            except OverflowError:  # raised at every x alike: the text is at fault, not a start
                shown = f" {op.kind} ".join(f"{v:g}" for v in vals) if len(vals) == 2 else \
                    f"{op.kind}({', '.join(f'{v:g}' for v in vals)})"
                raise ParseError(f"a constant in the {self.what} overflows a double ({shown}), so "
                                 "it cannot be evaluated at any point") from None
            except (ArithmeticError, ValueError, TypeError):
                v = err = math.nan
            if math.isfinite(v) and math.isfinite(err):
                op = Op("num", (), v, err)
        key = (op.kind, op.args, op.value, op.err)
        found = self.index.get(key)
        if found is not None:
            return found
        if len(self.ops) >= MAX_OPERATIONS:
            raise ParseError(f"the equation has more than {MAX_OPERATIONS} operations")
        self.ops.append(op)
        self.index[key] = len(self.ops) - 1
        return len(self.ops) - 1


def _literal(v: float, exact: bool) -> Op:
    """A number as written: integers are exact, anything else carries half an ulp."""
    return Op("num", (), v, 0.0 if exact else 0.5 * EPS * abs(v))


_SLOPES: dict[str, Callable[[float, float], float]] = {}


def _slope(name: str, u: float, v: float) -> float:
    """The derivative of a whitelisted function at u (v = fn(u)), from the same rules the
    generated code uses."""
    fn = _SLOPES.get(name)
    if fn is None:
        src = f"lambda u, v: {_RULES[name][0].format(u='u', v='v')}"
        fn = eval(compile(src, "<linkage-rule>", "eval"), dict(_NAMESPACE))  # our own template
        _SLOPES[name] = fn
    return fn(u, v)  # type: ignore[no-any-return]


def _folded_error(kind: str, vals: list[float], errs: list[float], v: float) -> float:
    """First-order bound on a folded constant's error: the arguments' errors carried by
    the local slope, plus one rounding of the result (as :func:`generate_bound`)."""
    own = EPS * abs(v)
    if kind == "neg":
        return errs[0]
    if kind in FUNCTIONS:
        return own + (abs(_slope(kind, vals[0], v)) * _small(errs[0], vals[0]) if errs[0] else 0.0)
    (a, b), (ea, eb) = vals, errs
    if kind in "+-":
        return own + ea + eb
    ea, eb = (_small(ea, a) if ea else 0.0), (_small(eb, b) if eb else 0.0)
    if kind == "*":
        return own + abs(b) * ea + abs(a) * eb
    if kind == "/":
        return own + ea / abs(b) + (_quotient_err(v, b, eb) if eb else 0.0)
    return own + (abs(b * v / a) * ea if ea else 0.0) + (abs(v * math.log(abs(a))) * eb if eb else 0.0)


def parse_tree(text: str, what: str) -> tuple[ast.Expression, str]:
    """The syntax tree of user text (``^`` read as ``**``) after the checks every parser
    here shares: not empty, at most MAX_LENGTH characters, a single expression. Returns
    the tree and the text as error messages show it; ``what`` names it in them."""
    if not isinstance(text, str) or not text.strip():
        raise ParseError(f"{what} is empty")
    if len(text) > MAX_LENGTH:
        raise ParseError(f"{what} is longer than {MAX_LENGTH} characters")
    src = text.replace("^", "**").strip()
    shown = text if len(text) <= 60 else text[:57] + "..."
    try:
        return ast.parse(src, mode="eval"), shown
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise ParseError(f"could not parse {what} {shown!r}: {exc.msg}{col}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ParseError(f"{what} {shown!r} is too deeply nested or malformed") from None


def call_argument(node: ast.Call, where: str) -> ast.AST:
    """The one argument of a call of a whitelisted function, or a ParseError; ``where``
    ends the message ("in the equation 'x'")."""
    if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
        name = node.func.id if isinstance(node.func, ast.Name) else "that call"
        raise ParseError(f"unknown function {name!r} {where}; allowed: {', '.join(sorted(FUNCTIONS))}")
    if len(node.args) != 1 or node.keywords:
        raise ParseError(f"{node.func.id}() takes exactly one argument {where}")
    return node.args[0]


def walk_postorder(root: ast.AST, children: Callable[[ast.AST], list[ast.AST]],
                   emit: Callable[[ast.AST], object]) -> None:
    """Visit a checked tree bottom-up without recursion, so nestings of any depth the
    parser accepts cost time and memory linear in their length: ``children(node)``
    checks a node and names those to visit first; ``emit(node)`` runs after them."""
    stack: list[tuple[ast.AST, bool]] = [(root, False)]
    while stack:
        node, visited = stack.pop()
        if visited:
            emit(node)
            continue
        stack.append((node, True))
        stack.extend((c, False) for c in reversed(children(node)))


def parse_ops(text: str, *, what: str = "equation", variables: tuple[str, ...] = ("x",),
              constants: Mapping[str, float] | None = None) -> tuple[Op, ...]:
    """Parse user text into a checked operation list (the last one is the result).

    ``variables``: the names it may use as variables (``x`` alone for an equation; a
    variable other than the first is an ``Op("var", value=its index)``, for
    :func:`function_of`); ``constants``: named numbers (``--const T0=5``), each read as a
    literal of that value."""
    tree, _ = parse_tree(text, f"the {what}")
    shown = text if len(text) <= 60 else text[:57] + "..."
    names = _Names(variables, dict(constants or {}))
    b = _Builder(what)
    out: list[int] = []
    walk_postorder(tree.body, lambda node: _check(node, shown, what, names),
                   lambda node: out.append(_emit(node, b, out, names)))
    # The result is the root's operation, which folding or sharing may have placed
    # before later (now unused) ones: keep the list up to it.
    return tuple(b.ops[: out[-1] + 1])


@frozen
class _Names:
    """The names a text may use besides pi, e and the functions."""

    variables: tuple[str, ...]
    constants: dict[str, float]

    def usage(self) -> str:
        named = [*self.variables, *self.constants, *CONSTANTS]
        return f"use {', '.join(named)} and {', '.join(sorted(FUNCTIONS))}"


def _check(node: ast.AST, shown: str, what: str, names: _Names) -> list[ast.AST]:
    """Validate one node; return the children to visit first."""
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ParseError(f"the {what} {shown!r} may contain only numbers, not {node.value!r}")
        try:
            v = float(node.value)
        except OverflowError:
            raise ParseError(f"a number in the {what} is too large for a double") from None
        if not math.isfinite(v):
            raise ParseError(f"a number in the {what} is too large for a double")
        return []
    if isinstance(node, ast.Name):
        if node.id in names.variables or node.id in names.constants or node.id in CONSTANTS:
            return []
        raise ParseError(f"unknown name {node.id!r} in the {what} {shown!r}; {names.usage()}")
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
        return [node.operand]
    if isinstance(node, ast.BinOp) and type(node.op) in BINOPS:
        return [node.left, node.right]
    if isinstance(node, ast.Call):
        return [call_argument(node, f"in the {what} {shown!r}")]
    raise ParseError(f"{type(node).__name__} is not allowed in the {what} {shown!r}; "
                     f"use numbers, {', '.join(names.variables)}, + - * / ** and functions")


def _emit(node: ast.AST, b: _Builder, out: list[int], names: _Names) -> int:
    if isinstance(node, ast.Constant):
        v = float(node.value)
        return b.add(_literal(v, v.is_integer() and abs(v) <= 2.0**53))
    if isinstance(node, ast.Name):
        if node.id in names.variables:
            i = names.variables.index(node.id)
            return b.add(Op("x") if i == 0 else Op("var", (), float(i)))
        if node.id in names.constants:  # a named constant stands for its value, as written
            return b.add(_literal(names.constants[node.id], False))
        return b.add(_literal(CONSTANTS[node.id], False))
    if isinstance(node, ast.UnaryOp):
        a = out.pop()
        return a if isinstance(node.op, ast.UAdd) else b.add(Op("neg", (a,)))
    if isinstance(node, ast.BinOp):
        right, left = out.pop(), out.pop()
        return b.add(Op(BINOPS[type(node.op)], (left, right)))
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
    return b.add(Op(node.func.id, (out.pop(),)))


# --- code generation --------------------------------------------------------------------

def _num(v: float) -> str:
    return repr(v) if v >= 0.0 else f"({v!r})"


class _Source:
    """A generated ``fn`` being written: its lines, and per op the expression (a name or a
    literal) of its value and of its first and second derivatives (None: identically zero)."""

    def __init__(self, order: int) -> None:
        self.order = order
        self.lines = ["def fn(x):"]
        self.v: list[str] = []
        self.d: list[str | None] = []
        self.dd: list[str | None] = []

    def emit(self, name: str, expr: str) -> str:
        self.lines.append(f"    {name} = {expr}")
        return name

    def push(self, value: str, first: str | None, second: str | None) -> None:
        self.v.append(value)
        self.d.append(first)
        self.dd.append(second)


def generate(ops: tuple[Op, ...], order: int) -> str:
    """Source of ``def fn(x)`` returning the value (order 0), f' (1) or f'' (2)."""
    s = _Source(order)
    for i, op in enumerate(ops):
        if op.kind == "num":
            s.push(_num(op.value), None, None)
        elif op.kind == "x":
            s.push("x", "1.0" if order else None, None)
        elif op.kind == "var":  # another variable: held fixed by the derivatives (partial in x)
            s.push(f"v{int(op.value)}", None, None)
        elif op.kind == "neg":
            a = op.args[0]
            va, da, dda = s.v[a], s.d[a], s.dd[a]
            s.push(s.emit(f"t{i}", f"-{va}"), s.emit(f"d{i}", f"-{da}") if order and da else None,
                   s.emit(f"e{i}", f"-{dda}") if order > 1 and dda else None)
        elif op.kind in FUNCTIONS:
            _function(s, i, op)
        else:
            _binary(s, i, op, ops)
    result = [s.v, s.d, s.dd][order][-1]
    s.lines.append(f"    return {result or '0.0'}")
    return "\n".join(s.lines) + "\n"


def _function(s: _Source, i: int, op: Op) -> None:
    """A function of one argument, by the chain rule (:data:`_RULES`)."""
    a = op.args[0]
    va, da, dda = s.v[a], s.d[a], s.dd[a]
    vt = s.emit(f"t{i}", f"_{op.kind}({va})")
    if not (s.order and da):
        s.push(vt, None, None)
        return
    g1 = s.emit(f"g{i}", _RULES[op.kind][0].format(u=va, v=vt))
    first = s.emit(f"d{i}", f"{g1} * {da}")
    second = None
    if s.order > 1:
        g2 = _RULES[op.kind][1].format(u=va, v=vt, g1=g1)
        terms = [f"({g2}) * {da} * {da}"] + ([f"{g1} * {dda}"] if dda else [])
        second = s.emit(f"e{i}", " + ".join(terms))
    s.push(vt, first, second)


def _binary(s: _Source, i: int, op: Op, ops: tuple[Op, ...]) -> None:
    """a + b, a - b, a * b, a / b or a ** b, with its derivatives by the textbook rules."""
    a, c = op.args[0], op.args[1]
    va, da, dda = s.v[a], s.d[a], s.dd[a]
    vb, db, ddb = s.v[c], s.d[c], s.dd[c]
    k, t, z = op.kind, f"t{i}", "0.0"
    if k == "**":
        const_exp = ops[c].kind == "num"
        vt = s.emit(t, f"{va} * {va}" if const_exp and ops[c].value == 2.0 else f"_pow({va}, {vb})")
    else:
        vt = s.emit(t, f"{va} {k} {vb}")
    if not s.order or (da is None and db is None):
        s.push(vt, None, None)
        return
    second_too = s.order > 1
    if k in "+-":
        s.push(vt, s.emit(f"d{i}", f"{da or z} {k} {db or z}"),
               s.emit(f"e{i}", f"{dda or z} {k} {ddb or z}") if second_too and (dda or ddb) else None)
    elif k == "*":
        first = s.emit(f"d{i}", f"{da or z} * {vb} + {va} * {db or z}")
        s.push(vt, first, s.emit(f"e{i}", f"{dda or z} * {vb} + 2.0 * {da or z} * {db or z} + "
                                          f"{va} * {ddb or z}") if second_too else None)
    elif k == "/":
        di = s.emit(f"d{i}", f"({da or z} - {vt} * {db or z}) / {vb}")
        s.push(vt, di, s.emit(f"e{i}", f"({dda or z} - 2.0 * {di} * {db or z} - {vt} * {ddb or z}) / {vb}")
               if second_too else None)
    elif db is None:  # a ** c, c constant
        _constant_power(s, i, vt, va, da, dda, ops[c].value)
    else:  # a ** b = exp(b log a): d = v w, w = b' log a + b a'/a
        w = s.emit(f"w{i}", f"{db} * _log({va}) + {vb} * {da or z} / {va}")
        di = s.emit(f"d{i}", f"{vt} * {w}")
        second = None
        if second_too:
            wp = s.emit(f"q{i}", f"{ddb or z} * _log({va}) + 2.0 * {db} * {da or z} / {va} + "
                                 f"{vb} * ({dda or z} * {va} - {da or z} * {da or z}) / ({va} * {va})")
            second = s.emit(f"e{i}", f"{di} * {w} + {vt} * {wp}")
        s.push(vt, di, second)


def _constant_power(s: _Source, i: int, vt: str, va: str, da: str | None, dda: str | None, cv: float) -> None:
    """a ** c for a constant c: d = c a^(c-1) a', d2 = c (c-1) a^(c-2) a'^2 + c a^(c-1) a''."""
    if cv == 2.0:
        g1 = s.emit(f"g{i}", f"2.0 * {va}")
        g2 = "2.0"
    else:
        g1 = s.emit(f"g{i}", f"{_num(cv)} * _pow({va}, {_num(cv - 1.0)})")
        g2 = f"{_num(cv * (cv - 1.0))} * _pow({va}, {_num(cv - 2.0)})" if cv != 1.0 else "0.0"
    first = s.emit(f"d{i}", f"{g1} * {da}")
    second = None
    if s.order > 1:
        terms = [f"({g2}) * {da} * {da}"] + ([f"{g1} * {dda}"] if dda else [])
        second = s.emit(f"e{i}", " + ".join(terms))
    s.push(vt, first, second)


def generate_bound(ops: tuple[Op, ...]) -> str:
    """Source of ``def fn(x)`` returning a first-order bound on the rounding error of f(x):
    every operation contributes eps*|result| and passes on its arguments' bounds times the
    local derivative's magnitude."""
    lines = ["def fn(x):"]
    v: list[str] = []
    err: list[str | None] = []
    u = repr(EPS)
    for i, op in enumerate(ops):
        t = f"t{i}"
        if op.kind in ("num", "x", "var"):
            v.append({"num": _num(op.value), "x": "x", "var": f"v{int(op.value)}"}[op.kind])
            err.append(repr(op.err) if op.kind == "num" and op.err else None)
            continue
        a = op.args[0]
        if op.kind == "neg":
            lines.append(f"    {t} = -{v[a]}")
            v.append(t)
            err.append(err[a])
            continue
        if op.kind in FUNCTIONS:
            lines.append(f"    {t} = _{op.kind}({v[a]})")
            own = f"{u} * _fabs({t})"
            if err[a]:
                g1 = _RULES[op.kind][0].format(u=v[a], v=t)
                own += f" + _fabs({g1}) * _small({err[a]}, {v[a]})"
            lines.append(f"    r{i} = {own}")
            v.append(t)
            err.append(f"r{i}")
            continue
        c = op.args[1]
        va, vb, ea, eb = v[a], v[c], err[a], err[c]
        k = op.kind
        lines.append(f"    {t} = {'_pow(' + va + ', ' + vb + ')' if k == '**' else va + ' ' + k + ' ' + vb}")
        terms = [f"{u} * _fabs({t})"]
        if k in "+-":
            terms += [e for e in (ea, eb) if e]
        elif k == "*":
            terms += ([f"_fabs({vb}) * _small({ea}, {va})"] if ea else []) + \
                     ([f"_fabs({va}) * _small({eb}, {vb})"] if eb else [])
        elif k == "/":
            terms += ([f"{ea} / _fabs({vb})"] if ea else []) + \
                     ([f"_quotient_err({t}, {vb}, {eb})"] if eb else [])
        else:
            terms += ([f"_fabs({vb} * {t} / {va}) * _small({ea}, {va})"] if ea else []) + \
                     ([f"_fabs({t} * _log(_fabs({va}))) * _small({eb}, {vb})"] if eb else [])
        lines.append(f"    r{i} = {' + '.join(terms)}")
        v.append(t)
        err.append(f"r{i}")
    lines.append(f"    return {err[-1] or '0.0'}")
    return "\n".join(lines) + "\n"


def build(source: str) -> Fn:
    """Compile generated source (never user text) into a function."""
    namespace = dict(_NAMESPACE)
    exec(compile(source, "<linkage-equation>", "exec"), namespace)
    return namespace["fn"]  # type: ignore[no-any-return]


@frozen
class Expression:
    """A parsed function of x, compiled to straight-line code with exact derivatives."""

    text: str
    ops: tuple[Op, ...]

    @classmethod
    def parse(cls, text: str, *, what: str = "equation") -> Expression:
        return cls(text, parse_ops(text, what=what))

    def source(self, order: int = 0) -> str:
        """The generated code for f (0), f' (1), f'' (2); ``order=-1``: the rounding bound."""
        return generate_bound(self.ops) if order < 0 else generate(self.ops, order)

    def function(self) -> Fn:
        return build(self.source(0))

    def derivative(self) -> Fn:
        return build(self.source(1))

    def second_derivative(self) -> Fn:
        return build(self.source(2))

    def rounding_bound(self) -> Fn:
        return build(self.source(-1))


def function_of(text: str, variables: tuple[str, ...], constants: Mapping[str, float] | None = None,
                *, what: str = "expression") -> Callable[..., float]:
    """User text as a compiled function of several variables, called with them in the order
    of ``variables`` (``function_of("T0*(1 - omega/w0)", ("t", "theta", "omega"), {"T0": 5,
    "w0": 30})``); ``constants`` are named numbers. The same whitelist and code generation
    as an equation's (:func:`parse_ops`, :func:`generate`): the code is built from this
    module's own tokens, the variables named v0, v1, ... in it, never from user text."""
    from ..arguments import check_text

    check_text(what, text, optional=False)
    clash = [k for k in (constants or {}) if k in variables or k in CONSTANTS or k in FUNCTIONS]
    if clash:
        raise ParseError(f"the constant {clash[0]!r} has the name of a variable, constant or function")
    ops = parse_ops(text, what=what, variables=variables, constants=constants)
    header = "def fn(" + ", ".join(["x", *(f"v{i}" for i in range(1, len(variables)))]) + "):"
    return build(generate(ops, 0).replace("def fn(x):", header, 1))


def equation_problem(equation: str, g: str | None = None) -> ScalarProblem:
    """A ScalarProblem for ``equation = 0`` in x; ``g`` gives x = g(x) for fixed-point.

    Without ``g``, fixed-point iteration is not available for the equation.
    """
    from ..arguments import check_text

    check_text("equation", equation, optional=False)
    check_text("g", g)
    f = Expression.parse(equation)
    gx = Expression.parse(g, what="iteration function g") if g is not None else None
    return ScalarProblem(
        f=f.function(), fprime=f.derivative(), fsecond=f.second_derivative(),
        g=gx.function() if gx else None, gprime=gx.derivative() if gx else None,
        var="x", unit="", title=f"f(x) = {equation}", fbound=f.rounding_bound(),
    )
