"""Equations in x typed by users: parsed safely, differentiated exactly.

The text is parsed with :func:`ast.parse` (which only builds a tree, it runs
nothing) and every node is checked against a whitelist: numbers, the name ``x``,
the constants ``pi`` and ``e``, ``+ - * / **`` (``^`` is read as ``**``), unary
signs, and calls of the functions in :data:`FUNCTIONS` with one argument. The tree
is rebuilt as this module's own small expression nodes, differentiated symbolically
(so f' is exact, not a finite difference) and turned into nested Python closures.
No user text is ever passed to ``eval``.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable
from dataclasses import dataclass

from ..errors import ParseError
from .scalar import ScalarProblem

MAX_LENGTH = 2000

Fn = Callable[[float], float]

DEG = math.pi / 180.0


def _sign(v: float) -> float:
    return (v > 0.0) - (v < 0.0)


FUNCTIONS: dict[str, Fn] = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan,
    "asin": math.asin, "acos": math.acos, "atan": math.atan,
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh,
    "exp": math.exp, "log": math.log, "log10": math.log10, "sqrt": math.sqrt,
    "abs": abs,
    "sind": lambda v: math.sin(v * DEG), "cosd": lambda v: math.cos(v * DEG),
    "tand": lambda v: math.tan(v * DEG),
    "asind": lambda v: math.asin(v) / DEG, "acosd": lambda v: math.acos(v) / DEG,
    "atand": lambda v: math.atan(v) / DEG,
}
"""Functions an equation may call. Angles in radians, except the ``*d`` ones (degrees)."""

_INTERNAL: dict[str, Fn] = {"sign": _sign}
CONSTANTS = {"pi": math.pi, "e": math.e}


# --- the expression tree -------------------------------------------------------------

class Node:
    """An expression node. Subclasses are frozen dataclasses."""

    def __str__(self) -> str:  # pragma: no cover - overridden
        raise NotImplementedError


@dataclass(frozen=True)
class Num(Node):
    value: float

    def __str__(self) -> str:
        return repr(self.value) if self.value >= 0 else f"({self.value!r})"


@dataclass(frozen=True)
class Var(Node):
    def __str__(self) -> str:
        return "x"


@dataclass(frozen=True)
class Bin(Node):
    op: str
    left: Node
    right: Node

    def __str__(self) -> str:
        return f"({self.left} {self.op} {self.right})"


@dataclass(frozen=True)
class Neg(Node):
    arg: Node

    def __str__(self) -> str:
        return f"(-{self.arg})"


@dataclass(frozen=True)
class Call(Node):
    name: str
    arg: Node

    def __str__(self) -> str:
        return f"{self.name}({self.arg})"


ZERO, ONE = Num(0.0), Num(1.0)


def _pow(a: float, b: float) -> float:
    # math.pow raises ValueError for (-8) ** (1/3) where ** would return a complex.
    return math.pow(a, b)


_OPS: dict[str, Callable[[float, float], float]] = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a / b,
    "**": _pow,
}


# --- construction with light simplification ---------------------------------------------

def add(a: Node, b: Node) -> Node:
    if a == ZERO:
        return b
    if b == ZERO:
        return a
    return _fold(Bin("+", a, b))


def sub(a: Node, b: Node) -> Node:
    if b == ZERO:
        return a
    if a == ZERO:
        return neg(b)
    return _fold(Bin("-", a, b))


def mul(a: Node, b: Node) -> Node:
    if a == ZERO or b == ZERO:
        return ZERO
    if a == ONE:
        return b
    if b == ONE:
        return a
    return _fold(Bin("*", a, b))


def div(a: Node, b: Node) -> Node:
    if a == ZERO:
        return ZERO
    if b == ONE:
        return a
    return _fold(Bin("/", a, b))


def power(a: Node, b: Node) -> Node:
    if b == ZERO:
        return ONE
    if b == ONE:
        return a
    return _fold(Bin("**", a, b))


def neg(a: Node) -> Node:
    if isinstance(a, Num):
        return Num(-a.value)
    if isinstance(a, Neg):
        return a.arg
    return Neg(a)


def call(name: str, a: Node) -> Node:
    return _fold(Call(name, a))


def _fold(n: Node) -> Node:
    """Evaluate constant sub-trees once; leave them alone if that fails (e.g. 1/0)."""
    if isinstance(n, Bin) and isinstance(n.left, Num) and isinstance(n.right, Num):
        try:
            v = _OPS[n.op](n.left.value, n.right.value)
        except (ArithmeticError, ValueError):
            return n
        return Num(v) if math.isfinite(v) else n
    if isinstance(n, Call) and isinstance(n.arg, Num):
        try:
            v = {**FUNCTIONS, **_INTERNAL}[n.name](n.arg.value)
        except (ArithmeticError, ValueError):
            return n
        return Num(float(v)) if math.isfinite(v) else n
    return n


def has_var(n: Node) -> bool:
    if isinstance(n, Var):
        return True
    if isinstance(n, Bin):
        return has_var(n.left) or has_var(n.right)
    if isinstance(n, (Neg, Call)):
        return has_var(n.arg)
    return False


# --- differentiation -------------------------------------------------------------------

def derivative(n: Node) -> Node:
    """d n / dx, exactly, by the usual rules."""
    if isinstance(n, Num):
        return ZERO
    if isinstance(n, Var):
        return ONE
    if isinstance(n, Neg):
        return neg(derivative(n.arg))
    if isinstance(n, Bin):
        a, b = n.left, n.right
        da, db = derivative(a), derivative(b)
        if n.op == "+":
            return add(da, db)
        if n.op == "-":
            return sub(da, db)
        if n.op == "*":
            return add(mul(da, b), mul(a, db))
        if n.op == "/":
            return div(sub(mul(da, b), mul(a, db)), power(b, Num(2.0)))
        if not has_var(b):  # a ** c
            return mul(mul(b, power(a, sub(b, ONE))), da)
        # a ** b = exp(b log a): d = a**b (b' log a + b a' / a)
        return mul(n, add(mul(db, call("log", a)), div(mul(b, da), a)))
    if isinstance(n, Call):
        a = n.arg
        da = derivative(a)
        if da == ZERO:
            return ZERO
        return mul(_outer_derivative(n.name, a), da)
    raise TypeError(n)  # pragma: no cover


def _outer_derivative(name: str, a: Node) -> Node:
    one_minus_sq = sub(ONE, power(a, Num(2.0)))
    deg = Num(DEG)
    rules: dict[str, Callable[[], Node]] = {
        "sin": lambda: call("cos", a),
        "cos": lambda: neg(call("sin", a)),
        "tan": lambda: div(ONE, power(call("cos", a), Num(2.0))),
        "asin": lambda: div(ONE, call("sqrt", one_minus_sq)),
        "acos": lambda: neg(div(ONE, call("sqrt", one_minus_sq))),
        "atan": lambda: div(ONE, add(ONE, power(a, Num(2.0)))),
        "sinh": lambda: call("cosh", a),
        "cosh": lambda: call("sinh", a),
        "tanh": lambda: sub(ONE, power(call("tanh", a), Num(2.0))),
        "exp": lambda: call("exp", a),
        "log": lambda: div(ONE, a),
        "log10": lambda: div(ONE, mul(a, Num(math.log(10.0)))),
        "sqrt": lambda: div(ONE, mul(Num(2.0), call("sqrt", a))),
        "abs": lambda: call("sign", a),
        "sign": lambda: ZERO,
        "sind": lambda: mul(deg, call("cosd", a)),
        "cosd": lambda: neg(mul(deg, call("sind", a))),
        "tand": lambda: div(deg, power(call("cosd", a), Num(2.0))),
        "asind": lambda: div(Num(1.0 / DEG), call("sqrt", one_minus_sq)),
        "acosd": lambda: neg(div(Num(1.0 / DEG), call("sqrt", one_minus_sq))),
        "atand": lambda: div(Num(1.0 / DEG), add(ONE, power(a, Num(2.0)))),
    }
    return rules[name]()


# --- evaluation ---------------------------------------------------------------------------

def compile_node(n: Node) -> Fn:
    """Turn a tree into a Python function of x, as nested closures."""
    if isinstance(n, Num):
        v = n.value
        return lambda x: v
    if isinstance(n, Var):
        return lambda x: x
    if isinstance(n, Neg):
        fa = compile_node(n.arg)
        return lambda x: -fa(x)
    if isinstance(n, Call):
        fn = {**FUNCTIONS, **_INTERNAL}[n.name]
        fa = compile_node(n.arg)
        return lambda x: fn(fa(x))
    assert isinstance(n, Bin)
    fl, fr = compile_node(n.left), compile_node(n.right)
    if n.op == "+":
        return lambda x: fl(x) + fr(x)
    if n.op == "-":
        return lambda x: fl(x) - fr(x)
    if n.op == "*":
        return lambda x: fl(x) * fr(x)
    if n.op == "/":
        return lambda x: fl(x) / fr(x)
    if isinstance(n.right, Num) and n.right.value == 2.0:
        def square(x: float) -> float:
            t = fl(x)
            return t * t
        return square
    return lambda x: _pow(fl(x), fr(x))


# --- parsing ---------------------------------------------------------------------------------

_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}


def parse(text: str, *, what: str = "equation") -> Node:
    """Parse user text into a checked expression tree, or raise ParseError (one line)."""
    if not isinstance(text, str) or not text.strip():
        raise ParseError(f"the {what} is empty")
    if len(text) > MAX_LENGTH:
        raise ParseError(f"the {what} is longer than {MAX_LENGTH} characters")
    src = text.replace("^", "**").strip()
    try:
        tree = ast.parse(src, mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise ParseError(f"could not parse the {what} {text!r}: {exc.msg}{col}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ParseError(f"the {what} {text!r} is too deeply nested or malformed") from None
    try:
        return _convert(tree.body, text, what)
    except RecursionError:
        raise ParseError(f"the {what} {text!r} is too deeply nested") from None


def _convert(node: ast.AST, text: str, what: str) -> Node:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ParseError(f"the {what} {text!r} may contain only numbers, not {node.value!r}")
        try:
            v = float(node.value)
        except OverflowError:
            raise ParseError(f"the number {node.value} in the {what} is too large") from None
        return Num(v)
    if isinstance(node, ast.Name):
        if node.id == "x":
            return Var()
        if node.id in CONSTANTS:
            return Num(CONSTANTS[node.id])
        raise ParseError(
            f"unknown name {node.id!r} in the {what} {text!r}; use x, pi, e and "
            f"{', '.join(sorted(FUNCTIONS))}")
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
        inner = _convert(node.operand, text, what)
        return inner if isinstance(node.op, ast.UAdd) else neg(inner)
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        left = _convert(node.left, text, what)
        right = _convert(node.right, text, what)
        op = _BINOPS[type(node.op)]
        return {"+": add, "-": sub, "*": mul, "/": div, "**": power}[op](left, right)
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
            name = node.func.id if isinstance(node.func, ast.Name) else ast.unparse(node.func)
            raise ParseError(
                f"unknown function {name!r} in the {what} {text!r}; "
                f"allowed: {', '.join(sorted(FUNCTIONS))}")
        if len(node.args) != 1 or node.keywords:
            raise ParseError(f"{node.func.id}() takes exactly one argument in the {what} {text!r}")
        return call(node.func.id, _convert(node.args[0], text, what))
    shown = ast.unparse(node) if hasattr(ast, "unparse") else type(node).__name__
    raise ParseError(f"{shown!r} is not allowed in the {what} {text!r}; "
                     "use numbers, x, + - * / ** and functions")


@dataclass(frozen=True)
class Expression:
    """A parsed function of x with its exact first and second derivatives."""

    text: str
    tree: Node
    d1: Node
    d2: Node

    @classmethod
    def parse(cls, text: str, *, what: str = "equation") -> Expression:
        tree = parse(text, what=what)
        d1 = derivative(tree)
        return cls(text, tree, d1, derivative(d1))

    def function(self) -> Fn:
        return compile_node(self.tree)

    def derivative(self) -> Fn:
        return compile_node(self.d1)

    def second_derivative(self) -> Fn:
        return compile_node(self.d2)


def equation_problem(equation: str, g: str | None = None) -> ScalarProblem:
    """A ScalarProblem for ``equation = 0`` in x; ``g`` gives x = g(x) for fixed-point.

    Without ``g``, fixed-point iteration is not available for the equation.
    """
    f = Expression.parse(equation)
    gx = Expression.parse(g, what="iteration function g") if g is not None else None
    return ScalarProblem(
        f=f.function(), fprime=f.derivative(), fsecond=f.second_derivative(),
        g=gx.function() if gx else None, gprime=gx.derivative() if gx else None,
        var="x", unit="", title=f"f(x) = {equation}",
    )
