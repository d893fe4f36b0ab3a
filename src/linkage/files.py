"""Reading inputs and writing outputs so that no file is ever lost or half written.

Inputs: a mechanism file must be a regular file (not a FIFO, a device or a socket, which
could block or never end) of at most :data:`MAX_INPUT_BYTES`; it is read with that bound.

Outputs: every path is checked before any work is done (:func:`check_outputs`): it may not
resolve to an input (through symlinks and hard links alike), two outputs may not share a
path, and its folder must exist. While a command runs (:func:`command_paths`), every file it
has read (:func:`read_input`) and every file it has written count as well, so a path known
only once the work is done (a report's second table, ``FILE.NAME.csv``) meets the same
check, and :func:`atomic_target` checks each path it writes again, last (:func:`claim_output`).
Regular files are written to a temporary file in the same folder and renamed over the
target (:func:`write_atomic`, :func:`atomic_target`), so a full disk or an interrupted run
leaves the old file as it was. Special files (``/dev/null``, a terminal, a FIFO) are
written in place, since renaming over them would replace the device.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import os
import re
import stat
import sys
from collections.abc import Iterator, Sequence
from importlib.util import MAGIC_NUMBER
from pathlib import Path
from typing import Any

from .errors import InputError, OutputError, ParseError

MAX_INPUT_BYTES = 1_000_000
"""A mechanism file is a page of TOML; a megabyte is far beyond any real one."""

MAX_TOML_NESTING = 32
"""Deepest nesting of arrays, inline tables and table headers: a mechanism file needs 3."""
MAX_TOML_KEY_PARTS = 32
"""Most parts in one dotted key or header (``a.b.c`` has 3): a mechanism file needs 3.
tomllib's time grows with the square of a key's parts (160k parts: 55 s), so both are
checked on the text, before it is parsed."""

# an unclosed string runs to the end of its line (or text): never a failed match, so the
# pass stays linear (tomllib then reports the unclosed string)
_TOML_STRING = "|".join((
    r'"{3}(?:\\[\s\S]|[^\\])*?(?:"{3,5}|\Z)',  # multi-line basic (escapes allowed)
    r"'{3}[\s\S]*?(?:'{3,5}|\Z)",  # multi-line literal
    r'"(?:\\.|[^"\\\n])*"?',  # basic
    r"'[^'\n]*'?",  # literal
))
_TOML_TOKEN = (
    rf"(?P<string>{_TOML_STRING})|(?P<comment>#[^\n]*)|(?P<word>[A-Za-z0-9_-]+)|(?P<space>[ \t]+)"
    r"|(?P<open>[\[{])|(?P<close>[\]}])|(?P<dot>\.)|(?P<other>[^\[\]{}.\"'#A-Za-z0-9_ \t-]+)")


@functools.cache
def toml_tokens() -> re.Pattern[str]:
    """The tokenizer of :func:`check_toml_shape`, compiled on first use: compiling it costs
    a command that reads no TOML (``linkage solve``) half a millisecond of its start."""
    return re.compile(_TOML_TOKEN)


def check_toml_shape(text: str, where: str) -> None:
    """Refuse TOML nested deeper than MAX_TOML_NESTING or with a dotted key (or header) of
    more than MAX_TOML_KEY_PARTS parts, in one linear pass over the text. Strings and
    comments are skipped; a run of words, strings and dots counts as one key (a float's
    one dot makes it a run of two, and no valid value outside a string has more)."""
    if text.count(".") < MAX_TOML_KEY_PARTS and text.count("[") + text.count("{") <= MAX_TOML_NESTING:
        # too few dots and openers in the whole text for either refusal (each dot token and
        # each opener token is one such character): no tokenizer to compile, no pass (a
        # command reading one small file pays for neither)
        return

    def refuse(tok: re.Match[str], what: str) -> ParseError:
        line = text.count("\n", 0, tok.start()) + 1
        return ParseError(f"{where}: line {line}: {what}; a mechanism file needs a few")

    depth = 0
    parts = 1
    for tok in toml_tokens().finditer(text):
        kind = tok.lastgroup
        if kind == "dot":
            parts += 1
            if parts > MAX_TOML_KEY_PARTS:
                raise refuse(tok, f"a dotted key with more than {MAX_TOML_KEY_PARTS} parts")
        elif kind in ("word", "string", "space"):
            continue
        else:
            parts = 1
            if kind == "open":
                depth += 1
                if depth > MAX_TOML_NESTING:
                    raise refuse(tok, f"arrays and tables nested more than {MAX_TOML_NESTING} deep")
            elif kind == "close":
                depth = max(0, depth - 1)


def parse_toml(text: str, where: str) -> dict[str, Any]:
    """The TOML document in ``text``, its shape checked first; any failure a ParseError
    naming ``where``."""
    import sys

    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib
    check_toml_shape(text, where)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParseError(f"{where}: not valid TOML: {exc}{_given_twice(text, str(exc))}") from None
    except RecursionError:
        raise ParseError(f"{where}: not valid TOML: nested too deeply") from None
    except (ValueError, OverflowError, MemoryError) as exc:
        # e.g. an integer of more digits than Python converts (ValueError)
        raise ParseError(f"{where}: not valid TOML: {exc}") from None


def _given_twice(text: str, message: str) -> str:
    """The key a "Cannot overwrite a value" names by its line (a joint or link listed twice),
    when it reads plainly; else nothing."""
    found = re.match(r"Cannot overwrite a value \(at line (\d+)", message)
    lines = text.splitlines()
    if not found or not 0 < int(found.group(1)) <= len(lines):
        return ""
    key = lines[int(found.group(1)) - 1].partition("=")[0].strip()
    return f": {key} is given twice" if re.fullmatch(r"[A-Za-z0-9_\-]{1,60}", key) else ""


def read_input(path: Path, what: str = "mechanism file") -> str:
    """The text of a regular UTF-8 file of at most MAX_INPUT_BYTES, or a ParseError;
    ``-`` reads standard input (with the same bound)."""
    if str(path) == "-":
        import sys

        if sys.stdin is None:
            raise ParseError("standard input is closed: give a FILE, or - with input piped in")
        data = sys.stdin.buffer.read(MAX_INPUT_BYTES + 1) if hasattr(sys.stdin, "buffer") else \
            sys.stdin.read(MAX_INPUT_BYTES + 1).encode()
        if len(data) > MAX_INPUT_BYTES:
            raise ParseError(f"standard input has more than {MAX_INPUT_BYTES:,} bytes")
        return _text(data, "standard input")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ParseError(f"no such file: {path}") from None
    except OSError as exc:
        raise ParseError(f"cannot read {path}: {exc.strerror or exc}") from None
    except ValueError:  # os.stat's refusal of an embedded null byte
        raise ParseError(f"no such file: {str(path)!r} (a file name cannot hold a null byte)") from None
    if stat.S_ISDIR(st.st_mode):
        raise ParseError(f"{path} is a directory, not a {what}")
    if not stat.S_ISREG(st.st_mode):
        raise ParseError(f"{path} is not a regular file (a FIFO, a device or a socket); "
                         f"give the {what} itself")
    if st.st_size > MAX_INPUT_BYTES:
        raise ParseError(f"{path} has {st.st_size:,} bytes; a {what} may have at most "
                         f"{MAX_INPUT_BYTES:,}")
    try:
        # O_NONBLOCK: if the path was swapped for a FIFO since the stat, do not wait on it
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise ParseError(f"{path} is not a regular file")
            data = fh.read(MAX_INPUT_BYTES + 1)
    except OSError as exc:
        raise ParseError(f"cannot read {path}: {exc.strerror or exc}") from None
    if len(data) > MAX_INPUT_BYTES:
        raise ParseError(f"{path} is larger than {MAX_INPUT_BYTES:,} bytes")
    note_input(path)
    return _text(data, str(path))


def _text(data: bytes, where: str) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParseError(f"{where} is not UTF-8 text (byte {exc.start})") from None


def _identity(path: Path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino


class CommandPaths:
    """The files one command has read and written so far, each under its real path and its
    (device, inode) identity (a symlink and a hard link are the file they name)."""

    __slots__ = ("inputs", "planned", "written")

    def __init__(self) -> None:
        self.inputs: dict[object, str] = {}
        self.written: dict[object, str] = {}
        self.planned: dict[object, str] = {}
        """The outputs the command named (:func:`check_outputs`), each as "OPTION PATH"."""


RUNNING: CommandPaths | None = None
"""The running command's paths (:func:`command_paths`); None outside a command, where
reading and writing record nothing (a library caller's files are its own business)."""


@contextlib.contextmanager
def command_paths() -> Iterator[CommandPaths]:
    """While the block runs, :func:`read_input` records each file read, :func:`atomic_target`
    each file written, and :func:`check_outputs` refuses an output that is one of them."""
    global RUNNING
    outer, RUNNING = RUNNING, CommandPaths()
    try:
        yield RUNNING
    finally:  # None again (or a caller's own block's paths: a block within keeps its own record)
        RUNNING = outer


def _keys(path: Path | str) -> list[object]:
    """The real path and, for an existing file, its identity: the keys a file is known by."""
    ident = _identity(Path(path))
    return [os.path.realpath(path)] + ([ident] if ident is not None else [])


def note_input(path: Path | str) -> None:
    """Record ``path`` as read by the running command (if one runs)."""
    if RUNNING is not None and str(path) != "-":
        RUNNING.inputs.update(dict.fromkeys(_keys(path), str(path)))


def claim_output(path: Path | str) -> None:
    """The last check of a path about to be written by the running command (if one runs):
    not a file it read, not a file it wrote already; then recorded as written. Special files
    (``/dev/null``) are exempt: writing one replaces nothing."""
    run = RUNNING
    if run is None or _in_place(os.path.realpath(path)):
        return
    keys = _keys(path)
    for key in keys:
        if key in run.inputs:
            named = "" if run.inputs[key] == str(path) else f" {run.inputs[key]}"
            raise InputError(f"this command would write {path}, the input file{named}, and so replace it: "
                             "choose another output path")
        if key in run.written:
            also = "" if run.written[key] == str(path) else f" (as {run.written[key]})"
            raise InputError(f"this command would write {path} twice{also}: give each output its own path")
    run.written.update(dict.fromkeys(keys, str(path)))


def check_outputs(inputs: Sequence[Path | None], outputs: Sequence[tuple[str, Path | None]]) -> None:
    """Refuse, before any work, an output that is an input, two outputs on one path, an
    output in a missing folder or on a directory. ``outputs`` pairs option names with paths.
    Within a command (:func:`command_paths`) the files it has read and written so far count
    too, and the outputs checked are recorded as the command's: a file it names only later
    (a table beside -o, named once the report is made) is checked against them by
    :func:`check_more_outputs`."""
    given = [(opt, p) for opt, p in outputs if p is not None and str(p) != "-"]
    in_ids: dict[object, Path | str] = dict(RUNNING.inputs) if RUNNING is not None else {}
    for p in inputs:
        if p is not None and str(p) != "-":
            in_ids.update(dict.fromkeys(_keys(p), p))
    seen: dict[object, str] = dict(RUNNING.written) if RUNNING is not None else {}
    for opt, p in given:
        keys = _keys(p)  # (its real path, then its (device, inode) where it exists)
        for key in keys:
            if key in in_ids:
                raise InputError(f"{opt} {p} is the input file {in_ids[key]}; writing there would "
                                 "replace it: choose another path")
        for key in keys:
            if key in seen:
                raise InputError(f"{opt} {p} and {seen[key]} name the same file; give each output "
                                 "its own path")
        seen.update(dict.fromkeys(keys, f"{opt} {p}"))
        if RUNNING is not None:
            RUNNING.planned.update(dict.fromkeys(keys, f"{opt} {p}"))
        real = keys[0]
        if os.path.isdir(real):
            raise InputError(f"{opt} {p} is a directory; give a file name")
        parent = os.path.dirname(real) or "."
        if not os.path.isdir(parent):
            raise InputError(f"cannot write {opt} {p}: the folder {os.path.dirname(str(p)) or '.'} "
                             "does not exist")


def check_more_outputs(outputs: Sequence[tuple[str, Path]]) -> None:
    """Refuse, before anything of them is written, outputs a command names only once its
    work is done (the tables a one-table format writes beside -o) where one is an input or
    one of the outputs the command named at its start (its --plot, say), by
    :func:`check_outputs`' rule; outside a command, only among themselves."""
    planned = dict(RUNNING.planned) if RUNNING is not None else {}
    for opt, p in outputs:
        for key in _keys(p):
            if key in planned:
                raise InputError(f"{planned[key]} and {opt} {p} name the same file; give each output "
                                 "its own path")
    check_outputs([], outputs)


def _in_place(path: str) -> bool:
    """True for an existing special file (device, FIFO): written directly, never renamed over."""
    try:
        return not stat.S_ISREG(os.stat(path).st_mode)
    except OSError:
        return False


@contextlib.contextmanager
def atomic_target(path: Path, *, output: bool = True) -> Iterator[str]:
    """Yield a temporary path beside ``path``; on success rename it over ``path``.

    Writes through a symlink to its target. On any failure the temporary file is
    removed, the old file is untouched and an OutputError names the path. An ``output``
    of a command (not a cache: ``output=False``) is checked first by :func:`claim_output`.
    """
    if output:
        claim_output(path)
    real = os.path.realpath(path)
    if _in_place(real):
        try:
            yield real
        except OSError as exc:
            raise OutputError(f"cannot write {path}: {exc.strerror or exc}") from None
        return
    try:
        tmp = temporary_beside(real)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {exc.strerror or exc}") from None
    try:
        yield tmp
        _sync(tmp)  # on disk before the rename: a full disk is an error here, not a truncated file
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, real)
    except OSError as exc:
        _remove(tmp)
        raise OutputError(f"cannot write {path}: {exc.strerror or exc}") from None
    except BaseException:
        _remove(tmp)
        raise


def kept_code_path(beside: str, name: str) -> str | None:
    """Where a file of kept bytecode called ``name`` (this interpreter's cache tag appended)
    lives for a package whose own bytecode is in ``beside`` (its ``__pycache__``): there, or
    where Python puts that directory's bytecode under ``sys.pycache_prefix`` when it is set
    (the Python documentation, "sys.pycache_prefix"); None where this interpreter keeps no
    bytecode (no cache tag). One rule for every store of kept code (records, iterate)."""
    tag = sys.implementation.cache_tag
    if tag is None:
        return None
    if sys.pycache_prefix:
        beside = os.path.join(sys.pycache_prefix, os.path.dirname(os.path.abspath(beside)).lstrip(os.sep))
    return os.path.join(beside, f"{name}.{tag}.marshal")


def read_kept(path: str | None) -> Any:
    """What :func:`keep_quietly` kept at ``path`` with :func:`kept_bytes`, or None where the
    file is missing, unreadable, damaged or written by another bytecode version (the
    interpreter's magic number leads the file, as in a ``.pyc``: two builds that share a
    cache tag, a release and its pre-release, do not read each other's code)."""
    import marshal

    if path is None:
        return None
    try:
        with open(path, "rb") as kept:
            data = kept.read()
        if data[:len(MAGIC_NUMBER)] != MAGIC_NUMBER:
            return None
        return marshal.loads(data[len(MAGIC_NUMBER):])
    except (OSError, ValueError, EOFError, TypeError):
        return None


def kept_bytes(value: Any) -> bytes:
    """``value`` as :func:`read_kept` reads it back: the magic number, then marshal's bytes."""
    import marshal

    return MAGIC_NUMBER + marshal.dumps(value)


def compiled_kept(source: str, filename: str, store: str | None, kind: str = "loop") -> Any:
    """``compile(source, filename, "exec")``, its code kept between runs in the directory
    ``store`` (None: not kept) as Python keeps a module's bytecode. A kept file is used only
    if it holds this very source (compared whole, not by its hash) and file name for this
    interpreter's bytecode (its cache tag in the name, its magic number in the file:
    :func:`read_kept`), in the place :func:`kept_code_path` gives (``sys.pycache_prefix``
    followed); one that is missing, unreadable, damaged or of another source is compiled
    again and replaced. Nothing is written where Python writes no bytecode
    (``sys.dont_write_bytecode``) or the directory cannot be written."""
    import zlib
    from types import CodeType

    name = f"{kind}-{zlib.crc32(source.encode()):08x}-{len(source):x}"  # (kind: the file's prefix)
    path = None if store is None else kept_code_path(store, name)
    if path is None:
        return compile(source, filename, "exec")
    held = read_kept(path)
    if (type(held) is tuple and len(held) == 3 and held[0] == source and held[1] == filename
            and isinstance(held[2], CodeType)):
        return held[2]
    code = compile(source, filename, "exec")
    if not sys.dont_write_bytecode:
        keep_quietly(path, kept_bytes((source, filename, code)))
    return code


def keep_quietly(path: str, data: bytes) -> None:
    """Write a cache file (kept bytecode) whole or not at all, through :func:`atomic_target`
    (a reader never sees half a file); quietly: a cache that cannot be written is no error."""
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with atomic_target(Path(path), output=False) as part, open(part, "wb") as out:
            out.write(data)
    except (OSError, OutputError):
        return


def temporary_beside(real: str) -> str:
    """A new empty file beside ``real``, made by this call (``.name.XXXXXXXX.part.suffix``,
    mode 0600), as ``tempfile.mkstemp`` makes it: without tempfile's import (random and
    shutil: 5 ms of a fresh process, for one name)."""
    folder = os.path.dirname(real) or "."
    suffix = os.path.splitext(real)[1]
    flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    for _ in range(100):
        tmp = os.path.join(folder, f".{os.path.basename(real)}.{os.urandom(4).hex()}.part{suffix}")
        try:
            os.close(os.open(tmp, flags, 0o600))
        except FileExistsError:
            continue
        return tmp
    raise FileExistsError(errno.EEXIST, "no free temporary name", folder)


def _sync(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        if stat.S_ISREG(os.fstat(fd).st_mode):
            os.fsync(fd)
    finally:
        os.close(fd)


def _remove(path: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(path)


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` completely or not at all."""
    with atomic_target(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
