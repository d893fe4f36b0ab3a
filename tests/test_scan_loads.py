"""Loads in scans and in the Python sweep (issue 23): the batch engine's kinematics
(rates.solve_rates_np, place_motion_np) against the one-at-a-time rates, its forces against
the one-at-a-time forces, and a scan's load columns against each design swept on its own
(a file written with that design's joints), by the one peak rule."""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
import pytest

from linkage.cli import run_cli
from linkage.kinematics.force_sweeps import batch_forces, sweep_forces
from linkage.kinematics.forces import FORCE_STATUSES, force_peaks
from linkage.kinematics.loading import from_text, load
from linkage.kinematics.placing import place_motion_np
from linkage.kinematics.rates import rates_at, solve_rates_np
from linkage.kinematics.sweep import sweep_mechanism
from linkage.problems.loads import Loads
from linkage.problems.loops import LoopModel
from linkage.scan import scan
from test_forces import _loads_for  # the same random loads as the one-at-a-time tests

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted((ROOT / "sample_inputs").glob("*.toml"))
JOINT_SAMPLES = sorted((ROOT / "sample_inputs").glob("*_joints.toml"))
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"


def _solved(m, step: int = 7):
    angle = m.driver.kind == "angle"
    vals = (list(range(0, 360, step)) if angle else
            list(np.linspace(m.driver.value * 0.9, m.driver.value * 1.1, 25)))
    r = sweep_mechanism(m, vals)
    qs, ds = [], []
    for p in r.positions:
        if p.status == "converged":
            qs.append([math.radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
                       for u in m.unknowns])
            ds.append(math.radians(p.input) if angle else p.input)
    return r, qs, ds


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_numpy_rates_equal_the_one_at_a_time_rates(path: Path) -> None:
    m = load(path)
    _, qs, ds = _solved(m)
    q = [np.array(c) for c in zip(*qs)]
    model = LoopModel.compile(m)
    qd, qdd, ok = solve_rates_np(model, q, np.array(ds), 2.5, -0.7)
    placed = place_motion_np(model, q, np.array(ds), qd, 2.5, qdd, -0.7)
    checked = 0
    for i, (qq, d) in enumerate(zip(qs, ds)):
        ref = rates_at(m, qq, speed=2.5, accel=-0.7, driver=d)
        if ref.status != "ok":
            continue
        assert ok[i]
        for name, u in enumerate(m.unknowns):
            scale = max(abs(v) for v in ref.velocities.values()) + 1e-300
            assert qd[name][i] == pytest.approx(ref.velocities[u.name], abs=1e-9 * scale)
            scale = max(abs(v) for v in ref.accelerations.values()) + 1e-300
            assert qdd[name][i] == pytest.approx(ref.accelerations[u.name], abs=1e-9 * scale)
        for j, (x, y) in ref.joints.items():
            assert abs(placed[j][0][i] - complex(x, y)) <= 1e-9 * m.length_scale
        checked += 1
        if not ref.joints:  # a file whose loops name no joints: the unknowns' rates only
            continue
        vs = max(math.hypot(*v) for v in ref.joint_velocities.values())
        for j, (x, y) in ref.joint_velocities.items():
            assert abs(placed[j][1][i] - complex(x, y)) <= 1e-9 * vs
        acc = max(math.hypot(*v) for v in ref.joint_accelerations.values())
        for j, (x, y) in ref.joint_accelerations.items():
            assert abs(placed[j][2][i] - complex(x, y)) <= 1e-9 * acc
    assert checked >= 5


@pytest.mark.parametrize("path", JOINT_SAMPLES, ids=lambda p: p.stem)
@pytest.mark.parametrize("speed", [0.0, 12.0])
def test_batch_forces_equal_the_one_at_a_time_forces(path: Path, speed: float) -> None:
    m = load(path)
    rng = random.Random(hash((path.stem, speed)) & 0xFFFF)
    loads = _loads_for(m, rng, masses=bool(speed))
    result, _, _ = _solved(m, step=5)
    if speed:
        result = sweep_mechanism(m, [p.input for p in result.positions], speed=speed, accel=1.5)
    one = sweep_forces(m, result, loads, speed, 1.5 if speed else 0.0)
    angle = m.driver.kind == "angle"
    q = [np.array([(math.radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name])
                   if p.solution else np.nan for p in result.positions]) for u in m.unknowns]
    d = np.array([math.radians(p.input) if angle else p.input for p in result.positions])
    batch = batch_forces(m, q, d, loads, speed=speed, accel=1.5 if speed else 0.0)
    compared = 0
    for i, f in enumerate(one):
        if f is None:
            continue
        assert FORCE_STATUSES[batch.status[i]] in (f.status, "undefined" if f.status == "undefined" else "")
        if f.status != "ok":
            continue
        scale = max([abs(f.input)] + [p.magnitude for p in f.pins])
        assert batch.input[i] == pytest.approx(f.input, abs=1e-9 * scale)
        assert batch.pin_max[i] == pytest.approx(f.max_pin_force, abs=1e-9 * scale)
        assert batch.virtual_power[i] == pytest.approx(f.input, abs=1e-9 * scale)
        compared += 1
    assert compared >= 5


def test_scan_load_columns_equal_each_design_swept_on_its_own() -> None:
    """A scan moving the rocker's pivot with masses and a speed: each record's peak input,
    largest pin force and shaking force equal those of the design swept one position at a
    time (kinematics.rates) and reduced by the one peak rule. Moving a ground joint keeps
    every link's length: the design is the ground vector O2 -> O4 set to the new pivot."""
    base = load(LOADED)
    values = [float(v) for v in range(0, 360, 4)]
    cols = scan(str(LOADED), {"O4.x": (90.0, 110.0, 3), "O4.y": (-8.0, 8.0, 2)}, values=values,
                speed=10.0, accel=2.0)
    assert len(cols["design"]) == 6
    for k in range(6):
        x, y = float(cols["O4_x"][k]), float(cols["O4_y"][k])
        m = base.with_values({"ground": math.hypot(x, y), "theta_ground": math.degrees(math.atan2(y, x))}, {})
        r = sweep_mechanism(m, values, speed=10.0, accel=2.0, loads=m.extra["loads"])
        c = r.force_columns()
        codes = np.array([[FORCE_STATUSES.index(s) if s in FORCE_STATUSES else -1 for s in c["status"]]])
        arrays = [np.array([[np.nan if v is None else v for v in c[key]]], dtype=float)
                  for key in ("input", "max_pin_force")]
        shaking = np.hypot(np.array([[np.nan if v is None else v for v in c["ground_fx"]]], dtype=float),
                           np.array([[np.nan if v is None else v for v in c["ground_fy"]]], dtype=float))
        (at_in, at_pin, at_g), flagged = force_peaks(codes, *arrays, shaking)
        assert at_in[0] >= 0
        assert cols["peak_input"][k] == pytest.approx(abs(arrays[0][0, at_in[0]]), rel=1e-9)
        assert cols["max_pin_force"][k] == pytest.approx(arrays[1][0, at_pin[0]], rel=1e-9)
        assert cols["max_shaking_force"][k] == pytest.approx(shaking[0, at_g[0]], rel=1e-9)
        assert cols["forces_flagged"][k] == flagged[0]


def test_scan_near_a_toggle_counts_flagged_positions_and_never_peaks_them() -> None:
    """Designs whose coupler makes the crank stop short of a full turn pass limit
    positions: the forces there are flagged, counted, and no peak comes from them."""
    m = load(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    loads = Loads({}, {"rocker": -2.0}, {}, None)
    values = [float(v) for v in np.arange(0.0, 360.0, 0.25)]
    cols = scan(m, {"coupler": (60.0, 140.0, 9)}, values=values, loads=loads)
    assert (cols["forces_flagged"] > 0).any() and (cols["forces_flagged"] == 0).any()
    n = len(values)
    for k in range(len(cols["design"])):
        mm = m.with_values({"coupler": float(cols["coupler"][k])}, {})
        r = sweep_mechanism(mm, values, loads=loads)
        statuses = r.force_columns()["status"]
        # position by position: the batch flags exactly the positions the one-at-a-time
        # forces flag (it may name them near_toggle where the rates' own bounds make them
        # ill_conditioned), and counts the same ones ok
        q = [np.array([math.radians(p.solution[u.name]) if p.solution else np.nan for p in r.positions])
             for u in mm.unknowns]
        batch = batch_forces(mm, q, np.radians(values), loads)
        for s_one, code in zip(statuses, batch.status):
            if s_one != "unsolved":
                assert (s_one == "ok") == (code == 0)
        # the scan's records: its engine may leave a limit's last position unsolved where
        # the sweep reaches it (and flags it); the peaks come from the same ok positions
        flagged = sum(s in ("near_toggle", "ill_conditioned", "undefined") for s in statuses)
        unsolved_in_scan = round((1.0 - cols["solved_fraction"][k]) * n)
        assert flagged - unsolved_in_scan <= cols["forces_flagged"][k] <= flagged
        ok = [abs(v) for v, s in zip(r.force_columns()["input"], statuses) if s == "ok"]
        if ok:
            assert cols["peak_input"][k] == pytest.approx(max(ok), rel=1e-9)
        else:
            assert math.isnan(cols["peak_input"][k])


def test_scan_with_loads_on_the_command_line(tmp_path, capsys) -> None:
    out = tmp_path / "designs.csv"
    code = run_cli(["scan", str(ROOT / "sample_inputs" / "crank_rocker_joints.toml"), "--vary",
                    "coupler=110:130:5", "--torque", "rocker=-2", "--where", "forces_flagged == 0",
                    "--sort", "peak_input", "-f", "csv", "-o", str(out)])
    assert code == 0
    lines = out.read_text().splitlines()
    header = lines[0].split(",")
    for col in ("peak_input (N m)", "max_pin_force (N)", "max_shaking_force (N)", "forces_flagged"):
        assert col in header
    peaks = [float(line.split(",")[header.index("peak_input (N m)")]) for line in lines[1:]]
    assert peaks == sorted(peaks) and len(peaks) == 5


@pytest.mark.parametrize("args, says", [
    (["--vary", "coupler=110:130:3"], "changes the shape of coupler"),
    (["--vary", "O4.x=90:110:3", "--accel", "1"], "--accel needs --speed"),
])
def test_scan_loads_refusals(args, says, capsys) -> None:
    code = run_cli(["scan", str(LOADED), *args])
    err = capsys.readouterr().err
    assert code == 2 and says in err and len(err.strip().splitlines()) == 1


def test_scan_speed_without_loads_and_loads_on_a_loops_file_are_refused(capsys) -> None:
    code = run_cli(["scan", str(ROOT / "sample_inputs" / "crank_rocker_joints.toml"), "--vary",
                    "coupler=110:130:3", "--speed", "10"])
    err = capsys.readouterr().err
    assert code == 2 and "--speed in a scan" in err
    code = run_cli(["scan", str(ROOT / "sample_inputs" / "crank_rocker.toml"), "--vary", "r3=110:130:3",
                    "--torque", "r4=1"])
    err = capsys.readouterr().err
    assert code == 2 and "joints form" in err and len(err.strip().splitlines()) == 1


def test_sweep_result_carries_the_loads_as_columns() -> None:
    m = load(LOADED)
    values = [0.0, 45.0, 90.0]
    r = sweep_mechanism(m, values, speed=10.0, loads=m.extra["loads"])
    cols = r.force_columns()
    assert cols["status"] == ["ok"] * 3
    for i, v in enumerate(values):
        pos = r.positions[i]
        q = [math.radians(pos.solution[u.name]) for u in m.unknowns]
        from linkage.kinematics.forces import forces_at

        f = forces_at(m, q, speed=10.0, driver=math.radians(v))
        assert cols["input"][i] == pytest.approx(f.input, rel=1e-9)
        b = next(p for p in f.pins if p.joint == "B")
        assert cols["B_on_rocker_fx"][i] == pytest.approx(b.fx, rel=1e-9, abs=1e-9)
    with pytest.raises(ValueError):
        sweep_mechanism(m, values).force_columns()


def test_sweep_loads_table_has_every_pin_force_in_every_format(tmp_path, capsys) -> None:
    """The sweep's loads table (json here; csv, parquet and xlsx share its columns) gives
    each pin's force on its link, equal to linkage.forces at that position."""
    import json

    from linkage.kinematics.forces import forces_at

    code = run_cli(["sweep", str(LOADED), "--step", "60", "--speed", "10", "-f", "json"])
    assert code == 0
    table = next(t for t in json.loads(capsys.readouterr().out)["tables"] if t["name"] == "loads")
    cols = table["columns"]
    assert table["units"][cols.index("B_on_rocker_fx")] == "N"
    m = load(LOADED)
    r = sweep_mechanism(m, [row[0] for row in table["rows"]])
    for row, pos in zip(table["rows"], r.positions):
        q = [math.radians(pos.solution[u.name]) for u in m.unknowns]
        f = forces_at(m, q, speed=10.0, driver=math.radians(pos.input))
        for p in f.pins:
            assert row[cols.index(f"{p.joint}_on_{p.on}_fx")] == pytest.approx(p.fx, rel=1e-9, abs=1e-9)
            assert row[cols.index(f"{p.joint}_on_{p.on}_fy")] == pytest.approx(p.fy, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("unit", ["m", "ft", "in", "cm"])
def test_near_toggle_does_not_depend_on_the_length_unit(unit: str) -> None:
    """The same numbers in another unit are the same mechanism at another size: a pure
    torque load needs the same input torque, and the same positions are near a toggle
    (the force matrix is judged in the mechanism's own size). Found by the second reading:
    in m every position of the crank-rocker was flagged, in mm none."""
    text = (ROOT / "sample_inputs" / "crank_rocker_joints.toml").read_text()
    loads = Loads({}, {"rocker": -2.0}, {}, None)
    values = [float(v) for v in np.arange(0.0, 360.0, 0.5)]
    ref = load(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    other = from_text(text.replace('length_unit = "mm"', f'length_unit = "{unit}"'), f"in {unit}")
    for coupler in (120.0, 70.0):  # a full turn, and one stopped by limit positions
        a = sweep_mechanism(ref.with_values({"coupler": coupler}, {}), values, loads=loads).force_columns()
        b = sweep_mechanism(other.with_values({"coupler": coupler}, {}), values, loads=loads).force_columns()
        assert a["status"] == b["status"]
        assert "ok" in a["status"]
        for x, y, s in zip(a["input"], b["input"], a["status"]):
            if s == "ok":
                assert y == pytest.approx(x, rel=1e-9)
        m_a = scan(ref, {"coupler": (coupler, coupler + 1.0, 2)}, values=values, loads=loads)
        m_b = scan(other, {"coupler": (coupler, coupler + 1.0, 2)}, values=values, loads=loads)
        assert list(m_a["forces_flagged"]) == list(m_b["forces_flagged"])
        np.testing.assert_allclose(m_b["peak_input"], m_a["peak_input"], rtol=1e-9)


def test_python_loads_are_checked_as_a_files_are() -> None:
    """linkage.sweep, scan_designs and forces take a Loads checked by the file's one
    definition (problems.loads.parse_loads): one InputError naming it, never a KeyError,
    a numpy error or a silent NaN."""
    from linkage.errors import InputError
    from linkage.kinematics.forces import forces_at
    from linkage.problems.loads import Mass

    m = load(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    q = [u.value for u in m.unknowns]
    bad = [Loads({}, {"nosuch": 1.0}), Loads({}, {"rocker": "x"}), Loads({"B": (math.nan, 0.0)}),
           Loads({}, {}, {"rocker": Mass(-1.0, (0.0, 0.0), 0.0)}), Loads({"O2": (1.0, 0.0)}),
           Loads(gravity=(0.0, math.nan)), Loads(masses={"rocker": 3}), Loads({"B": (1e300, 0.0)}),
           Loads(forces=[("B", (1.0, 0.0))])]
    for loads in bad:
        with pytest.raises(InputError, match=r"^loads"):
            sweep_mechanism(m, [0.0, 10.0], loads=loads)
        with pytest.raises(InputError, match=r"^loads"):
            scan(m, {"coupler": (110.0, 120.0, 2)}, values=[0.0], loads=loads)
        with pytest.raises(InputError, match=r"^loads"):
            forces_at(m, q, loads)


def test_a_mass_keeps_its_links_drawn_shape_however_the_length_changes(capsys) -> None:
    """--set, with_values and --vary alike: a link whose mass (cg, inertia) is given for
    its drawn lengths cannot take other lengths; other links can."""
    from linkage.errors import InputError

    for args in (["scan", str(LOADED), "--set", "coupler=130", "--vary", "O4.x=95:105:3"],
                 ["solve", str(LOADED), "--set", "coupler=130"],
                 ["sweep", str(LOADED), "--set", "rocker=85", "--step", "90"],
                 ["scan", str(LOADED), "--vary", "coupler_A_P=50:70:3"]):
        code = run_cli(args)
        err = capsys.readouterr().err
        assert code == 2 and "[mass]" in err and len(err.strip().splitlines()) == 1, (args, err)
    m = load(LOADED)
    with pytest.raises(InputError, match="coupler = 130"):
        sweep_mechanism(m.with_values({"coupler": 130.0}, {}), [0.0], loads=m.extra["loads"])
    assert run_cli(["solve", str(LOADED), "--set", "crank=42"]) == 0  # the crank carries no mass
    capsys.readouterr()


def test_loads_need_a_known_length_unit(tmp_path, capsys) -> None:
    path = tmp_path / "furlong.toml"
    path.write_text(LOADED.read_text().replace('length_unit = "mm"', 'length_unit = "furlong"'))
    for args in (["scan", str(path), "--vary", "O4.x=95:105:3"], ["solve", str(path)],
                 ["sweep", str(path), "--step", "90"]):
        code = run_cli(args)
        err = capsys.readouterr().err
        assert code == 2 and "length_unit 'furlong'" in err and len(err.strip().splitlines()) == 1


def test_mechanical_advantage_is_one_number_of_one_kind(capsys) -> None:
    """Torque over torque for a turning driver, force over force for a sliding one (the
    force form), equal to the velocity ratio where the load acts along the motion; never a
    ratio with a unit (a sliding driver against a torque load), never with masses."""
    from linkage.kinematics.forces import forces_at
    from linkage.kinematics.rates import rates_at
    from linkage.problems.loads import Mass

    text = (ROOT / "sample_inputs" / "slider_crank_joints.toml").read_text()
    text = text.replace('link = "crank"', 'slider = "block"')
    text = text.replace("value = 45 ", "value = 146.88311367414514 ")
    m = from_text(text, "sliding driver")
    assert m.extra["drawing_driver"]["slider"] == "block"
    q = [u.value for u in m.unknowns]
    v = rates_at(m, q, speed=1.0).joint_velocities["A"]  # mm/s per mm/s of the block
    along = (v[0] / math.hypot(*v) * 10.0, v[1] / math.hypot(*v) * 10.0)  # 10 N along A's motion
    f = forces_at(m, q, Loads({"A": along}))
    assert f.input_unit == "N"
    assert f.mechanical_advantage == pytest.approx(1.0 / math.hypot(*v), rel=1e-9)  # v_in / v_out
    assert forces_at(m, q, Loads({}, {"coupler": 1.0})).mechanical_advantage is None
    crank = load(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    cq = [u.value for u in crank.unknowns]
    assert forces_at(crank, cq, Loads({}, {"rocker": -2.0})).mechanical_advantage == pytest.approx(
        1.0 / abs(rates_at(crank, cq, speed=1.0).velocities["theta_rocker"]), rel=1e-9)
    with_mass = Loads({}, {"rocker": -2.0}, {"rocker": Mass(1.0, (120.0, 30.0), 1e-3)}, (0.0, -9.81))
    assert forces_at(crank, cq, with_mass).mechanical_advantage is None
    r = sweep_mechanism(crank, [0.0, 90.0], loads=Loads({}, {"rocker": -2.0}))
    assert all(isinstance(x, float) for x in r.force_columns()["mechanical_advantage"])


def test_a_loaded_scan_on_a_dask_cluster_gives_the_local_records(tmp_path) -> None:
    """The loads travel with each task (ScanJob.loads, .motion): a scheduler and two worker
    processes on loopback give the records of the local run."""
    import json
    import subprocess
    import sys

    distributed = pytest.importorskip("distributed")
    args = [sys.executable, "-m", "linkage", "scan", str(LOADED), "--vary", "O4.x=95:105:4", "--vary",
            "O4.y=-5:5:3", "--speed", "300rpm", "--gravity", "9.81", "--torque", "rocker=-3", "--chunk", "3",
            "-f", "json"]
    local = subprocess.run(args, capture_output=True, text=True, check=True).stdout
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        remote = subprocess.run([*args, "--scheduler", cluster.scheduler_address], capture_output=True,
                                text=True, check=True).stdout
    a, b = json.loads(local), json.loads(remote)
    assert a == b
    assert a["loads"]["torques_N_m"] == {"rocker": -3.0}
    table = a["tables"][0]
    assert "peak_input" in table["columns"] and len(table["rows"]) == 12


@pytest.mark.parametrize("argv, says", [
    (["--torque", "nosuch=1"], "error: --torque nosuch: a torque acts on a moving link"),
    (["--torque", "rocker=1e300"], "error: --torque rocker: must be a finite number"),
    (["--load", "O2=1,2"], "error: --load O2: O2 is a fixed joint"),
    (["--torque", "rocker=1", "--gravity", "9.81"], "error: --gravity: it acts on the links' masses"),
])
def test_command_line_loads_are_named_by_their_option(argv, says, capsys) -> None:
    """A bad --load or --torque is named as it was typed, and gravity without a [mass]
    (it would load nothing: every column zero) is refused, for solve, sweep and scan."""
    crank = str(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    for command in (["solve", crank], ["sweep", crank, "--step", "90"],
                    ["scan", crank, "--vary", "coupler=110:120:2"]):
        code = run_cli([*command, *argv])
        err = capsys.readouterr().err.strip()
        assert code == 2 and err.startswith(says) and "\n" not in err, (command, argv, err)


def test_loads_page_shows_what_the_commands_print(capsys) -> None:
    """The figures of docs/loads.md come from the commands shown beside them."""
    section = (ROOT / "docs" / "loads.md").read_text()
    assert "$ linkage solve docs/crank_rocker_loads.toml --speed 300rpm --gravity 9.81 -f plain" in section
    assert run_cli(["solve", str(LOADED), "--speed", "300rpm", "--gravity", "9.81", "-f", "plain"]) == 0
    out = capsys.readouterr().out
    for line in ("input torque: 1.10243212952 N m (virtual power: 1.10243212952 N m)",
                 "     B   rocker  coupler  -73.5518178502  -48.9730331005  88.3641775841",
                 "on the ground (shaking force): fx = 27.1398890387 N, fy = -33.5376681256 N"):
        assert line in out and line in section
    crank = str(ROOT / "sample_inputs" / "crank_rocker_joints.toml")
    assert run_cli(["solve", crank, "--torque", "rocker=-2", "--speed", "1"]) == 0
    out = capsys.readouterr().out
    flat = " ".join(section.split())
    assert "linkage solve sample_inputs/crank_rocker_joints.toml --torque rocker=-2 --speed 1" in flat
    assert "= 8.2145" in out and "gives 8.2145" in flat
    assert "0.121735843" in out and "0.121736" in flat
