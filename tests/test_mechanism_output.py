"""-o FILE.toml of the commands that write a mechanism file (new, convert, synthesize): one
rule (cli.options.mechanism_output): an existing file is kept unless --force, the input never
replaced (not even with --force), the file written whole (temporary file and rename) and only
when the command succeeds."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DRAWING = ROOT / "sample_inputs" / "fourbar_me581_joints.toml"
SYNTHESIZE = ["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150", "--phi", "0:90",
              "-f", "plain"]
"""A design without defects (Freudenstein's log10 generator)."""
OLD = "# an existing file: kept\n"


def _commands(tmp_path: Path) -> dict[str, list[str]]:
    source = tmp_path / "drawn.toml"
    source.write_text(DRAWING.read_text())
    return {"new": ["new", "fourbar"], "convert": ["convert", str(source)], "synthesize": SYNTHESIZE}


def _one_error_line(r, *needles: str) -> None:
    assert r.code == 2, (r.code, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.err
    for needle in needles:
        assert needle in lines[0], lines[0]


@pytest.mark.parametrize("command", ["new", "convert", "synthesize"])
def test_synthesize_o_and_convert_o_keep_an_existing_file_unless_force(cli, tmp_path, command) -> None:
    target = tmp_path / "existing.toml"
    target.write_text(OLD)
    args = _commands(tmp_path)[command]
    r = cli(*args, "-o", str(target))
    _one_error_line(r, f"-o {target} exists", "--force")
    assert target.read_text() == OLD and r.out == ""  # refused before any work: no report either
    r = cli(*args, "-o", str(target), "--force")
    assert r.code == 0, r.err
    text = target.read_text()
    assert text != OLD and ("[joints]" in text or "[[loops]]" in text)
    assert f"wrote {target}" in r.err


def test_synthesize_with_a_defect_leaves_an_existing_file_as_it_was(cli, tmp_path) -> None:
    """It exited 1 with a transmission defect and had replaced the file."""
    target = tmp_path / "design.toml"
    target.write_text(OLD)
    r = cli(*SYNTHESIZE, "--min-transmission", "89", "-o", str(target), "--force")
    assert r.code == 1 and "transmission" in r.out
    assert f"note: {target} not written: the design has defects (transmission)" in r.err
    assert target.read_text() == OLD
    fresh = tmp_path / "fresh.toml"
    assert cli(*SYNTHESIZE, "--min-transmission", "89", "-o", str(fresh)).code == 1
    assert not fresh.exists()


@pytest.mark.parametrize("command", ["new", "convert", "synthesize"])
def test_a_mechanism_file_is_written_whole_or_not_at_all(cli, tmp_path, monkeypatch, command) -> None:
    """A write that fails (a full disk, here simulated at the sync before the rename) leaves
    the old file and no temporary file."""
    import linkage.files

    def full_disk(path: str) -> None:
        raise OSError(28, "No space left on device")

    target = tmp_path / "existing.toml"
    target.write_text(OLD)
    args = _commands(tmp_path)[command]
    before = set(tmp_path.iterdir())
    monkeypatch.setattr(linkage.files, "_sync", full_disk)
    r = cli(*args, "-o", str(target), "--force")
    assert r.code != 0 and "No space left on device" in r.err and "Traceback" not in r.err
    assert target.read_text() == OLD
    assert set(tmp_path.iterdir()) == before


def test_no_command_overwrites_its_own_input_even_with_force(cli, tmp_path) -> None:
    source = tmp_path / "drawn.toml"
    source.write_text(DRAWING.read_text())
    link = tmp_path / "link.toml"
    link.symlink_to(source)
    for target in (source, link):
        r = cli("convert", str(source), "-o", str(target), "--force")
        _one_error_line(r, "is the input file")
        assert source.read_text() == DRAWING.read_text()


@pytest.mark.parametrize("command", ["new", "convert", "synthesize"])
def test_every_mechanism_writer_offers_force(cli, command) -> None:
    r = cli(command, "--help")
    assert r.code == 0 and "--force" in r.out
