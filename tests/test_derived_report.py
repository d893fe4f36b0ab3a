"""What a person sees of the derived closed forms: headers and titles that read
on one line where the terminal has room, --branch's help and refusals in the same words in
solve and sweep, the old closed_form key's refusal saying what to do, and a six-bar sweep
saying which loop its one transmission column is."""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import pytest

from pty_run import run

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
LINKAGE = [sys.executable, "-m", "linkage"]
JOINTS_TITLE = "Joints (the first loop's first joint at the origin, x along 0 deg)"


def _lines(text: str) -> list[str]:
    return [line.rstrip() for line in text.splitlines()]


def test_a_header_over_narrow_numbers_takes_the_room_its_table_leaves():
    """At 80 columns the crossed branch's last part had 'true', 'error', '(deg)', 'vs',
    'crossed' on five lines beside 40 empty columns, and 'Phi2 (mm)' on two."""
    shown = run([*LINKAGE, "solve", str(SAMPLES / "crank_rocker.toml"), "--branch", "crossed"], 80)
    lines = _lines(shown)
    assert max(len(line) for line in lines) <= 80
    assert any("true error (deg) vs crossed" in line for line in lines), shown
    assert any(re.search(r"Phi1 \(mm\)\s+Phi2 \(mm\)", line) for line in lines), shown
    assert not any(line.strip() in ("true", "error", "(deg)", "vs") for line in lines)


@pytest.mark.parametrize("cols", [80, 200])
def test_a_long_title_over_a_narrow_table_reads_on_one_line(cols):
    """The joints table is narrower than its title: rich wrapped the title to the table's
    width (three lines at 200 columns for the inverted slider-crank), and 'x (mm)' over
    short numbers on two."""
    shown = run([*LINKAGE, "solve", str(SAMPLES / "inverted_slider_crank.toml")], cols)
    lines = _lines(shown)
    assert JOINTS_TITLE in lines, shown
    joint_header = next(line for line in lines if line.strip().startswith("joint"))
    assert re.search(r"joint\s+x \(mm\)\s+y \(mm\)", joint_header), joint_header


def test_widen_headers_gives_only_the_room_left():
    from linkage.render.report import widen_headers

    headers = ["k", "a long header here", "b c"]
    # natural widths 2, 4, 3: the table takes 1 + (2+3) + (4+3) + (3+3) = 19 characters
    assert widen_headers(headers, [0, 1, 2], [2, 4, 3], 19) == [2, 4, 3]
    # 10 to spare: the long header (18 characters) takes all 10, left to right
    assert widen_headers(headers, [0, 1, 2], [2, 4, 3], 29) == [2, 14, 3]
    # plenty of room: each header whole, never wider than its header or its numbers
    assert widen_headers(headers, [0, 1, 2], [2, 4, 3], 200) == [2, 18, 3]
    assert widen_headers(headers, [0, 2], [2, 4, 3], 200) == [2, 3]


def _words(text: str) -> str:
    """Help text with its box drawing and line breaks gone."""
    return " ".join(re.sub(r"[│╭╮╰╯─]", " ", text).split())


def test_branch_help_says_what_the_signs_are_in_solve_and_sweep(cli):
    solve = _words(cli("solve", "--help").out)
    sweep = _words(cli("sweep", "--help").out)
    assert "+ or - for the root taken in each closed-form step with two, in loop order" in solve
    assert "two-way" not in solve
    # sweep's help named only open or crossed: now the same names and signs as solve's
    for word in ("as in solve --branch", "open/crossed for a six-bar", "'open (mirror)'", "+-"):
        assert word in sweep, word


@pytest.mark.parametrize("name,names,signs", [
    ("crank_rocker.toml", "open or crossed", "+, -"),
    ("watt_sixbar.toml", "open/open, open/crossed, crossed/open or crossed/crossed", "++, +-, -+, --"),
])
def test_sweep_refusal_lists_each_choice_once(cli, name, names, signs):
    """It listed every name twice (each again with ' (mirror)': eight for the Watt six-bar)."""
    run_ = cli("sweep", str(SAMPLES / name), "--branch", "sideways")
    assert run_.code == 2 and len(run_.err.splitlines()) == 1 and run_.err.startswith("error: ")
    assert f"--branch must be {names}, or their signs {signs} " in run_.err
    assert run_.err.count("(mirror)") == 1 and "got 'sideways'" in run_.err


def test_sweep_refusal_of_a_mechanism_named_only_by_signs(cli):
    run_ = cli("sweep", str(SAMPLES / "inverted_slider_crank.toml"), "--branch", "open")
    assert run_.code == 2 and "--branch must be + or -; " in run_.err and "their signs" not in run_.err


def test_solve_refusal_says_what_a_sign_is(cli):
    run_ = cli("solve", str(SAMPLES / "crank_rocker.toml"), "--branch", "+-")
    assert run_.code == 2 and len(run_.err.splitlines()) == 1
    assert "one per closed-form step with two roots: +, -" in run_.err and "two-way" not in run_.err


@pytest.mark.parametrize("sample,key", [("fourbar_abcd.toml", "fourbar"),
                                        ("crank_rocker.toml", "slider_crank"),
                                        ("offset_slider.toml", "fourbar")])
def test_a_refused_old_key_says_to_delete_it(cli, tmp_path, sample, key):
    path = tmp_path / sample
    text = (SAMPLES / sample).read_text()
    path.write_text(text.replace("length_unit = ", f'closed_form = "{key}"\nlength_unit = ', 1))
    run_ = cli("solve", str(path))
    assert run_.code == 2 and len(run_.err.splitlines()) == 1 and run_.err.startswith("error: ")
    assert "closed_form" in run_.err and "delete it" in run_.err, run_.err
    # without the key the same file solves
    assert cli("solve", str(SAMPLES / sample), "--format", "json").code == 0


def _mu(coupler_deg: float, output_deg: float) -> float:
    """The transmission angle: the angle between two link directions (acos of the cosine,
    [0, 180] deg), folded into 0..90 (the acute angle between the two lines)."""
    mu = math.degrees(math.acos(math.cos(math.radians(output_deg - coupler_deg))))
    return min(mu, 180.0 - mu)


def test_watt_sweep_says_its_transmission_column_is_the_worst_loops(cli):
    """One column for two four-bar loops: the line under the loops says which, and the
    column is that loop's angle (computed here from each loop's coupler and output)."""
    args = ("--from", "0", "--to", "360", "--step", "10")
    text = cli("sweep", str(SAMPLES / "watt_sixbar.toml"), *args, "--format", "plain").out
    assert "transmission angle 0..90: at each position, of the four-bar loop farthest from 90 deg" in text
    one = cli("sweep", str(SAMPLES / "crank_rocker.toml"), *args, "--format", "plain").out
    assert "farthest from 90" not in one
    doc = json.loads(cli("sweep", str(SAMPLES / "watt_sixbar.toml"), *args, "--format", "json").out)
    switched = set()
    for p in doc["positions"]:
        s = p["solution"]
        loops = (_mu(s["theta3"], s["theta4"]), _mu(s["theta6"], s["theta7"]))
        worst = max(range(2), key=lambda i: abs(loops[i] - 90.0))
        switched.add(worst)
        assert p["transmission"] == pytest.approx(loops[worst], abs=1e-8), (p["input"], loops)
    assert switched == {0, 1}  # the column is not one loop's throughout


def test_sweep_refusal_of_a_name_absent_at_the_start_says_what_a_sign_is(cli):
    """It said 'or give the signs of the 1 two-way step, e.g. +'."""
    run_ = cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "60", "--branch", "open (mirror)")
    assert run_.code == 2 and len(run_.err.splitlines()) == 1
    assert "no 'open (mirror)' assembly anywhere in theta2 = 0..360 deg; at 0: open, crossed" in run_.err
    assert "one + or - per closed-form step with two roots" in run_.err and "two-way" not in run_.err


def test_a_six_bar_sweep_names_its_one_four_bar_loop(cli):
    """The Stephenson six-bar's sweep said 'four-bar: Grashof crank-rocker' of a six-bar;
    solve names the loop, and now the sweep does too (a single four-bar stays 'four-bar')."""
    short, p, q, long_ = sorted((40.0, 120.0, 80.0, 100.0))  # r2, r3, r4, r1 of loop O2-A-B-O4
    facts = f"Grashof crank-rocker (s + l = {short + long_:g}, p + q = {p + q:g})"
    six = cli("sweep", str(SAMPLES / "stephenson_sixbar.toml"), "--step", "120", "--format", "plain").out
    assert f"four-bar loop O2-A-B-O4: {facts}" in six.splitlines()
    four = cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "120", "--format", "plain").out
    assert f"four-bar: {facts}" in four.splitlines()


def test_sweep_refusal_of_a_coupled_file_says_how_to_choose_its_assembly(cli):
    """The sweep has no --guess: the way to another assembly is the file's guesses."""
    run_ = cli("sweep", str(SAMPLES / "offset_slider.toml"), "--branch", "open")
    assert run_.code == 2 and len(run_.err.splitlines()) == 1
    assert "loop 1 has 3 unknowns, loop 2 has 3 unknowns (coupled); its sweep follows the assembly " \
           "of the file's guesses (change them under [unknowns] to follow another)" in run_.err


def test_counts_agree_with_their_number(cli):
    """--branch starts on the closed form, so one step is usual: '1 iterations' read oddly."""
    one = cli("solve", str(SAMPLES / "crank_rocker.toml"), "--branch", "crossed", "--format", "plain").out
    doc = json.loads(cli("solve", str(SAMPLES / "crank_rocker.toml"), "--branch", "crossed",
                         "--format", "json").out)
    assert doc["iteration_count"] == 1 and doc["njev"] == 1 and doc["nfev"] == 2
    assert "1 iteration, 2 residual evaluations, 1 Jacobian evaluation, max|Phi|" in one
    four = cli("solve", str(SAMPLES / "crank_rocker.toml"), "--format", "plain").out
    assert "4 iterations, 5 residual evaluations, 4 Jacobian evaluations, max|Phi|" in four


def test_solve_help_says_what_the_closed_form_header_means(cli):
    """The header's 'closed form: loops 1, 2 (stepwise)' and '(coupled)' were explained nowhere
    a student would look first."""
    text = _words(cli("solve", "--help").out)
    assert '("loops 1, 2 (stepwise)": loop 1 solved first, then loop 2 with its answers)' in text
    assert "which are coupled (Newton only)" in text


def test_a_sweep_plots_cannot_be_assembled_band_ends_at_the_limit_positions():
    """The red band ran from the last unassembled grid value to the first solved one
    (100..106 deg of the rocker-driven ME581 at step 2), so it said "cannot be assembled"
    over 104.48..106 deg, where it can. It now ends at the limits, which the law of
    cosines gives here: |B - O2| = r2 + r3 = 90 with B 45 from O4 and O4 90 from O2."""
    import linkage
    from linkage.render.plots import bands

    r = linkage.sweep(SAMPLES / "fourbar_me581_theta4.toml", [float(v) for v in range(100, 262, 2)],
                      branch="open")
    # 90^2 = 90^2 + 45^2 - 2 * 90 * 45 cos(180 - theta4)  =>  cos(theta4) = -45 / 180
    limit = math.degrees(math.acos(-0.25))
    red = [(a, b) for a, b, status in bands(r) if status == "no_solution"]
    assert red == [(100.0, pytest.approx(limit, abs=1e-9)), (pytest.approx(360.0 - limit, abs=1e-9), 260.0)]
