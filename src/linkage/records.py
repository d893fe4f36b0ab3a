"""The package's frozen dataclasses, made as :func:`dataclasses.dataclass` makes them, with
the bytecode of their generated methods kept between runs.

Python 3.11's ``dataclass`` writes each class's ``__init__``, ``__repr__``, ``__eq__``,
``__hash__``, ``__setattr__`` and ``__delattr__`` as source text and compiles it on every
import (a cold ``linkage sweep`` makes ten classes; what keeping them saves is measured in
docs/performance.md, "Dataclass methods kept between runs"). :func:`frozen` is
``dataclass(frozen=True)`` whose compilations, while it makes the class, go through
:func:`kept_code`: the code of a source this package's classes gave before, read back from
one file in the package's ``__pycache__`` as Python keeps a module's bytecode. The source
is the dictionary's key, compared whole, so a kept code object is the compilation of that
very text; the file's name carries the interpreter's ``cache_tag``. Nothing else changes:
the same source runs through the same ``exec`` with the same namespaces, compiled with the
flags ``dataclasses`` compiles it with (none inherited).

Only this package's classes made through :func:`frozen` (a module under ``linkage.``),
in the thread making one, use the store:
another thread's or a user's dataclasses compile as ever and are never written down, so
the file holds at most this package's classes' methods, and only the texts its last
writing run used (an edited class's old texts leave it). The directory is the package's
``__pycache__``, or its place under ``sys.pycache_prefix`` where that is set. Nothing is
written where Python writes no bytecode (``sys.dont_write_bytecode``) or the directory cannot be written; a
damaged or foreign file is read as empty and replaced.
"""

from __future__ import annotations

import builtins
import dataclasses
import os
import sys
import threading
from types import CodeType
from typing import Any, TypeVar

T = TypeVar("T")

KEPT_MODULES = "linkage."
"""The modules whose classes' methods are kept (a user's class made by :func:`frozen` is
made as ever)."""

_BESIDE = os.path.join(os.path.dirname(__file__), "__pycache__")
STORE: str | None = _BESIDE
"""The directory of the kept file (beside the package's own bytecode); None: nowhere."""

_STATE = threading.local()
"""``making``: the module whose class this thread is making through :func:`frozen`, or None."""

_MAKING = threading.RLock()
"""Held while :func:`frozen` has ``dataclasses.exec`` in place (one class at a time)."""

_LOCK = threading.Lock()
"""Guards the kept codes."""


def store_path(module: str) -> str | None:
    """The kept file of ``module``'s classes for this interpreter, or None (no store, no
    cache tag). A file a module: a command reads only the classes it imports."""
    tag = sys.implementation.cache_tag
    if STORE is None or tag is None:
        return None
    where = STORE
    if sys.pycache_prefix and where == _BESIDE:  # where Python keeps this package's bytecode
        where = os.path.join(sys.pycache_prefix, os.path.dirname(os.path.abspath(__file__)).lstrip(os.sep))
    return os.path.join(where, f"dataclass-{module}.{tag}.marshal")


def _read(path: str | None) -> dict[str, CodeType]:
    """The kept codes, or {} where the file is missing, unreadable or not such a table."""
    import marshal

    if path is None:
        return {}
    try:
        with open(path, "rb") as kept:
            held = marshal.loads(kept.read())
    except (OSError, ValueError, EOFError, TypeError):
        return {}
    if type(held) is not dict or not all(type(k) is str and isinstance(v, CodeType) for k, v in held.items()):
        return {}
    return held


_codes: dict[str, dict[str, CodeType]] = {}
"""Each module's kept codes, read when it first makes a class."""
_added: set[str] = set()
"""The modules whose codes this run compiled (written at exit)."""
_used: dict[str, dict[str, CodeType]] = {}
"""Each module's codes this run read or compiled: what is written back, so a class's old
texts (an edited source tree) leave the file at its next write instead of piling up."""


def kept_code(module: str, source: str) -> CodeType:
    """``source`` compiled as ``exec(source, ...)`` compiles it in :mod:`dataclasses` (file
    name ``<string>``, no inherited future flags), or the kept code of that very text."""
    with _LOCK:
        codes = _codes.get(module)
        if codes is None:
            codes = _codes[module] = _read(store_path(module))
        code = codes.get(source)
        _used.setdefault(module, {})
        if code is None:
            code = compile(source, "<string>", "exec", dont_inherit=True)
            codes[source] = code
            if not _added:
                import atexit

                atexit.register(save)  # the first run of a command writes its files once
            _added.add(module)
        _used[module][source] = code
    return code


def _exec(source: Any, globals: Any = None, locals: Any = None, /) -> None:
    """``exec`` as :mod:`dataclasses` calls it, through the kept codes while this thread
    makes a class through :func:`frozen` (any other call passes straight through)."""
    if type(source) is str:
        module = getattr(_STATE, "making", None)
        # another thread's class (or a user's) is compiled here too while the name is in
        # place: as dataclasses compiles it, without this module's __future__ flags
        source = kept_code(module, source) if module is not None else \
            compile(source, "<string>", "exec", dont_inherit=True)
    builtins.exec(source, globals, locals)


_ABSENT = object()


def frozen(cls: type[T]) -> type[T]:
    """``dataclasses.dataclass(frozen=True)(cls)``, its methods' bytecode kept (see the module)."""
    with _MAKING:
        had = dataclasses.__dict__.get("exec", _ABSENT)
        dataclasses.exec = _exec  # type: ignore[attr-defined]  # the name dataclasses calls
        _STATE.making = cls.__module__ if cls.__module__.startswith(KEPT_MODULES) else None
        try:
            return dataclasses.dataclass(frozen=True)(cls)
        finally:
            _STATE.making = None
            if had is _ABSENT:
                del dataclasses.exec  # type: ignore[attr-defined]
            else:
                dataclasses.exec = had  # type: ignore[attr-defined]


def save() -> None:
    """Write the codes of each module this run compiled new ones for; quietly: a store
    that cannot be written is no error."""
    if sys.dont_write_bytecode:
        return
    import marshal

    from .files import keep_quietly

    with _LOCK:
        todo = [(store_path(m), marshal.dumps(_used[m])) for m in sorted(_added)]
        _added.clear()
    for path, data in todo:
        if path is not None:
            keep_quietly(path, data)
