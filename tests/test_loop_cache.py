"""The bytecode of the generated loops is kept between runs (iterate.compiled), as Python
keeps a module's: a kept loop is the same code, and a damaged, foreign or unwritable
cache is never an error."""

from __future__ import annotations

import marshal
import math
import os
import sys

import pytest

from linkage import iterate
from linkage.files import kept_bytes, read_kept
from linkage.methods.newton import NEWTON_QUIET_LOOP

SOURCE = "def f(x):\n    return x * 2.0 + 1.0\n"


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setattr(iterate, "LOOP_CACHE", str(tmp_path))
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    return tmp_path


def kept(cache) -> list[str]:
    return sorted(p.name for p in cache.iterdir())


def test_a_kept_loop_is_the_code_compiled_from_its_source(cache):
    source = iterate.loop_source(NEWTON_QUIET_LOOP)
    first = iterate.compiled(source, "<linkage-loop newton_quiet>", True)
    (name,) = kept(cache)
    assert name.endswith(f".{sys.implementation.cache_tag}.marshal")
    again = iterate.compiled(source, "<linkage-loop newton_quiet>", True)
    assert again == first == compile(source, "<linkage-loop newton_quiet>", "exec")
    assert read_kept(str(cache / name))[0] == source


def test_a_loop_built_from_the_cache_is_the_loop_built_by_compiling(cache):
    from linkage.methods import newton

    names = {k: v for k, v in vars(newton).items() if k.startswith("_") and not k.startswith("__")}
    fresh = iterate.build_loop(NEWTON_QUIET_LOOP, dict(names), fixed_source=True)
    from_cache = iterate.build_loop(NEWTON_QUIET_LOOP, dict(names), fixed_source=True)
    assert len(kept(cache)) == 1 and fresh.__code__ == from_cache.__code__


def test_a_command_run_from_kept_loops_prints_what_one_compiling_them_prints():
    """Fresh processes, as a person runs them: the first may write the package's kept
    loops, the second reads them; the third compiles them (no bytecode written or read)."""
    import subprocess

    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    command = [sys.executable, "-m", "linkage", "solve", "--method", "newton"]
    runs = [subprocess.run(command, capture_output=True, text=True, env=env, check=True).stdout
            for _ in range(2)]
    compiling = subprocess.run([sys.executable, "-B", "-c",
                                "import sys; from linkage import iterate; iterate.LOOP_CACHE = None; "
                                "from linkage.cli.entry import main; sys.argv = ['linkage', 'solve', "
                                "'--method', 'newton']; main()"],
                               capture_output=True, text=True, env=env, check=False)
    assert runs[0] == runs[1] == compiling.stdout and "converged" in runs[0].lower()


def test_a_damaged_kept_file_is_compiled_again_and_replaced(cache):
    iterate.compiled(SOURCE, "<t>", True)
    (name,) = kept(cache)
    for damage in (b"", b"\x00garbage", marshal.dumps(("x",)), kept_bytes(("x",)), kept_bytes(42),
                   (cache / name).read_bytes()[:-7]):
        (cache / name).write_bytes(damage)
        namespace: dict = {}
        exec(iterate.compiled(SOURCE, "<t>", True), namespace)
        assert namespace["f"](2.0) == 5.0
        assert read_kept(str(cache / name))[0] == SOURCE


def test_a_kept_file_of_another_source_or_filename_is_not_used(cache):
    iterate.compiled(SOURCE, "<t>", True)
    (name,) = kept(cache)
    other = "def f(x):\n    return math.inf\n"
    (cache / name).write_bytes(kept_bytes((other, "<t>", compile(other, "<t>", "exec"))))
    namespace: dict = {"math": math}
    exec(iterate.compiled(SOURCE, "<t>", True), namespace)
    assert namespace["f"](2.0) == 5.0
    code = iterate.compiled(SOURCE, "<u>", True)
    assert code.co_filename == "<u>"


def test_a_kept_file_of_another_bytecode_version_is_not_used(cache):
    """The interpreter's magic number leads the file, as in a .pyc: code kept by another
    build with the same cache tag (a release and its pre-release) is compiled again."""
    from importlib.util import MAGIC_NUMBER

    iterate.compiled(SOURCE, "<t>", True)
    (name,) = kept(cache)
    foreign = compile("def f(x):\n    return -1.0\n", "<t>", "exec")
    other_magic = bytes([MAGIC_NUMBER[0] ^ 1]) + MAGIC_NUMBER[1:]
    (cache / name).write_bytes(other_magic + marshal.dumps((SOURCE, "<t>", foreign)))
    namespace: dict = {}
    exec(iterate.compiled(SOURCE, "<t>", True), namespace)
    assert namespace["f"](2.0) == 5.0
    assert (cache / name).read_bytes().startswith(MAGIC_NUMBER)  # replaced


def test_the_loop_cache_follows_pycache_prefix(cache, monkeypatch, tmp_path):
    prefix = tmp_path / "prefix"
    monkeypatch.setattr(sys, "pycache_prefix", str(prefix))
    iterate.compiled(SOURCE, "<t>", True)
    (written,) = [p for p in prefix.rglob("*.marshal")]
    assert str(written.parent) == str(prefix) + os.path.dirname(os.path.abspath(str(cache)))


def test_nothing_is_kept_for_a_model_loop_or_where_python_writes_no_bytecode(cache, monkeypatch):
    iterate.compiled(SOURCE, "<t>", False)
    assert kept(cache) == []
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    iterate.compiled(SOURCE, "<t>", True)
    assert kept(cache) == []


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root writes anywhere")
def test_an_unwritable_cache_is_no_error(cache):
    os.chmod(cache, 0o500)
    try:
        namespace: dict = {}
        exec(iterate.compiled(SOURCE, "<t>", True), namespace)
        assert namespace["f"](1.0) == 3.0 and kept(cache) == []
    finally:
        os.chmod(cache, 0o700)


def test_a_cache_that_is_a_file_is_no_error(tmp_path, monkeypatch):
    blocker = tmp_path / "not_a_directory"
    blocker.write_text("x")
    monkeypatch.setattr(iterate, "LOOP_CACHE", str(blocker))
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    namespace: dict = {}
    exec(iterate.compiled(SOURCE, "<t>", True), namespace)
    assert namespace["f"](1.0) == 3.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not_a_directory"]


def test_the_model_loops_are_not_kept():
    """newton_two's loop is built from a mechanism's numbers: one file per mechanism
    ever solved would grow without bound, so it is compiled every time."""
    import inspect

    from linkage.methods import newton_two

    assert "fixed_source" not in inspect.getsource(newton_two.compiled_newton_two)
