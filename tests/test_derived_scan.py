"""Scans on the derivation (issue 19): the closed-form engine, the branch a design follows
and the four-bar columns come from ``m.derivation`` for every dyadic mechanism, not from
a ``closed_form`` key. References: the one-at-a-time sweep of each design (an independent
engine: continuation, step halving, its own gap rules), circle intersections and the
Grashof and transmission rules written out here."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.errors import InputError, ParseError
from linkage.kinematics.angles import angle_extent, closes_circle
from linkage.kinematics.designs import CONVERGED, engine_for, solve_designs
from linkage.kinematics.loading import from_text, load
from linkage.problems.closed_form import grashof
from linkage.scan import ScanJob, run_chunk
from linkage.scan.request import default_branch

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
STATUS = {0: "converged", 1: "no_solution", 2: "failed", 3: "off_branch"}
VALUES = tuple(float(v) for v in range(0, 360, 4))

# A four-bar written with Norton's names (a crank, b coupler, c rocker, d ground), other
# angle names, and no closed_form key: crank_rocker.toml's lengths.
NORTON = """
name = "four-bar, Norton's names"
length_unit = "mm"
[parameters]
a = { value = 40, unit = "mm" }
b = { value = 120, unit = "mm" }
c = { value = 80, unit = "mm" }
d = { value = 100, unit = "mm" }
ground = { value = 0, unit = "deg" }
[driver]
name = "t2"
value = 30
unit = "deg"
[unknowns]
t3 = { guess = 20, unit = "deg" }
t4 = { guess = 55, unit = "deg" }
[[loops]]
name = "O2-A-B-O4"
vectors = [
  { length = "a", angle = "t2" },
  { length = "b", angle = "t3" },
  { length = "c", angle = "t4", sign = -1 },
  { length = "d", angle = "ground", sign = -1 },
]
"""


def scan_records(text: str) -> list[dict]:
    """``linkage scan -f json``'s rows as dicts (the registry's shape: the records under
    "tables", with their column names)."""
    (t,) = json.loads(text)["tables"]
    return [dict(zip(t["columns"], r)) for r in t["rows"]]


def folded(mu_deg: float) -> float:
    return min(mu_deg, 180.0 - mu_deg)


def wrapped(deg: float) -> float:
    """|deg| wrapped into [0, 180]: the angle between two directions."""
    return abs((deg + 180.0) % 360.0 - 180.0)


# --- the engine runs on the derivation ----------------------------------------------------------

@pytest.mark.parametrize("name", ["crank_rocker", "slider_crank", "watt_sixbar", "fourbar_me581_theta4"])
def test_every_dyadic_sample_scans_on_the_closed_form(name):
    m = load(SAMPLES / f"{name}.toml")
    branch = default_branch(m, None, 1e-12)
    assert engine_for(m, branch) == "closed form"
    assert engine_for(load(SAMPLES / "offset_slider.toml"), None) == "continuation"  # coupled


# --- parity with the one-at-a-time sweep, design by design ------------------------------------

CASES = {
    "crank_rocker": {"r2": (25.0, 55.0), "r3": (90.0, 150.0), "r4": (55.0, 110.0)},
    "slider_crank": {"r2": (20.0, 60.0), "r3": (90.0, 160.0), "e": (-30.0, 30.0)},
    "watt_sixbar": {"r2": (30.0, 50.0), "r5": (55.0, 95.0), "r6": (85.0, 125.0), "r7": (55.0, 95.0)},
}


def _designs(name: str, n: int, seed: int) -> tuple[tuple[str, ...], np.ndarray]:
    rng = np.random.default_rng(seed)
    names = tuple(CASES[name])
    lo = np.array([CASES[name][k][0] for k in names])
    hi = np.array([CASES[name][k][1] for k in names])
    return names, lo + rng.random((n, len(names))) * (hi - lo)


def _transmissions(name: str, sol: dict[str, float]) -> list[float]:
    """Each four-bar loop's transmission angle (deg, folded into [0, 90]), written out:
    between the coupler and the output link from its ground pivot."""
    if name == "slider_crank":
        return []
    out = [folded(wrapped(sol["theta4"] - sol["theta3"]))]
    if name == "watt_sixbar":  # loop 2: coupler r6 (theta6), output O6-D = r7 e^(i theta7)
        out.append(folded(wrapped(sol["theta7"] - sol["theta6"])))
    return out


@pytest.mark.parametrize("name,asked", [("crank_rocker", None), ("crank_rocker", "crossed"),
                                        ("slider_crank", None), ("slider_crank", "crossed"),
                                        ("watt_sixbar", None)])
def test_scan_columns_equal_the_sweep_of_each_design(name, asked):
    """Statuses, positions (to 1e-12 of each column's largest value), the branch label,
    feasible and solved fractions, the range of every unknown, the Grashof class and the
    transmission extremes of every four-bar loop: the scan's record of each random design
    is what the one-at-a-time sweep of that design gives."""
    m = load(SAMPLES / f"{name}.toml")
    names, designs = _designs(name, 12, seed=19)
    branch = default_branch(m, asked, 1e-12)
    job = ScanJob("", m.source, (), names, VALUES, branch, 1e-12, m)
    rec = run_chunk(job, 0, designs)
    sol = solve_designs(m, {k: designs[:, j] for j, k in enumerate(names)}, np.array(VALUES),
                        branch=branch)
    partial = legacy = 0
    for i, row in enumerate(designs):
        design = m.with_values(dict(zip(names, map(float, row))), {})
        one = linkage.sweep(design, list(VALUES), batch=False, branch=asked)
        statuses = [p.status for p in one.positions]
        mine = [STATUS[int(c)] for c in sol.status[i]]
        for k, (a, b) in enumerate(zip(mine, statuses)):
            if (a, b) == ("off_branch", "no_solution"):
                # a sweep without the closed form calls a gap no_solution when least squares
                # from its anchors finds nothing; the derivation shows another assembly there
                assert design.derivation.solutions(math.radians(VALUES[k])), (name, i, k)
                statuses[k] = a
        if mine != statuses and any(p.branch and p.branch.startswith("det") for p in one.positions):
            # a sweep that follows the sign of det J (the six-bar's, until the sweep follows
            # the derivation) cannot tell after a gap whether it is back on its branch: the
            # derivation's signs can. Designs whose sweep reaches a gap are compared there.
            legacy += 1
            continue
        assert mine == statuses, (name, i)
        partial += "converged" != statuses[0] or len(set(statuses)) > 1
        solved = [p for p in one.positions if p.status == "converged"]
        assert rec["solved_fraction"][i] == len(solved) / len(VALUES)
        assembled = sum(s in ("converged", "off_branch") for s in statuses)
        assert rec["feasible_fraction"][i] == assembled / len(VALUES)
        for j, u in enumerate(m.unknowns):
            mine = sol.solution[i, :, j]
            theirs = np.array([p.solution[u.name] if p.solution else np.nan for p in one.positions])
            biggest = np.nanmax(np.abs(theirs), initial=0.0)
            assert np.allclose(mine, theirs, rtol=0.0, atol=1e-12 * max(biggest, 1.0), equal_nan=True), \
                (name, i, u.name, np.nanmax(np.abs(mine - theirs)))
            if not solved:
                continue
            shown = [p.solution[u.name] if p.solution else None for p in one.positions]
            if u.kind == "angle":
                lo, hi, span = angle_extent(shown, closes_circle(list(VALUES)))
            else:
                lo, hi = min(p.solution[u.name] for p in solved), max(p.solution[u.name] for p in solved)
                span = hi - lo
            for key, want in zip(("min", "max", "range"), (lo, hi, span)):
                assert abs(rec[f"{u.name}_{key}"][i] - want) <= 1e-12 * max(abs(want), 1.0), (name, i, key)
        for p in solved:
            # the label: the derivation names the sweep's configuration as the scan's branch
            q = [math.radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
                 for u in m.unknowns]
            assert design.derivation.name_of(q, math.radians(p.input)) == branch
            if not p.branch.startswith("det"):  # a sweep that labels by the derivation
                assert p.branch == branch
        # the four-bar loops' columns
        v = dict(zip(names, map(float, row)))
        value = {k: v.get(k, q.value) for k, q in m.parameters.items()}
        if name != "slider_crank":
            assert rec["grashof"][i] == grashof(value["r1"], value["r2"], value["r3"], value["r4"])
        if name == "watt_sixbar":
            assert rec["grashof_2"][i] == grashof(value["g"], value["r5"], value["r6"], value["r7"])
        if solved and name != "slider_crank":
            mus = [_transmissions(name, p.solution) for p in solved]
            for k, suffix in enumerate(("", "_2")[:len(mus[0])]):
                assert abs(rec[f"min_transmission_deg{suffix}"][i] - min(mu[k] for mu in mus)) <= 1e-9
                assert abs(rec[f"max_transmission_deg{suffix}"][i] - max(mu[k] for mu in mus)) <= 1e-9
    assert legacy <= len(designs) // 2  # most designs are compared
    assert name == "slider_crank" or partial or legacy  # some designs meet gaps


# --- a branch is its signs ------------------------------------------------------------------------

def test_branch_names_and_signs_are_the_same_branches():
    m = load(SAMPLES / "watt_sixbar.toml")
    params = {"r5": np.array([60.0, 70.0, 80.0])}
    vals = np.arange(0.0, 360.0, 10.0)
    named = m.derivation.named_solutions(0.0)
    for name, (signs, _q) in named.items():
        text = "".join("+" if s > 0 else "-" for s in signs)
        by_name = solve_designs(m, params, vals, branch=name)
        by_signs = solve_designs(m, params, vals, branch=text)
        assert (by_name.status == by_signs.status).all()
        np.testing.assert_array_equal(by_name.solution, by_signs.solution)
    crank = load(SAMPLES / "crank_rocker.toml")
    np.testing.assert_array_equal(solve_designs(crank, {}, vals, branch="+").solution,
                                  solve_designs(crank, {}, vals, branch="open").solution)


@pytest.mark.parametrize("text", ["left", "open", "open/sideways", "+", "+++"])
def test_a_branch_that_is_none_of_the_mechanisms_is_refused_with_the_choices(text):
    m = load(SAMPLES / "watt_sixbar.toml")
    with pytest.raises(InputError) as err:
        default_branch(m, text, 1e-12)
    assert "open or crossed / open or crossed" in str(err.value) and "++" in str(err.value)


def test_a_branch_on_coupled_loops_says_why_there_is_none():
    with pytest.raises(InputError, match="loop 1 has 3 unknowns"):
        default_branch(load(SAMPLES / "offset_slider.toml"), "open", 1e-12)


def test_the_cli_takes_names_and_signs(cli):
    a = cli("scan", str(SAMPLES / "watt_sixbar.toml"), "--vary", "r5=60:80:3", "--step", "30",
            "--branch", "open/crossed", "-f", "json")
    b = cli("scan", str(SAMPLES / "watt_sixbar.toml"), "--vary", "r5=60:80:3", "--step", "30",
            "--branch", "+-", "-f", "json")
    assert a.code == b.code == 0, (a.err, b.err)
    # the records are the same; the JSON document says which --branch was asked for
    assert scan_records(a.out) == scan_records(b.out) and "theta7_range" in a.out
    bad = cli("scan", str(SAMPLES / "watt_sixbar.toml"), "--vary", "r5=60:80:3", "--branch", "open")
    assert bad.code == 2 and bad.err.startswith("error: ") and len(bad.err.strip().splitlines()) == 1


def test_a_rocker_driven_four_bar_follows_its_sign_branch():
    """Driven by theta4, the two assemblies are mirror images of A across O2-B, and
    open/crossed changes along each. Each design keeps one side of O2-B (the sign of the
    derivation's step) over its whole range, starts on the named assembly, and every
    position is one of the two circle intersections, solved wherever they exist."""
    m = load(SAMPLES / "fourbar_me581_theta4.toml")
    r2s = np.array([20.0, 30.0, 35.0])
    vals = np.arange(0.0, 360.0, 2.0)
    sol = solve_designs(m, {"r2": r2s}, vals, branch="open")
    r1, r3, r4 = 90.0, 60.0, 45.0
    for i, r2 in enumerate(r2s):
        sides = set()
        first = True
        for k, v in enumerate(vals):
            b = r1 + r4 * complex(math.cos(math.radians(v)), math.sin(math.radians(v)))
            meets = abs(r2 - r3) <= abs(b) <= r2 + r3
            assert (sol.status[i, k] == CONVERGED) == meets, (r2, v)
            if not meets:
                continue
            t2, t3 = (math.radians(sol.solution[i, k, j]) for j in range(2))
            a = r2 * complex(math.cos(t2), math.sin(t2))
            assert abs(a + r3 * complex(math.cos(t3), math.sin(t3)) - b) < 1e-9 * r1
            assert abs(abs(a) - r2) < 1e-9 * r1
            cross = (b.conjugate() * a).imag  # which side of O2-B A is on
            sides.add(cross > 0)
            if first:  # the assembly named open where the design's sweep starts
                assert math.sin(math.radians(v) - t3) > 0
                first = False
        assert len(sides) == 1, r2


# --- the columns follow from the derivation's four-bar loops -------------------------------------

def test_a_four_bar_with_any_names_gets_the_four_bar_columns(cli, tmp_path):
    """Norton's names, no closed_form key: the same records as crank_rocker.toml's."""
    path = tmp_path / "norton.toml"
    path.write_text(NORTON)
    ours = cli("scan", str(path), "--vary", "a=30:50:3", "--step", "10", "--where",
               "min_transmission_deg > 20", "-f", "json")
    assert ours.code == 0, ours.err
    theirs = cli("scan", str(SAMPLES / "crank_rocker.toml"), "--vary", "r2=30:50:3", "--step", "10",
                 "--where", "min_transmission_deg > 20", "-f", "json")
    mine, ref = (scan_records(run.out) for run in (ours, theirs))
    assert len(mine) == len(ref) == 2  # a = 50 transmits below 20 deg somewhere
    for a, b in zip(mine, ref):
        assert a["grashof"] == b["grashof"] == "crank-rocker"
        for key in ("min_transmission_deg", "max_transmission_deg", "feasible_fraction"):
            assert a[key] == pytest.approx(b[key], rel=1e-12, abs=1e-12), key
        assert a["t4_range"] == pytest.approx(b["theta4_range"], rel=1e-12)


def test_the_second_four_bar_loop_has_suffixed_columns_that_may_not_clash():
    m = load(SAMPLES / "watt_sixbar.toml")
    from linkage.problems.columns import columns_of

    cols = [c[0] for c in columns_of(m, ("r2",))]
    for loop in ("", "_2"):
        assert {f"grashof{loop}", f"min_transmission_deg{loop}", f"max_transmission_deg{loop}"} <= set(cols)
    r7 = 'r7 = { value = 80, unit = "mm" }'
    clash = r7 + '\ngrashof_2 = { value = 1, unit = "mm" }'
    text = (SAMPLES / "watt_sixbar.toml").read_text().replace(r7, clash)
    with pytest.raises(ParseError, match="grashof_2"):
        from_text(text, "clash.toml")


def test_the_scan_target_is_judged_at_two_thousand_designs():
    from linkage.measure.sweeps import SCAN_DESIGNS, scan_keys, targets

    def row(times: dict[str, float]) -> tuple:
        return next(r for r in targets(times) if "Watt six-bar designs" in r[0])

    six, four = scan_keys(SCAN_DESIGNS)
    assert row({six: 2.5, four: 1.0})[2:] == (2.5, True)
    assert row({six: 3.5, four: 1.0})[2:] == (3.5, False)
    six, four = scan_keys(SCAN_DESIGNS // 10)  # --quick: measured, not judged
    assert row({six: 2.0, four: 1.0})[2:] == (2.0, None)


@pytest.mark.parametrize("name,varied", [
    ("crank_rocker", ("r1", "r2", "r3", "r4", "theta1")), ("slider_crank", ("r2", "r3", "e")),
    ("watt_sixbar", ("r2", "r3", "r4", "r5", "r6", "r7", "g", "gamma")),
    ("fourbar_me581_theta4", ("r1", "r2", "r3", "r4"))])
def test_a_name_is_one_sign_tuple_exactly_where_the_engine_says_so(name, varied):
    """Where designs.py takes a name's signs from one design for all (Derivation.names_are_signs),
    every configuration of random designs at random driver values on one sign tuple
    carries one name, by the name rule written out here (sin of the output from the
    coupler; the coupler against the slide); a rocker-driven four-bar's does not."""

    m = load(SAMPLES / f"{name}.toml")
    der = m.derivation
    rng = np.random.default_rng(5)
    params = {k: q.value * rng.uniform(0.5, 1.5, (400, 1)) if q.kind == "length"
              else rng.uniform(-np.pi, np.pi, (400, 1)) for k, q in m.parameters.items() if k in varied}
    params = {**{k: q.value for k, q in m.parameters.items()}, **params}
    drivers = rng.uniform(-np.pi, np.pi, (1, 50))
    constant = True
    for signs in der.branches:
        q, ok = der.solve_np(drivers, signs, params)
        at = {u.name: c for u, c in zip(m.unknowns, q)}
        at[m.driver.name] = np.broadcast_to(drivers, ok.shape)
        if name == "slider_crank":
            words = [np.cos(at["theta3"]) > 0]  # the coupler points the way s grows
        else:
            words = [np.sin(at["theta4"] - at["theta3"]) > 0]
            if name == "watt_sixbar":
                words.append(np.sin(at["theta7"] - at["theta6"]) > 0)
        for w in words:
            constant &= len(np.unique(w[ok])) == 1
    assert constant == der.names_are_signs
