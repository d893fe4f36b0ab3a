"""CAD export (docs/plots.md, "CAD export"): ``linkage draw FILE -o pose.dxf`` / ``-o pose.svg``
hold the links, joints and coupler curves in the file's units at the solved coordinates.

Geometry is read back (ezdxf for a DXF, xml.etree for an SVG) and compared with the solver's
joints and, independently, with the four-bar's closed form (two circles meet: A = r2 e^(i
theta2), B on the circles about A and O4, P 60 mm from A at theta3 + 30 deg; worked out here,
not by the package). The hostile cases follow the crashes reported against Pyslvs' DXF
export (its issue 52): a slider, a six-bar, a point on a joint, micrometre and kilometre
scales, a driver range that cannot all be assembled.
"""

from __future__ import annotations

import cmath
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import linkage
from conftest import run_process
from linkage.kinematics.rates import rates_at
from linkage.solve import solve_system

ezdxf = pytest.importorskip("ezdxf")

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
SVG = "{http://www.w3.org/2000/svg}"


def solved_joints(path: Path, *sets: str) -> dict[str, tuple[float, float]]:
    """The joints and points as ``draw`` solves them (its tolerance, 1e-12)."""
    m = linkage.load_mechanism(str(path)).with_values(
        {k: float(v) for k, v in (s.split("=") for s in sets)}, {})
    r = solve_system(m.problem(), tol=1e-12, record=False)
    assert r.converged
    return {k: tuple(v) for k, v in rates_at(m, list(r.x)).joints.items()}


def crank_rocker(theta2_deg: float, r2: float = 40.0, branch: int = 1, scale: float = 1.0
                 ) -> dict[str, complex] | None:
    """crank_rocker.toml's joints in closed form (r1 = 100, r3 = 120, r4 = 80 times
    ``scale``); branch +1 open (sin(theta4 - theta3) > 0), -1 crossed; None where the
    circles do not meet."""
    r1, r2, r3, r4 = 100 * scale, r2 * scale, 120 * scale, 80 * scale
    a = r2 * cmath.exp(1j * math.radians(theta2_deg))
    o4 = complex(r1, 0)
    d = abs(o4 - a)
    along = (d * d + r3 * r3 - r4 * r4) / (2 * d)
    h2 = r3 * r3 - along * along
    if h2 < 0:
        return None
    u = (o4 - a) / d
    for side in (1, -1):
        b = a + u * (along + 1j * side * math.sqrt(h2))
        t3, t4 = cmath.phase(b - a), cmath.phase(b - o4)
        if (math.sin(t4 - t3) > 0) == (branch > 0):
            p = a + 60 * scale * cmath.exp(1j * (t3 + math.radians(30)))
            return {"O2": 0j, "A": a, "B": b, "O4": o4, "P": p}
    raise AssertionError("no branch matched")


def draw(cli, tmp_path: Path, source: Path, suffix: str, *args: str) -> Path:
    out = tmp_path / f"pose{suffix}"
    run = cli("draw", str(source), "-o", str(out), *args)
    assert run.code == 0, run.err
    return out


def dxf_marks(doc) -> dict[str, tuple[float, float]]:
    """Each label's text -> the centre of the circle it labels (the circle nearest it)."""
    msp = doc.modelspace()
    circles = [c.dxf.center for c in msp.query("CIRCLE")]
    out = {}
    for t in msp.query("TEXT"):
        at = t.dxf.insert
        c = min(circles, key=lambda c: math.dist((c.x, c.y), (at.x, at.y)))
        out[t.dxf.text] = (c.x, c.y)
    return out


def svg_marks(root) -> dict[str, tuple[float, float]]:
    return {c.get("data-name"): (float(c.get("cx")), float(c.get("cy")))
            for c in root.iter(f"{SVG}circle") if c.get("data-name")}


def svg_points(element) -> list[tuple[float, float]]:
    return [tuple(map(float, pair.split(","))) for pair in element.get("points").split()]


def dxf_paths(doc) -> list[list[tuple[float, float]]]:
    return [[(x, y) for x, y in e.get_points("xy")]
            for e in doc.modelspace().query("LWPOLYLINE[layer=='PATHS']")]


def near(a: tuple[float, float], b: tuple[float, float] | complex, tol: float) -> bool:
    b = (b.real, b.imag) if isinstance(b, complex) else b
    return abs(a[0] - b[0]) <= tol and abs(a[1] - b[1]) <= tol


# --- DXF -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["crank_rocker_joints", "crank_rocker", "slider_crank_joints",
                                  "rapier_drive", "stephenson_sixbar_joints", "watt_sixbar",
                                  "inverted_slider_joints"])
def test_dxf_passes_ezdxf_audit_and_holds_the_solved_joints(cli, tmp_path, name):
    out = draw(cli, tmp_path, SAMPLES / f"{name}.toml", ".dxf")
    doc = ezdxf.readfile(out)
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    assert doc.header["$INSUNITS"] == 4  # mm
    marks = dxf_marks(doc)
    joints = solved_joints(SAMPLES / f"{name}.toml")
    assert set(marks) == set(joints)
    for j, xy in joints.items():
        assert near(marks[j], xy, 1e-9), (j, marks[j], xy)


def test_dxf_has_a_layer_per_body_and_the_joints_paths_and_ground_pivots(cli, tmp_path):
    doc = ezdxf.readfile(draw(cli, tmp_path, SAMPLES / "crank_rocker_joints.toml", ".dxf"))
    layers = {layer.dxf.name for layer in doc.layers}
    assert {"GROUND", "LINK_crank", "LINK_coupler", "LINK_rocker", "JOINTS", "PATHS"} <= layers
    msp = doc.modelspace()
    joints = solved_joints(SAMPLES / "crank_rocker_joints.toml")
    outline = {e.dxf.layer: [tuple(p) for p in e.get_points("xy")] for e in msp.query("LWPOLYLINE")
               if e.dxf.layer.startswith("LINK_")}
    assert outline["LINK_crank"] == [joints["O2"], joints["A"]]
    assert outline["LINK_rocker"] == [joints["O4"], joints["B"]]
    coupler = msp.query("LWPOLYLINE[layer=='LINK_coupler']").first
    assert coupler.closed and [tuple(p) for p in coupler.get_points("xy")] == [joints[k] for k in "ABP"]
    # each ground pivot marked by a triangle whose apex is under it
    pivots = [list(e.get_points("xy")) for e in msp.query("LWPOLYLINE[layer=='GROUND']") if e.closed]
    assert len(pivots) == 2 and sorted(p[0][0] for p in pivots) == [0.0, 100.0]
    assert {t.dxf.text for t in msp.query("TEXT[layer=='JOINTS']")} == {"O2", "A", "B", "O4"}
    assert {t.dxf.text for t in msp.query("TEXT[layer=='PATHS']")} == {"P"}


def test_dxf_coupler_curve_is_the_closed_form_path_of_p(cli, tmp_path):
    doc = ezdxf.readfile(draw(cli, tmp_path, SAMPLES / "crank_rocker.toml", ".dxf"))
    (path,) = dxf_paths(doc)
    assert len(path) == 361  # 0 to 360 deg in 360 steps
    for k, xy in enumerate(path):
        assert near(xy, crank_rocker(k)["P"], 1e-9), k


@pytest.mark.parametrize("unit,code", [("mm", 4), ("cm", 5), ("m", 6), ("in", 1), ("ft", 2)])
def test_dxf_insunits_is_the_files_length_unit(cli, tmp_path, unit, code):
    text = (SAMPLES / "crank_rocker_joints.toml").read_text().replace('length_unit = "mm"',
                                                                      f'length_unit = "{unit}"')
    source = tmp_path / "m.toml"
    source.write_text(text)
    doc = ezdxf.readfile(draw(cli, tmp_path, source, ".dxf"))
    assert doc.header["$INSUNITS"] == code
    assert doc.header["$MEASUREMENT"] == (0 if unit in ("in", "ft") else 1)


# --- assembly gaps ----------------------------------------------------------------------------------


GAP = ("--set", "r2=70", "--from", "-180", "--to", "180")
"""crank_rocker.toml with a 70 mm crank: a triple rocker, which cannot be assembled for
theta2 within 18.19 deg of 0 (s + l = 190 > p + q = 180)."""


def check_gap_pieces(pieces: list[list[tuple[float, float]]]) -> None:
    """Two pieces, -180 to -19 and 19 to 180 deg: the vertices the closed-form P at
    consecutive grid angles on one assembly, none inside the gap (nothing drawn across it)."""
    assert len(pieces) == 2
    runs = []
    for piece in pieces:
        def at(k: int, b: int, xy: tuple[float, float]) -> bool:
            j = crank_rocker(k, r2=70, branch=b)
            return j is not None and near(xy, j["P"], 1e-9)

        # the first vertex's angle and assembly: those from which the second continues
        (k0, b0), = [(k, b) for k in range(-180, 182 - len(piece)) for b in (1, -1)
                     if at(k, b, piece[0]) and at(k + 1, b, piece[1])]
        assert all(at(k0 + i, b0, xy) for i, xy in enumerate(piece))
        runs.append((k0, k0 + len(piece) - 1))
    assert sorted(runs) == [(-180, -19), (19, 180)]


def test_a_coupler_curve_breaks_where_the_linkage_cannot_be_assembled_dxf(cli, tmp_path):
    doc = ezdxf.readfile(draw(cli, tmp_path, SAMPLES / "crank_rocker.toml", ".dxf", *GAP))
    pieces = dxf_paths(doc)
    check_gap_pieces(pieces)


def test_a_coupler_curve_breaks_where_the_linkage_cannot_be_assembled_svg(cli, tmp_path):
    root = ET.parse(draw(cli, tmp_path, SAMPLES / "crank_rocker.toml", ".svg", *GAP)).getroot()
    check_gap_pieces([svg_points(e) for e in root.iter(f"{SVG}polyline") if e.get("class") == "path"])


# --- SVG --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("unit,width_unit,per", [("mm", "mm", 1), ("cm", "cm", 1), ("in", "in", 1),
                                                 ("m", "mm", 1000), ("ft", "in", 12)])
def test_svg_user_unit_is_the_files_unit_with_width_in_a_real_unit(cli, tmp_path, unit, width_unit, per):
    text = (SAMPLES / "crank_rocker_joints.toml").read_text().replace('length_unit = "mm"',
                                                                      f'length_unit = "{unit}"')
    source = tmp_path / "m.toml"
    source.write_text(text)
    out = draw(cli, tmp_path, source, ".svg")
    root = ET.parse(out).getroot()
    _, _, vw, vh = map(float, root.get("viewBox").split())
    for key, v in (("width", vw), ("height", vh)):
        number, suffix = re.fullmatch(r"([0-9.e+-]+)([a-z]+)", root.get(key)).groups()
        assert suffix == width_unit and math.isclose(float(number), v * per, rel_tol=1e-15)
    desc = root.find(f"{SVG}desc").text
    assert f"one user unit is 1 {unit}" in desc
    if per != 1:
        assert f"SVG has no {unit}" in desc and f"SVG has no {unit}" in out.read_text().split("<svg")[0]
    # geometry in the file's own numbers: a length unit changes no coordinate
    assert svg_marks(root)["B"] == pytest.approx((145.57934415070798, 65.74590015195868), abs=1e-9)


@pytest.mark.parametrize("name", ["crank_rocker_joints", "slider_crank_joints", "stephenson_sixbar_joints",
                                  "rapier_drive_joints"])
def test_svg_holds_the_solved_joints(cli, tmp_path, name):
    root = ET.parse(draw(cli, tmp_path, SAMPLES / f"{name}.toml", ".svg")).getroot()
    joints = solved_joints(SAMPLES / f"{name}.toml")
    marks = svg_marks(root)
    assert set(marks) == set(joints)
    for j, xy in joints.items():
        assert near(marks[j], xy, 1e-9)
    labels = {t.text for t in root.iter(f"{SVG}text")}
    assert labels == set(joints)
    # the shapes are drawn with y up (SVG's y points down): one flip, on the geometry group
    assert root.find(f"{SVG}g[@id='geometry']").get("transform") == "scale(1,-1)"


def test_svg_coupler_curve_is_the_closed_form_path_of_p(cli, tmp_path):
    root = ET.parse(draw(cli, tmp_path, SAMPLES / "crank_rocker.toml", ".svg", "--step", "10")).getroot()
    (path,) = [svg_points(e) for e in root.iter(f"{SVG}polyline") if e.get("class") == "path"]
    assert len(path) == 37
    for k, xy in enumerate(path):
        assert near(xy, crank_rocker(10 * k)["P"], 1e-9)


# --- hostile cases ----------------------------------------------------------------------------------


def test_a_slider_is_drawn_as_its_block_on_its_line(cli, tmp_path):
    source = SAMPLES / "slider_crank_joints.toml"
    doc = ezdxf.readfile(draw(cli, tmp_path, source, ".dxf"))
    assert not doc.audit().has_errors
    b = solved_joints(source)["B"]
    (line,) = doc.modelspace().query("LINE[layer=='GROUND']")
    start, end = line.dxf.start, line.dxf.end
    assert start.y == end.y == 10.0  # the line y = 10 mm the block slides on, through B
    # the block's travel over a turn (79.6 to 159.6 mm: B's x) lies on the drawn line
    assert start.x < 79.6 and end.x > 159.6
    (block,) = doc.modelspace().query("LWPOLYLINE[layer=='LINK_block']")
    corners = list(block.get_points("xy"))
    assert block.closed and len(corners) == 4
    centre = (sum(x for x, _ in corners) / 4, sum(y for _, y in corners) / 4)
    assert near(centre, b, 1e-9)


def test_a_point_exactly_at_a_joint(cli, tmp_path):
    text = (SAMPLES / "crank_rocker_joints.toml").read_text()
    text = re.sub(r"^P = \[[^\]]*\]", "P = [145.57934415070798, 65.74590015195868]", text, flags=re.M)
    source = tmp_path / "at_joint.toml"
    source.write_text(text)
    for suffix in (".dxf", ".svg"):
        out = draw(cli, tmp_path, source, suffix)
    doc = ezdxf.readfile(tmp_path / "pose.dxf")
    assert not doc.audit().has_errors
    marks = dxf_marks(doc)
    assert near(marks["P"], marks["B"], 1e-9)
    (path,) = dxf_paths(doc)  # P's path is B's: an arc of the rocker's circle about O4
    assert all(math.isclose(math.dist(xy, (100, 0)), 80, abs_tol=1e-9) for xy in path)
    assert svg_marks(ET.parse(out).getroot())["P"] == pytest.approx(marks["B"], abs=1e-9)


@pytest.mark.parametrize("unit,scale", [("mm", 1e-3), ("m", 10.0)])
def test_micrometre_and_kilometre_scales(cli, tmp_path, unit, scale):
    """crank_rocker.toml at 40 um to 120 um (in mm) and at 400 m to 1.2 km (in m)."""
    text = (SAMPLES / "crank_rocker.toml").read_text()
    text = text.replace('length_unit = "mm"', f'length_unit = "{unit}"')
    text = re.sub(r'value = (\d+), unit = "mm"',
                  lambda m: f'value = {float(m[1]) * scale!r}, unit = "{unit}"', text)
    text = text.replace("length = 60,", f"length = {60 * scale!r},")
    source = tmp_path / "scaled.toml"
    source.write_text(text)
    doc = ezdxf.readfile(draw(cli, tmp_path, source, ".dxf", "--step", "5"))
    assert not doc.audit().has_errors
    tol = 1e-12 * 100 * scale  # the closed form and Newton agree to rounding of the size
    for j, xy in dxf_marks(doc).items():
        assert near(xy, crank_rocker(30, scale=scale)[j], tol), j
    (path,) = dxf_paths(doc)
    for k, xy in enumerate(path):
        assert near(xy, crank_rocker(5 * k, scale=scale)["P"], tol)
    root = ET.parse(draw(cli, tmp_path, source, ".svg", "--step", "5")).getroot()
    for j, xy in svg_marks(root).items():
        assert near(xy, crank_rocker(30, scale=scale)[j], tol)
    # symbols scale with the mechanism: a joint's circle is 1.2 % of the sheet
    r = float(next(root.iter(f"{SVG}circle")).get("r"))
    assert 1e-3 * 120 * scale < r < 0.05 * 220 * scale


def test_a_loops_file_without_joint_names_is_drawn_vector_by_vector(cli, tmp_path):
    doc = ezdxf.readfile(draw(cli, tmp_path, SAMPLES / "offset_slider.toml", ".dxf"))
    assert not doc.audit().has_errors
    assert len(doc.modelspace().query("LWPOLYLINE")) >= 6


# --- refusals, atomic writes and lazy imports ------------------------------------------------------


def test_an_unknown_suffix_is_refused_by_the_picture_rule(cli, tmp_path):
    run = cli("draw", str(SAMPLES / "crank_rocker.toml"), "-o", str(tmp_path / "pose.dwg"))
    assert run.code == 2 and "use one of .png, .svg, .pdf, .dxf" in run.err
    assert not (tmp_path / "pose.dwg").exists()


def test_a_missing_ezdxf_is_one_line_naming_the_cad_extra(cli, tmp_path, monkeypatch):
    import sys

    out = tmp_path / "pose.dxf"
    out.write_text("the old drawing")
    monkeypatch.setitem(sys.modules, "ezdxf", None)  # find_spec then reports it missing
    run = cli("draw", str(SAMPLES / "crank_rocker.toml"), "-o", str(out))
    assert run.code == 2
    assert run.err.strip() == "error: a .dxf needs ezdxf: pip install 'linkage-kinematics[cad]'"
    assert out.read_text() == "the old drawing"


@pytest.mark.parametrize("suffix", [".svg", ".dxf"])
def test_a_failed_write_leaves_the_old_file(cli, tmp_path, monkeypatch, suffix):
    import linkage.files

    out = tmp_path / f"pose{suffix}"
    out.write_text("the old drawing")

    def full_disk(_path):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(linkage.files, "_sync", full_disk)  # the atomic writer's last step fails
    run = cli("draw", str(SAMPLES / "crank_rocker.toml"), "-o", str(out))
    assert run.code != 0 and "No space left on device" in run.err
    assert out.read_text() == "the old drawing"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary file left


def test_ezdxf_is_imported_only_for_a_dxf(tmp_path):
    probe = ("import sys\nfrom linkage.cli import run_cli\n"
             f"run_cli(['draw', {str(SAMPLES / 'crank_rocker.toml')!r}, '-o', {str(tmp_path / 'p.svg')!r}])\n"
             "print('ezdxf' in sys.modules, 'matplotlib' in sys.modules)")
    done = run_process(code=probe)
    assert done.stdout.split() == ["False", "False"], done.stderr


def test_names_a_layer_cannot_hold_or_that_differ_by_case_give_distinct_valid_layers(cli, tmp_path):
    text = (SAMPLES / "crank_rocker_joints.toml").read_text()
    text = text.replace('crank = ["O2", "A"]', '"Crank/1" = ["O2", "A"]')
    text = text.replace('link = "crank"', 'link = "Crank/1"')
    text = text.replace('coupler = ["A", "B", "P"]', '"crank:1" = ["A", "B", "P"]')
    text = text.replace("P = [", '"<P&1>" = [').replace('"B", "P"]', '"B", "<P&1>"]')
    source = tmp_path / "names.toml"
    source.write_text(text)
    doc = ezdxf.readfile(draw(cli, tmp_path, source, ".dxf"))
    assert not doc.audit().has_errors
    layers = {layer.dxf.name for layer in doc.layers}
    assert {"LINK_Crank_1", "LINK_crank_1-2"} <= layers
    assert "<P&1>" in {t.dxf.text for t in doc.modelspace().query("TEXT")}
    root = ET.parse(draw(cli, tmp_path, source, ".svg")).getroot()
    assert "<P&1>" in {t.text for t in root.iter(f"{SVG}text")}


def test_a_slider_driven_file_without_a_range_is_drawn_at_its_pose(cli, tmp_path):
    """A length driver has no natural range: with no points to trace, the sheet is the pose,
    the slider's line reaching past its block."""
    text = (SAMPLES / "slider_crank_joints.toml").read_text()
    driver = '[driver]\nslider = "block"\nvalue = 146.88311367414514\n'
    text = re.sub(r"\[driver\].*", driver, text, flags=re.S)
    source = tmp_path / "slider_driven.toml"
    source.write_text(text)
    doc = ezdxf.readfile(draw(cli, tmp_path, source, ".dxf"))
    assert not doc.audit().has_errors
    assert dxf_paths(doc) == []
    (line,) = doc.modelspace().query("LINE[layer=='GROUND']")
    assert line.dxf.start.x < 146.88311367414514 < line.dxf.end.x and line.dxf.start.y == 10.0
    assert {t.dxf.text for t in doc.modelspace().query("TEXT")} == {"O2", "A", "B"}
