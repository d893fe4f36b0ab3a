"""The stress battery, the regressions it caught, and a seeded fuzz test of the CLI."""

from __future__ import annotations

import json
import math
import random
import sys
from pathlib import Path

import pytest

from linkage import Status, fourbar_equation, solve_scalar
from linkage.measure.stress import run, summary_rows, totals

EPS = sys.float_info.epsilon
SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def test_quick_battery_is_clean_and_deterministic(cli):
    first = cli("stress", "--quick", "--format", "json")
    assert first.code == 0, first.err
    doc = json.loads(first.out)
    assert doc["false_convergences"] == 0 and doc["crashes"] == 0
    assert doc["seconds"] < 60
    again = json.loads(cli("stress", "--quick", "--format", "json").out)
    strip = [{k: v for k, v in row.items()} for row in doc["summary"]]
    assert strip == again["summary"]  # same seed, same outcome, row by row


@pytest.mark.parametrize("seed", [0, 1])
def test_full_battery_is_clean(seed):
    report = run(quick=False, seed=seed)
    rows = summary_rows(report)
    false, crashes = totals(rows)
    ours = [t.examples for (_, m), t in report["tallies"].items() if t.examples and m[:5] != "scipy"]
    assert false == 0, ours
    assert crashes == 0
    mgh = {m: t for (f, m), t in report["tallies"].items() if f == "mgh"}
    assert mgh["newton"].cases == 66 and mgh["newton"].false == 0
    if "scipy-hybr" in mgh:  # done-when 2: at least as many as scipy hybr
        assert mgh["newton"].right >= mgh["scipy-hybr"].right
    assert sum(r[2] for r in rows) > 5000


def test_hybrid_reaches_4_eps_on_every_bracketed_classic_case():
    """Done-when 2: every APS and Chandrupatla case whose bracket holds a sign change."""
    h = run(quick=False, seed=0, methods=["hybrid", "bisection"])["hybrid"]
    assert h["cases"] == 200 and h["within_4_eps"] == 200, h["failures"]
    assert h["hybrid_iterations"] < h["bisection_iterations"] / 2


# --- regressions, each named after what the battery caught -----------------------------------


def test_regression_hybrid_interpolation_underflow_bisects():
    """x^9 near its root: the inverse-quadratic denominator underflowed to 0 and the
    hybrid stopped with a division by zero; now it bisects that step."""
    for f, br in ((lambda x: x**9, (-1.0, 4.0)), (lambda x: x**19, (-2.0, 5.0))):
        r = solve_scalar(f, method="hybrid", bracket=br, tol=1e-300, rtol=4 * EPS, max_iter=2000)
        assert r.converged and (abs(r.x) <= 1e-30 or f(r.x) == 0.0), r.message


def test_regression_complex_value_is_a_domain_error():
    """x ** (1/n) at negative x is complex in Python; the check of the residual raised
    TypeError out of the solver. It is now a named domain error."""
    r = solve_scalar(lambda x: x ** (1.0 / 3.0) - 2.0, method="secant", x0=-1.0, x1=-2.0)
    assert r.status is Status.DOMAIN_ERROR and "non-real" in r.message
    r0 = solve_scalar(lambda x: x**0.5, method="bisection", bracket=(-1.0, 4.0))
    assert r0.status is Status.DOMAIN_ERROR


@pytest.mark.parametrize(
    "f,bracket",
    [
        (lambda x: (-1.0 if x < 1 else 1.0) + 0.1 * x, (0.5, 1.7)),
        (lambda x: 1.0 / (1.0 - x) if x != 1 else math.inf, (0.3, 1.9)),
    ],
    ids=["jump", "pole"],
)
@pytest.mark.parametrize("method", ["bisection", "regula-falsi", "hybrid"])
def test_regression_bracket_on_a_jump_or_pole_is_not_a_root(f, bracket, method):
    """Every bracketing method used to report converged_step on a sign change that is a
    jump or a pole; the residual does not shrink there, and that is now a named stop."""
    r = solve_scalar(f, method=method, bracket=bracket, tol=1e-10)
    assert not r.converged and r.status in (Status.DISCONTINUITY, Status.NON_FINITE), r.message


@pytest.mark.parametrize(
    "f,bracket,root",
    [
        (
            lambda x: (
                math.exp(500.5 * 1000 * x) - 1.859
                if 0 <= x <= 2e-3 / 1001
                else (-0.859 if x < 0 else math.e - 1.859)
            ),
            (-1e4, 1e-4),
            math.log(1.859) / 500500.0,
        ),
        (lambda x: x**3 - 1.6251234902833584e-207, (0.0, 1.0), 1.6251234902833584e-207 ** (1 / 3)),
    ],
    ids=["steep exponential (aps15)", "tiny constant term"],
)
def test_regression_steep_and_tiny_roots_are_still_roots(f, bracket, root):
    """The discontinuity check must not flag a steep root, nor one whose bracket end has
    a tiny |f| (hypothesis found the second one)."""
    for method in ("bisection", "hybrid", "regula-falsi"):
        r = solve_scalar(f, method=method, bracket=bracket, tol=1e-9, max_iter=500)
        assert r.converged, (method, r.message)
        assert abs(r.x - root) <= 1e-9 + 4 * EPS * abs(root) or f(r.x) == 0.0


def test_regression_secant_far_chord_is_not_convergence():
    """aps03 from -2 and 11: the chord through f(-2) = 1.6e5 gave a step below one ulp at
    11, where f is an exponential tail, not a zero; the secant claimed a root at 11."""
    f = lambda x: -200 * x * math.exp(-3 * x)  # noqa: E731
    r = solve_scalar(f, method="secant", x0=-2.0, x1=11.0, tol=1e-300, rtol=4 * EPS, max_iter=500)
    assert not r.converged or abs(r.x) < 1e-10


def test_regression_tiny_step_from_a_far_slope():
    """aps06 with n = 60: a chord through f = -1.6e32 made a tiny step at x = 0.5, where
    f = 1; the secant claimed a root there."""
    n = 60
    f = lambda x: 2 * x * math.exp(-n) - 2 * math.exp(-n * x) + 1  # noqa: E731
    r = solve_scalar(f, method="secant", x0=1 / 30, x1=0.5, tol=1e-300, rtol=4 * EPS, max_iter=500)
    assert not r.converged or abs(r.x - 0.011552453009332421) < 1e-12


def test_rounding_noise_does_not_block_convergence():
    """The residual rules above must still let Newton finish where the last iterates
    differ only by rounding noise (the student report at alpha = 10, tol 1e-12)."""
    r = solve_scalar(fourbar_equation(10.0), method="newton", tol=1e-12)
    assert r.converged and abs(r.x - 8.0693453136225160) < 1e-12


def test_tolerance_below_epsilon_ends_with_a_named_stop():
    for method in ("bisection", "hybrid", "newton", "secant", "regula-falsi"):
        r = solve_scalar(fourbar_equation(70.0), method=method, tol=1e-20, max_iter=1000)
        assert r.status in (Status.PRECISION_LIMIT, Status.CONVERGED_EXACT), (method, r.status)
        assert r.iterations < 200


# --- CLI fuzz -------------------------------------------------------------------------------------

NUMBERS = [
    "0",
    "-1",
    "1",
    "0.5",
    "70",
    "5/3",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "-inf",
    "abc",
    "",
    "--",
    "1/0",
    "3e",
    "360",
    "50",
    "60",
    "7",
]
OPTIONS = {
    "solve": [
        "--method",
        "--alpha",
        "--r1",
        "--r2",
        "--r3",
        "--links",
        "--equation",
        "--g",
        "--x0",
        "--x1",
        "--bracket",
        "--tol",
        "--rtol",
        "--ftol",
        "--max-iter",
        "--format",
        "--digits",
        "--set",
        "--guess",
        "--fd-step",
        "--damped",
        "--show-jacobian",
    ],
    "sweep": [
        "--from",
        "--to",
        "--step",
        "--points",
        "--method",
        "--branch",
        "--set",
        "--tol",
        "--format",
        "--digits",
        "--batch",
        "--no-batch",
    ],
}
WORDS = [
    "newton",
    "secant",
    "bisection",
    "hybrid",
    "fixed-point",
    "regula-falsi",
    "lm",
    "newton-fd",
    "all",
    "open",
    "crossed",
    "json",
    "csv",
    "plain",
    "table",
    "github",
    "x**2-2",
    "sin(x)",
    "x^",
    "theta2=80",
    "r1=-3",
    "theta3=0",
    "junk",
    "theta2",
    "__import__('os')",
    "cos(x)",
]
FILES = [
    str(SAMPLES / "fourbar_me581.toml"),
    str(SAMPLES / "rapier_drive.toml"),
    str(SAMPLES / "crank_rocker.toml"),
    "/nonexistent.toml",
    str(SAMPLES),
    str(Path(__file__)),
]


VALID = {
    "solve": [
        ["--max-iter", "2"],
        ["--method", "newton"],
        ["--method", "secant"],
        ["--method", "fixed-point"],
        ["--method", "all"],
        ["--alpha", "130"],
        ["--alpha", "10"],
        ["--tol", "1e-12"],
        ["--tol", "1e-20"],
        ["--format", "json"],
        ["--format", "csv"],
        ["--digits", "5"],
        ["--x0", "85"],
    ],
    "sweep": [
        ["--step", "30"],
        ["--points", "7"],
        ["--from", "100"],
        ["--to", "200"],
        ["--branch", "crossed"],
        ["--format", "json"],
        ["--set", "theta2=10"],
        ["--tol", "1e-9"],
    ],
    "solve FILE": [
        ["--set", "theta2=180"],
        ["--guess", "theta3=30", "--guess", "theta4=30"],
        ["--method", "lm"],
        ["--method", "newton-fd"],
        ["--damped"],
        ["--max-iter", "2"],
        ["--show-jacobian"],
        ["--format", "csv"],
    ],
}


def valid_invocation(rng: random.Random) -> list[str]:
    kind = rng.choice(list(VALID))
    args = (
        ["solve", rng.choice(FILES[:3])]
        if kind == "solve FILE"
        else (["sweep", rng.choice(FILES[:3])] if kind == "sweep" else ["solve"])
    )
    for pair in rng.sample(VALID[kind], rng.randint(1, 3)):
        args += pair
    return args


def random_invocation(rng: random.Random) -> list[str]:
    if rng.random() < 0.3:
        return valid_invocation(rng)
    command = rng.choice(["solve", "solve", "solve", "sweep", rng.choice(["draw", "stress", "bogus", ""])])
    args = [command] if command else []
    if command == "sweep" or (command == "solve" and rng.random() < 0.4):
        args.append(rng.choice(FILES))
    for _ in range(rng.randint(0, 5)):
        opt = rng.choice(OPTIONS.get(command, ["--help", "--format", "--seed", "--quick", "-o"]))
        args.append(opt)
        for _ in range(rng.choice([0, 1, 1, 1, 2, 4])):
            args.append(rng.choice(NUMBERS + WORDS))
    if command == "stress":
        args = ["stress", "--help"]  # the battery itself is tested above; here only parsing
    if command == "draw":
        args = [a for a in args if a not in ("-o", "--output", "--animate")]
    return args


def test_cli_fuzz_no_traceback_and_known_exit_codes(cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # anything an invocation writes lands here
    rng = random.Random(20261122)
    codes = {0: 0, 1: 0, 2: 0}
    for _ in range(1200):
        args = random_invocation(rng)
        run = cli(*args)
        assert run.code in (0, 1, 2), (args, run.code, run.err[-300:])
        text = run.out + run.err
        assert "Traceback" not in text and "internal error" not in text, (args, text[-500:])
        if run.code == 2:
            assert len(run.err.strip().splitlines()) == 1, (args, run.err)
        codes[run.code] += 1
    assert all(codes.values()), codes  # the fuzz reached every outcome


# --- mechanism-file mutations and numeric extremes ---------------------------------------------

EXTREMES = [0, -1, 1e-320, 3e-320, 1e-300, 1e308, 1.7e308, 10**58, 10**400, -(10**30), 0.5, 1e6, 1e7,
            float("nan"), float("inf"), "text", True, [1, 2], {"value": 1}, ""]


def toml_value(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if v != v else ("inf" if v == float("inf") else repr(v))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + " }"
    return json.dumps(v)


def mutate(text: str, rng: random.Random) -> str:
    """One to three random edits of a mechanism file: a number, a name, a key, a type,
    a line dropped or doubled, nesting, truncation."""
    import re

    for _ in range(rng.randint(1, 3)):
        kind = rng.randrange(8)
        numbers = list(re.finditer(r"(?<![\w.])-?\d+(\.\d+)?(e-?\d+)?", text))
        names = list(re.finditer(r'"(\w+)"', text))
        lines = text.splitlines()
        if kind == 0 and numbers:
            m = rng.choice(numbers)
            text = text[:m.start()] + toml_value(rng.choice(EXTREMES)) + text[m.end():]
        elif kind == 1 and names:
            m = rng.choice(names)
            new = rng.choice(['"nosuch"', '"theta2"', '"r1"', '""', '"' + "x" * 300 + '"', "7"])
            text = text[:m.start()] + new + text[m.end():]
        elif kind == 2 and lines:
            i = rng.randrange(len(lines))
            del lines[i]
            text = "\n".join(lines)
        elif kind == 3 and lines:
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
            text = "\n".join(lines)
        elif kind == 4:
            text = text[: rng.randrange(len(text) + 1)]
        elif kind == 5 and lines:
            i = rng.randrange(len(lines))
            lines[i] = lines[i].replace("=", "= [", 1) + "]" if "=" in lines[i] else lines[i]
            text = "\n".join(lines)
        elif kind == 6:
            depth = rng.choice([3, 50, 400])
            text += "\nnotes = " + "[" * depth + "1" + "]" * depth + "\n"
        else:
            for key in ("unit", "sign", "offset", "closed_form", "length_unit", "guess", "value"):
                if key in text and rng.random() < 0.3:
                    junk = toml_value(rng.choice(EXTREMES))
                    text = text.replace(f"{key} = ", f"{key} = {junk}, x{key} = ", 1)
    return text


MUTATION_COMMANDS = [
    ["solve"], ["solve", "--method", "lm"], ["solve", "--method", "newton-fd"], ["solve", "--format", "json"],
    ["sweep", "--step", "45"], ["sweep", "--points", "5", "--format", "csv"],
]


def well_behaved(run, args: list[str], context: str = "") -> int:
    """The CLI's contract for any input: exit 0, 1 or 2, no traceback or internal error,
    and exit 2 is one line. Returns the exit code."""
    assert run.code in (0, 1, 2), (context, args, run.code, run.err[-300:])
    out = run.out + run.err
    assert "Traceback" not in out and "internal error" not in out, (context, args, out[-500:])
    if run.code == 2:
        assert len(run.err.strip().splitlines()) == 1, (args, run.err)
    return run.code


def test_cli_fuzz_mechanism_mutations_and_extremes(cli, tmp_path, monkeypatch):
    """At least 2,000 invocations on mutated sample files and extreme numbers: no traceback,
    no internal error, exit codes 0, 1 or 2, and exit 2 is one line."""
    monkeypatch.chdir(tmp_path)
    rng = random.Random(9)
    samples = sorted(SAMPLES.glob("*.toml"))
    codes = {0: 0, 1: 0, 2: 0}
    count = 0
    for i in range(1400):
        text = mutate(rng.choice(samples).read_text(), rng)
        path = tmp_path / f"m{i % 7}.toml"
        path.write_text(text)
        args = [*rng.choice(MUTATION_COMMANDS)]
        args.insert(1, str(path))
        codes[well_behaved(cli(*args), args, text[:2000])] += 1
        count += 1
    for _ in range(700):
        value = toml_value(rng.choice(EXTREMES))
        args = rng.choice([
            ["solve", str(SAMPLES / "fourbar_me581.toml"), "--set", f"r{rng.randint(1, 4)}={value}"],
            ["solve", str(SAMPLES / "fourbar_me581.toml"), "--guess", f"theta3={value}"],
            ["solve", "--links", "2", "4", value, "5"],
            ["solve", "--equation", "x**2-2", "--x0", value],
            ["solve", "--method", "bisection", "--bracket", value, "2"],
            ["solve", "--tol", value],
            ["solve", "--max-iter", value],
            ["sweep", str(SAMPLES / "crank_rocker.toml"), "--from", value, "--to", "1e9", "--step", "1"],
            ["sweep", str(SAMPLES / "crank_rocker.toml"), "--points", value],
            ["solve", str(SAMPLES / "slider_crank.toml"), "--fd-step", value, "--method", "newton-fd"],
        ])
        codes[well_behaved(cli(*args), args)] += 1
        count += 1
    assert count >= 2000
    assert all(codes.values()), codes


# --- rates, points and scan options (issue 18) -------------------------------------------------

SPEEDS = ["10", "600rpm", "90deg/s", "10rad/s", "250mm/s", "-3", "0", "1e308", "nan", "inf", "", "abc",
          "10rpm/s", "5rad/s^2", "1e-320", "3e", "5/3"]
SCAN_OPTIONS = {
    "--vary": ["r2=20:60:3", "r2=20:60", "r4=60:120:2", "r2=60:20:3", "r2=1:1:1", "nosuch=1:2:2",
               "r2=nan:1:2", "r2=0:-5:2", "r2", "r2=1:2:0", "r2=1:2:1e9", "theta2=10:20:2"],
    "--samples": ["3", "0", "-1", "2.5", "1e9", "abc"],
    "--sampling": ["lhs", "random", "sobol"],
    "--seed": ["0", "-1", "7", "1e30", "99999999999999999999"],
    "--from": ["0", "-180", "nan", "1e308"],
    "--to": ["90", "359", "-1", "inf"],
    "--step": ["30", "45", "0", "-30", "1e-9"],
    "--branch": ["open", "crossed", "sideways"],
    "--set": ["r3=80", "r1=-3", "theta2=10", "nosuch=1"],
    "--tol": ["1e-9", "0", "-1", "nan"],
    "--where": ["full_cycle", "theta4_range > 10", "__import__('os')", "nosuch > 1", "1 +"],
    "--sort": ["theta4_range", "nosuch", "design"],
    "--top": ["2", "0", "-1", "1e9"],
    "--scheduler": ["threads", "synchronous", "bogus", "tls://127.0.0.1:1", "tcp://127.0.0.1:99999",
                    "ucx://127.0.0.1:1"],
    "--workers": ["1", "2", "0", "-1", "100000"],
    "--chunk": ["1", "7", "0", "-3"],
    "--format": ["csv", "json", "plain", "table", "nosuch"],
    "--digits": ["5", "2", "40"],
}


def rate_invocation(rng: random.Random) -> list[str]:
    """solve FILE or sweep FILE with --speed/--accel (and sometimes --path, --batch)."""
    file = str(SAMPLES / rng.choice(["fourbar_me581.toml", "slider_crank.toml", "crank_rocker.toml",
                                      "watt_sixbar.toml", "fourbar_me581_theta4.toml"]))
    if rng.random() < 0.5:
        args = ["solve", file]
        if rng.random() < 0.3:
            args += ["--set", f"theta2={rng.choice(['112.024312837', '0', '90', '180', '360', '1e-9'])}"]
    else:
        args = ["sweep", file, "--step", rng.choice(["30", "45", "90"])]
        if rng.random() < 0.3:
            args.append("--batch")
        if rng.random() < 0.3:
            args += ["--path", rng.choice(["P", "A", "nosuch", ""])]
    args += ["--speed", rng.choice(SPEEDS)]
    if rng.random() < 0.7:
        args += ["--accel", rng.choice(SPEEDS)]
    if rng.random() < 0.4:
        args += ["--format", rng.choice(["json", "csv", "plain"])]
    return args


def scan_invocation(rng: random.Random) -> list[str]:
    """A small scan of the crank-rocker (at most a few designs x a dozen positions) with
    random options, valid and not."""
    args = ["scan", str(SAMPLES / "crank_rocker.toml"), "--step", "30"]
    if rng.random() < 0.8:
        args += ["--vary", "r2=20:60:3"]
    for opt in rng.sample(sorted(SCAN_OPTIONS), rng.randint(1, 4)):
        value = rng.choice(SCAN_OPTIONS[opt])
        if opt == "--samples" and value in ("1e9",):
            value = "5"  # a valid huge draw is a size test (tests/test_bounds.py), not a fuzz case
        args += [opt, value]
    if rng.random() < 0.2:
        args.append("--desc")
    return args


def with_points(text: str, rng: random.Random) -> str:
    """A [points] table added to a mechanism, valid or not."""
    start = rng.choice(['"A"', '"B"', '"O2"', '"nosuch"', '""', "7"])
    length = toml_value(rng.choice([60, 0, -5, 1e308, float("nan"), "theta3", "r2", "nosuch", 1e-320]))
    angle = toml_value(rng.choice(["theta3", "theta4", "theta2", 30, float("inf"), "nosuch", "s"]))
    offset = toml_value(rng.choice([30, 0, -720, 1e308, float("nan"), "x"]))
    name = rng.choice(["Q", "P", "A", "theta3", "Q_x", "design", "x" * 100])
    return text + f'\n[points.{name}]\nfrom = {start}\nvectors = [ {{ length = {length}, angle = {angle}, ' \
                  f'offset = {offset} }} ]\n'


def test_cli_fuzz_rates_points_and_scan_options(cli, tmp_path, monkeypatch):
    """Rates (--speed/--accel), [points] tables and scan options, valid and not: the CLI's
    contract holds (exit 0, 1 or 2; no traceback or internal error; exit 2 is one line)."""
    monkeypatch.chdir(tmp_path)
    rng = random.Random(18)
    codes = {0: 0, 1: 0, 2: 0}
    samples = sorted(SAMPLES.glob("*.toml"))
    for i in range(240):
        pick = i % 3
        if pick == 0:
            args = rate_invocation(rng)
        elif pick == 1:
            args = scan_invocation(rng)
        else:
            path = tmp_path / f"p{i % 5}.toml"
            path.write_text(with_points(rng.choice(samples).read_text(), rng))
            args = rng.choice([["solve", str(path), "--speed", "10"], ["sweep", str(path), "--step", "60",
                               "--speed", "10", "--format", "json"], ["scan", str(path), "--step", "60"],
                               ["solve", str(path)]])
        codes[well_behaved(cli(*args), args)] += 1
    assert codes[0] and codes[2], codes


def test_stress_seed_has_every_seed_s_range(cli):
    """--seed -1 ran (exit 0) where every other command's --seed refuses it: one line,
    exit 2, the same words (arguments.check_whole with MAX_SEED)."""
    run = cli("stress", "--quick", "--seed", "-1")
    said = "error: --seed must be a whole number from 0 to 2**64 - 1, got -1"
    assert run.code == 2 and run.err.strip() == said
