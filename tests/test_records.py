"""records.frozen: dataclass(frozen=True) with its generated methods' bytecode kept
between runs (docs/performance.md, "Dataclass methods kept between runs")."""

from __future__ import annotations

import dataclasses
import inspect
import marshal
import os
import re
import subprocess
import sys
import threading
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
    for junk in (b"", b"\x00garbage", marshal.dumps({"x": 1}), marshal.dumps([1])):
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
