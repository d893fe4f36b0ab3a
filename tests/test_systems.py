"""Loop-closure systems: P3, P5, the sample mechanisms, closed forms, failures, files."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import matches
from linkage import Status, load_mechanism, solve_system
from linkage.kinematics.loading import parse_mechanism
from linkage.problems.closed_form import (
    Indeterminate,
    fourbar_positions,
    slider_crank_positions,
    wrap_degrees,
)

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = str(SAMPLES / "fourbar_me581.toml")

# worked example P3, docs/worked_examples.md: k, theta3, theta4 (deg), Phi1, Phi2 (cm), det J, dtheta3,
# dtheta4 (rad)
P3_ROWS = (
    ("1", "0", "90", "-17.3215", "-17.8108", "-2700.0", "0.2968461", "0.3849212"),
    ("2", "17.0080", "112.0544", "-3.04875", "3.03231", "-2689.53", "-0.0661765", "0.0452519"),
    ("3", "13.2164", "114.6471", "-0.14438", "0.00679", "-2646.45", "-0.0011287", "0.0031514"),
    ("4", "13.1517", "114.8277", "-0.00013", "0.00019", "-2644.13", "-3.9e-06", "1.9e-06"),
    ("5", "13.1515", "114.8278", "-4.9e-10", "-3.3e-11", "-2644.13", "-3.0e-12", "1.1e-11"),
)


def matches_sig(value: float, printed: str) -> bool:
    """For figures printed in e-notation: agree to the printed significant digits."""
    if "e" not in printed:
        return matches(value, printed)
    mantissa = printed.split("e")[0]
    digits = len(mantissa.replace("-", "").replace(".", "").lstrip("0"))
    return abs(value - float(printed)) <= 0.5 * 10 ** (math.floor(math.log10(abs(float(printed))))
                                                       - digits + 1) * (1 + 1e-9)


def p3_view(doc_rows: list[dict]) -> list[tuple[float, ...]]:
    keys = ("k", "theta3 (deg)", "theta4 (deg)", "Phi1 (cm)", "Phi2 (cm)",
            "det J (cm^2/rad^2)", "dtheta3 (rad)", "dtheta4 (rad)")
    return [tuple(r[k] for k in keys) for r in doc_rows]


def test_p3_table_from_the_cli(cli):
    run = cli("solve", ME581, "--format", "json")
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    rows = p3_view(doc["iterations"])
    assert len(rows) == len(P3_ROWS)
    for got, want in zip(rows, P3_ROWS):
        for g, w in zip(got, want):
            assert matches_sig(g, w), (want[0], g, w)
    assert matches(doc["solution"]["theta3"], "13.151499346")
    assert matches(doc["solution"]["theta4"], "114.827770616")
    assert doc["branch"] == "open" and doc["nfev"] >= 5 and doc["njev"] == 5


def test_p3_from_the_api_and_the_crossed_branch():
    problem = load_mechanism(ME581).problem()
    result = solve_system(problem, tol=1e-12)
    t3, t4 = problem.to_display(result.x)
    assert (t3, t4) == (pytest.approx(13.151499346, abs=5e-10), pytest.approx(114.827770616, abs=5e-10))
    crossed = solve_system(problem, [math.radians(-50), math.radians(200)], tol=1e-12)
    c3, c4 = problem.to_display(crossed.x)
    assert wrap_degrees(c3 - -51.898819255) == pytest.approx(0, abs=5e-9)
    assert wrap_degrees(c4 - 206.424909476) == pytest.approx(0, abs=5e-9)
    assert math.sin(math.radians(c4 - c3)) < 0 < math.sin(math.radians(t4 - t3))


def test_newton_fd_shows_the_notes_numerical_jacobian(cli):
    run = cli("solve", ME581, "--method", "newton-fd", "--fd-step", "0.001", "--show-jacobian",
              "--format", "json")
    assert run.code == 0
    doc = json.loads(run.out)
    first = doc["iterations"][0]
    j = [first[f"dPhi{e}/d{q} (cm/rad)"] for e in (1, 2) for q in ("theta3", "theta4")]
    # column theta3 = {-0.0300, 60.0000}, column theta4 = {45.0000, 0.0225}
    for got, want in zip(j, ("-0.0300", "45.0000", "60.0000", "0.0225")):
        assert matches(got, want), (got, want)
    assert matches(doc["solution"]["theta3"], "13.151499346")
    assert matches(doc["solution"]["theta4"], "114.827770616")
    table = cli("solve", ME581, "--method", "newton-fd", "--fd-step", "0.001", "--show-jacobian")
    assert "dPhi1/dtheta3 (cm/rad)" in table.out


def test_theta4_driven_file_returns_theta2_65(cli):
    doc = json.loads(cli("solve", str(SAMPLES / "fourbar_me581_theta4.toml"), "--format", "json").out)
    assert matches(doc["solution"]["theta2"], "65.000000000")
    assert matches(doc["solution"]["theta3"], "13.151499346")


def test_rapier_drive_reaches_p5_from_the_books_guess():
    problem = load_mechanism(SAMPLES / "rapier_drive.toml").problem()
    result = solve_system(problem, tol=1e-6)
    assert result.converged and result.iterations <= 6
    got = problem.to_display(result.x)
    for g, w in zip(got, ("188.572556", "67.394934", "175.143712", "-216.940343")):
        assert matches(g, w), (g, w)


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
@pytest.mark.parametrize("method", ["newton", "newton-fd", "lm"])
def test_every_sample_converges_with_every_method(path, method):
    problem = load_mechanism(path).problem()
    result = solve_system(problem, method=method, tol=1e-10, max_iter=100)
    assert result.converged, result.message
    assert max(abs(v) for v in problem.F(list(result.x))) < 1e-8


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_analytic_jacobian_matches_central_differences(path, data):
    problem = load_mechanism(path).problem()
    q = [data.draw(st.floats(-math.pi, math.pi)) if k == "angle" else data.draw(st.floats(-500, 500))
         for k in problem.kinds]
    analytic = problem.J(q)
    for j in range(problem.n):
        h = 1e-6 * max(1.0, abs(q[j]))
        up, down = list(q), list(q)
        up[j] += h
        down[j] -= h
        fu, fd = problem.F(up), problem.F(down)
        for i in range(problem.n):
            central = (fu[i] - fd[i]) / (2 * h)
            scale = max(1.0, max(abs(v) for row in analytic for v in row))
            assert analytic[i][j] == pytest.approx(central, abs=1e-6 * scale)


def fourbar_doc(r1, r2, r3, r4, theta2, g3, g4):
    return {
        "name": "random four-bar", "length_unit": "mm", "closed_form": "fourbar",
        "parameters": {k: {"value": v, "unit": "mm"} for k, v in
                       (("r1", r1), ("r2", r2), ("r3", r3), ("r4", r4))} | {
                           "theta1": {"value": 0, "unit": "deg"}},
        "driver": {"name": "theta2", "value": theta2, "unit": "deg"},
        "unknowns": {"theta3": {"guess": g3, "unit": "deg"}, "theta4": {"guess": g4, "unit": "deg"}},
        "loops": [{"name": "L", "vectors": [
            {"length": "r2", "angle": "theta2"}, {"length": "r3", "angle": "theta3"},
            {"length": "r4", "angle": "theta4", "sign": -1},
            {"length": "r1", "angle": "theta1", "sign": -1}]}],
    }


links = st.floats(0.2, 5.0)


@settings(max_examples=120, deadline=None)
@given(links, links, links, links, st.floats(-180, 180), st.sampled_from(["open", "crossed"]),
       st.floats(-1, 1), st.floats(-1, 1))
def test_newton_finds_the_closed_form_on_both_branches(r1, r2, r3, r4, theta2, branch, n3, n4):
    try:
        sols = fourbar_positions(r1, r2, r3, r4, 0.0, theta2=math.radians(theta2))
    except Indeterminate:
        return
    if branch not in sols:
        return
    exact = sols[branch]
    if any(abs(math.sin(s_["theta4"] - s_["theta3"])) < 0.05 for s_ in sols.values()):
        return  # near a toggle position: the closed form itself is ill-conditioned there
    if len(sols) == 2 and max(abs(math.remainder(sols["open"][k] - sols["crossed"][k], 2 * math.pi))
                              for k in ("theta3", "theta4")) < math.radians(30):
        return  # the branches lie within the start's perturbation: "nearest" is ambiguous
    g3 = math.degrees(exact["theta3"]) + n3
    g4 = math.degrees(exact["theta4"]) + n4
    problem = parse_mechanism(fourbar_doc(r1, r2, r3, r4, theta2, g3, g4)).problem()
    result = solve_system(problem, tol=1e-12, max_iter=60)
    assert result.converged, result.message
    t3, t4 = result.x
    assert abs(math.remainder(t3 - exact["theta3"], 2 * math.pi)) < 1e-9
    assert abs(math.remainder(t4 - exact["theta4"], 2 * math.pi)) < 1e-9


@settings(max_examples=80, deadline=None)
@given(st.floats(0.5, 3), st.floats(3.5, 8), st.floats(-0.4, 0.4), st.floats(-180, 180),
       st.sampled_from(["open", "crossed"]))
def test_slider_crank_matches_its_closed_form(r2, r3, e, theta2, branch):
    exact = slider_crank_positions(r2, r3, e, math.radians(theta2))[branch]
    mech = load_mechanism(SAMPLES / "slider_crank.toml").with_values(
        {"r2": r2, "r3": r3, "e": e, "theta2": theta2},
        {"theta3": math.degrees(exact["theta3"]) + 2.0, "s": exact["s"] + 0.1})
    result = solve_system(mech.problem(), tol=1e-12)
    assert result.converged
    assert abs(math.remainder(result.x[0] - exact["theta3"], 2 * math.pi)) < 1e-9
    assert result.x[1] == pytest.approx(exact["s"], abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(links, links, links, links, st.floats(-180, 180))
def test_lm_never_claims_success_above_tolerance(r1, r2, r3, r4, theta2):
    problem = parse_mechanism(fourbar_doc(r1, r2, r3, r4, theta2, 10.0, 80.0)).problem()
    result = solve_system(problem, method="lm", tol=1e-9, max_iter=200)
    if result.converged:
        # the promise is max|Phi| <= tol x the length scale (rules.residual_gate): at
        # r = 2, theta2 = 1e-7 deg (a change point) a solve stops at 1.75e-9 <= 2e-9
        assert max(abs(v) for v in problem.F(list(result.x))) <= 1e-9 * problem.length_scale
        assert result.meta["ftol"] == 1e-9 * problem.length_scale
    try:
        sols = fourbar_positions(r1, r2, r3, r4, 0.0, theta2=math.radians(theta2))
    except Indeterminate:
        return
    if sols == {}:
        assert not result.converged and result.status is Status.NO_SOLUTION
    elif result.status is Status.CONVERGED_STEP:
        # a step-converged claim is a forward one: within tol of a root the closed form gives
        assert gap_to_roots(result.x, sols) <= 1e-9 * 10


def gap_to_roots(x, sols):
    """The largest angle (rad) by which x misses the nearest closed-form assembly."""
    return min(max(abs(math.remainder(v - sol[k], 2 * math.pi)) for v, k in zip(x, ("theta3", "theta4")))
               for sol in sols.values())


def test_lm_closing_in_on_a_family_of_roots_claims_no_step():
    """Regression (found by Hypothesis): r1 = r2 = 1.5, r3 = r4 = 0.9921875 at theta2 =
    4.4e-94 rad. At theta2 = 0 every theta3 = theta4 closes the loops; LM closed in on
    45 deg, quadratically, with J ever more singular, and called its last small step
    (2.3e-13) convergence, 45 deg from every root at this theta2. A step from a J that
    Newton's own test calls singular bounds nothing: the claim is now the residual's."""
    problem = parse_mechanism(fourbar_doc(1.5, 1.5, 0.9921875, 0.9921875, 4.4170598989597503e-94,
                                          10.0, 80.0)).problem()
    result = solve_system(problem, method="lm", tol=1e-9, max_iter=200)
    assert result.status is not Status.CONVERGED_STEP
    assert result.status is Status.CONVERGED_RESIDUAL
    assert max(abs(v) for v in problem.F(list(result.x))) <= 1e-9 * problem.length_scale


def test_lm_at_a_change_point_claims_the_residual_not_a_step():
    """Regression (found by Hypothesis): r1..r4 = 2 at theta2 = 1e-7 deg. LM stopped at
    theta3 = theta4 = 45 deg, a point of the family of roots at theta2 = 0, 45 deg from
    any root at 1e-7 deg (theta3 near 0 or 180), and called it step-converged with
    "error 2.87e-13", its damped step. The error is now the undamped step: the claim made
    is the residual's (max|Phi| 1.75e-9 within tol x scale), named as such."""
    problem = parse_mechanism(fourbar_doc(2.0, 2.0, 2.0, 2.0, 1e-7, 10.0, 80.0)).problem()
    result = solve_system(problem, method="lm", tol=1e-9, max_iter=200)
    assert result.status is Status.CONVERGED_RESIDUAL
    sols = fourbar_positions(2.0, 2.0, 2.0, 2.0, 0.0, theta2=math.radians(1e-7))
    assert gap_to_roots(result.x, sols) > 0.1  # far from every root: a residual claim, not a step one


def test_a_change_point_is_indeterminate_not_unassemblable():
    """Regression: r1 = r2 = r3 = r4 at theta2 = 0 puts A on O4, where every theta4
    works; the closed form once called that 'cannot be assembled' while LM solved it."""
    with pytest.raises(Indeterminate):
        fourbar_positions(1.0, 1.0, 1.0, 1.0, 0.0, theta2=0.0)
    problem = parse_mechanism(fourbar_doc(1, 1, 1, 1, 0.0, 10.0, 80.0)).problem()
    result = solve_system(problem, method="lm", tol=1e-9)
    assert result.converged and problem.reference() is None


def test_non_assemblable_input_is_no_solution_with_rows(cli):
    """The library's solve runs and names it no_solution, with its rows; the command line
    refuses it as bad input (one line, exit 2: docs/output.md, "Exit codes")."""
    problem = load_mechanism(ME581).with_values({"theta2": 180}, {}).problem()
    r = solve_system(problem)
    assert r.status is Status.NO_SOLUTION and "cannot be assembled at theta2 = 180" in r.message
    assert len(r.history.rows) > 0
    lm = solve_system(problem, method="lm")
    assert lm.status is Status.NO_SOLUTION and not lm.converged
    for method in ("newton", "lm"):
        run = cli("solve", ME581, "--set", "theta2=180", "--method", method, "--format", "json")
        assert run.code == 2 and run.out == ""
        assert run.err.strip().endswith("cannot be assembled at theta2 = 180 deg (the closed form has no "
                                         "real solution)"), run.err


def test_singular_start_is_a_named_stop(cli):
    """The textbook iteration (--plain) stops at a singular start with det and cond; the
    default, globalised, steps off it with a damped step and reaches an assembly."""
    run = cli("solve", ME581, "--plain", "--guess", "theta3=30", "--guess", "theta4=30", "--format", "json")
    assert run.code == 1
    doc = json.loads(run.out)
    assert doc["status"] == "singular_jacobian"
    assert "det J = " in doc["message"] and "cond J = " in doc["message"]
    assert len(doc["iterations"]) == 1
    recovered = json.loads(cli("solve", ME581, "--guess", "theta3=30", "--guess", "theta4=30",
                               "--format", "json").out)
    assert recovered["converged"]
    branch = recovered["reference"][recovered["branch"]]
    for name in ("theta3", "theta4"):
        assert recovered["solution"][name] == pytest.approx(branch[name], abs=1e-9)


MALFORMED = {
    "unknown unit": ('r1 = { value = 1, unit = "in" }', "parameters.r1.unit"),
    "unknown name in a loop": ('r1 = { value = 1, unit = "cm" }', "loops[0].vectors[3].length"),
    "missing guess": ("", "unknowns.theta4"),
    "bad sign": ("", "loops[0].vectors[0].sign"),
    "negative length": ('r1 = { value = -1, unit = "cm" }', "parameters.r1.value"),
    "unknown top-level key": ("", "colour"),
}


def malformed_text(case: str) -> str:
    text = Path(ME581).read_text()
    if case == "unknown unit":
        # not "in": an inch is converted on read now
        return text.replace('r1 = { value = 90, unit = "cm" }', 'r1 = { value = 90, unit = "furlong" }')
    if case == "unknown name in a loop":
        return text.replace('{ length = "r1", angle = "theta1", sign = -1 }',
                            '{ length = "r9", angle = "theta1", sign = -1 }')
    if case == "missing guess":
        return text.replace('theta4 = { guess = 90, unit = "deg" }', 'theta4 = { unit = "deg" }')
    if case == "bad sign":
        return text.replace('{ length = "r2", angle = "theta2" }',
                            '{ length = "r2", angle = "theta2", sign = 2 }')
    if case == "negative length":
        return text.replace('r1 = { value = 90, unit = "cm" }', 'r1 = { value = -90, unit = "cm" }')
    return 'colour = "red"\n' + text


@pytest.mark.parametrize("case", list(MALFORMED))
def test_malformed_files_exit_2_naming_the_key(cli, tmp_path, case):
    path = tmp_path / "bad.toml"
    path.write_text(malformed_text(case))
    run = cli("solve", str(path))
    assert run.code == 2
    assert len(run.err.strip().splitlines()) == 1
    assert MALFORMED[case][1] in run.err and str(path) in run.err


def test_invalid_toml_names_the_line(cli, tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text('name = "x"\n[[loops]\n')
    run = cli("solve", str(path))
    assert run.code == 2 and "line 2" in run.err


def test_equation_count_must_match_unknowns(tmp_path, cli):
    extra = 'theta4 = { guess = 90, unit = "deg" }\nr5 = { guess = 1, unit = "cm" }'
    text = Path(ME581).read_text().replace('theta4 = { guess = 90, unit = "deg" }', extra)
    path = tmp_path / "count.toml"
    path.write_text(text)
    run = cli("solve", str(path))
    assert run.code == 2 and "2 equations but there are 3 unknowns" in run.err


def test_csv_for_a_mechanism_has_units_in_every_header(cli):
    run = cli("solve", ME581, "--format", "csv", "--table", "iterations")
    lines = run.out.splitlines()
    header = lines[0].split(",")
    assert all("(" in h for h in header if h not in ("k", "cond J")), header


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
@settings(max_examples=25, deadline=None)
@given(driver=st.floats(-180, 180))
def test_loop_closure_holds_at_every_converged_position(path, driver):
    """Whatever the driver value, a solve that claims convergence closes every loop."""
    m = load_mechanism(path)
    problem = m.with_values({m.driver.name: driver}, {}).problem()
    for method in ("newton", "lm"):
        result = solve_system(problem, method=method, tol=1e-10, max_iter=100, record=False)
        if result.converged:
            scale = max(q.value for q in m.parameters.values() if q.kind == "length")
            assert max(abs(v) for v in problem.F(list(result.x))) <= 1e-9 * max(1.0, scale)


def test_rocker_driven_fourbar_keeps_both_assemblies_and_labels_each_position():
    """Driven by theta4, the two assemblies are mirror images of A across O2-B, and
    sin(theta4 - theta3) can have the same sign on both (theta4 = 189 deg here): the
    closed form once labelled both "crossed" and lost one, and the sweep labelled every
    position with the file's own theta4. (Issue 18 changed the label to the
    configuration rule whatever the driver: both keep distinct keys, the second
    "crossed (mirror)", and each sweep position carries its own configuration's label.
    Issue 19: a sweep follows one assembly by its signs, the one that carries the
    requested name where the name first appears; its positions turn from open to crossed
    along it, and the mirror assembly is reached by its own key or signs.)"""
    import math
    from itertools import pairwise

    from linkage.kinematics.sweep import sweep
    from linkage.problems.closed_form import fourbar_positions

    sols = fourbar_positions(90.0, 20.0, 60.0, 45.0, 0.0, theta4=math.radians(189.0))
    assert set(sols) == {"crossed", "crossed (mirror)"}
    assert sols["crossed"]["theta2"] != sols["crossed (mirror)"]["theta2"]
    assert all(math.sin(s["theta4"] - s["theta3"]) < 0 for s in sols.values())
    assert math.sin(sols["crossed"]["theta3"] - sols["crossed"]["theta2"]) < 0
    m = load_mechanism(SAMPLES / "fourbar_me581_theta4.toml").with_values({"r2": 20.0}, {})
    followed = {}
    for branch in ("open", "crossed", "open (mirror)"):
        result = sweep(m, [float(v) for v in range(0, 360, 3)], branch=branch)
        solved = [p for p in result.positions if p.solution]
        assert solved
        for p in solved:
            side = math.sin(math.radians(p.input - p.solution["theta3"]))
            assert p.branch == ("open" if side > 0 else "crossed"), p
        # one assembly: constant signs, reported as the sweep's branch, and no jump
        signs = {m.derivation.signs_of([math.radians(p.solution[u.name]) for u in m.unknowns],
                                       math.radians(p.input)) for p in solved}
        assert len(signs) == 1 and result.branch == "+-"[signs.pop()[0] < 0], (branch, signs)
        assert max(abs(math.remainder(b.solution["theta2"] - a.solution["theta2"], 360.0))
                   for a, b in pairwise(solved)) < 15.0
        # where the name first appears (the closed form above, r2 = 20), the sweep carries it
        first = next(p for p in solved if branch.removesuffix(" (mirror)") in
                     {k.removesuffix(" (mirror)") for k in
                      fourbar_positions(90.0, 20.0, 60.0, 45.0, 0.0, theta4=math.radians(p.input))})
        if not branch.endswith("(mirror)"):
            assert first.branch == branch
        followed[branch] = (result.branch, {p.branch for p in solved})
    # both assemblies reached, and each passes through both names
    assert {b for b, _ in followed.values()} == {"+", "-"}
    assert all(names == {"open", "crossed"} for _, names in followed.values())
