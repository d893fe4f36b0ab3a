"""Issue 19, what `solve` and the problem layer show from the closed form derived from the
loops: the true-error column and JSON reference for every dyadic mechanism, the header
that says which loops are closed-form and which coupled, --branch by name or by signs, the
old closed_form key checked and noted, and every four-bar loop's Grashof class and
transmission angle, whatever its names and whichever joint drives.

References are computed here, independently of the code under test: circle intersections
in complex numbers (no shared formula), the law of cosines, worked example P3, docs/worked_examples.md and the
figures in the sample files' comments.
"""

from __future__ import annotations

import cmath
import json
import math
import sys
from pathlib import Path

import pytest

from derived_reference import XY, abcd_text
from linkage.errors import ParseError
from linkage.kinematics.loading import load, parse_mechanism
from pty_run import run as pty

ROOT = Path(__file__).resolve().parent.parent
SAMPLES = ROOT / "sample_inputs"
LINKAGE = [sys.executable, "-m", "linkage"]

# --- independent references -----------------------------------------------------------------


def circles(p: complex, rp: float, q: complex, rq: float) -> list[complex]:
    """The points X with |X - p| = rp and |X - q| = rq: the left one first (seen from p
    towards q), then the right one."""
    d = abs(q - p)
    a = (rp * rp - rq * rq + d * d) / (2 * d)
    h2 = rp * rp - a * a
    if h2 < 0:
        return []
    u = (q - p) / d
    base = p + a * u
    h = math.sqrt(h2)
    return [base + 1j * h * u, base - 1j * h * u]


def deg(z: complex) -> float:
    return math.degrees(cmath.phase(z))


def wrap(a: float) -> float:
    return (a + 180.0) % 360.0 - 180.0


def fourbar_by_crank(a: float, b: float, c: float, d: float, t2: float) -> dict[str, tuple[float, float]]:
    """{name: (theta3, theta4)} in degrees of the loop a e^(i t2) + b e^(i t3) - c e^(i t4)
    - d = 0: B on the circle about A (b) and about O4 = d (c); open where the output turns
    anticlockwise from the coupler, sin(theta4 - theta3) > 0 (worked example P3, docs/worked_examples.md)."""
    A = a * cmath.exp(1j * math.radians(t2))
    out = {}
    for B in circles(A, b, complex(d, 0.0), c):
        t3, t4 = deg(B - A), deg(B - d)
        out["open" if math.sin(math.radians(t4 - t3)) > 0 else "crossed"] = (t3, t4)
    return out


def transmission(a: float, b: float, c: float, d: float, t2: float) -> float:
    """The transmission angle: the angle at B between coupler and output, by the law of
    cosines (deg), folded into 0..90 (the acute angle between the two links' lines)."""
    ad2 = a * a + d * d - 2 * a * d * math.cos(math.radians(t2))
    mu = math.degrees(math.acos((b * b + c * c - ad2) / (2 * b * c)))
    return min(mu, 180.0 - mu)


# input, coupler, output, ground (cm): worked example P3, docs/worked_examples.md
P3 = (30.0, 60.0, 45.0, 90.0)
P3_OPEN = (13.151499346, 114.827770616)  # theta3, theta4 at theta2 = 65, P3's figures
P3_CROSSED = (-51.898819255, 206.424909476)


def abcd_file(tmp_path: Path, driver: str, value: float, guesses: dict[str, float],
              links: tuple[float, float, float, float] = P3, key: str = "") -> Path:
    """A four-bar written with textbook names a (input), b (coupler), c (output), d
    (ground), no closed_form key, driven by any of theta2, theta3, theta4."""
    text = abcd_text(links, driver, value, guesses, unit="cm", name="Norton four-bar", key=key)
    path = tmp_path / f"abcd_{driver}.toml"
    path.write_text(text)
    return path


def solve_json(cli, *args: str) -> dict:
    run = cli("solve", *map(str, args), "--format", "json")
    assert run.code == 0, run.err
    return json.loads(run.out)


# --- 1. reference and branch_of from the derivation -----------------------------------------

def test_abcd_fourbar_gets_the_true_error_column_and_p3s_reference(cli, tmp_path):
    """No key, names a, b, c, d: the reference is both of P3's assemblies (docs/worked_examples.md),
    and the iteration table has the true-error column against the branch solved."""
    path = abcd_file(tmp_path, "theta2", 65.0, {"theta3": 0.0, "theta4": 90.0})
    doc = solve_json(cli, path)
    ref = doc["reference"]
    assert set(ref) == {"open", "crossed"}
    for name, want in (("open", P3_OPEN), ("crossed", P3_CROSSED)):
        got = (ref[name]["theta3"], ref[name]["theta4"])
        assert all(abs(wrap(g - w)) < 1e-9 for g, w in zip(got, want)), (name, got, want)
        mine = fourbar_by_crank(*P3, 65.0)[name]
        assert all(abs(wrap(g - w)) < 1e-10 for g, w in zip(got, mine)), (name, got, mine)
    assert doc["branch"] == "open"
    column = "true error (deg) vs open"
    assert column in doc["iterations"][0]
    # the true error is the distance from the closed form: the last row's below 1e-9
    last = doc["iterations"][-1]
    assert last[column] == pytest.approx(max(abs(last["theta3 (deg)"] - P3_OPEN[0]),
                                             abs(last["theta4 (deg)"] - P3_OPEN[1])), abs=1e-9)


def test_crossed_slider_shows_no_false_turn(cli):
    """Driven from a guess in the other turn (theta3 near 180), the crossed slider-crank
    converges to 188.76 deg; its reference, -171.24 in (-180, 180], is the same angle: the
    true error is small, not 360, and the text shows the reference in the solution's turn."""
    path = SAMPLES / "slider_crank.toml"
    doc = solve_json(cli, path, "--guess", "theta3=180", "--guess", "s=-80")
    assert doc["branch"] == "crossed"
    # the independent slider: sin(theta3) = (e - r2 sin(theta2)) / r3, cos(theta3) < 0
    t3 = 180.0 - math.degrees(math.asin((10 - 40 * math.sin(math.radians(45))) / 120))
    assert doc["solution"]["theta3"] == pytest.approx(t3, abs=1e-9)
    assert doc["reference"]["crossed"]["theta3"] == pytest.approx(t3 - 360.0, abs=1e-9)
    errors = [row["true error (deg, mm) vs crossed"] for row in doc["iterations"]]
    assert max(errors) < 20.0 and errors[-1] < 1e-4, errors  # the row's iterate, before its step
    text = cli("solve", str(path), "--guess", "theta3=180", "--guess", "s=-80", "--format", "plain").out
    line = next(x for x in text.splitlines() if x.startswith("theta3 = "))
    shown = float(line.split("crossed branch: ")[1].rstrip(")"))
    assert shown == pytest.approx(t3, abs=1e-9)


def test_branch_of_names_a_configuration_from_the_derivation(tmp_path):
    """The problem's branch_of (display units) names P3's two assemblies as the P3 rule
    does, with no closed_form key."""
    m = load(abcd_file(tmp_path, "theta2", 65.0, {"theta3": 0.0, "theta4": 90.0}))
    problem = m.problem()
    for name, (t3, t4) in fourbar_by_crank(*P3, 65.0).items():
        assert problem.branch_of({"theta3": t3, "theta4": t4}) == name


# --- 5 (and 1). the same configuration named the same under every driver ---------------------

@pytest.mark.parametrize("config", ["open", "crossed"])
@pytest.mark.parametrize("driver", ["theta2", "theta3", "theta4"])
def test_one_configuration_one_name_under_every_driver(cli, tmp_path, config, driver):
    """P3's configuration at theta2 = 65, solved with theta2, the coupler's theta3 or the
    rocker's theta4 as the driver (a start 2 deg off), carries the same name, the same
    Grashof class and the same transmission angle (law of cosines)."""
    t3, t4 = fourbar_by_crank(*P3, 65.0)[config]
    config_deg = {"theta2": 65.0, "theta3": t3, "theta4": t4}
    others = {k: v + 2.0 for k, v in config_deg.items() if k != driver}
    doc = solve_json(cli, abcd_file(tmp_path, driver, config_deg[driver], others))
    for k, v in doc["solution"].items():
        assert abs(wrap(v - config_deg[k])) < 1e-8, (k, v, config_deg[k])
    assert doc["branch"] == config
    assert doc["reference"] and any(k.removesuffix(" (mirror)") == config for k in doc["reference"])
    (fact,) = doc["fourbars"]
    assert fact["loop"] == "O2-A-B-O4"
    # 30 + 90 > 60 + 45: not Grashof (P3's file comment)
    assert fact["type"] == "non-Grashof triple rocker" and fact["grashof"] is False
    assert fact["transmission_deg"] == pytest.approx(transmission(*P3, 65.0), abs=1e-9)


def test_every_driver_gets_branch_by_name(cli, tmp_path):
    """--branch works on the abcd four-bar driven through its coupler: 'crossed' starts
    from P3's crossed configuration exactly (theta2 = 65)."""
    t3, t4 = fourbar_by_crank(*P3, 65.0)["crossed"]
    path = abcd_file(tmp_path, "theta3", t3, {"theta2": 0.0, "theta4": 0.0})
    doc = solve_json(cli, path, "--branch", "crossed")
    assert doc["branch"] == "crossed"
    assert abs(wrap(doc["solution"]["theta2"] - 65.0)) < 1e-9
    assert abs(wrap(doc["solution"]["theta4"] - t4)) < 1e-9


# --- 1 and 5 on a six-bar -------------------------------------------------------------------

def watt_assemblies() -> dict[str, tuple[float, float, float, float]]:
    """Every assembly of sample_inputs/watt_sixbar.toml at theta2 = 30, stepwise: loop 1
    the crank-rocker (100, 40, 120, 80); loop 2 from O4: C = 70 e^(i (theta4 + 40)), D on
    the circles about C (110) and about O6 = 120 e^(i 60) (80); each loop open where its
    output turns anticlockwise from its coupler."""
    out = {}
    for n1, (t3, t4) in fourbar_by_crank(40.0, 120.0, 80.0, 100.0, 30.0).items():
        C = 70.0 * cmath.exp(1j * math.radians(t4 + 40.0))
        O6 = 120.0 * cmath.exp(1j * math.radians(60.0))
        for D in circles(C, 110.0, O6, 80.0):
            t6, t7 = deg(D - C), deg(D - O6)
            n2 = "open" if math.sin(math.radians(t7 - t6)) > 0 else "crossed"
            out[f"{n1}/{n2}"] = (t3, t4, t6, t7)
    return out


def test_watt_sixbar_reference_true_error_and_both_loops_facts(cli):
    """The Watt six-bar (no key) gets the true-error column and all four assemblies in its
    reference, the file's figures on open/open, and a line per four-bar loop naming it."""
    path = SAMPLES / "watt_sixbar.toml"
    doc = solve_json(cli, path)
    mine = watt_assemblies()
    assert set(doc["reference"]) == set(mine) == {"open/open", "open/crossed", "crossed/open",
                                                  "crossed/crossed"}
    for name, want in mine.items():
        got = [doc["reference"][name][k] for k in ("theta3", "theta4", "theta6", "theta7")]
        assert all(abs(wrap(g - w)) < 1e-9 for g, w in zip(got, want)), (name, got, want)
    # the file's comment: theta3 = 22.409, theta4 = 55.268, theta6 = 73.910, theta7 = 116.696
    assert [round(doc["solution"][k], 3) for k in ("theta3", "theta4", "theta6", "theta7")] == \
        [22.409, 55.268, 73.910, 116.696]
    assert doc["branch"] == "open/open"
    assert "true error (deg) vs open/open" in doc["iterations"][0]
    facts = {f["loop"]: f for f in doc["fourbars"]}
    assert set(facts) == {"O2-A-B-O4", "O4-C-D-O6"}
    # 40 + 120 < 100 + 80, the crank shortest; 70 + 120 = 110 + 80
    assert facts["O2-A-B-O4"]["type"] == "Grashof crank-rocker"
    assert facts["O4-C-D-O6"]["type"] == "change point"
    t3, t4, t6, t7 = mine["open/open"]
    assert facts["O2-A-B-O4"]["transmission_deg"] == pytest.approx(abs(wrap(t4 - t3)), abs=1e-9)
    assert facts["O4-C-D-O6"]["transmission_deg"] == pytest.approx(abs(wrap(t7 - t6)), abs=1e-9)
    text = cli("solve", str(path), "--format", "plain").out
    assert "four-bar loop O2-A-B-O4: Grashof crank-rocker, transmission angle" in text
    assert "four-bar loop O4-C-D-O6: change point, transmission angle" in text


def test_crank_rocker_facts_by_the_law_of_cosines(cli):
    doc = solve_json(cli, SAMPLES / "crank_rocker.toml")
    (fact,) = doc["fourbars"]
    assert fact["type"] == "Grashof crank-rocker"
    assert fact["transmission_deg"] == pytest.approx(transmission(40.0, 120.0, 80.0, 100.0, 30.0), abs=1e-9)


def test_a_closed_form_with_no_choice_names_its_one_assembly(cli, tmp_path):
    """Two lengths (s along x, t along y, closing on r e^(i theta)): linear, one assembly,
    s = r cos(theta), t = r sin(theta); it is called 'only', and --branch says there is
    nothing to choose."""
    path = tmp_path / "xy.toml"
    path.write_text(XY)
    doc = solve_json(cli, path)
    assert doc["branch"] == "only" and set(doc["reference"]) == {"only"}
    assert doc["reference"]["only"]["s"] == pytest.approx(50 * math.cos(math.radians(30)), abs=1e-12)
    assert doc["reference"]["only"]["t"] == pytest.approx(25.0, abs=1e-12)
    assert "true error (mm) vs only" in doc["iterations"][0]
    run = cli("solve", str(path), "--branch", "+")
    assert run.code == 2 and "nothing to choose" in run.err


# --- 2. the header ----------------------------------------------------------------------------

@pytest.mark.parametrize("sample, summary", [
    ("crank_rocker", "closed form: loop 1"),
    ("watt_sixbar", "closed form: loops 1, 2 (stepwise)"),
    # each loop of the offset slider has three unknowns (its file: theta14, theta15, s4, s6)
    ("offset_slider", "no closed form: loop 1 has 3 unknowns, loop 2 has 3 unknowns (coupled)"),
])
def test_header_says_which_loops_are_closed_form(cli, sample, summary):
    path = SAMPLES / f"{sample}.toml"
    assert solve_json(cli, path)["closed_form"] == summary
    text = cli("solve", str(path), "--format", "plain").out
    head = text.split("\n\n")[0].splitlines()
    assert head[-1] == summary, head


def test_coupled_mechanism_has_no_reference_and_no_true_error(cli):
    doc = solve_json(cli, SAMPLES / "offset_slider.toml")
    assert doc["reference"] is None and doc["branch"] is None and doc["fourbars"] == []
    assert not any(k.startswith("true error") for k in doc["iterations"][0])


def test_header_at_80_columns_in_a_terminal():
    seen = pty([*LINKAGE, "solve", str(SAMPLES / "watt_sixbar.toml")], 80)
    lines = [line.rstrip() for line in seen.splitlines()]
    assert "closed form: loops 1, 2 (stepwise)" in lines
    assert max(len(line) for line in lines) <= 80


# --- 3. --branch --------------------------------------------------------------------------------

@pytest.mark.parametrize("name, signs", [("open/open", "++"), ("open/crossed", "+-"),
                                         ("crossed/open", "-+"), ("crossed/crossed", "--")])
def test_branch_by_name_or_signs_on_the_six_bar(cli, name, signs):
    path = SAMPLES / "watt_sixbar.toml"
    want = watt_assemblies()[name]
    for text in (name, signs):
        doc = solve_json(cli, path, "--branch", text)
        assert doc["branch"] == name
        got = [doc["solution"][k] for k in ("theta3", "theta4", "theta6", "theta7")]
        assert all(abs(wrap(g - w)) < 1e-9 for g, w in zip(got, want)), (text, got, want)
        assert doc["iteration_count"] <= 1  # started on the closed form


def test_branch_without_a_closed_form_says_why(cli):
    path = SAMPLES / "offset_slider.toml"
    run = cli("solve", str(path), "--branch", "open")
    assert run.code == 2 and run.out == ""
    assert run.err == (f"error: --branch needs a closed form; {path} has none: "
                       "loop 1 has 3 unknowns, loop 2 has 3 unknowns (coupled); choose its assembly "
                       "with --guess\n")


def test_unknown_branch_lists_the_assemblies_and_the_sign_form(cli):
    run = cli("solve", str(SAMPLES / "watt_sixbar.toml"), "--branch", "sideways")
    assert run.code == 2 and len(run.err.splitlines()) == 1 and run.err.startswith("error: ")
    for word in ("open/open", "open/crossed", "crossed/open", "crossed/crossed", "++", "+-", "-+", "--"):
        assert word in run.err
    # where it cannot be assembled (P3 reaches only |theta2| <= 112.02 deg), it says so
    run = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--set", "theta2=150", "--branch", "+")
    assert run.code == 2 and "cannot be assembled" in run.err and len(run.err.splitlines()) == 1


def test_mirror_key_still_selects_the_rocker_driven_second_assembly(cli):
    """fourbar_me581_theta4: both assemblies at its theta4 are open; P3's own (theta2 = 65)
    is 'open', the other 'open (mirror)' (A reflected across O2-B)."""
    path = SAMPLES / "fourbar_me581_theta4.toml"
    plain = solve_json(cli, path, "--branch", "open")
    mirror = solve_json(cli, path, "--branch", "open (mirror)")
    assert plain["solution"]["theta2"] == pytest.approx(65.0, abs=1e-8)
    # independent: A on the circle about O2 (30) and about B (60), the other of the two
    B = 90.0 + 45.0 * cmath.exp(1j * math.radians(114.827770616))
    other = [A for A in circles(0j, 30.0, B, 60.0) if abs(wrap(deg(A) - 65.0)) > 1.0]
    assert len(other) == 1
    assert abs(wrap(mirror["solution"]["theta2"] - deg(other[0]))) < 1e-6
    assert mirror["branch"] == "open"


# --- 4. the old closed_form key ------------------------------------------------------------------

def _with_old_key(tmp_path, name: str, key: str) -> Path:
    """A sample with the old closed_form key put back (the samples no longer carry it)."""
    text = (SAMPLES / name).read_text()
    path = tmp_path / name
    path.write_text(text.replace('length_unit = ', f'closed_form = "{key}"\nlength_unit = ', 1))
    return path


def test_old_key_is_noted_once_per_command(cli, tmp_path):
    old = _with_old_key(tmp_path, "crank_rocker.toml", "fourbar")
    for args in (["solve", str(old)], ["sweep", str(old), "--from", "0", "--to", "20", "--step", "10"]):
        run = cli(*args, "--format", "json")
        assert run.code == 0
        assert run.err == (f"note: {old}: closed_form is no longer needed: "
                           "the closed form is derived from the loops\n"), args
    for name in ("crank_rocker.toml", "watt_sixbar.toml"):
        assert cli("solve", str(SAMPLES / name), "--format", "json").err == ""


def test_a_refused_command_says_only_its_error(cli):
    run = cli("solve", str(SAMPLES / "crank_rocker.toml"), "--branch", "sideways")
    assert run.code == 2 and len(run.err.splitlines()) == 1 and run.err.startswith("error: ")


def test_library_exposes_the_note_and_prints_nothing(capsys, tmp_path):
    old = _with_old_key(tmp_path, "slider_crank.toml", "slider_crank")
    m = load(old)
    assert m.closed_form == "slider_crank"
    assert m.closed_form_note == (f"{old}: closed_form is no longer needed: "
                                  "the closed form is derived from the loops")
    assert load(SAMPLES / "slider_crank.toml").closed_form_note is None
    assert capsys.readouterr().err == ""


def test_old_key_still_checked(tmp_path):
    """The key is still read and checked as before: a fourbar claim needs the names r1..r4
    (a, b, c, d are refused), a slider-crank claim on another loop is refused, a true one
    loads (and carries the note)."""
    good = abcd_file(tmp_path, "theta2", 65.0, {"theta3": 0.0, "theta4": 90.0},
                     key='closed_form = "fourbar"')
    with pytest.raises(ParseError, match="closed_form"):
        load(good)  # fourbar names r1..r4: a, b, c, d are not those names
    doc = {"name": "x", "length_unit": "cm", "closed_form": "slider_crank",
           "parameters": {"r2": {"value": 40, "unit": "cm"}, "r3": {"value": 120, "unit": "cm"},
                          "e": {"value": 10, "unit": "cm", "signed": True}},
           "driver": {"name": "theta2", "value": 45, "unit": "deg"},
           "unknowns": {"theta3": {"guess": 0, "unit": "deg"}, "s": {"guess": 150, "unit": "cm"}},
           "loops": [{"name": "L", "vectors": [
               {"length": "r2", "angle": "theta2"}, {"length": "r3", "angle": "theta3"},
               {"length": "s", "angle": 0, "sign": -1}, {"length": "e", "angle": 90, "sign": 1}]}]}
    with pytest.raises(ParseError, match="does not describe this file"):
        parse_mechanism(doc)  # + i e where the slider-crank has - i e
    doc["loops"][0]["vectors"][3]["sign"] = -1
    m = parse_mechanism(doc)
    assert m.derivation.complete and m.closed_form_note is not None
