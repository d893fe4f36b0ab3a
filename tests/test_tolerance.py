"""linkage tolerance and linkage.tolerance (issue 31, the tolerance study; docs/tolerance.md).

The linear bands are checked against central finite differences of re-solved designs
(each solved by linkage.sweep on its own, a different engine); the Monte Carlo against
the linear normal model as the tolerances shrink (within each statistic's sampling
error); the near-limit four-bar against the assembly condition |O4A| >= r3 - r4."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.errors import InputError

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
CRANK = SAMPLES / "crank_rocker.toml"
CRANK_JOINTS = SAMPLES / "crank_rocker_joints.toml"
VALUES = [0.0, 45.0, 100.0, 200.0, 290.0]


def _outputs(m: linkage.Mechanism, values: list[float]) -> np.ndarray:
    """Every unknown (deg) and named point (x, y) of m at each value, (outputs, positions),
    solved position by position by linkage.sweep."""
    r = linkage.sweep(m, values)
    rows = []
    for p in r.positions:
        assert p.status == "converged"
        row = [p.solution[u.name] for u in m.unknowns]
        q = [math.radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
             for u in m.unknowns]
        joints = linkage.position_rates(m, q, driver=math.radians(p.input)).joints
        for name in m.points:
            row += list(joints[name])
        rows.append(row)
    return np.array(rows).T


def _central(m: linkage.Mechanism, moved, h: float, values: list[float]) -> np.ndarray:
    """(f(+h) - f(-h)) / 2h, ``moved(m, step)`` the mechanism moved by ``step``."""
    return (_outputs(moved(m, h), values) - _outputs(moved(m, -h), values)) / (2.0 * h)


def _assert_close(linear: np.ndarray, fd: np.ndarray) -> None:
    assert np.all(np.abs(linear - fd) <= 1e-6 * np.maximum(1.0, np.abs(fd))), np.max(np.abs(linear - fd))


SLIDER_JOINTS = SAMPLES / "slider_crank_joints.toml"


JOINTS_LENGTHS = ["crank", "coupler", "rocker", "ground", "coupler_A_P"]


@pytest.mark.parametrize("path,names", [(CRANK, ["r1", "r2", "r3", "r4"]), (CRANK_JOINTS, JOINTS_LENGTHS),
                                        (SLIDER_JOINTS, ["crank", "coupler", "e_block"])])
def test_linear_bands_equal_finite_differences(path, names):
    m = linkage.load_mechanism(path)
    s = linkage.tolerance(path, {n: 0.05 for n in names}, VALUES, samples=None)
    assert s.status == ("ok",) * len(VALUES)
    for i, name in enumerate(names):
        def moved(mm, step, name=name):
            return mm.with_values({name: mm.parameters[name].value + step}, {})

        _assert_close(s.sensitivity[:, i, :], _central(m, moved, 1e-5, VALUES))
    # the bands are the contributions' sums, by their definitions
    c = s.sensitivity * 0.05
    assert np.allclose(s.worst_case, np.abs(c).sum(axis=1), rtol=1e-15)
    assert np.allclose(s.rss, np.sqrt((c ** 2).sum(axis=1)), rtol=1e-15)


def test_a_fixed_joints_coordinate_is_its_ground_vector_moved():
    """O4.x and O4.y move the pivot with every link's length kept: the ground vector from
    O2 becomes (x - x0, y - y0), as linkage scan --vary O4.x moves it."""
    m = linkage.load_mechanism(CRANK_JOINTS)
    s = linkage.tolerance(CRANK_JOINTS, {"O4.x": 0.1, "O4.y": 0.1}, VALUES, samples=None)
    for i, (dx, dy) in enumerate([(1.0, 0.0), (0.0, 1.0)]):
        def moved(mm, step, dx=dx, dy=dy):
            x, y = 100.0 + step * dx, 0.0 + step * dy
            ground = {"ground": math.hypot(x, y), "theta_ground": math.degrees(math.atan2(y, x))}
            return mm.with_values(ground, {})

        _assert_close(s.sensitivity[:, i, :], _central(m, moved, 1e-5, VALUES))


def test_monte_carlo_converges_to_the_linear_bands_as_tolerances_shrink():
    """With the tolerances scaled by 1e-3 the outputs are linear in them: the Monte
    Carlo's sigma over the linear sigma is 1, its 0.135/99.865 percentiles are nominal -/+
    RSS and its median nominal, each within 4.5 of its standard errors."""
    n = 20_000
    tols = {name: 0.05e-3 for name in ("r1", "r2", "r3", "r4")}
    s = linkage.tolerance(CRANK, tols, VALUES, samples=n, seed=3)
    assert s.not_assembled_anywhere == 0.0
    sigma = s.linear_sigma
    assert np.all(np.abs(s.mc_sigma / sigma - 1.0) <= 4.5 / math.sqrt(2.0 * (n - 1)))
    z = 3.0  # the 0.135% and 99.865% points of a normal
    p = 0.00135
    se_tail = math.sqrt(p * (1 - p) / n) / (math.exp(-z * z / 2) / math.sqrt(2 * math.pi))
    se_median = math.sqrt(0.25 / n) / (1 / math.sqrt(2 * math.pi))
    assert np.all(np.abs(s.mc_low - (s.nominal - s.rss)) <= 4.5 * se_tail * sigma)
    assert np.all(np.abs(s.mc_high - (s.nominal + s.rss)) <= 4.5 * se_tail * sigma)
    assert np.all(np.abs(s.mc_median - s.nominal) <= 4.5 * se_median * sigma)


def test_a_uniform_monte_carlo_has_the_uniform_linear_sigma():
    """Uniform within ±D: each input's sigma is D / sqrt(3), and so the linear sigma."""
    n = 20_000
    s = linkage.tolerance(CRANK, {name: 0.05e-3 for name in ("r2", "r3", "r4")}, VALUES, samples=n,
                          seed=5, distribution="uniform")
    assert np.allclose(s.linear_sigma, s.rss / math.sqrt(3.0), rtol=1e-15)
    assert np.all(np.abs(s.mc_sigma / s.linear_sigma - 1.0) <= 4.5 / math.sqrt(2.0 * (n - 1)))


def test_near_limit_band_is_flagged_and_monte_carlo_reports_not_assembling():
    """r1 = 100, r2 = 40, r3 = 120, r4 = 60.05 ± 0.1: at theta2 = 0 the coupler and rocker
    fold (|O4A| = r1 - r2 = 60 must be >= r3 - r4, so r4 >= 60 assembles). The linear band
    there is near_limit, not a bare number; far from it (theta2 = 90) ok. A design assembles
    everywhere exactly when r4 >= 60 (|O4A| is least at 0): the Monte Carlo's share not
    assembling is P(r4 < 60) = Phi(-0.05 / (0.1 / 3)) within its sampling error."""
    m = linkage.load_mechanism(CRANK).with_values({"r4": 60.05}, {})
    n = 4000
    s = linkage.tolerance(m, {"r4": 0.1}, [0.0, 1.0, 90.0], samples=n, seed=1)
    assert s.status[0] == "near_limit" and s.status[-1] == "ok"
    assert not math.isnan(s.nonlinearity[-1]) and s.nonlinearity[-1] < 0.01
    expected = 0.5 * math.erfc(1.5 / math.sqrt(2.0))
    se = math.sqrt(expected * (1 - expected) / n)
    assert abs(s.not_assembled[0] - expected) <= 4.5 * se
    assert s.not_assembled_anywhere == s.not_assembled[0]
    assert s.not_assembled[-1] == 0.0


def test_cli_near_limit_is_in_the_status_column_and_the_status_line(cli):
    r = cli("tolerance", str(CRANK), "--set", "r4=60.05", "--tol", "r4=0.1", "--from", "0", "--to", "10",
            "--step", "10", "--samples", "500", "-f", "plain")
    assert r.code == 0, r.err
    assert "near_limit" in r.out
    assert "status: near_limit: 1, ok: 1; near_limit at theta2 = 0 deg" in r.out
    assert "not assembling at some position:" in r.out


def test_monte_carlo_is_the_same_on_every_scheduler():
    """Design i is drawn once: the chunks may run anywhere."""
    args = (CRANK, {"r2": 0.05, "r3": 0.05}, [0.0, 180.0])
    a = linkage.tolerance(*args, samples=300, seed=7, scheduler="synchronous")
    b = linkage.tolerance(*args, samples=300, seed=7, scheduler="threads", workers=2)
    for name in ("mc_low", "mc_median", "mc_high", "mc_sigma", "not_assembled"):
        assert np.array_equal(getattr(a, name), getattr(b, name))


def test_json_report_carries_the_reading_of_the_tolerances(cli, tmp_path):
    out = tmp_path / "t.json"
    r = cli("tolerance", str(CRANK), "--tol", "r2=±0.05", "--step", "120", "--samples", "100", "-o", str(out))
    assert r.code == 0, r.err
    doc = json.loads(out.read_text())
    assert doc["tolerances"] == {"r2": 0.05} and doc["distribution"] == "normal"
    assert "3 sigma" in doc["reading"]
    positions = doc["tables"][0]
    assert positions["name"] == "positions" and "theta4_rss" in positions["columns"]


BAD = [
    (["--tol", "r2=-0.1"], "D > 0"),
    (["--tol", "r2=0"], "D > 0"),
    (["--tol", "zz=0.1"], "not a parameter"),
    (["--tol", "theta1=0.1"], "not a length"),
    (["--tol", "theta2=0.1"], "the driver"),
    (["--tol", "theta3=0.1"], "an unknown"),
    (["--tol", "r2=0.1", "--samples", "0"], "--samples"),
    (["--tol", "r2=40"], "as large as r2"),
    (["--tol", "r2=abc"], "--tol r2"),
    (["--tol", "r2"], "NAME=±D"),
    (["--tol", "r2=0.1", "--tol", "r2=0.2"], "twice"),
    (["--tol", "r2=0.1", "--distribution", "beta"], "--distribution"),
    (["--tol", "r2=0.1", "--plot-output", "theta9", "--plot", "x.png"], "--plot-output theta9"),
    (["--tol", "O4.x=0.1"], "joints file"),
    ([], "at least one tolerance"),
]


@pytest.mark.parametrize("args,says", BAD, ids=[" ".join(a) or "none" for a, _ in BAD])
def test_bad_input_is_one_line_and_exit_2(cli, tmp_path, args, says):
    args = [str(tmp_path / a) if a.endswith(".png") else a for a in args]
    r = cli("tolerance", str(CRANK), *args)
    assert r.code == 2
    assert r.err.count("\n") == 1 and r.err.startswith("error: ") and says in r.err, r.err
    assert not list(tmp_path.iterdir())


def test_plot_draws_the_bands(cli, tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / "bands.png"
    r = cli("tolerance", str(CRANK_JOINTS), "--tol", "coupler=0.1", "--tol", "O4.x=0.1", "--step", "30",
            "--samples", "200", "--plot", str(png), "--plot-output", "P.y", "-f", "plain")
    assert r.code == 0, r.err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_api_refuses_what_the_command_refuses():
    with pytest.raises(InputError, match="D > 0"):
        linkage.tolerance(CRANK, {"r2": -0.1})
    with pytest.raises(InputError, match="not a length"):
        linkage.tolerance(CRANK, {"theta1": 0.1})
    with pytest.raises(InputError, match="samples"):
        linkage.tolerance(CRANK, {"r2": 0.1}, samples=0)
