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
    output lengths are its cranks' lengths, in the table above. Its max_pose_error (relative,
    or rad) stood unexplained under the "(mm)" title."""
    seen = run([sys.executable, "-m", "linkage", "synthesize", "--motion", "--poses", POSES], 80)
    assert "best: design 1" in seen, seen
    assert fits(seen)
    assert parts(seen) == [2, 2], parts(seen)
    assert re.search(r"rigidity residual \(relative to the poses' size\) at most \d", seen), seen
    crank_lines = seen[seen.index("Burmester cranks (mm)"):seen.index("four-bars (mm)")]
    assert "residual" not in crank_lines and "length" in crank_lines
    # the four-bars table's title gives the lengths' unit: the pose error says it is none
    assert "max_pose_error: the largest distance from a pose" in " ".join(seen.split())


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


TIMED = ["--point=0.1579,2.4375,20", "--point=0.3675,3.0987,60", "--point=-0.1131,3.2206,100",
         "--point=-0.7817,2.8793,140", "--point=-1.3129,2.2146,180"]


def test_timed_path_designs_at_80_columns_keep_the_judgement_in_the_first_part():
    """The designs table (too wide for 80 columns) stacked the least transmission angle, the
    ranking's key that the defects name, in the second part, away from the defects."""
    seen = run([sys.executable, "-m", "linkage", "synthesize", "--path", *TIMED], 80)
    assert fits(seen)
    assert parts(seen) == [2, 2], parts(seen)
    first = seen[seen.index("(columns part 1 of 2)"):seen.index("(columns part 2 of 2)")]
    for head in ("design", "grashof", "defects", "transmission_min", "(deg)"):
        assert head in first, first
    second = seen[seen.index("(columns part 2 of 2)"):seen.index("defects: branch")]
    assert "point_error" in second and "timing_error" in second and "transmission_min" not in second


def test_path_reports_say_how_to_get_the_cognates_table_they_point_to(cli):
    """"... is in the cognates table": a terminal shows no such table, and --table needs a
    file format. The hint is the command that prints it."""
    seen = run([sys.executable, "-m", "linkage", "synthesize", "--path", *TIMED], 80)
    assert "cognates table (--table cognates -f csv)" in " ".join(seen.split()), seen
    r = cli("synthesize", "--path", *TIMED, "--table", "cognates", "-f", "csv")
    assert r.code == 0 and r.out.startswith("design,cognate,"), r.err
    assert len(r.out.splitlines()) == 1 + 12  # the 12 four-bars, each cognate a row


def test_path_reports_put_the_transmission_angle_beside_the_design_and_files_keep_every_column():
    """The nine-point, timed and search reports' terminal tables: the judgement first, the
    links after; the designs table (files) keeps its own order and the pivots."""
    from linkage.render.data import from_rows
    from linkage.render.path_search import SEARCH_HEADS
    from linkage.render.path_search import TERMINAL_COLUMNS as SEARCH
    from linkage.render.path_synthesis import (
        HEADS,
        TERMINAL_COLUMNS,
        TIMED_HEADS,
        TIMED_TERMINAL,
        terminal_table,
    )

    def headers(heads: list[tuple[str, str, str]], names: tuple[str, ...]) -> list[str]:
        row = tuple(1 if kind == "int" else "x" if kind == "text" else 0.5 for _, _, kind in heads)
        return list(terminal_table(from_rows("designs", heads, [row]), names, 4).headers)

    for heads, names in ((HEADS, TERMINAL_COLUMNS), (TIMED_HEADS, TIMED_TERMINAL), (SEARCH_HEADS, SEARCH)):
        shown = headers(heads, names)
        k = shown.index("transmission_min (deg)")
        assert k < shown.index("ground") and "design" == shown[0], shown
        assert "Ax" not in shown and "Ax" in [h for h, _, _ in heads]
    assert [h for h, _, _ in HEADS].index("transmission_min") > [h for h, _, _ in HEADS].index("ground")


def test_the_double_assemblies_line_names_what_it_counts(cli):
    """"1 of them double" followed the alpha test's line ("0 of 0 nonsingular roots
    certified, 0 of them real"), so it read as one of those roots. At a change point the
    terminal keeps the multiplicity column: the line says how many, the column which."""
    crank_rocker = str(ROOT / "sample_inputs" / "crank_rocker.toml")
    at_change_point = ("--set", "r2=40", "--set", "r4=60", "--set", "theta2=0")
    r = cli("assemblies", crank_rocker, *at_change_point, "-f", "plain")
    assert r.code == 0, r.err
    assert "1 of the real assemblies double (two assemblies that meet here" in r.out, r.out
    assert "of them double" not in r.out and "multiplicity" in r.out
