"""`linkage new KIND` (issue 21): a commented joints-form file from link lengths that solves
at its drawn crank angle to its drawn joints and sweeps as written, for each kind and both
branches. References derived here: the four-bar by the law of cosines, the slider-crank
by sin(theta3) = (e - r2 sin theta2) / r3, the inverted slider-crank by
A - O4 = (s + i e) e^(i theta4)."""

from __future__ import annotations

import csv
import io
import math

import pytest

from linkage import solve_system
from linkage.files import parse_toml
from linkage.kinematics.loading import from_text, load
from linkage.kinematics.rates import rates_at
from linkage.problems import templates
from linkage.problems.loops import shown_value
from linkage.problems.start import start_on_branch
from linkage.samples import sample_path

# lengths for which both branches assemble over a whole crank turn (the Stephenson sample's
# dyad does not close on the four-bar's crossed branch, so it gets a longer one here); every
# other registered kind is tested with its sample's
LONGER = {"stephenson": ["--links", "40", "120", "80", "100", "60", "140", "110", "160"]}
KINDS = {kind: LONGER.get(kind, []) for kind in templates.KINDS}


def made(cli, tmp_path, kind: str, *args: str) -> str:
    """The text of the file `linkage new KIND ARGS -o FILE` wrote (a new FILE each time)."""
    path = tmp_path / f"{kind}-{len(list(tmp_path.iterdir()))}.toml"
    r = cli("new", kind, *args, "-o", str(path))
    assert r.code == 0, r.err
    assert r.err == f"wrote {path}\n"
    return path.read_text()


def solved(text: str, value: float | None = None, branch: str | None = None):
    m = from_text(text, "<new>")
    if value is not None:
        m = m.with_values({m.driver.name: value}, {})
    if branch is not None:
        m = start_on_branch(m, branch, False)
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    return m, r


@pytest.mark.parametrize("branch", ["open", "crossed"])
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_file_solves_to_its_drawing_and_sweeps(cli, tmp_path, kind: str, branch: str) -> None:
    text = made(cli, tmp_path, kind, *KINDS[kind], "--branch", branch)
    drawn = {j: tuple(p) for j, p in parse_toml(text, "<new>")["joints"].items()}
    m, r = solved(text)
    placed = rates_at(m, r.x).joints
    for name, xy in drawn.items():
        assert placed[name] == pytest.approx(xy, abs=1e-9), name
    (path,) = tmp_path.iterdir()
    sweep = cli("sweep", str(path), "--format", "csv")
    assert sweep.code == 0, sweep.err
    rows = list(csv.DictReader(io.StringIO(sweep.out)))
    assert len(rows) == 361
    assert {row["status"] for row in rows} == {"converged"}
    unknowns = [c for c in rows[0] if c.startswith(("theta_", "s_")) and c != "theta_crank (deg)"]
    assert len(unknowns) == len(m.unknowns)
    assert all(math.isfinite(float(row[c])) for row in rows for c in unknowns)


def fourbar(theta2: float, r2: float, r3: float, r4: float, r1: float,
            open_branch: bool) -> tuple[float, float]:
    """theta3, theta4 (rad) by the law of cosines in the triangles A-B-O4 at A and at O4:
    open puts B on the left of A -> O4 (the rocker turns anticlockwise from the coupler)."""
    t2 = math.radians(theta2)
    ax, ay = r2 * math.cos(t2), r2 * math.sin(t2)
    d = math.hypot(r1 - ax, -ay)
    beta = math.atan2(-ay, r1 - ax)  # A -> O4
    psi = math.acos((r3 * r3 + d * d - r4 * r4) / (2 * r3 * d))  # at A, between AO4 and AB
    phi = math.acos((r4 * r4 + d * d - r3 * r3) / (2 * r4 * d))  # at O4, between O4A and O4B
    sign = 1 if open_branch else -1
    return beta + sign * psi, beta + math.pi - sign * phi


def same_angle(a: float, b: float) -> float:
    return math.remainder(a - b, 2 * math.pi)


@pytest.mark.parametrize("theta2", [0.0, 45.0, 100.0, 200.0, 300.0])
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_a_fourbar_is_the_law_of_cosines(cli, tmp_path, theta2: float, branch: str) -> None:
    links = (30.0, 90.0, 70.0, 80.0)  # Grashof: 30 + 90 < 70 + 80, the crank turns fully
    want = fourbar(theta2, *links, branch == "open")
    # drawn at theta2
    text = made(cli, tmp_path, "fourbar", "--links", *map(str, links), "--angle", str(theta2),
                "--branch", branch)
    xy = parse_toml(text, "<new>")["joints"]
    ax, ay = xy["A"]
    assert (xy["B"][0] - ax, xy["B"][1] - ay) == pytest.approx(
        (90 * math.cos(want[0]), 90 * math.sin(want[0])), rel=1e-12, abs=1e-12)
    _, r = solved(text)
    assert [same_angle(g, w) for g, w in zip(r.x, want)] == pytest.approx([0.0, 0.0], abs=1e-12)
    # drawn at 30 deg, solved at theta2 on the branch
    text = made(cli, tmp_path, "fourbar", "--links", *map(str, links), "--branch", branch)
    m, r = solved(text, theta2, branch)
    assert [same_angle(g, w) for g, w in zip(r.x, want)] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert m.derivation.name_of(list(r.x), math.radians(theta2)) == branch


def slider_crank(theta2: float, r2: float, r3: float, e: float, open_branch: bool) -> tuple[float, float]:
    """theta3 (rad) and the block's x: sin(theta3) = (e - r2 sin(theta2)) / r3, open where
    cos(theta3) > 0 (the coupler points the way the slide grows)."""
    t2 = math.radians(theta2)
    t3 = math.asin((e - r2 * math.sin(t2)) / r3)
    if not open_branch:
        t3 = math.pi - t3
    return t3, r2 * math.cos(t2) + r3 * math.cos(t3)


@pytest.mark.parametrize("theta2", [0.0, 45.0, 120.0, 250.0])
@pytest.mark.parametrize("branch", ["open", "crossed"])
@pytest.mark.parametrize("e", [10.0, -12.5, 0.0])
def test_a_slider_crank_is_its_closed_form(cli, tmp_path, theta2: float, branch: str, e: float) -> None:
    t3, s = slider_crank(theta2, 40.0, 120.0, e, branch == "open")
    text = made(cli, tmp_path, "slider-crank", "--links", "40", "120", str(e), "--angle", str(theta2),
                "--branch", branch)
    assert parse_toml(text, "<new>")["joints"]["B"] == pytest.approx([s, e], rel=1e-12, abs=1e-12)
    m, r = solved(text)
    assert [u.name for u in m.unknowns] == ["theta_coupler", "s_block"]
    assert same_angle(r.x[0], t3) == pytest.approx(0.0, abs=1e-12)
    assert r.x[1] == pytest.approx(s, rel=1e-12)
    assert m.derivation.name_of(list(r.x), math.radians(theta2)) == branch
    # drawn at its default angle, solved at theta2 on the branch
    _, r = solved(made(cli, tmp_path, "slider-crank", "--links", "40", "120", str(e), "--branch", branch),
                  theta2, branch)
    assert same_angle(r.x[0], t3) == pytest.approx(0.0, abs=1e-12)
    assert r.x[1] == pytest.approx(s, rel=1e-12)


@pytest.mark.parametrize("theta2", [60.0, 0.0, 130.0, 240.0])
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_an_inverted_slider_is_its_closed_form(cli, tmp_path, theta2: float, branch: str) -> None:
    """A - O4 = (s + i e) e^(i theta4): s = +-sqrt(|A - O4|^2 - e^2) (open: +), theta4 =
    arg(A - O4) - atan2(e, s); at 60 deg, s = 50 sqrt(3) and theta4 = 150 deg exactly."""
    r2, r1, e = 40.0, 100.0, 10.0
    t2 = math.radians(theta2)
    dx, dy = r2 * math.cos(t2) - r1, r2 * math.sin(t2)
    s = (1 if branch == "open" else -1) * math.sqrt(dx * dx + dy * dy - e * e)
    t4 = math.atan2(dy, dx) - math.atan2(e, s)
    text = made(cli, tmp_path, "inverted-slider", "--angle", str(theta2), "--branch", branch)
    m, r = solved(text)
    assert [u.name for u in m.unknowns] == ["theta_rocker", "s_block"]
    assert m.parameters["e_block"].value == pytest.approx(e, rel=1e-12)
    assert same_angle(r.x[0], t4) == pytest.approx(0.0, abs=1e-12)
    assert r.x[1] == pytest.approx(s, rel=1e-12)
    if theta2 == 60.0 and branch == "open":
        assert (math.degrees(r.x[0]), r.x[1]) == pytest.approx((150.0, 50 * math.sqrt(3)), rel=1e-13)


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_loops_form_solves_to_the_same_answers(cli, tmp_path, kind: str) -> None:
    joints = made(cli, tmp_path, kind, *KINDS[kind])
    r = cli("new", kind, *KINDS[kind], "--form", "loops")
    assert r.code == 0, r.err
    assert "[[loops]]" in r.out and "[joints]" not in r.out
    assert r.out.startswith(f"# drawn by: linkage new {kind} --links ")
    (path,) = tmp_path.iterdir()
    converted = cli("convert", str(path)).out
    assert converted.splitlines()[1:] == r.out.splitlines()[2:]  # one derivation, from one drawing
    for value in (None, 10.0, 95.0, 275.0):
        a, b = solved(joints, value)[1], solved(r.out, value)[1]
        assert list(a.x) == pytest.approx(list(b.x), abs=1e-12)


def test_the_command_in_the_file_makes_the_file_again(cli, tmp_path) -> None:
    import shlex

    text = made(cli, tmp_path, "stephenson", "--links", "1/3", "120", "80.5", "100", "60", "100", "90", "160",
                "--angle", "-33.25", "--branch", "open/crossed", "--unit", "cm", "--name", "it's mine")
    first = text.splitlines()[0]
    assert first.startswith("# Stephenson III six-bar, drawn by: linkage new stephenson "
                            "--links 0.3333333333333333 120 80.5 ")
    words = shlex.split(first.split("drawn by: ", 1)[1])
    again = cli(*words[1:])
    assert again.code == 0 and again.out == text


@pytest.mark.parametrize("kind", list(templates.KINDS))
def test_every_registered_kind_makes_a_file_that_solves_with_its_samples_dimensions(cli, tmp_path,
                                                                                     kind: str) -> None:
    """A kind is one registry entry (templates.KINDS) and its sample file: with no --links
    the file ``linkage new KIND`` writes solves to its drawing, in both forms, and its
    defaults are its sample's lengths and driver value."""
    k = templates.KINDS[kind]
    text = made(cli, tmp_path, kind)
    drawn = {j: tuple(p) for j, p in parse_toml(text, "<new>")["joints"].items()}
    m, r = solved(text)
    placed = rates_at(m, r.x).joints
    for name, xy in drawn.items():
        assert placed[name] == pytest.approx(xy, abs=1e-9), name
    loops = cli("new", kind, "--form", "loops")
    assert loops.code == 0, loops.err
    _, r2 = solved(loops.out)
    assert list(r2.x) == pytest.approx(list(r.x), abs=1e-9)
    sample = load(sample_path(k.sample))
    assert shown_value(sample.driver) == pytest.approx(k.angle_deg, abs=1e-12)
    lengths = sorted(abs(q.value) for q in sample.parameters.values() if q.kind == "length")
    assert lengths == sorted(abs(v) for v in k.defaults)


def test_the_defaults_are_the_samples_and_the_file_says_how_it_was_made(cli, tmp_path) -> None:
    text = made(cli, tmp_path, "fourbar")
    doc = parse_toml(text, "<new>")
    assert doc["driver"] == {"link": "crank", "value": 30.0}
    xy = doc["joints"]
    lengths = [math.dist(xy["O2"], xy["A"]), math.dist(xy["A"], xy["B"]), math.dist(xy["O4"], xy["B"]),
               math.dist(xy["O2"], xy["O4"])]
    assert lengths == pytest.approx([40, 120, 80, 100], rel=1e-14)  # crank_rocker.toml's
    assert "# Four-bar, drawn by: linkage new fourbar --links 40 120 80 100 --angle 30 --branch open" in text
    assert "# --links order for fourbar: crank (O2A), coupler (AB), rocker (O4B), ground (O2O4)" in text
    # the six-bars' second dyads: each length where the file's joints put it
    text = made(cli, tmp_path, "watt", "--links", *"41 121 81 101 71 111 79 119".split())
    xy = parse_toml(text, "<new>")["joints"]
    assert [math.dist(xy[p], xy[q]) for p, q in (("O2", "A"), ("A", "B"), ("O4", "B"), ("O2", "O4"),
                                                  ("O4", "C"), ("C", "D"), ("O6", "D"), ("O4", "O6"))] == \
        pytest.approx([41, 121, 81, 101, 71, 111, 79, 119], rel=1e-13)
    xy = parse_toml(made(cli, tmp_path, "stephenson", *KINDS["stephenson"]), "<new>")["joints"]
    assert [math.dist(xy[p], xy[q]) for p, q in (("A", "C"), ("C", "D"), ("O6", "D"), ("O2", "O6"))] == \
        pytest.approx([60, 140, 110, 160], rel=1e-13)


def test_unit_name_and_standard_output(cli, tmp_path) -> None:
    r = cli("new", "fourbar", "--unit", "in", "--name", 'My "first" \\ four-bar')
    assert r.code == 0 and r.err == ""
    m = from_text(r.out, "<new>")
    assert m.name == 'My "first" \\ four-bar' and m.length_unit == "in"
    assert cli("new", "fourbar", "-o", "-").out == cli("new", "fourbar").out


def test_an_existing_file_is_kept_unless_forced(cli, tmp_path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text("keep me")
    r = cli("new", "fourbar", "-o", str(path))
    assert r.code == 2 and "exists" in r.err and "--force" in r.err
    assert path.read_text() == "keep me"
    assert cli("new", "fourbar", "-o", str(path), "--force").code == 0
    assert from_text(path.read_text(), "<new>").name == "Four-bar"


@pytest.mark.parametrize(("args", "message"), [
    (["fivebar"], "KIND: 'fivebar' is not a kind linkage new draws (kinds: fourbar, slider-crank, "
                  "inverted-slider, watt, stephenson)"),
    (["fourbar", "--links", "40", "120", "80"], "--links: fourbar takes 4 lengths (crank coupler rocker "
                                                 "ground), got 3"),
    (["watt", "--links", "40"], "--links: watt takes 8 lengths"),
    (["fourbar", "--links", "40", "0", "80", "100"], "--links: coupler must be a positive length, got 0"),
    (["fourbar", "--links", "40", "120", "-80", "100"], "--links: rocker must be a positive length, got -80"),
    (["fourbar", "--links", "nan", "120", "80", "100"], "--links nan must be a finite number"),
    (["fourbar", "--links"], "--links: give the lengths after it (fourbar: crank coupler rocker ground)"),
    (["fourbar", "40", "120", "80", "100"], "give the lengths after --links"),
    (["fourbar", "--links", "40", "20", "20", "100"],
     "--links 40 20 20 100: the fourbar cannot be assembled at 30 deg (open): coupler + rocker = 40 < "
     "68.3505433, the distance from A to the rocker's pivot O4"),
    (["fourbar", "--links", "40", "120", "20", "100", "--branch", "crossed"],
     "|coupler - rocker| = 100 > 68.3505433, the distance from A to the rocker's pivot O4"),
    (["slider-crank", "--links", "40", "20", "-30", "--angle", "90"],
     "the slider-crank cannot be assembled at 90 deg (open): coupler = 20 < 70, the distance from A to "
     "the slider's line y = -30"),
    (["inverted-slider", "--links", "40", "100", "70", "--angle", "0"],
     "the offset |70| > 60, the distance from A to O4"),
    (["inverted-slider", "--links", "100", "100", "0", "--angle", "0"], "A is drawn on O4"),
    (["stephenson", "--branch", "crossed"],
     "(crossed): link5 + link6 = 190 < 212.470527, the distance from C to link6's pivot O6"),
    (["watt", "--branch", "open/crossed/open"], "--branch: 'open/crossed/open': give open or crossed, or "
                                                "one word per dyad"),
    (["fourbar", "--branch", "open/open"], "--branch: 'open/open': give open or crossed"),
    (["fourbar", "--angle", "nan"], "--angle: must be a finite number of degrees"),
    (["fourbar", "--unit", "px"], "--unit: 'px' is not a length unit (units: mm, cm, m, in, ft)"),
    (["fourbar", "--name", "two\nlines"], "--name: must be one line of printable text"),
    (["fourbar", "--form", "loop"], "--form: 'loop': give joints or loops"),
    (["fourbar", "--angel", "30"], "no such option: --angel"),
    (["--links", "40", "120", "80", "100", "fourbar"], "give KIND first: linkage new fourbar --links"),
    ([], "Missing argument 'KIND'"),
])
def test_what_cannot_be_drawn_is_refused_in_one_line(cli, tmp_path, args: list[str], message: str) -> None:
    out = tmp_path / "out.toml"
    r = cli("new", *args, "-o", str(out))
    assert r.code == 2
    assert r.err.startswith("error: ") and r.err.count("\n") == 1 and "Traceback" not in r.err
    assert message in r.err
    assert r.out == ""
    assert list(tmp_path.iterdir()) == []


def test_a_file_that_is_not_toml_is_refused(cli, tmp_path) -> None:
    r = cli("new", "fourbar", "-o", str(tmp_path / "x.txt"))
    assert r.code == 2 and "name it with .toml" in r.err and r.err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_the_library_names_its_arguments() -> None:
    from linkage.errors import InputError
    from linkage.problems.templates import template

    doc = template("slider-crank", [40, 120, -5], 90.0, "crossed", "cm", "s")
    assert doc["sliders"] == {"block": {"on": "ground", "angle": 0.0}} and doc["length_unit"] == "cm"
    with pytest.raises(InputError, match=r"^links: offset = 1e\+200"):
        template("slider-crank", [40, 120, 1e200])
    with pytest.raises(InputError, match=r"^angle_deg: "):
        template("fourbar", angle_deg=math.inf)
