"""The package's frozen dataclasses and named tuples, made as :func:`dataclasses.dataclass`
and :class:`typing.NamedTuple` make them, with the bytecode of their generated methods kept
between runs.

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

:data:`NamedTuple` is :class:`typing.NamedTuple` (its class syntax) made the same way:
:func:`collections.namedtuple` evaluates each class's ``__new__`` from text, kept here as
``frozen``'s methods are, and the annotations reach ``typing``'s class maker as
placeholders, so that it compiles no :class:`typing.ForwardRef` for each field; the
class's ``__annotations__`` are the strings the class body wrote (this package's modules
have ``from __future__ import annotations``), which :func:`typing.get_type_hints` reads as
it reads typing's ForwardRefs. Everything else is typing's own class maker: the same
checks, fields, defaults, methods and errors (docs/performance.md, "Dataclass methods kept
between runs").
"""

from __future__ import annotations

import builtins
import collections
import contextlib
import dataclasses
import os
import sys
import threading
import typing
from collections.abc import Iterator
from types import CodeType
from typing import TYPE_CHECKING, Any, TypeVar

# at import, not while a class is made: files' own imports (pathlib, urllib.parse) make named
# tuples, which would go through kept_code while it holds its lock
from .files import keep_quietly, kept_bytes, kept_code_path, read_kept

T = TypeVar("T")

KEPT_MODULES = "linkage."
"""The modules whose classes' methods are kept (a user's class made by :func:`frozen` is
made as ever)."""

STORE: str | None = os.path.join(os.path.dirname(__file__), "__pycache__")
"""The directory of the kept file (beside the package's own bytecode); None: nowhere."""

_STATE = threading.local()
"""``making``: the module whose class this thread is making through :func:`frozen`, or None."""

_MAKING = threading.RLock()
"""Held while :func:`frozen` has ``dataclasses.exec`` in place (one class at a time)."""

_LOCK = threading.Lock()
"""Guards the kept codes."""


def store_path(module: str) -> str | None:
    """The kept file of ``module``'s classes for this interpreter, or None (no store, no
    cache tag): :func:`~linkage.files.kept_code_path`'s rule. A file a module: a command
    reads only the classes it imports."""
    return None if STORE is None else kept_code_path(STORE, f"dataclass-{module}")


def _read(path: str | None) -> dict[str, CodeType]:
    """The kept codes, or {} where the file is missing, unreadable, of another bytecode
    version (:func:`~linkage.files.read_kept`) or not such a table."""
    held = read_kept(path)
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


EVAL_KEY = "\0eval\0"
"""What an ``eval`` source's key starts with (a NUL: no ``exec`` source, which is the key
as it is, can contain one)."""


def kept_code(module: str, source: str, mode: str = "exec") -> CodeType:
    """``source`` compiled as ``exec(source, ...)`` compiles it in :mod:`dataclasses` (file
    name ``<string>``, no inherited future flags), or as ``eval(source, ...)`` does in
    :mod:`collections` (``mode="eval"``), or the kept code of that very text and mode."""
    key = source if mode == "exec" else EVAL_KEY + source
    with _LOCK:
        codes = _codes.get(module)
        if codes is None:
            codes = _codes[module] = _read(store_path(module))
        code = codes.get(key)
        _used.setdefault(module, {})
        if code is None:
            code = compile(source, "<string>", mode, dont_inherit=True)
            codes[key] = code
            if not _added:
                import atexit

                atexit.register(save)  # the first run of a command writes its files once
            _added.add(module)
        _used[module][key] = code
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


def _eval(source: Any, globals: Any = None, locals: Any = None, /) -> Any:
    """``eval`` as :func:`collections.namedtuple` calls it, through the kept codes while this
    thread makes a class through :data:`NamedTuple` (any other call passes straight through,
    compiled as ``eval`` compiles a string there: leading blanks dropped, no future flags)."""
    if type(source) is str:
        module = getattr(_STATE, "making", None)
        source = source.lstrip(" \t")
        source = kept_code(module, source, "eval") if module is not None else \
            compile(source, "<string>", "eval", dont_inherit=True)
    return builtins.eval(source, globals, locals)


_ABSENT = object()


@contextlib.contextmanager
def _routed(namespace: Any, name: str, routed: Any, module: Any) -> Iterator[None]:
    """While this thread makes a class of ``module``: the builtin ``name`` a class maker's
    module (``namespace``) calls is ``routed`` (through the kept codes for this package's
    classes), one class at a time; as it was afterwards."""
    with _MAKING:
        had = namespace.__dict__.get(name, _ABSENT)
        setattr(namespace, name, routed)
        _STATE.making = module if type(module) is str and module.startswith(KEPT_MODULES) else None
        try:
            yield
        finally:
            _STATE.making = None
            if had is _ABSENT:
                delattr(namespace, name)
            else:
                setattr(namespace, name, had)


class SignatureDoc:
    """The docstring :func:`dataclasses.dataclass` writes for a class that has none (its
    name and signature, by the same expression), written when it is first read instead of
    while the class is made: ``inspect.signature`` is most of what making such a class
    costs a command's start (docs/performance.md, "Dataclass methods kept between runs")."""

    def __get__(self, obj: Any, owner: type) -> str:
        import inspect

        try:
            # In some cases fetching a signature is not possible (dataclasses' words)
            text_sig = str(inspect.signature(owner)).replace(" -> None", "")
        except (TypeError, ValueError):
            text_sig = ""
        text = owner.__name__ + text_sig
        owner.__doc__ = text  # written once; a class's own __doc__ is never inherited
        return text


def frozen(cls: type[T]) -> type[T]:
    """``dataclasses.dataclass(frozen=True)(cls)``, its methods' bytecode kept (see the module),
    and, for a class without a docstring, the one dataclass writes written when first read
    (:class:`SignatureDoc`)."""
    bare = not cls.__doc__  # dataclass's own test
    if bare:
        cls.__doc__ = "(written when read)"  # so that dataclass writes none now
    with _routed(dataclasses, "exec", _exec, cls.__module__):  # the name dataclasses calls
        made = dataclasses.dataclass(frozen=True)(cls)
    if bare:
        made.__doc__ = SignatureDoc()  # type: ignore[assignment]
    return made


_TYPING_BASE = typing.NamedTuple.__mro_entries__((typing.NamedTuple,))[0]  # type: ignore[attr-defined]
"""What a class statement naming :class:`typing.NamedTuple` derives from (typing's class
maker asks for it among the bases)."""


def named_tuple(typename: str, bases: tuple[type, ...], ns: dict[str, Any]) -> type:
    """The class ``class typename(typing.NamedTuple)`` with body ``ns`` makes, through
    typing's own class maker, its fields' annotations given as placeholders (no ForwardRef
    compiled) and put back as written, and namedtuple's ``__new__`` through the kept codes
    (see the module)."""
    written = ns.get("__annotations__", {})
    body = dict(ns)
    body["__annotations__"] = dict.fromkeys(written, Any)
    if "__orig_bases__" in body:  # the bases as written: typing's NamedTuple, as there
        written_bases = body["__orig_bases__"]
        body["__orig_bases__"] = tuple(typing.NamedTuple if b is NamedTuple else b for b in written_bases)
    bases = tuple(_TYPING_BASE if b is _KEPT_BASE else b for b in bases)
    with _routed(collections, "eval", _eval, ns.get("__module__")):  # the name namedtuple calls
        made = typing.NamedTupleMeta.__new__(typing.NamedTupleMeta, typename, bases, body)  # type: ignore[attr-defined]
    made.__annotations__ = made.__new__.__annotations__ = dict(written)
    return made  # type: ignore[no-any-return]


class _KeptTupleMeta(type):
    """The metaclass of :data:`NamedTuple`'s base: a class statement's class is
    :func:`named_tuple`'s."""

    def __new__(cls, typename: str, bases: tuple[type, ...], ns: dict[str, Any]) -> Any:  # type: ignore[misc]
        return named_tuple(typename, bases, ns)


_KEPT_BASE = type.__new__(_KeptTupleMeta, "NamedTuple", (), {})

if TYPE_CHECKING:
    from typing import NamedTuple as NamedTuple
else:
    def NamedTuple(*args: Any, **kwargs: Any) -> Any:
        """:class:`typing.NamedTuple`'s class syntax, its compilations kept (see the module):
        ``class Point(NamedTuple): x: float; y: float = 0.0``."""
        raise TypeError("linkage.records.NamedTuple is a base class: class Name(NamedTuple): ...")

    def _mro_entries(bases: tuple[Any, ...]) -> tuple[Any, ...]:
        """typing's own entries for the same bases (its checks, its errors), this base for its."""
        entries = typing.NamedTuple.__mro_entries__(tuple(typing.NamedTuple if b is NamedTuple else b
                                                           for b in bases))
        return tuple(_KEPT_BASE if b is _TYPING_BASE else b for b in entries)

    NamedTuple.__mro_entries__ = _mro_entries


def save() -> None:
    """Write the codes of each module this run compiled new ones for; quietly: a store
    that cannot be written is no error."""
    if sys.dont_write_bytecode:
        return
    with _LOCK:
        todo = [(store_path(m), kept_bytes(_used[m])) for m in sorted(_added)]
        _added.clear()
    for path, data in todo:
        if path is not None:
            keep_quietly(path, data)
