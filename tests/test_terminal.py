"""What a person sees: tables at 80 and 200 columns in a real pseudo-terminal, and the
seed's own table from one command."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest

from linkage.methods import SCALAR_METHODS
from pty_run import run

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
LINKAGE = [sys.executable, "-m", "linkage"]
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]\d+)?")
STATUSES = ("converged_step", "converged_exact", "converged", "no_solution", "off_branch", "max_iter",
            "precision_limit", "invalid_bracket", "discontinuity", "stalled")

COMMANDS = [
    ["solve"],
    ["solve", str(SAMPLES / "fourbar_me581.toml")],
    ["solve", "--method", "all"],
    ["sweep", str(SAMPLES / "fourbar_me581.toml"), "--step", "30"],
    ["sweep", "--from", "10", "--to", "160", "--step", "30"],
    ["solve", str(SAMPLES / "slider_crank.toml"), "--speed", "600rpm"],
    ["sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "90", "--speed", "10", "--accel", "5"],
]


def _cells(text: str, timed: bool) -> list[str]:
    """Every number and status word in the table rows of a plain rendering (without the
    timing column of --method all, which differs from run to run)."""
    out = []
    for line in text.splitlines():
        if not line.strip() or set(line.strip()) <= set("-━ "):
            continue
        words = line.split()
        if timed and words and words[0] in SCALAR_METHODS:
            words = words[:-1]
        out += [t for t in words if NUMBER.fullmatch(t) or t in STATUSES]
    return out


@pytest.mark.parametrize("cols", [80, 200])
@pytest.mark.parametrize("args", COMMANDS, ids=" ".join)
def test_every_number_and_status_is_printed_whole(args, cols):
    """The plain output (no width) lists the table cells; at 80 and 200 columns in a
    pseudo-terminal each one must appear as a whole token: no number or status is
    wrapped, folded or cut."""
    import subprocess

    plain = subprocess.run([*LINKAGE, *args, "--format", "plain"], capture_output=True, text=True).stdout
    seen = run([*LINKAGE, *args], cols)
    tokens = set(seen.split())
    missing = [c for c in _cells(plain, "all" in args) if c not in tokens]
    assert not missing, (cols, missing[:10], seen[:3000])
    assert max(len(line) for line in seen.splitlines()) <= cols


def test_seed_002s_table_from_one_command(cli):
    """`linkage sweep --from 10 --to 160 --step 30`: the student report's phi for each alpha."""
    printed = {10: "8.06934531362", 40: "32.01518035933", 70: "54.88776318878",
               100: "75.27087338607", 130: "90.12408036526", 160: "92.73496285135"}
    run_ = cli("sweep", "--from", "10", "--to", "160", "--step", "30", "--format", "json")
    assert run_.code == 0, run_.err
    rows = json.loads(run_.out)["positions"]
    assert [r["alpha"] for r in rows] == [10, 40, 70, 100, 130, 160]
    for r in rows:
        want = printed[int(r["alpha"])]
        assert f"{r['phi']:.11f}" == want, (r, want)


def test_columns_picks_what_a_table_and_the_csv_show(cli):
    run = cli("sweep", str(SAMPLES / "fourbar_me581.toml"), "--step", "90", "--columns", "theta4,det",
              "--format", "csv")
    header = run.out.splitlines()[0].split(",")
    assert header[0].startswith("theta2") and header[1].startswith("theta4") and header[2].startswith("det J")
    assert len(header) == 3
    text = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--columns", "theta3", "--format", "plain").out
    assert "left out" in text and "max|Phi|" in text.split("left out")[1]
    assert cli("solve", "--columns", "nothing-like-this").code == 2


def test_columns_refuses_a_name_that_matches_nothing_beside_one_that_matches(cli):
    """A misspelt name was dropped silently when another name matched (theta3,zzz showed
    theta3): each name must begin some column (of a table or of the display; the first too)."""
    me581 = str(SAMPLES / "fourbar_me581.toml")
    run = cli("sweep", me581, "--step", "90", "--columns", "theta3,zzz")
    assert run.code == 2 and run.err.count("\n") == 1 and "'zzz': matches no column" in run.err
    tol = ("tolerance", me581, "--tol", "r2=0.01", "--samples", "20", "--step", "90", "--columns")
    run = cli(*tol, "status,worst")
    assert run.code == 2 and "'worst': matches no column" in run.err and "theta3_worst_case" in run.err
    assert cli("sweep", me581, "--step", "90", "--columns", "theta2,theta3").code == 0  # the first column
    shown = cli(*tol, "status,nominal", "-f", "plain")  # a display header ("nominal")
    assert shown.code == 0 and "nominal" in shown.out


def test_sentences_wrap_only_when_a_table_is_too_wide():
    """A cell of words (a benchmark target) wraps between words, read from the left,
    when the table would not fit the terminal; numbers never wrap."""
    from linkage.render.report import PROSE_WIDTH, column_widths, is_prose

    headers = ("target", "ratio", "met")
    rows = [("1. scalar Newton, history off, within 2x of the hand loop", "3.66", "no")]
    wide = column_widths(headers, rows, 200)
    assert wide[0] == len(rows[0][0]) and not is_prose(rows, 0, wide[0])
    narrow = column_widths(headers, rows, 60)
    assert narrow == [PROSE_WIDTH, 5, 3] and is_prose(rows, 0, narrow[0])
    assert not is_prose(rows, 1, narrow[1])
