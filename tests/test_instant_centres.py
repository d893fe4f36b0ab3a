"""Instant centres and centrodes (`linkage centres`, `linkage.instant_centres`,
`linkage.centrodes`; docs/centres.md).

The references here are independent of kinematics/centres.py: the velocity centre of two
bodies computed in this file from the joints' velocities (the rates engine's, through the
public linkage.position_rates) as I = P + k x v_rel(P) / omega_rel, and the four-bar's and
slider-crank's centres in closed form (Norton, Design of Machinery, sec. 6.3: I13 where
O2A meets O4B, I24 where AB meets O2O4; a slider's I14 at infinity across its line).
"""

from __future__ import annotations

import itertools
import json
import math
import random
from pathlib import Path

import pytest

import linkage
from linkage.errors import InputError
from linkage.kinematics.centres import CHECK_RTOL, at_driver, velocity_residual
from linkage.kinematics.loading import from_text

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_inputs"
DRAWABLE = sorted(p.name for p in SAMPLES.glob("*.toml") if p.name != "offset_slider.toml")
AGREE = 1e-9
"""Kennedy's centres and the velocities' agree to this, relative to the mechanism's size
(and for a centre far out, to its distance squared over the size)."""


# --- the independent references ---------------------------------------------------------------

def _omega(drawing, rates, body):
    """A body's angular velocity from two of its joints' velocities; a one-joint slider's is
    its line's body's; the ground's 0."""
    if body == "ground":
        return 0.0
    if body in drawing.sliders and len(drawing.bodies[body]) < 2:
        return _omega(drawing, rates, drawing.sliders[body].on)
    a, b = drawing.bodies[body][:2]
    (xa, ya), (xb, yb) = rates.joints[a], rates.joints[b]
    (ua, va), (ub, vb) = rates.joint_velocities[a], rates.joint_velocities[b]
    dx, dy = xb - xa, yb - ya
    return (dx * (vb - va) - dy * (ub - ua)) / (dx * dx + dy * dy)


def _field(drawing, rates, body, at):
    """The velocity of body's point at ``at``, from its first joint."""
    if body == "ground":
        return 0.0, 0.0
    j = drawing.bodies[body][0]
    w = _omega(drawing, rates, body)
    (x, y), (u, v) = rates.joints[j], rates.joint_velocities[j]
    return u - w * (at[1] - y), v + w * (at[0] - x)


def velocity_reference(m, q, d, i, j):
    """The centre of bodies i and j where their relative velocity vanishes: ('finite', x, y),
    ('at infinity', direction in [0, 180) deg) or ('at rest',)."""
    drawing = m.extra["drawing"]
    rates = linkage.position_rates(m, q, speed=1.0, driver=d)
    size = m.length_scale
    p = rates.joints[drawing.bodies[j][0] if j != "ground" else drawing.bodies[i][0]]
    vi, vj = _field(drawing, rates, i, p), _field(drawing, rates, j, p)
    rx, ry = vj[0] - vi[0], vj[1] - vi[1]
    dw = _omega(drawing, rates, j) - _omega(drawing, rates, i)
    fastest = max(math.hypot(*v) for v in rates.joint_velocities.values())
    if abs(dw) * size <= 1e-12 * fastest:
        if math.hypot(rx, ry) <= 1e-12 * fastest:
            return ("at rest",)
        return ("at infinity", math.degrees(math.atan2(rx, -ry)) % 180.0)
    return ("finite", p[0] - ry / dw, p[1] + rx / dw)


def agree(centre, reference, size, origin=(0.0, 0.0)):
    if reference[0] == "at rest":
        return True  # every point is the centre: the velocities do not place it
    if centre.kind != reference[0]:
        return False
    if centre.kind == "at infinity":
        gap = abs(centre.direction_deg - reference[1]) % 180.0
        return math.radians(min(gap, 180.0 - gap)) <= AGREE
    far = math.hypot(centre.x - origin[0], centre.y - origin[1]) / size
    return math.hypot(centre.x - reference[1], centre.y - reference[2]) <= AGREE * size * (1.0 + far * far)


def check_against_velocities(ic, pose):
    m, q, d = pose.mechanism, list(pose.q), pose.driver
    size = m.length_scale
    xs = list(pose.rates.joints.values())
    origin = (sum(x for x, _ in xs) / len(xs), sum(y for _, y in xs) / len(xs))
    for c in ic.centres:
        ref = velocity_reference(m, q, d, c.i, c.j)
        assert agree(c, ref, size, origin), (ic.mechanism, c, ref)
        assert c.residual is not None and c.residual <= CHECK_RTOL, c


# --- every sample ------------------------------------------------------------------------------

@pytest.mark.parametrize("name", DRAWABLE)
def test_kennedy_centres_are_the_velocity_centres_on_every_sample(name):
    """Every sample at its own pose and at three more driver values: each centre found by
    the joints or Kennedy (never left to the velocities), equal to the velocities' centre
    to 1e-9, and v = omega x r about it to 1e-9 of the fastest motion."""
    m = linkage.load_mechanism(SAMPLES / name)
    unit = 180.0 / math.pi if m.driver.kind == "angle" else 1.0
    values = [None] + ([m.driver.value * unit + k for k in (-20.0, 17.0, 41.0)]
                       if m.driver.kind == "angle" else [m.driver.value * 0.9, m.driver.value * 1.05])
    checked = 0
    for v in values:
        try:
            _, pose, converted = at_driver(m, v)
        except InputError as exc:
            assert "cannot be assembled" in str(exc)
            continue
        ic = linkage.instant_centres(m, v)
        assert converted == (m.extra.get("drawing") is None)
        n = len(ic.bodies)
        assert len(ic.centres) == n * (n - 1) // 2
        assert ic.status == "ok", ic.message
        assert {c.how for c in ic.centres} <= {"primary", "Kennedy"}
        check_against_velocities(ic, pose)
        checked += 1
    assert checked >= 2


def test_every_sample_over_a_turn_passes_the_velocity_check():
    """Every 10 deg of a turn where each sample assembles: status ok, and the worst check
    and the worst distance between Kennedy's centre and the velocities' (`pytest -s`
    prints them; far centres, 1,000 sizes out, miss most)."""
    worst_check = worst_apart = 0.0
    poses = 0
    for name in DRAWABLE:
        m = linkage.load_mechanism(SAMPLES / name)
        for v in range(0, 360, 10):
            try:
                ic = linkage.instant_centres(m, v)
            except InputError:
                continue
            assert ic.status == "ok", (name, v, ic.message)
            poses += 1
            worst_check = max(worst_check, ic.worst_residual)
            worst_apart = max([worst_apart] + [c.velocity_separation for c in ic.centres
                                               if c.velocity_separation is not None])
    print(f"\n{poses} poses: worst velocity check {worst_check:.2g}, worst separation from the "
          f"velocities' centre {worst_apart:.2g}")
    assert poses > 400 and worst_check <= CHECK_RTOL and worst_apart <= AGREE


def test_six_bars_have_fifteen_centres_seven_pins_eight_by_kennedy():
    for name in ("watt_sixbar_joints.toml", "stephenson_sixbar_joints.toml"):
        ic = linkage.instant_centres(SAMPLES / name)
        hows = [c.how for c in ic.centres]
        assert len(hows) == 15 and hows.count("primary") == 7 and hows.count("Kennedy") == 8, hows


def test_a_loops_file_that_names_no_joints_is_refused_with_the_way_to_draw_it():
    with pytest.raises(InputError, match="names no joints"):
        linkage.instant_centres(SAMPLES / "offset_slider.toml")


# --- random four-bars and slider-cranks, both branches: the closed forms ----------------------------

def fourbar_text(a, b, c, d, theta, sign):
    ax, ay = a * math.cos(theta), a * math.sin(theta)
    ex, ey = d - ax, -ay
    e = math.hypot(ex, ey)
    if not abs(b - c) < e < b + c:
        return None
    along = (b * b - c * c + e * e) / (2 * e)
    h = math.sqrt(max(b * b - along * along, 0.0))
    bx = ax + along * ex / e - sign * h * ey / e
    by = ay + along * ey / e + sign * h * ex / e
    joints = {"O2": (0.0, 0.0), "A": (ax, ay), "B": (bx, by), "O4": (d, 0.0)}
    return _doc(joints, ["O2", "O4"], {"crank": ["O2", "A"], "coupler": ["A", "B"], "rocker": ["O4", "B"]},
                math.degrees(math.atan2(ay, ax))), joints


def slider_text(a, b, e, theta, sign):
    ax, ay = a * math.cos(theta), a * math.sin(theta)
    if not abs(e - ay) < b:
        return None
    bx = ax + sign * math.sqrt(b * b - (e - ay) ** 2)
    joints = {"O2": (0.0, 0.0), "A": (ax, ay), "B": (bx, e)}
    text = _doc(joints, ["O2"], {"crank": ["O2", "A"], "coupler": ["A", "B"], "block": ["B"]},
                math.degrees(math.atan2(ay, ax)), '[sliders]\nblock = { on = "ground", angle = 0 }\n')
    return text, joints


def _doc(joints, ground, links, value, extra=""):
    lines = ['name = "random"', 'length_unit = "mm"', f"ground = {json.dumps(ground)}", "[joints]"]
    lines += [f"{k} = [{x!r}, {y!r}]" for k, (x, y) in joints.items()]
    lines += ["[links]"] + [f"{k} = {json.dumps(v)}" for k, v in links.items()]
    return "\n".join(lines) + "\n" + extra + f'[driver]\nlink = "crank"\nvalue = {value!r}\n'


def meet(p1, p2, p3, p4):
    """Where line p1p2 meets line p3p4 (Cramer), or None for (nearly) parallel lines."""
    d1 = (p2[0] - p1[0], p2[1] - p1[1])
    d2 = (p4[0] - p3[0], p4[1] - p3[1])
    den = d1[0] * d2[1] - d1[1] * d2[0]
    if abs(den) <= 1e-3 * math.hypot(*d1) * math.hypot(*d2):
        return None
    t = ((p3[0] - p1[0]) * d2[1] - (p3[1] - p1[1]) * d2[0]) / den
    return p1[0] + t * d1[0], p1[1] + t * d1[1]


def near(centre, point, size):
    far = math.hypot(*point) / size
    return centre.kind == "finite" and math.hypot(centre.x - point[0], centre.y - point[1]) <= \
        AGREE * size * (1.0 + far * far)


def _random_centres(make, count, seed):
    """``count`` random mechanisms from ``make(rng)`` (text, joints, branch sign), each
    checked against the velocities: (centres, the pose's joints, size), both branches met."""
    rng = random.Random(seed)
    signs = set()
    while len(signs) < 2 or count > 0:
        built = make(rng)
        if built is None:
            continue
        text, _, sign = built
        try:
            m = from_text(text, "random")
            _, pose, _ = at_driver(m)
        except InputError:
            continue  # a drawing too near a limit to pass the joints form's checks
        if pose.rates.status != "ok":
            continue
        ic = linkage.instant_centres(m)
        assert ic.status == "ok", ic.message
        check_against_velocities(ic, pose)
        signs.add(sign)
        count -= 1
        yield ic, pose.rates.joints, m.length_scale


def _kennedy_at(ic, expected, size):
    """Each labelled centre is Kennedy's and at its closed form's point (None: lines too
    near parallel for the closed form's Cramer rule to be a reference)."""
    for label, point in expected:
        c = next(c for c in ic.centres if c.label == label)
        assert c.how == "Kennedy"
        if point is not None:
            assert near(c, point, size), (label, c, point)


def test_random_fourbars_both_branches_have_the_closed_form_centres():
    def make(rng):
        a, b, c, d = (rng.uniform(20, 150) for _ in range(4))
        sign = rng.choice((1, -1))
        built = fourbar_text(a, b, c, d, rng.uniform(0, 2 * math.pi), sign)
        return None if built is None else (*built, sign)

    for ic, joints, size in _random_centres(make, 60, 31):
        O2, A, B, O4 = (joints[k] for k in ("O2", "A", "B", "O4"))
        _kennedy_at(ic, (("I13", meet(O2, A, O4, B)), ("I24", meet(A, B, O2, O4))), size)
        for label, at in (("I12", O2), ("I23", A), ("I34", B), ("I14", O4)):
            assert near(next(c for c in ic.centres if c.label == label), at, size)


def test_random_slider_cranks_both_branches_have_the_closed_form_centres():
    def make(rng):
        sign = rng.choice((1, -1))
        built = slider_text(rng.uniform(10, 60), rng.uniform(70, 200), rng.uniform(-30, 30),
                            rng.uniform(0, 2 * math.pi), sign)
        return None if built is None else (*built, sign)

    for ic, joints, size in _random_centres(make, 60, 32):
        O2, A, B = (joints[k] for k in ("O2", "A", "B"))
        i14 = ic.centre("ground", "block")
        assert i14.kind == "at infinity" and i14.how == "primary"
        assert min(abs(i14.direction_deg - 90.0), 180 - abs(i14.direction_deg - 90.0)) < 1e-9
        # I13 where O2A meets the perpendicular to the slide through B; I24 where AB meets the
        # perpendicular through O2
        _kennedy_at(ic, (("I13", meet(O2, A, B, (B[0], B[1] + 1.0))), ("I24", meet(A, B, O2, (0.0, 1.0)))),
                    size)


# --- points at infinity ------------------------------------------------------------------------------

def _parallelogram(theta_deg=60.0):
    text, _ = fourbar_text(40.0, 100.0, 40.0, 100.0, math.radians(theta_deg), 1)
    return from_text(text, "parallelogram")


def test_a_parallelograms_i13_and_i24_are_at_infinity():
    """O2A parallel to O4B puts I13 at infinity along them (the coupler translates); AB
    parallel to O2O4 puts I24 at infinity along the ground (crank and rocker turn alike)."""
    m = _parallelogram()
    _, pose, _ = at_driver(m)
    B = pose.rates.joints["B"]
    assert abs(B[0] - 120.0) < 1e-9 and abs(B[1] - 40.0 * math.sin(math.radians(60.0))) < 1e-9
    ic = linkage.instant_centres(m)
    assert ic.status == "ok", ic.message
    i13, i24 = ic.centre("ground", "coupler"), ic.centre("crank", "rocker")
    assert (i13.kind, i24.kind) == ("at infinity", "at infinity")
    assert (i13.x, i13.y, i24.x, i24.y) == (None, None, None, None)
    assert abs(i13.direction_deg - 60.0) < 1e-9
    assert min(i24.direction_deg, 180.0 - i24.direction_deg) < 1e-9
    check_against_velocities(ic, pose)


def test_a_parallelograms_fixed_centrode_is_all_at_infinity_not_huge_numbers():
    cd = linkage.centrodes(_parallelogram(), list(range(10, 171, 20)))
    assert [p.status for p in cd.points] == ["ok"] * 9
    for p in cd.points:
        assert p.fixed.kind == "at infinity" and p.fixed.x is None
        assert abs(p.fixed.direction_deg - p.input) < 1e-9  # along the crank
        assert p.moving.kind == "at infinity"


def test_a_fourbar_with_every_joint_on_one_line_has_undefined_centres():
    """The parallelogram folded flat: O2A and O4B are one line, and so are AB and O2O4, so
    Kennedy's lines coincide, and the velocities are undefined there (J is singular)."""
    joints = {"O2": (0.0, 0.0), "A": (40.0, 0.0), "B": (140.0, 0.0), "O4": (100.0, 0.0)}
    links = {"crank": ["O2", "A"], "coupler": ["A", "B"], "rocker": ["O4", "B"]}
    text = _doc(joints, ["O2", "O4"], links, 0.0)
    ic = linkage.instant_centres(from_text(text, "flat"))
    assert ic.status == "undefined"
    assert [c.label for c in ic.centres if c.kind == "undefined"] == ["I13", "I24"]
    assert "toggle" in ic.message


# --- the velocity check can fail ----------------------------------------------------------------------

def test_the_velocity_check_catches_a_centre_off_by_1e_6_of_the_size():
    from linkage.kinematics.centres import HomogeneousFrame, body_motions, fastest_motion, relative_centre

    _, pose, _ = at_driver(SAMPLES / "crank_rocker_joints.toml")
    frame = HomogeneousFrame.of(pose.rates.joints)
    motions = body_motions(pose.mechanism, pose.rates, frame)
    scale = fastest_motion(motions, pose.rates, frame)
    h = relative_centre(motions, "ground", "coupler")
    x, y = h[0] / h[2], h[1] / h[2]
    good = velocity_residual((x, y, 1.0), "ground", "coupler", motions, pose.rates, frame,
                             pose.mechanism, scale)
    bad = velocity_residual((x + 1e-6, y, 1.0), "ground", "coupler", motions, pose.rates, frame,
                            pose.mechanism, scale)
    assert good <= 1e-14 and bad > 1e-7


# --- centrodes ----------------------------------------------------------------------------------------

def test_the_crank_rockers_centrodes_are_its_kennedy_i13_in_both_frames():
    m = linkage.load_mechanism(SAMPLES / "crank_rocker_joints.toml")
    values = list(range(0, 360, 15))
    cd = linkage.centrodes(m, values)
    assert cd.body == "coupler" and cd.frame_joint == "A"
    for p in cd.points:
        assert p.status == "ok"
        ic = linkage.instant_centres(m, p.input)
        i13 = ic.centre("ground", "coupler")
        assert i13.how == "Kennedy"
        if i13.kind == "at infinity":
            assert p.fixed.kind == "at infinity"
            continue
        size = m.length_scale
        assert near(i13, (p.fixed.x, p.fixed.y), size)
        # the moving centrode's point, carried by the coupler's pose, is the same point
        _, pose, _ = at_driver(m, p.input)
        ax, ay = pose.rates.joints["A"]
        bx, by = pose.rates.joints["B"]
        t = math.atan2(by - ay, bx - ax)
        x = ax + math.cos(t) * p.moving.x - math.sin(t) * p.moving.y
        y = ay + math.sin(t) * p.moving.x + math.cos(t) * p.moving.y
        assert math.hypot(x - p.fixed.x, y - p.fixed.y) <= 1e-9 * size * (1 + (math.hypot(x, y) / size) ** 2)


def test_the_crank_rockers_fixed_centrode_passes_through_infinity_where_o2a_and_o4b_turn_parallel():
    """I13 is at infinity where the crank O2A and the rocker O4B are parallel: the sweep
    names the intervals where their cross product changes sign, and no others."""
    m = linkage.load_mechanism(SAMPLES / "crank_rocker_joints.toml")
    values = list(range(0, 361, 10))
    cd = linkage.centrodes(m, values)

    def parallel(v):
        _, pose, _ = at_driver(m, v)
        (ox, oy), (ax, ay), (bx, by), (px, py) = (pose.rates.joints[k] for k in ("O2", "A", "B", "O4"))
        return (ax - ox) * (by - py) - (ay - oy) * (bx - px)

    turns = [(a, b) for a, b in itertools.pairwise(values) if parallel(a) * parallel(b) < 0]
    assert len(turns) == 2 and cd.through_infinity == tuple((float(a), float(b)) for a, b in turns)


def test_the_crossed_branch_has_its_own_centres_checked_against_its_velocities():
    """--branch crossed: the other assembly at the same crank angle, B mirrored across the
    line AO4; its I13 is where O2A meets O4B there, and its centrode follows it."""
    for name in ("crank_rocker.toml", "crank_rocker_joints.toml"):
        m = linkage.load_mechanism(SAMPLES / name)
        _, pose, _ = at_driver(m, 30.0, "crossed")
        ic = linkage.instant_centres(m, 30.0, branch="crossed")
        assert ic.status == "ok"
        check_against_velocities(ic, pose)
        joints = pose.rates.joints
        O2, A, B, O4 = (joints[k] for k in ("O2", "A", "B", "O4"))
        assert B[1] < 0  # the crossed assembly at 30 deg: B below the ground line
        coupler = ic.bodies[2]
        assert near(ic.centre("ground", coupler), meet(O2, A, O4, B), m.length_scale)
        cd = linkage.centrodes(m, [30.0], branch="crossed")
        fixed = cd.points[0].fixed
        assert near(ic.centre("ground", coupler), (fixed.x, fixed.y), m.length_scale)


def test_the_centrodes_of_a_loops_file_and_its_drawing_agree():
    a = linkage.centrodes(SAMPLES / "crank_rocker.toml", [0, 45, 90])
    b = linkage.centrodes(SAMPLES / "crank_rocker_joints.toml", [0, 45, 90])
    assert a.body == "link3" and b.body == "coupler"
    assert (a.driver, b.driver) == ("theta2", "theta_crank")
    for p, r in zip(a.points, b.points):
        assert math.hypot(p.fixed.x - r.fixed.x, p.fixed.y - r.fixed.y) < 1e-9 * 120


# --- the command ---------------------------------------------------------------------------------------

def test_the_command_prints_every_centre_with_units_and_exits_0(cli):
    r = cli("centres", str(SAMPLES / "slider_crank_joints.toml"), "--format", "plain")
    assert r.code == 0, r.err
    assert "x (mm)" in r.out and "direction (deg)" in r.out and "at infinity" in r.out
    assert "status: ok" in r.out
    assert sum(line.strip().startswith("I") for line in r.out.splitlines()) == 6


@pytest.mark.parametrize("fmt", ["csv", "json", "plain", "github", "latex", "html", "rst", "parquet", "xlsx"])
def test_every_format(cli, tmp_path, fmt):
    suffix = {"plain": "txt", "github": "md", "latex": "tex"}.get(fmt, fmt)
    out = tmp_path / f"c.{suffix}"
    r = cli("centres", str(SAMPLES / "crank_rocker_joints.toml"), "--centrodes", "--step", "90",
            "-o", str(out), "--format", fmt)
    assert r.code == 0, r.err
    assert out.stat().st_size > 0
    if fmt == "json":
        doc = json.loads(out.read_text())
        t = {t["name"]: t for t in doc["tables"]}
        assert t["centres"]["columns"][:6] == ["centre", "body_i", "body_j", "x", "y", "where"]
        assert t["centres"]["units"][3:5] == ["mm", "mm"]
        assert len(t["centres"]["rows"]) == 6 and len(t["centrodes"]["rows"]) == 5
        assert doc["status"] == "ok" and doc["bodies"] == ["ground", "crank", "coupler", "rocker"]
    if fmt == "csv":  # one table per file: c.csv and c.centrodes.csv
        assert "centre,body_i,body_j,x (mm),y (mm),where,direction (deg),how" in out.read_text()
        assert "theta_crank (deg),status,fixed_x (mm)" in (tmp_path / "c.centrodes.csv").read_text()


def test_the_plot_draws_the_centres_and_the_centrodes(cli, tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "c.png"
    r = cli("centres", str(SAMPLES / "crank_rocker_joints.toml"), "--centrodes", "--step", "10",
            "--plot", str(out), "--format", "csv", "--table", "centres")
    assert r.code == 0, r.err
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_plot_does_not_load_matplotlib_unless_asked():
    from conftest import run_process

    path = str(SAMPLES / "crank_rocker_joints.toml")
    r = run_process(code="import sys\nfrom linkage.cli.entry import run_cli\n"
                         f"run_cli(['centres', {path!r}, '--format', 'csv'])\n"
                         "print('matplotlib' in sys.modules)")
    assert r.stdout.strip().endswith("False"), r.stdout + r.stderr


def _one_line(r, code, *needles):
    assert r.code == code, (r.code, r.out, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.err
    assert "Traceback" not in r.err and "internal error" not in r.err
    for n in needles:
        assert n in r.err, r.err


def test_a_mechanism_of_mobility_two_is_refused(cli, tmp_path):
    path = tmp_path / "five.toml"
    path.write_text('name = "five-bar"\nlength_unit = "mm"\nground = ["O2", "O4"]\n[joints]\n'
                    'O2 = [0.0, 0.0]\nA = [0.0, 40.0]\nC = [50.0, 80.0]\nB = [100.0, 40.0]\n'
                    'O4 = [100.0, 0.0]\n[links]\n'
                    'crank = ["O2", "A"]\nl3 = ["A", "C"]\nl4 = ["C", "B"]\nrocker = ["O4", "B"]\n'
                    '[driver]\nlink = "crank"\nvalue = 90\n')
    _one_line(cli("centres", str(path)), 2, "mobility 2")


def test_a_pose_that_cannot_be_assembled_is_refused(cli):
    _one_line(cli("centres", str(SAMPLES / "fourbar_me581_joints.toml"), "--set", "theta_crank=150"), 2,
              "cannot be assembled at theta_crank = 150 deg")


def test_at_a_toggle_the_status_says_the_velocities_are_undefined_and_exits_1(cli):
    r = cli("centres", str(SAMPLES / "slider_crank.toml"), "--set", "e=0", "--set", "r3=40", "--set",
            "theta2=90", "--format", "plain")
    assert r.code == 1, r.err
    assert "status: toggle: the velocities are undefined here" in r.out


def test_centrode_options_without_centrodes_are_refused(cli):
    _one_line(cli("centres", str(SAMPLES / "crank_rocker_joints.toml"), "--step", "5"), 2,
              "--step", "--centrodes")
    _one_line(cli("centres", str(SAMPLES / "crank_rocker_joints.toml"), "--centrodes", "--body", "wheel"), 2,
              "body must name a link")


def test_a_pinned_bodys_centrode_never_passes_through_infinity():
    """An adversary's pass: the rocker's centre relative to the ground is O4 at every position,
    yet its reversals were listed as passes through infinity (the homogeneous point flips
    sign with omega, the point does not move)."""
    import linkage

    cd = linkage.centrodes(str(SAMPLES / "crank_rocker_joints.toml"), [x * 2.5 for x in range(144)],
                           body="rocker")
    assert cd.through_infinity == ()
    coupler = linkage.centrodes(str(SAMPLES / "crank_rocker_joints.toml"), [x * 2.5 for x in range(144)])
    assert coupler.through_infinity == ((67.5, 70.0), (292.5, 295.0))  # as docs/centres.md says


def test_a_translating_coupler_reports_no_crossings(tmp_path):
    """A parallelogram's coupler never turns: its centre is at infinity throughout, and the
    sign of its rounding-noise angular velocity is no crossing."""
    import linkage

    path = tmp_path / "pg.toml"
    path.write_text('name = "parallelogram"\nlength_unit = "mm"\nground = ["O2", "O4"]\n[joints]\n'
                    'O2 = [0.0, 0.0]\nA = [34.64101615137755, 20.0]\nB = [134.64101615137756, 20.0]\n'
                    'O4 = [100.0, 0.0]\n[links]\ncrank = ["O2", "A"]\ncoupler = ["A", "B"]\n'
                    'rocker = ["O4", "B"]\n[driver]\nlink = "crank"\nvalue = 30\n')
    cd = linkage.centrodes(str(path), [30, 60, 90, 120, 150])
    assert cd.through_infinity == ()


def test_a_drawn_30_degrees_is_reported_as_30_not_29_999999999999996(cli) -> None:
    """Finding: ``linkage centres -f json`` gave driver_value 29.999999999999996 for the
    crank drawn at 30 (a radian round trip by math.degrees): the degrees read are kept."""
    from linkage.kinematics.centres import read_degrees

    r = cli("centres", str(SAMPLES / "crank_rocker_joints.toml"), "-f", "json")
    assert json.loads(r.out)["driver_value"] == 30
    rng = random.Random(30)
    for _ in range(2000):
        typed = round(rng.uniform(-720.0, 720.0), rng.randint(0, 8))
        assert read_degrees(typed * (math.pi / 180.0), "deg") == typed
    assert read_degrees(0.5, "rad") == math.degrees(0.5)
