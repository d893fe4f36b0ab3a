"""records.frozen: dataclass(frozen=True) with its generated methods' bytecode kept
between runs (docs/performance.md, "Dataclass methods kept between runs")."""

from __future__ import annotations

import collections
import copy
import dataclasses
import inspect
import marshal
import os
import re
import subprocess
import sys
import threading
import typing
from pathlib import Path

import pytest

from linkage import records

METHODS = ("__init__", "__repr__", "__eq__", "__hash__", "__setattr__", "__delattr__")


@pytest.fixture
def store(tmp_path, monkeypatch):
    """An empty store in tmp_path, as a fresh process sees it."""
    monkeypatch.setattr(records, "STORE", str(tmp_path))
    monkeypatch.setattr(records, "_codes", {})
    monkeypatch.setattr(records, "_added", set())
    monkeypatch.setattr(records, "_used", {})
    monkeypatch.setattr(records, "KEPT_MODULES", "")  # this test module's classes kept too
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    return tmp_path


def _shape(cls: type) -> list[tuple]:
    out = []
    for name in METHODS:
        fn = cls.__dict__.get(name)
        code = fn.__code__
        out.append((name, code.co_code, code.co_consts, code.co_names, code.co_varnames,
                    code.co_filename, code.co_qualname, fn.__qualname__, fn.__defaults__,
                    fn.__kwdefaults__, fn.__annotations__))
    return out


def _classes(make):
    """The same two class statements (one with defaults and a factory), made by ``make``."""
    @make
    class Point:
        x: float
        y: float = 0.0
        tags: tuple[str, ...] = ()

    @make
    class Box:
        corner: Point
        size: list[float] = dataclasses.field(default_factory=list)
        label: str | None = None

    return Point, Box


def test_frozen_is_dataclass_frozen_cold_and_warm(store):
    """Compiled (cold store), read back (warm, another process's store) and plain
    dataclass(frozen=True): the same methods, code for code, annotations included (this
    test module has ``from __future__ import annotations``; dataclasses compiles without it)."""
    plain = _classes(dataclasses.dataclass(frozen=True))
    cold = _classes(records.frozen)
    records.save()
    tag = sys.implementation.cache_tag
    assert sorted(p.name for p in store.iterdir()) == [f"dataclass-{__name__}.{tag}.marshal"]
    records._codes.clear()
    warm = _classes(records.frozen)
    for a, b, c in zip(plain, cold, warm):
        assert _shape(a) == _shape(b) == _shape(c)
        assert [(f.name, f.type, f.default) for f in dataclasses.fields(a)] == \
            [(f.name, f.type, f.default) for f in dataclasses.fields(c)]
    point, box = warm
    p = point(1.5)
    assert repr(p).endswith("Point(x=1.5, y=0.0, tags=())")
    assert p == point(1.5, 0.0) and hash(p) == hash(point(1.5, 0.0)) and p != point(2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.x = 2.0  # type: ignore[misc]
    b1, b2 = box(p), box(p)
    assert b1.size == [] and b1.size is not b2.size


def test_a_kept_code_is_used_only_for_its_own_text(store):
    """The store is keyed by the whole source: a class whose fields differ compiles anew."""
    _classes(records.frozen)
    before = len(records._codes[__name__])

    @records.frozen
    class Other:
        a: int
        b: int = 2

    assert len(records._codes[__name__]) > before
    assert Other(1) == Other(1, 2) and repr(Other(1)).endswith("Other(a=1, b=2)")


def test_a_damaged_or_foreign_store_is_read_as_empty_and_replaced(store):
    path = Path(records.store_path(__name__))
    from importlib.util import MAGIC_NUMBER

    from linkage.files import kept_bytes

    code = compile("x = 1", "<string>", "exec")
    other_magic = bytes([MAGIC_NUMBER[0] ^ 1]) + MAGIC_NUMBER[1:]
    for junk in (b"", b"\x00garbage", marshal.dumps({"x": 1}), marshal.dumps([1]), kept_bytes({"x": 1}),
                 kept_bytes([1]), other_magic + marshal.dumps({"a": code})):
        path.write_bytes(junk)
        records._codes.clear()
        records._added.clear()
        point, _ = _classes(records.frozen)
        assert point(1.0) == point(1.0, 0.0)
        records.save()
        assert records._read(str(path))  # replaced by a real table


def test_nothing_is_written_without_bytecode(store, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    _classes(records.frozen)
    records.save()
    assert list(store.iterdir()) == []


def test_an_unwritable_store_is_no_error(store, monkeypatch):
    monkeypatch.setattr(records, "STORE", str(store / "a_file"))
    (store / "a_file").write_text("not a directory")
    point, _ = _classes(records.frozen)
    records.save()
    assert point(1.0).x == 1.0


def test_other_dataclasses_pass_straight_through(store):
    """A class made by plain dataclass (a user's, another thread's) is never kept, and
    dataclasses' own namespace is as it was after frozen returns."""
    assert "exec" not in dataclasses.__dict__
    seen = []

    def other_thread():
        @dataclasses.dataclass(frozen=True)
        class Theirs:
            z: int

        seen.append(Theirs(3).z)

    t = threading.Thread(target=other_thread)
    _classes(records.frozen)
    t.start()
    t.join()
    _classes(dataclasses.dataclass(frozen=True))
    assert seen == [3]
    assert "exec" not in dataclasses.__dict__
    assert all("Theirs" not in src for codes in records._codes.values() for src in codes)


def test_the_cli_prints_the_same_from_kept_and_compiled_methods(tmp_path):
    """A fresh process with no store (writing it) and one reading it print the same."""
    code = ("import sys, linkage.records as r; r.STORE = sys.argv[1]; "
            "from linkage.cli import main; "
            "sys.argv = ['linkage', 'sweep', sys.argv[2], '--step', '45']; main()")
    from linkage.samples import sample_path

    args = [sys.executable, "-c", code, str(tmp_path), str(sample_path("crank_rocker.toml"))]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    first = subprocess.run(args, capture_output=True, text=True, env=env)
    kept = sorted(p.name for p in tmp_path.iterdir())
    second = subprocess.run(args, capture_output=True, text=True, env=env)
    assert first.returncode == second.returncode == 0, first.stderr + second.stderr
    assert first.stdout == second.stdout and "theta" in first.stdout
    assert any(name.startswith("dataclass-linkage.result.") for name in kept)
    assert sorted(p.name for p in tmp_path.iterdir()) == kept


def test_every_frozen_dataclass_of_the_package_is_made_by_records_frozen():
    """One way to make the package's frozen records: a new class that skips records.frozen
    would compile its methods at every import again."""
    src = Path(records.__file__).parent
    offenders = [str(p.relative_to(src)) for p in sorted(src.rglob("*.py"))
                 if re.search(r"^@(dataclasses\.)?dataclass\(frozen=True\)", p.read_text(), re.M)]
    assert offenders == []


def test_every_named_tuple_of_the_package_is_made_by_records_named_tuple():
    """One way to make the package's named tuples too: typing's own compiles a ForwardRef per
    field and namedtuple's __new__ at every import (records.py is the one module that uses it)."""
    src = Path(records.__file__).parent
    pattern = r"^from typing import [^\n]*\bNamedTuple\b|\btyping\.NamedTuple\b"
    offenders = [str(p.relative_to(src)) for p in sorted(src.rglob("*.py"))
                 if p.name != "records.py" and re.search(pattern, p.read_text(), re.M)]
    assert offenders == []


def test_a_users_class_made_by_frozen_is_not_kept(store, monkeypatch):
    monkeypatch.setattr(records, "KEPT_MODULES", "linkage.")
    point, _ = _classes(records.frozen)
    records.save()
    assert point(1.0) == point(1.0, 0.0) and list(store.iterdir()) == []


def test_an_edited_class_leaves_its_old_texts_at_the_next_write(store):
    """The store holds the texts its last writing run used, not every text ever made."""
    _classes(records.frozen)
    records.save()
    first = set(records._read(records.store_path(__name__)))
    records._codes.clear()
    records._used.clear()

    @records.frozen
    class Point:  # the same name, edited: one field more
        x: float
        y: float = 0.0
        z: float = 0.0

    records.save()
    second = set(records._read(records.store_path(__name__)))
    assert second and not (second - set(records._used[__name__])) and len(second) < len(first) + 6


def test_the_store_follows_pycache_prefix(monkeypatch, tmp_path):
    monkeypatch.setattr(sys, "pycache_prefix", str(tmp_path))
    path = records.store_path("linkage.result")
    assert path.startswith(str(tmp_path)) and path.endswith(".marshal")


def test_a_dataclass_made_in_another_thread_meanwhile_is_as_ever(store):
    """While frozen makes a class (its default read by dataclass blocks it there), another
    thread's plain dataclass compiles as dataclasses compiles it: evaluated annotations,
    not this module's string ones (records.py has the annotations future)."""
    inside, release = threading.Event(), threading.Event()

    class Slow:
        def __get__(self, obj, owner):
            inside.set()
            release.wait(5)
            return 0

    out = {}

    def user_thread():
        inside.wait(5)
        try:
            @dataclasses.dataclass
            class User:
                x: int
                y: float = 1.0

            out["during"] = (User.__init__.__annotations__, str(inspect.signature(User)), inside.is_set())
        finally:
            release.set()

    t = threading.Thread(target=user_thread)
    t.start()

    @records.frozen
    class Pkg:
        x: int = Slow()

    t.join()

    @dataclasses.dataclass
    class User:
        x: int
        y: float = 1.0

    assert out["during"] == (User.__init__.__annotations__, str(inspect.signature(User)), True)
    assert "exec" not in dataclasses.__dict__


# --- records.NamedTuple: typing.NamedTuple's class syntax, namedtuple's __new__ kept -------

def _tuples(base):
    """The same class statements (defaults, a method, a property, a class attribute, a
    docstring, a nested class) with ``base`` as their base."""
    class Plain(base):
        a: int
        b: str

    class Point(base):
        """A point."""

        x: float
        y: float = 0.0
        tags: tuple[str, ...] = ()
        ORIGIN_NAME = "O"

        def norm(self) -> float:
            return (self.x * self.x + self.y * self.y) ** 0.5

        @property
        def flipped(self) -> Point:
            return self._replace(x=self.y, y=self.x)

    class Outer:
        class Inner(base):
            value: int | None = None

    return Plain, Point, Outer.Inner


_METHODS = (classmethod, staticmethod, property)


def _code_of(v) -> object:
    """A method's code (namedtuple's methods: the very code object of collections' closures)."""
    f = v.fget if isinstance(v, property) else getattr(v, "__func__", v)
    return (type(v), f.__code__, f.__name__, f.__defaults__)


def _tuple_shape(cls: type) -> dict:
    new = cls.__new__
    code = new.__code__
    own = {k: v for k, v in vars(cls).items() if k not in ("__new__", "__annotations__")}
    return {"mro": [c.__name__ for c in cls.__mro__], "metaclass": type(cls), "own": sorted(own),
            "attrs": {k: v for k, v in own.items() if not callable(v) and not isinstance(v, _METHODS)
                      and type(v).__name__ != "_tuplegetter"},
            "getters": {k: v.__reduce__()[1] for k, v in own.items() if type(v).__name__ == "_tuplegetter"},
            "code": {k: _code_of(v) for k, v in own.items() if callable(v) or isinstance(v, _METHODS)},
            "new": (code.co_code, code.co_consts, code.co_names, code.co_varnames, code.co_filename,
                    new.__name__, new.__qualname__, new.__doc__, new.__defaults__, new.__kwdefaults__),
            "annotations": {k: getattr(v, "__forward_arg__", v) for k, v in cls.__annotations__.items()},
            "new annotations": {k: getattr(v, "__forward_arg__", v) for k, v in new.__annotations__.items()},
            "hints": typing.get_type_hints(cls),
            "signature": re.sub(r"ForwardRef\(('[^']*'|\"[^\"]*\")\)", r"\1", str(inspect.signature(cls))),
            "orig bases": getattr(cls, "__orig_bases__", None)}


def test_named_tuple_is_typing_named_tuple_cold_and_warm(store):
    """Compiled (cold store), read back (warm) and typing.NamedTuple's: the same class,
    attribute for attribute and __new__ code for code; the annotations are the strings the
    body wrote where typing holds ForwardRefs of them, and read as the same type hints."""
    plain = _tuples(typing.NamedTuple)
    cold = _tuples(records.NamedTuple)
    records.save()
    records._codes.clear()
    warm = _tuples(records.NamedTuple)
    assert any(key.startswith(records.EVAL_KEY) for key in records._codes[__name__])
    for a, b, c in zip(plain, cold, warm):
        assert _tuple_shape(a) == _tuple_shape(b) == _tuple_shape(c)
        assert all(type(v) is str for v in c.__annotations__.values())
        assert c.__new__.__annotations__ is c.__annotations__
    for point in (plain[1], warm[1]):
        p = point(3.0, 4.0)
        assert isinstance(p, tuple) and p == (3.0, 4.0, ()) and hash(p) == hash((3.0, 4.0, ()))
        assert repr(p) == "Point(x=3.0, y=4.0, tags=())" and p.norm() == 5.0
        assert p.flipped == point(4.0, 3.0) and p._asdict() == {"x": 3.0, "y": 4.0, "tags": ()}
        assert point._make([1.0, 2.0, ("t",)]) == point(1.0, 2.0, ("t",)) and point(1.0).y == 0.0
        assert copy.deepcopy(p) == p and type(copy.deepcopy(p)) is point and p.ORIGIN_NAME == "O"
        with pytest.raises(AttributeError):
            p.x = 1.0  # type: ignore[misc]
        with pytest.raises(TypeError):
            point()  # type: ignore[call-arg]
    assert warm[2].__qualname__ == plain[2].__qualname__ and warm[2]().value is None


def test_named_tuple_refuses_what_typing_refuses(store):
    """typing's own class maker decides: the same errors, word for word."""
    def errors(base):
        out = []
        bodies = ("a: int = 1\n    b: int", "a: int\n    def _replace(self): pass",
                  "a: int\n    __slots__ = ()")
        for body in bodies:
            try:
                exec(f"class Bad(base):\n    {body}\n", {"base": base, "__name__": __name__})
            except (TypeError, AttributeError) as exc:
                out.append((type(exc), str(exc)))
        return out

    assert errors(records.NamedTuple) == errors(typing.NamedTuple) and len(errors(typing.NamedTuple)) == 3

    def with_a_second_base(base):
        try:
            class Two(base, dict):
                a: int
        except TypeError as exc:
            return str(exc)
        return None

    assert with_a_second_base(records.NamedTuple) == with_a_second_base(typing.NamedTuple) is not None
    t = typing.TypeVar("t")

    def generic(base):
        class Holder(base, typing.Generic[t]):
            item: t

        return repr(Holder[int]).rsplit(".", 1)[-1], Holder(1), Holder.__mro__[1:]

    if sys.version_info >= (3, 11):  # a generic NamedTuple is 3.11's (3.10 refuses both alike, above)
        assert generic(records.NamedTuple) == generic(typing.NamedTuple)
    with pytest.raises(TypeError, match="base class"):
        records.NamedTuple("Functional", [("a", int)])


def test_a_namedtuple_made_in_another_thread_meanwhile_is_as_ever(store):
    """While records.NamedTuple makes a class (its field's name, read by namedtuple, blocks
    it there), another thread's collections.namedtuple evaluates its __new__ as ever
    (through the pass-through), and it is not kept; collections' namespace is as it was
    afterwards."""
    inside, release = threading.Event(), threading.Event()

    class SlowName(str):
        def __str__(self):  # namedtuple takes str() of each field name
            inside.set()
            release.wait(5)
            return str.__str__(self)

    out = {}

    def user_thread():
        inside.wait(5)
        try:
            theirs = collections.namedtuple("Theirs", "p q", defaults=(1,))
            out["during"] = (theirs(0), theirs.__new__.__code__.co_filename, "eval" in collections.__dict__)
        finally:
            release.set()

    t = threading.Thread(target=user_thread)
    t.start()
    body = {"__module__": __name__, "__qualname__": "Pkg", "__annotations__": {SlowName("x"): "int"}}
    made = records.named_tuple("Pkg", (records._KEPT_BASE,), body)
    t.join()
    assert made(0) == (0,) and made._fields == ("x",)
    assert repr(out["during"][0]) == "Theirs(p=0, q=1)" and out["during"][1:] == ("<string>", True)
    assert "eval" not in collections.__dict__
    assert all("_cls, p, q" not in src for codes in records._codes.values() for src in codes)


def test_a_users_named_tuple_is_not_kept(store, monkeypatch):
    monkeypatch.setattr(records, "KEPT_MODULES", "linkage.")
    point = _tuples(records.NamedTuple)[1]
    records.save()
    assert point(1.0) == point(1.0, 0.0) and list(store.iterdir()) == [] and __name__ not in records._codes


def test_an_undocumented_class_reads_the_docstring_dataclass_writes(store):
    """dataclass writes a class without a docstring its name and signature (by
    inspect.signature, most of making such a class): frozen writes it when first read,
    the same text, read from the class, an instance, inspect.getdoc and pydoc alike."""
    import pydoc

    plain = _classes(dataclasses.dataclass(frozen=True))
    kept = _classes(records.frozen)
    for a, b in zip(plain, kept):
        assert isinstance(b.__dict__["__doc__"], records.SignatureDoc)  # not written yet
        assert b.__doc__ == a.__doc__ and a.__doc__.startswith(a.__name__ + "(")
        assert b.__dict__["__doc__"] == a.__doc__  # written once, then a plain string
    point = kept[0]
    assert point(1.0).__doc__ == plain[0](1.0).__doc__ and inspect.getdoc(point) == inspect.getdoc(plain[0])
    assert pydoc.render_doc(point).replace(point.__qualname__, "") == \
        pydoc.render_doc(plain[0]).replace(plain[0].__qualname__, "")

    @records.frozen
    class Documented:
        """Its own words."""

        a: int

    class Sub(kept[1]):
        pass

    assert Documented.__doc__ == "Its own words." and Sub.__doc__ is None
