"""`linkage convert --form joints`: a loops file drawn as joints and links (issue 21,
"converting back reproduces the joints"). Joints -> loops -> joints gives back the drawing;
loops -> joints places every joint as the loops do at the driver value and elsewhere; a
file that cannot be drawn says why in one line."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import tomllib

from linkage import solve_system
from linkage.errors import InputError
from linkage.kinematics.loading import from_text, load
from linkage.kinematics.rates import rates_at
from linkage.kinematics.to_joints import joints_doc
from linkage.problems.toml_text import loops_text

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
DRAWINGS = sorted(SAMPLES.glob("*_joints.toml"))
LOOPS = sorted(p for p in SAMPLES.glob("*.toml") if not p.name.endswith("_joints.toml")
               and p.name != "offset_slider.toml")


def _line_deg(doc: dict, name: str) -> float:
    spec = doc["sliders"][name]
    if "angle" in spec:
        return spec["angle"]
    (x0, y0), (x1, y1) = (doc["joints"][j] for j in spec["line"])
    return math.degrees(math.atan2(y1 - y0, x1 - x0))


@pytest.mark.parametrize("path", DRAWINGS, ids=lambda p: p.stem)
def test_joints_to_loops_to_joints_gives_the_drawing_back(path: Path) -> None:
    drawn = tomllib.loads(path.read_text())
    back = joints_doc(from_text(loops_text(drawn, str(path)), "<loops>"))
    assert back["ground"] == drawn["ground"]
    assert back["links"] == drawn["links"]
    assert set(back["joints"]) == set(drawn["joints"])
    for name, xy in drawn["joints"].items():
        assert back["joints"][name] == pytest.approx(xy, abs=1e-9), name
    assert set(back.get("sliders", {})) == set(drawn.get("sliders", {}))
    for name, spec in drawn.get("sliders", {}).items():
        assert back["sliders"][name]["on"] == spec["on"]
        gap = math.remainder(back["sliders"][name]["angle"] - _line_deg(drawn, name), 180.0)
        assert gap == pytest.approx(0.0, abs=1e-9)
    assert back["driver"] == pytest.approx(drawn["driver"]) if "value" in drawn["driver"] else True


def _placed(m, values: dict | None = None, guesses: dict | None = None) -> dict:
    m = m.with_values(values or {}, guesses or {})
    r = solve_system(m.problem(), tol=1e-13)
    assert r.converged, r.status
    return rates_at(m, r.x).joints


@pytest.mark.parametrize("path", LOOPS, ids=lambda p: p.stem)
def test_loops_to_joints_places_every_joint_as_the_loops_do(path: Path) -> None:
    """Joints compared by name, not unknowns (the drawing names its links anew): at the
    file's driver value and at others, both solved from the drawn pose."""
    original = load(path)
    drawing = from_text(_convert_text(original), "<drawn>")
    first = solve_system(original.problem(), tol=1e-13)
    pose = {u.name: (math.degrees(x) if u.kind == "angle" else x) for u, x in zip(original.unknowns, first.x)}
    base = (math.degrees(original.driver.value) if original.driver.kind == "angle"
            else original.driver.value)
    size = max(math.hypot(*xy) for xy in _placed(original).values())
    assert drawing.driver.kind == original.driver.kind
    for step in (0.0, 4.0, -7.0, 15.0):
        want = _placed(original, {original.driver.name: base + step}, pose)
        drawn_base = math.degrees(drawing.driver.value)
        got = _placed(drawing, {drawing.driver.name: drawn_base + step})
        shared = set(want) & set(got)
        assert {j for j in want if j} <= shared | {""}
        for name in shared:
            assert got[name] == pytest.approx(want[name], abs=1e-10 * size), (step, name)


def _convert_text(m) -> str:
    from linkage.kinematics.to_joints import joints_text

    return joints_text(m, m.source)


def test_the_rapier_is_drawn_with_its_rapier_a_slider_carrying_its_pin_and_tip() -> None:
    doc = joints_doc(load(SAMPLES / "rapier_drive.toml"))
    assert doc["sliders"] == {"block_s16": {"on": "ground", "angle": 0.0}}
    assert doc["links"]["block_s16"] == ["E", "D"]
    assert doc["ground"] == ["A0", "C0"]
    assert doc["links"]["link14"][:2] == ["C", "B"]  # theta14 runs C -> B: a4 with sign -1


def test_the_names_of_the_loops_stay_beside_the_links(cli) -> None:
    r = cli("convert", str(SAMPLES / "fourbar_me581.toml"))
    assert r.code == 0, r.err
    assert 'link2 = ["O2", "A"]  # theta2: r2' in r.out
    assert 'link = "link2"\nvalue = 65.0' in r.out
    from_text(r.out, "<printed>")


@pytest.mark.parametrize(("args", "message"), [
    (["offset_slider.toml"], "loops[0] (crank) names no joints: give joints = [...]"),
    (["fourbar_me581.toml", "--form", "loops"], "is already in the loops form: --form joints converts it"),
    (["fourbar_me581_joints.toml", "--form", "joints"], "is already in the joints form: --form loops"),
    (["fourbar_me581.toml", "--form", "sketch"], "--form 'sketch': write joints or loops"),
    (["fourbar_me581.toml", "-o", "out.txt"], "name it with .toml"),
])
def test_what_cannot_be_converted_says_why_in_one_line(cli, args: list[str], message: str) -> None:
    r = cli("convert", str(SAMPLES / args[0]), *args[1:])
    assert r.code == 2
    assert r.err.count("\n") == 1 and r.err.startswith("error: ") and message in r.err, r.err


def test_a_loop_with_an_unnamed_joint_between_two_links_is_refused() -> None:
    text = (SAMPLES / "fourbar_me581.toml").read_text().replace(
        'joints = ["O2", "A", "B", "O4"]', 'joints = ["O2", "A", "", "O4"]')
    with pytest.raises(InputError, match=r"the point after vector 1 joins two links: name it"):
        joints_doc(from_text(text, "<unnamed>"))


def test_a_file_whose_guesses_do_not_solve_is_refused() -> None:
    m = load(SAMPLES / "fourbar_me581.toml").with_values({"theta2": 180.0}, {})
    with pytest.raises(InputError, match=r"its loops do not solve at theta2 = 180 deg"):
        joints_doc(m)


def test_the_written_file_is_a_new_file_and_the_input_is_kept(cli, tmp_path) -> None:
    src = tmp_path / "w.toml"
    src.write_text((SAMPLES / "watt_sixbar.toml").read_text())
    out = tmp_path / "w_joints.toml"
    r = cli("convert", str(src), "-o", str(out))
    assert r.code == 0, r.err
    assert src.read_text() == (SAMPLES / "watt_sixbar.toml").read_text()
    again = cli("convert", str(out))  # and back to loops: the Watt's two loops
    assert again.code == 0 and again.out.count("[[loops]]") == 2
    same = cli("convert", str(src), "-o", str(src))
    assert same.code == 2 and same.err.startswith("error: ")
