"""What a person sees of ``linkage assemblies`` and ``linkage synthesize`` (motion, path,
help) in an 80-column terminal: each test is named after what was wrong when read there.
The terminal's tables leave out what the lines above them say; files keep every column."""

from __future__ import annotations

import re
import sys
from pathlib import Path
from types import SimpleNamespace

from linkage.render.assemblies import quiet_columns
from pty_run import run

ROOT = Path(__file__).resolve().parents[1]
SIXBAR = str(ROOT / "sample_inputs" / "stephenson_sixbar.toml")
POSES = str(ROOT / "docs" / "motion_poses.txt")


def parts(seen: str) -> list[int]:
    """The N of every "(columns part k of N)" label: how many stacked parts each table took."""
    return [int(n) for n in re.findall(r"\(columns part \d+ of (\d+)\)", seen)]


def fits(seen: str, width: int = 80) -> bool:
    return all(len(line.rstrip()) <= width for line in seen.splitlines())


def test_assemblies_at_80_columns_stack_no_part_for_the_multiplicity_or_an_empty_note():
    """The assemblies table stacked a third part holding only ``multiplicity`` (1 for every
    assembly: the summary counts the double ones), and the paths table carried a ``note``
    column with nothing in it."""
    seen = run([sys.executable, "-m", "linkage", "assemblies", SIXBAR, "--paths"], 80)
    assert "alpha test" in seen and "Paths" in seen, seen
    assert fits(seen)
    assert parts(seen) and max(parts(seen)) == 2, parts(seen)
    assert "multiplicity" not in seen and " note" not in seen


def test_files_of_assemblies_keep_the_multiplicity_and_the_note(cli):
    r = cli("assemblies", SIXBAR, "--table", "assemblies", "-f", "csv")
    assert r.code == 0 and "multiplicity" in r.out.splitlines()[0], r.out
    r = cli("assemblies", SIXBAR, "--table", "paths", "-f", "csv")
    assert r.code == 0 and r.out.splitlines()[0].endswith(",note"), r.out


def test_quiet_columns_keep_a_double_assembly_and_a_path_note():
    """The terminal drops the multiplicity only when every assembly is simple, and the note
    only when no path has one."""
    def result(times: tuple[int, ...], notes: list[str]) -> SimpleNamespace:
        return SimpleNamespace(multiplicity=times,
                               solutions=SimpleNamespace(endpoints=[SimpleNamespace(note=n) for n in notes]))

    assert quiet_columns(result((1, 1), ["", ""])) == ("multiplicity", "note")
    assert quiet_columns(result((1, 2), ["", ""])) == ("note",)
    assert quiet_columns(result((1, 1), ["", "tracked twice"])) == ("multiplicity",)


def test_motion_at_80_columns_fits_the_cranks_and_stacks_the_four_bars_in_two_parts():
    """The cranks table stacked a second part holding only ``residual`` (relative, under a
    "(mm)" title), and the four-bars table a third holding only ``defects``: its input and
    output lengths are its cranks' lengths, in the table above."""
    seen = run([sys.executable, "-m", "linkage", "synthesize", "--motion", "--poses", POSES], 80)
    assert "best: design 1" in seen, seen
    assert fits(seen)
    assert parts(seen) == [2, 2], parts(seen)
    assert re.search(r"rigidity residual \(relative to the poses' size\) at most \d", seen), seen
    crank_lines = seen[seen.index("Burmester cranks (mm)"):seen.index("four-bars (mm)")]
    assert "residual" not in crank_lines and "length" in crank_lines


def test_files_of_motion_keep_the_residual_and_the_input_and_output_lengths(cli):
    r = cli("synthesize", "--motion", "--poses", POSES, "--table", "cranks", "-f", "csv")
    assert "residual" in r.out.splitlines()[0], r.out
    r = cli("synthesize", "--motion", "--poses", POSES, "--table", "designs", "-f", "csv")
    head = r.out.splitlines()[0].split(",")
    assert "input" in head and "output" in head, head


def test_help_of_synthesize_at_80_columns_says_what_point_search_and_samples_do_for_paths():
    """``--point``'s help read only "--path"; ``--search`` and ``--samples`` spoke only of
    function generation's candidates."""
    seen = run([sys.executable, "-m", "linkage", "synthesize", "--help"], 80)
    assert fits(seen)
    text = " ".join(seen.replace("│", " ").split())
    point = text[text.index("--point X,Y[,DEG]"):text.index("--via")]
    assert "coupler curve" in point and "crank's angle" in point, point
    search = text[text.index("--search "):text.index("--vary NAME")]
    assert "with --path" in search, search
    samples = text[text.index("--samples <int>"):text.index("--sampling")]
    assert "with --path" in samples, samples
    assert "--motion and --path" in text
