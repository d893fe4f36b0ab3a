"""The layout of reports as a person reads them (one report, one writer registry): each
test is named after what was wrong when the output was read at 80 columns, piped and in
files."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from linkage.render.tools import bench_report
from pty_run import run

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = str(SAMPLES / "fourbar_me581.toml")


def test_samples_binary_format_is_refused_without_asking_for_an_o_file(cli):
    """``samples -f parquet`` said "give -o FILE.parquet", but -o copies a sample (and
    needs NAME): following the advice gave a second refusal."""
    for fmt in ("parquet", "xlsx"):
        r = cli("samples", "-f", fmt)
        assert r.code == 2 and r.out == ""
        assert r.err.startswith("error: ") and r.err.count("\n") == 1, r.err
        assert "-o" not in r.err and "standard output" in r.err, r.err
    assert cli("samples", "-f", "csv").code == 0


def test_help_of_samples_format_offers_only_what_the_listing_can_do(cli):
    r = cli("samples", "--help")
    assert r.code == 0
    text = " ".join(r.out.split())
    start = text.index("--format")
    option = text[start:text.index("--help", start)]
    assert "parquet" not in option and "xlsx" not in option, option


def test_rate_tables_stand_a_blank_line_below_the_convergence_summary(cli):
    """"estimated order ..." ran straight into "Velocities and accelerations"."""
    r = cli("solve", ME581, "--speed", "600rpm", "--format", "plain")
    assert r.code == 0, r.err
    lines = r.out.splitlines()
    k = lines.index("Velocities and accelerations")
    assert lines[k - 1] == "" and lines[k - 2].startswith("estimated order"), lines[k - 3:k + 1]


def test_bench_title_counts_one_batch_in_the_singular():
    def title(n: int) -> str:
        return bench_report([], {}, {}, [], n, [], False).title

    assert "1 timed batch each" in title(1)
    assert "3 timed batches each" in title(3)


def test_columns_part_label_is_never_broken_across_lines():
    """At 80 columns the joints table's title wrapped as "... (columns part" / "1 of 2)"."""
    seen = run([sys.executable, "-m", "linkage", "solve", ME581, "--speed", "600rpm"], 80)
    assert "Joints" in seen
    parts = re.findall(r"\(columns part[^)]*\)", seen)
    assert parts and all(re.fullmatch(r"\(columns part \d+ of \d+\)", p) for p in parts), parts
    assert all(len(line.rstrip()) <= 80 for line in seen.splitlines())


def test_latex_tables_escape_the_bar_of_max_phi(cli):
    """tabulate escapes & % _ ^ but not |: "max|Phi| (cm)" compiled as "max—Phi— (cm)" in
    LaTeX's default font. latex_raw is the format that escapes nothing, and stays so."""
    r = cli("solve", ME581, "--format", "latex")
    assert r.code == 0, r.err
    tables = [line for line in r.out.splitlines() if not line.startswith("%")]
    assert any(r"max\textbar{}Phi\textbar{} (cm)" in line for line in tables)
    assert not any("|" in line for line in tables)
    raw = cli("solve", ME581, "--format", "latex_raw")
    assert any("max|Phi| (cm)" in line for line in raw.out.splitlines() if not line.startswith("%"))


def test_unknown_format_names_the_tabulate_formats_people_use(cli):
    """The refusal listed the first eight tabulate formats by name (asciidoc, colon_grid,
    double_grid, ...), not github or latex, which the suffixes .md and .tex stand for."""
    r = cli("solve", "-f", "nosuch")
    assert r.code == 2 and r.err.startswith("error: ") and r.err.count("\n") == 1, r.err
    for name in ("github", "latex", "html", "rst"):
        assert name in r.err, r.err
    assert "colon_grid" not in r.err


def test_format_help_says_which_formats_need_a_file(cli):
    r = cli("solve", "--help")
    text = " ".join(r.out.replace("│", " ").split())
    assert "csv, json, parquet or xlsx (parquet and xlsx to -o FILE)" in text, text
