"""Filters typed by users (``scan --where``): parsed like equations, never evaluated by Python.

The text goes through :func:`~linkage.problems.expression.parse_tree` (the equation
parser's own checks and :func:`ast.parse`, which only builds a tree; ``^`` is ``**``
there too) and every node is
checked against a whitelist: numbers, ``true``/``false``, quoted text compared with
``==``/``!=`` to a text column, the names of the records' columns and the constants
``pi`` and ``e``, ``+ - * / **``, unary signs, the functions of equations
(:data:`~linkage.problems.expression.FUNCTIONS`, one argument), comparisons (chains
too) and ``and``/``or``/``not``. The tree becomes a list of operations walked without
recursion and applied to whole columns with numpy. A comparison with NaN (a metric with
no solved position) is false, so such a design never passes a numeric test.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..errors import ParseError
from ..records import frozen
from .expression import (
    BINOPS,
    CONSTANTS,
    DEG,
    FUNCTIONS,
    MAX_OPERATIONS,
    call_argument,
    parse_tree,
    walk_postorder,
)

NUMPY_FUNCTIONS: dict[str, Callable[[Any], Any]] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
    "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "exp": np.exp,
    "log": np.log, "log10": np.log10, "sqrt": np.sqrt, "abs": np.abs,
    "sind": lambda v: np.sin(v * DEG), "cosd": lambda v: np.cos(v * DEG),
    "tand": lambda v: np.tan(v * DEG), "asind": lambda v: np.arcsin(v) / DEG,
    "acosd": lambda v: np.arccos(v) / DEG, "atand": lambda v: np.arctan(v) / DEG,
}
assert set(NUMPY_FUNCTIONS) == set(FUNCTIONS)

_COMPARE = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
_TESTS = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal, "==": np.equal,
          "!=": np.not_equal}
_ARITH = {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.true_divide, "**": np.power}
_WORDS = {"true": True, "false": False, "True": True, "False": False}


@frozen
class _Op:
    kind: str  # num, text, col, neg, not, and, or, an arithmetic symbol, a comparison, a function
    args: tuple[int, ...] = ()
    value: Any = None
    type: str = "number"  # number, bool or text


class Where:
    """A checked filter: call it with the columns (name -> array) to get a boolean mask."""

    def __init__(self, text: str, ops: tuple[_Op, ...]) -> None:
        self.text = text
        self.ops = ops

    @property
    def names(self) -> set[str]:
        return {op.value for op in self.ops if op.kind == "col"}

    def __call__(self, columns: Mapping[str, np.ndarray], size: int) -> np.ndarray:
        vals: list[Any] = []
        with np.errstate(all="ignore"):
            for op in self.ops:
                a = [vals[i] for i in op.args]
                if op.kind in ("num", "text"):
                    v = op.value
                elif op.kind == "col":
                    v = columns[op.value]
                elif op.kind == "neg":
                    v = np.negative(a[0])
                elif op.kind == "not":
                    v = np.logical_not(a[0])
                elif op.kind == "and":
                    v = np.logical_and(a[0], a[1])
                elif op.kind == "or":
                    v = np.logical_or(a[0], a[1])
                elif op.kind in _ARITH:
                    v = _ARITH[op.kind](a[0], a[1])
                elif op.kind in NUMPY_FUNCTIONS:
                    v = NUMPY_FUNCTIONS[op.kind](a[0])
                else:
                    v = _TESTS[op.kind](a[0], a[1])
                vals.append(v)
        out = np.broadcast_to(np.asarray(vals[-1], dtype=bool), (size,))
        return np.array(out)


def parse_where(text: str, columns: Mapping[str, str]) -> Where:
    """Check ``text`` against the whitelist; ``columns`` maps each column name to its type
    (number, bool or text). Raises ParseError with one line saying what is wrong."""
    tree, shown = parse_tree(text, "--where")
    ops: list[_Op] = []
    out: list[int] = []

    def emit(node: ast.AST) -> None:
        _emit(node, ops, out, shown, columns)
        if len(ops) > MAX_OPERATIONS:
            raise ParseError(f"--where has more than {MAX_OPERATIONS} operations")

    walk_postorder(tree.body, lambda node: _children(node, shown, columns), emit)
    if ops[out[-1]].type != "bool":
        raise ParseError(f"--where {shown!r} must be a test (a comparison, true/false, "
                         "and/or/not), not a number")
    return Where(text, tuple(ops))


def _children(node: ast.AST, shown: str, columns: Mapping[str, str]) -> list[ast.AST]:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, str):
            if len(node.value) > 100:
                raise ParseError(f"text in --where {shown!r} is longer than 100 characters")
            return []
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ParseError(f"--where {shown!r} may contain only numbers and quoted text, "
                             f"not {node.value!r}")
        try:
            v = float(node.value)
        except OverflowError:
            v = math.inf
        if not math.isfinite(v):
            raise ParseError("a number in --where is too large for a double")
        return []
    if isinstance(node, ast.Name):
        if node.id in columns or node.id in CONSTANTS or node.id in _WORDS:
            return []
        raise ParseError(f"unknown name {node.id!r} in --where {shown!r}; the columns are "
                         f"{', '.join(columns)}")
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub, ast.Not)):
        return [node.operand]
    if isinstance(node, ast.BinOp) and type(node.op) in BINOPS:
        return [node.left, node.right]
    if isinstance(node, ast.BoolOp) and isinstance(node.op, (ast.And, ast.Or)):
        return list(node.values)
    if isinstance(node, ast.Compare) and all(type(o) in _COMPARE for o in node.ops):
        return [node.left, *node.comparators]
    if isinstance(node, ast.Call):
        return [call_argument(node, f"in --where {shown!r}")]
    raise ParseError(f"{type(node).__name__} is not allowed in --where {shown!r}; use column "
                     "names, numbers, + - * / **, comparisons, and, or, not")


def _emit(node: ast.AST, ops: list[_Op], out: list[int], shown: str, columns: Mapping[str, str]) -> None:
    def add(op: _Op) -> None:
        ops.append(op)
        out.append(len(ops) - 1)

    def need(i: int, kind: str, what: str) -> None:
        if ops[i].type != kind:
            raise ParseError(f"--where {shown!r}: {what} needs a {kind}, got a {ops[i].type}")

    if isinstance(node, ast.Constant):
        if isinstance(node.value, str):
            add(_Op("text", (), node.value, "text"))
        else:
            add(_Op("num", (), float(node.value)))
        return
    if isinstance(node, ast.Name):
        if node.id in columns:  # a column shadows a constant of the same name
            add(_Op("col", (), node.id, columns[node.id]))
        elif node.id in _WORDS:
            add(_Op("num", (), _WORDS[node.id], "bool"))
        else:
            add(_Op("num", (), CONSTANTS[node.id]))
        return
    if isinstance(node, ast.UnaryOp):
        a = out.pop()
        if isinstance(node.op, ast.Not):
            need(a, "bool", "not")
            add(_Op("not", (a,), None, "bool"))
        else:
            need(a, "number", "a sign")
            if isinstance(node.op, ast.USub):
                add(_Op("neg", (a,)))
            else:
                out.append(a)
        return
    if isinstance(node, ast.BinOp):
        b, a = out.pop(), out.pop()
        need(a, "number", "arithmetic")
        need(b, "number", "arithmetic")
        add(_Op(BINOPS[type(node.op)], (a, b)))
        return
    if isinstance(node, ast.Call):
        a = out.pop()
        assert isinstance(node.func, ast.Name)
        need(a, "number", f"{node.func.id}()")
        add(_Op(node.func.id, (a,)))
        return
    if isinstance(node, ast.BoolOp):
        args = [out.pop() for _ in node.values][::-1]
        for a in args:
            need(a, "bool", "and/or")
        kind = "and" if isinstance(node.op, ast.And) else "or"
        acc = args[0]
        for a in args[1:]:
            ops.append(_Op(kind, (acc, a), None, "bool"))
            acc = len(ops) - 1
        out.append(acc)
        return
    assert isinstance(node, ast.Compare)
    items = [out.pop() for _ in range(len(node.comparators) + 1)][::-1]
    tests = []
    for op, a, b in zip(node.ops, items, items[1:]):
        ta, tb = ops[a].type, ops[b].type
        if "text" in (ta, tb):
            if ta != tb or type(op) not in (ast.Eq, ast.NotEq):
                raise ParseError(f"--where {shown!r}: text is compared only with == or != to a "
                                 "text column, e.g. grashof == \"crank-rocker\"")
        elif ta != tb:
            raise ParseError(f"--where {shown!r}: cannot compare a {ta} with a {tb}")
        ops.append(_Op(_COMPARE[type(op)], (a, b), None, "bool"))
        tests.append(len(ops) - 1)
    acc = tests[0]
    for t in tests[1:]:
        ops.append(_Op("and", (acc, t), None, "bool"))
        acc = len(ops) - 1
    out.append(acc)
