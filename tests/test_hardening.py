"""Regressions from the adversarial pass (issue 9), each named after the attack.

Bad input: exit 2 and one line. A non-root: exit 1, a named status, no claimed root.
No file lost or truncated. Hangs and memory blow-ups are run in a child process with a
1 GB address-space limit and a generous timeout that only guards against a hang.
"""

from __future__ import annotations

import errno
import json
import math
import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from linkage import Status, load_mechanism, solve_scalar, solve_system
from linkage.problems.expression import Expression, equation_problem

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = SAMPLES / "fourbar_me581.toml"


def one_line_exit_2(run) -> None:
    assert run.code == 2, (run.code, run.err)
    lines = [ln for ln in run.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), run.err
    assert "Traceback" not in run.err and "internal error" not in run.err


def bounded(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    """``linkage ARGS`` in a child limited to 1 GB of address space."""

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))

    return subprocess.run([sys.executable, "-m", "linkage", *args], capture_output=True, text=True,
                          timeout=60, preexec_fn=limit, input=stdin)


# --- data loss ------------------------------------------------------------------------------

@pytest.mark.parametrize("command", [("solve",), ("sweep", "--step", "30"), ("solve", "--set", "theta2=150")])
def test_output_onto_the_input_file_is_refused(cli, tmp_path, command):
    m = tmp_path / "m.toml"
    shutil.copy(ME581, m)
    before = m.read_bytes()
    run = cli(command[0], str(m), *command[1:], "-o", str(m))
    one_line_exit_2(run)
    assert m.read_bytes() == before


def test_output_through_a_symlink_to_the_input_is_refused(cli, tmp_path):
    m = tmp_path / "m.toml"
    shutil.copy(ME581, m)
    link = tmp_path / "out.csv"
    link.symlink_to(m)
    before = m.read_bytes()
    one_line_exit_2(cli("solve", str(m), "-o", str(link)))
    assert m.read_bytes() == before


def test_output_through_a_hard_link_to_the_input_is_refused(cli, tmp_path):
    m = tmp_path / "m.toml"
    shutil.copy(ME581, m)
    os.link(m, tmp_path / "hard.json")
    one_line_exit_2(cli("solve", str(m), "-o", str(tmp_path / "hard.json")))


def test_one_path_for_two_outputs_is_refused(cli, tmp_path):
    out = tmp_path / "same.png"
    one_line_exit_2(cli("sweep", str(ME581), "--step", "30", "-o", str(out), "--plot", str(out)))
    assert not out.exists()


def test_plot_suffix_is_checked_before_any_work(cli, tmp_path):
    one_line_exit_2(cli("sweep", str(ME581), "--plot", str(tmp_path / "foo.txt")))


def test_a_failed_write_leaves_the_old_file_intact(cli, tmp_path, monkeypatch):
    out = tmp_path / "table.csv"
    out.write_text("precious\n")

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("linkage.files.os.fsync", full)
    run = cli("solve", "-o", str(out))
    one_line_exit_2(run)
    assert "No space left" in run.err
    assert out.read_text() == "precious\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]  # no temporary left


def test_stdout_on_a_full_disk_is_one_line_not_an_internal_error():
    with open("/dev/full", "w") as full:
        p = subprocess.run([sys.executable, "-m", "linkage", "solve"], stdout=full, stderr=subprocess.PIPE,
                           text=True, timeout=60)
    assert p.returncode == 2
    assert p.stderr.strip().startswith("error: cannot write to standard output")
    assert len(p.stderr.strip().splitlines()) == 1


def test_output_to_dev_full_is_one_line(cli):
    one_line_exit_2(cli("solve", "-o", "/dev/full"))


def test_a_path_with_a_line_break_is_still_one_error_line(cli, tmp_path):
    """A file name holding a newline is quoted with \\n, not broken over lines (docs/output.md: one line)."""
    run = cli("solve", str(tmp_path / "no\nfile.toml"))
    one_line_exit_2(run)
    assert "no\\nfile.toml" in run.err
    one_line_exit_2(cli("solve", "-e", "x - 1", "-o", str(tmp_path / "no\ndir" / "x.json")))


# --- false convergence ------------------------------------------------------------------------

@pytest.mark.parametrize("equation,x0", [
    ("x**99999999", "1"),            # Newton's step test at 0.99999999 with f = 0.368
    ("1/(x-1)", "1.0000001"),         # a pole
    ("tan(x)", "1.5707963"),          # a pole, f = 1.9e7
    ("sqrt(x)-1", "1e-320"),          # a tiny step from a huge slope, f = -1
])
def test_newton_small_step_is_not_a_root(cli, equation, x0):
    run = cli("solve", "--equation", equation, "--x0", x0, "--format", "json")
    assert run.code == 1, run.out[-300:]
    doc = json.loads(run.out)
    assert not doc["converged"] and doc["status"] in ("stalled", "discontinuity", "max_iter", "diverged",
                                                       "domain_error", "non_finite", "precision_limit")


@pytest.mark.parametrize("equation", ["0/0 + x", "0*log(x)+x"])
def test_simplifier_keeps_nan_and_domain_restrictions(cli, equation):
    run = cli("solve", "--equation", equation, "--x0", "1", "--format", "json")
    assert run.code == 1
    assert json.loads(run.out)["converged"] is False
    f = equation_problem(equation).f
    with pytest.raises((ZeroDivisionError, ValueError)):
        f(0.0 if "log" in equation else 1.0)


def test_regression_certified_roots_still_converge():
    """The evidence test does not reject real roots: simple, triple, and linear fixed-point."""
    for text, x0 in (("x**2 - 2", 1.0), ("(x - 1)**3", 1.3), ("exp(x) - 3*x", 0.0)):
        r = solve_scalar(equation_problem(text), method="newton", x0=x0, tol=1e-10)
        assert r.converged, (text, r.message)


def test_regression_linear_fixed_point_runs_on_until_certified():
    """g = exp(x)/3 has rate 0.62: a step of 7e-13 leaves an error of 1.2e-12, so the run
    goes on until a sign change shows the root within the tolerance."""
    p = equation_problem("exp(x) - 3*x", "exp(x)/3")
    r = solve_scalar(p, method="fixed-point", x0=0.0, tol=1e-12, max_iter=500)
    assert r.converged
    assert abs(r.x - 0.6190612867359451) <= 1e-12


def test_micrometre_fourbar_without_assembly_is_not_converged(cli):
    """ME581 scaled to micrometres (in cm: 9e-7 ...) at theta2 = 150 cannot be assembled;
    an absolute residual tolerance called that converged."""
    args = ["--set", "r1=9e-7", "--set", "r2=3e-7", "--set", "r3=6e-7", "--set", "r4=4.5e-7",
            "--set", "theta2=150"]
    m = load_mechanism(ME581).with_values({"r1": 9e-7, "r2": 3e-7, "r3": 6e-7, "r4": 4.5e-7,
                                           "theta2": 150}, {})
    for method in ("lm", "newton"):
        r = solve_system(m.problem(), method=method)
        assert not r.converged and r.status is Status.NO_SOLUTION
        # the command line refuses it (bad input: the closed form has no assembly there)
        one_line_exit_2(cli("solve", str(ME581), *args, "--method", method, "--format", "json"))


def test_units_do_not_change_the_answer():
    """The ME581 four-bar in cm and the same four-bar in km: same iterations, same angles."""
    m = load_mechanism(ME581)
    big = m.with_values({k: m.parameters[k].value * 1e5 for k in ("r1", "r2", "r3", "r4")}, {})
    small = m.with_values({k: m.parameters[k].value * 1e-5 for k in ("r1", "r2", "r3", "r4")}, {})
    results = [solve_system(x.problem(), tol=1e-10) for x in (m, big, small)]
    assert all(r.converged for r in results)
    assert len({r.iterations for r in results}) == 1
    for r in results[1:]:
        assert r.x == pytest.approx(results[0].x, abs=1e-12)


def test_offset_slider_in_metres_without_assembly_is_not_converged():
    m = load_mechanism(SAMPLES / "offset_slider.toml")
    metres = m.with_values({k: q.value / 1000 for k, q in m.parameters.items() if q.kind == "length"}, {})
    for value in (150.0, 160.0):  # inside the offset slider's no-assembly gap
        r = solve_system(metres.with_values({m.driver.name: value}, {}).problem(), method="lm")
        assert not r.converged and r.status in (Status.LOCAL_MINIMUM, Status.NO_SOLUTION)


@pytest.mark.parametrize("tol", ["1e308", "0.5"])
def test_meaninglessly_loose_system_tolerance_is_refused(cli, tol):
    one_line_exit_2(cli("solve", str(ME581), "--tol", tol, "--set", "theta2=150"))


@pytest.mark.parametrize("links", [("3e-320",) * 4, ("1", "2", "3e-320", "2")])
def test_subnormal_link_lengths_are_refused(cli, links):
    one_line_exit_2(cli("solve", "--links", *links))


def test_extreme_but_normal_link_lengths_give_the_ratio_answer(cli):
    ref = json.loads(cli("solve", "--links", "2", "4", "3", "5", "--format", "json").out)["solution"]
    for k in (1e-300, 9e307 / 5):
        links = [str(v * k) for v in (2, 4, 3, 5)]
        doc = json.loads(cli("solve", "--links", *links, "--format", "json").out)
        assert doc["solution"]["phi"] == pytest.approx(ref["phi"], abs=1e-9)


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def _claimed(text: str) -> str:
    """The file with the old claim closed_form = "fourbar" (no longer needed, still checked)."""
    return text.replace('length_unit = ', 'closed_form = "fourbar"\nlength_unit = ', 1)


def test_closed_form_that_does_not_match_the_loops_is_refused(cli, tmp_path):
    text = _claimed(ME581.read_text()).replace('sign = -1 }', 'sign = 1 }', 1)
    assert text != _claimed(ME581.read_text())
    run = cli("solve", str(write(tmp_path, "lie.toml", text)))
    one_line_exit_2(run)
    assert "does not describe" in run.err


def test_closed_form_with_theta3_as_the_driver_is_refused(cli, tmp_path):
    text = _claimed(ME581.read_text())
    text = text.replace('name = "theta2"', 'name = "theta3"').replace("theta3 = {", "theta2 = {", 1)
    path = write(tmp_path, "t3.toml", text)
    run = cli("solve", str(path))
    one_line_exit_2(run)
    assert "closed_form" in run.err and "driver" in run.err


# --- hangs and memory ------------------------------------------------------------------------

@pytest.mark.parametrize("equation", [
    "*".join(f"(x-{i})" for i in range(200)),
    "*".join(["sin(x)"] * 280),
    "sin(" * 199 + "x" + ")" * 199,
])
def test_large_equations_compile_in_linear_size(equation):
    e = Expression.parse(equation)
    assert len(e.ops) <= 3 * 200 + 5
    assert len(e.source(2).splitlines()) < 10 * len(e.ops)
    r = bounded("solve", "--equation", equation, "--x0", "0.5")
    assert r.returncode in (0, 1) and "Traceback" not in r.stderr


@pytest.mark.parametrize("op", ["+", "-", "*"])
def test_long_operator_chains_are_not_a_recursion_error(cli, op):
    run = cli("solve", "--equation", op.join(["x"] * 600) + " - 1", "--x0", "0.5")
    assert run.code in (0, 1) and "internal error" not in run.err


def test_huge_max_iter_is_refused_and_long_runs_keep_bounded_history(cli):
    for n in ("10000000", str(10**30)):
        one_line_exit_2(cli("solve", "--equation", "x**3-2*x+2", "--x0", "0", "--max-iter", n))
    r = solve_scalar(equation_problem("x**3 - 2*x + 2"), method="newton", x0=0.0, max_iter=100_000)
    assert r.status is Status.MAX_ITER and r.iterations == 100_000
    assert len(r.history.rows) == 500 and r.history.elided == 100_000 - 500


@pytest.mark.parametrize("args", [
    ("--points", str(10**9)),
    ("--from", "1e300", "--to", "1e300"),
    ("--from", "1e26", "--to", "2e26"),
    ("--from", "1e26", "--to", "1e26"),
    ("--from", "1e26", "--to", "1e26", "--points", "3"),
])
def test_sweep_sizes_and_unresolvable_ranges_are_refused(cli, args):
    one_line_exit_2(cli("sweep", str(SAMPLES / "crank_rocker.toml"), *args))


def test_a_fifo_as_the_mechanism_file_is_refused(cli, tmp_path):
    fifo = tmp_path / "m.toml"
    os.mkfifo(fifo)
    one_line_exit_2(cli("solve", str(fifo)))


def test_a_symlink_to_dev_zero_is_refused(cli, tmp_path):
    link = tmp_path / "zero.toml"
    link.symlink_to("/dev/zero")
    one_line_exit_2(cli("solve", str(link)))


def test_an_oversized_mechanism_file_is_refused(cli, tmp_path):
    big = write(tmp_path, "big.toml", ME581.read_text() + "#" * 2_000_000 + "\n")
    one_line_exit_2(cli("solve", str(big)))


# --- numbers that overflow, one line each --------------------------------------------------------

@pytest.mark.parametrize("args", [
    ("solve", str(ME581), "--set", "r1=1e400"),
    ("solve", "--r1", "1e400"),
    ("solve", "--links", "1", "1", "1", "1e400"),
    ("solve", str(ME581), "--guess", "theta3=1e400"),
    ("solve", str(ME581), "--set", "theta2=" + "9" * 400),
    ("solve", "--r1", "1" * 58 + "/0"),
    ("solve", "--alpha", "1e400"),
    ("solve", "--x0", "1e400"),
    ("solve", str(ME581), "--set", "r1=1e-300"),
    ("solve", str(ME581), "--set", "r1=9e307"),
    ("sweep", str(ME581), "--set", "r1=9e307", "--set", "r2=9e307", "--set", "r3=9e307",
     "--set", "r4=9e307"),
    ("solve", "--method", "bisection", "--bracket", "-1e308", "1e308"),
    ("solve", "--method", "hybrid", "--bracket", "-inf", "1"),
])
def test_overflowing_numbers_are_one_line(cli, args):
    one_line_exit_2(cli(*args))


def test_huge_fd_step_is_not_an_internal_error(cli):
    run = cli("solve", str(ME581), "--method", "newton-fd", "--fd-step", "1e308")
    assert run.code in (1, 2) and "internal error" not in run.err


@pytest.mark.parametrize("body", [
    "r1 = { value = " + "9" * 401 + ", unit = \"cm\" }",
    "r1 = { value = nan, unit = \"cm\" }",
    "r1 = { value = inf, unit = \"cm\" }",
])
def test_file_numbers_that_overflow_name_the_key(cli, tmp_path, body):
    text = ME581.read_text()
    start = text.index("r1 = {")
    end = text.index("\n", start)
    path = write(tmp_path, "m.toml", text[:start] + body + text[end:])
    run = cli("solve", str(path))
    one_line_exit_2(run)
    assert "r1" in run.err


def test_offset_nan_in_a_loop_is_one_line(cli, tmp_path):
    text = (SAMPLES / "rapier_drive.toml").read_text()
    mutated = text.replace("sign = -1 }", "sign = -1, offset = nan }", 1)
    assert mutated != text
    run = cli("solve", str(write(tmp_path, "m.toml", mutated)))
    one_line_exit_2(run)
    assert "offset" in run.err


def test_deeply_nested_toml_is_one_line(cli, tmp_path):
    path = write(tmp_path, "deep.toml", 'name = "x"\nnotes = ' + "[" * 600 + "]" * 600 + "\n")
    one_line_exit_2(cli("solve", str(path)))


def test_closed_pipe_on_stdout_is_one_line_and_nonzero(capsys, monkeypatch):
    """A reader that goes away (``| head``): the write raises BrokenPipeError. (Pipes here
    may buffer megabytes, so the failure is injected rather than provoked.)"""
    from linkage.cli import run_cli

    class ClosedPipe:
        def write(self, text: str) -> int:
            raise BrokenPipeError(errno.EPIPE, "Broken pipe")

        def flush(self) -> None:
            raise BrokenPipeError(errno.EPIPE, "Broken pipe")

        def isatty(self) -> bool:
            return False

    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    code = run_cli(["sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "10", "--format", "csv"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip().startswith("error: cannot write to standard output")
    assert len(err.strip().splitlines()) == 1


# --- system solver robustness ---------------------------------------------------------------------

WATT = SAMPLES / "watt_sixbar.toml"
ROUGH = ("theta3=0", "theta4=90", "theta6=0", "theta7=90")


def _watt_reference(theta2_deg: float) -> list[tuple[float, float, float, float]]:
    """Both loops by circle intersections (no Newton): every assembly at theta2, in degrees."""
    import cmath
    import math

    from linkage.problems.closed_form import fourbar_positions

    d = math.radians
    out = []
    for sol in fourbar_positions(100, 40, 120, 80, 0.0, theta2=d(theta2_deg)).values():
        t3, t4 = sol["theta3"], sol["theta4"]
        o4 = 100 + 0j
        c = o4 + 70 * cmath.exp(1j * (t4 + d(40)))
        o6 = o4 + 120 * cmath.exp(1j * d(60))
        from linkage.problems.closed_form import circle_points

        for dpt in circle_points(o6, 80, c, 110):
            out.append(tuple(math.degrees(v) for v in (t3, t4, cmath.phase(dpt - c), cmath.phase(dpt - o6))))
    return out


def test_watt_sixbar_from_a_rough_guess_converges_where_plain_newton_cycles(cli):
    """The sample Watt six-bar from a rough guess: the textbook iteration cycles to the cap;
    the default globalised Newton and lm reach an assembly that the circle-intersection
    reference confirms."""
    guesses = [a for g in ROUGH for a in ("--guess", g)]
    plain = json.loads(cli("solve", str(WATT), "--plain", *guesses, "--format", "json").out)
    assert plain["status"] == "max_iter" and plain["solution"] is None and plain["last_iterate"]
    for method in ("newton", "lm"):
        doc = json.loads(cli("solve", str(WATT), "--method", method, *guesses, "--format", "json").out)
        assert doc["converged"], doc["message"]
        got = [doc["solution"][k] for k in ("theta3", "theta4", "theta6", "theta7")]
        refs = _watt_reference(30)
        best = min(max(abs((g - r + 180) % 360 - 180) for g, r in zip(got, ref)) for ref in refs)
        assert best <= 1e-9


def test_brown_almost_linear_is_not_called_singular():
    """Brown n = 10 from x10: the old row-scaled test stopped as 'singular' at cond 4e25
    while Newton converges; the equilibrated test lets it run."""
    from linkage.problems.mgh import brown_almost_linear

    s = brown_almost_linear(10)
    r = solve_system(s.F, s.start(10.0), jac=s.J, tol=1e-10, ftol=1e-10, max_iter=200, record=False)
    assert r.converged and max(abs(v) for v in s.F(list(r.x))) <= 1e-8


def test_lm_at_a_local_minimum_says_so():
    """Powell badly scaled from x100: lm stops where |F| cannot be lowered; that is a
    local_minimum (no root from this start), not a proof that no solution exists."""
    from linkage.problems.mgh import mgh_cases

    named = {label: (s, f) for label, s, f in mgh_cases()}
    seen = set()
    for label, (s, f) in named.items():
        r = solve_system(s.F, s.start(f), jac=s.J, method="lm", tol=1e-10, ftol=1e-10, max_iter=200,
                         record=False)
        if not r.converged:
            seen.add(r.status)
            assert r.status is not Status.NO_SOLUTION, label
    assert Status.LOCAL_MINIMUM in seen


def test_noise_around_an_ill_conditioned_root_is_not_a_jump():
    """x^3 - 3x^2 + 3x - 1 (an expanded (x - 1)^3): near x = 1 its values are rounding
    noise, so |f| does not shrink under bisection. That was reported as a jump or a pole
    (`discontinuity`); f's own noise next to the sign change now identifies a root."""
    f = lambda x: x * x * x - 3.0 * x * x + 3.0 * x - 1.0  # noqa: E731
    fp = lambda x: 3.0 * x * x - 6.0 * x + 3.0  # noqa: E731
    for tol in (1e-4, 1e-5):
        r = solve_scalar(f, method="newton", fprime=fp, x0=1.5, tol=tol, record=False)
        assert r.converged, r.message
        assert abs(r.x - 1.0) <= tol + 2e-5  # within the tolerance and f's band of noise (eps^(1/3))
    # jumps and poles are still named as such
    jump = lambda x: (-1.0 if x < 1 else 1.0) + 0.1 * x  # noqa: E731
    pole = lambda x: 1.0 / (1.0 - x) if x != 1 else math.inf  # noqa: E731
    for g, br in ((jump, (0.5, 1.7)), (pole, (0.3, 1.9))):
        assert solve_scalar(g, method="bisection", bracket=br, tol=1e-12).status is Status.DISCONTINUITY


def test_a_bracketing_answer_near_the_root_is_not_called_a_jump():
    """Regula falsi's answer can sit 100 times nearer the root than its bracket is wide;
    eight halvings of that bracket did not bring |f| below the answer's, and a smooth
    cubic was reported as a discontinuity (found by hypothesis)."""
    c = (0.015625, -3.0, 1.0)
    r = solve_scalar(lambda x: ((x + c[2]) * x + c[1]) * x + c[0], method="regula-falsi",
                     bracket=(0.0, 0.03125), tol=0.0078125)
    assert r.converged, r.message


@pytest.mark.parametrize("method", ["bisection", "regula-falsi", "hybrid"])
@pytest.mark.parametrize("tol", [1e-2, 1e-8, 1e-14])
def test_a_pole_is_never_a_root(method, tol):
    """tan has no root in [1, 2], only a pole at pi/2: at tight tolerances the bracket
    closed to a few ulps and was accepted; 1/(x - 0.3) raised ZeroDivisionError from the
    check itself."""
    import math

    for f, bracket in ((math.tan, (1.0, 2.0)), (lambda x: 1.0 / (x - 0.3), (0.0, 1.0))):
        r = solve_scalar(f, method=method, bracket=bracket, tol=tol)
        assert r.status is Status.DISCONTINUITY, (method, tol, r.message)


@pytest.mark.parametrize("method", ["bisection", "regula-falsi", "hybrid"])
@pytest.mark.parametrize("tol", [1e-2, 1e-8, 1e-14])
def test_a_jump_is_not_a_root(method, tol):
    """The hybrid landed on the jump itself (x = 0.5), whose neighbouring floats read f
    on both sides of it: the noise test took that for a root's rounding noise."""
    r = solve_scalar(lambda x: x - 0.5 + 0.001 * math.copysign(1.0, x - 0.5), method=method,
                     bracket=(0.0, 1.0), tol=tol)
    assert r.status is Status.DISCONTINUITY, r.message


def test_criteria_of_any_type_are_refused_with_input_error():
    """The checked criteria are remembered: a list could not be (TypeError from the cache)
    and True shared 1's entry, so max_iter=True passed after a run with max_iter=1."""
    from linkage import InputError, solve_system

    f = lambda x: x * x - 2  # noqa: E731
    assert solve_scalar(f, method="bisection", bracket=(0.0, 2.0), max_iter=1).iterations == 1
    with pytest.raises(InputError):
        solve_scalar(f, method="bisection", bracket=(0.0, 2.0), max_iter=True)
    for bad in ([1e-3], {"a": 1}):
        with pytest.raises(InputError):
            solve_scalar(f, method="bisection", bracket=(0.0, 2.0), tol=bad)
        with pytest.raises(InputError):
            solve_system(lambda q: [q[0] - 1, q[1] - 2], (0.0, 0.0), jac=lambda q: [[1, 0], [0, 1]], tol=bad)


def test_a_second_sigterm_while_terminating_is_ignored_not_a_traceback(monkeypatch):
    """timeout(1) signals its child and then the child's group: the second SIGTERM reached
    the interpreter's exit while it joined the worker threads and printed a traceback after
    "error: terminated". The first raises KeyboardInterrupt (the one line, exit 143); the
    handler then ignores SIGTERM, and a second call does nothing."""
    import signal

    from linkage.cli import entry

    monkeypatch.setattr(entry, "_terminated", [])
    before = signal.getsignal(signal.SIGTERM)
    try:
        with pytest.raises(KeyboardInterrupt):
            entry._on_sigterm(signal.SIGTERM, None)
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN
        entry._on_sigterm(signal.SIGTERM, None)  # a second one, already unwinding: nothing
        assert entry._terminated == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, before)
