"""Units for people (issue 21, its units part): a bare number in a mechanism file means the
file's unit for its use (length_unit for a vector's length, degrees for an angle); lengths
in mm, cm, m, in or ft are converted on read; a unit that cannot be read names the key and
lists the units accepted."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from linkage import load_mechanism, solve_system
from linkage.errors import InputError
from linkage.kinematics.loading import from_text
from linkage.problems.loops import length_factor

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"

LOOP = """
[[loops]]
name = "O2-A-B-O4"
joints = ["O2", "A", "B", "O4"]
vectors = [
  { length = "r2", angle = "theta2" },
  { length = "r3", angle = "theta3" },
  { length = "r4", angle = "theta4", sign = -1 },
  { length = "r1", angle = "theta1", sign = -1 },
]
"""


def fourbar(params: str, driver: str = "name = \"theta2\"\nvalue = 30", unit: str = "mm",
            unknowns: str = "theta3 = 20\ntheta4 = 50") -> str:
    return (f'name = "bare"\nlength_unit = "{unit}"\n[parameters]\n{params}\n[driver]\n{driver}\n'
            f"[unknowns]\n{unknowns}\n{LOOP}")


def solution(text: str, theta2: float) -> list[float]:
    m = from_text(text, "<test>").with_values({"theta2": theta2}, {})
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    return [math.degrees(v) for v in r.x]


def law_of_cosines(r1: float, r2: float, r3: float, r4: float, theta2_deg: float) -> tuple[float, float]:
    """The open assembly of the crank-rocker, derived here: A = r2 e^(i theta2), B on the
    circles |B - A| = r3 and |B - O4| = r4, O4 = (r1, 0), B above the line A-O4."""
    t = math.radians(theta2_deg)
    ax, ay = r2 * math.cos(t), r2 * math.sin(t)
    dx, dy = r1 - ax, -ay
    d = math.hypot(dx, dy)
    a = (r3 * r3 - r4 * r4 + d * d) / (2 * d)
    h = math.sqrt(r3 * r3 - a * a)
    bx, by = ax + a * dx / d - h * dy / d, ay + a * dy / d + h * dx / d
    return math.degrees(math.atan2(by - ay, bx - ax)), math.degrees(math.atan2(by, bx - r1))


@pytest.mark.parametrize("theta2", [0.0, 30.0, 97.5, 200.0, 333.0])
def test_bare_numbers_solve_as_the_sample_with_units(theta2: float) -> None:
    bare = fourbar("r1 = 100\nr2 = 40\nr3 = 120\nr4 = 80\ntheta1 = 0")
    sample = (SAMPLES / "crank_rocker.toml").read_text()
    got, want = solution(bare, theta2), solution(sample, theta2)
    assert got == pytest.approx(want, abs=1e-12)
    ref = law_of_cosines(100, 40, 120, 80, theta2)
    assert [((g - r + 180) % 360) - 180 for g, r in zip(got, ref)] == pytest.approx([0, 0], abs=1e-9)


def test_lengths_in_other_units_are_converted_on_read() -> None:
    # 0.04 m = 40 mm, 4.724409448818898 in = 120 mm (to the last digit), 8 cm = 80 mm,
    # 0.328083989501312 ft = 100 mm: NIST's 1 in = 0.0254 m and 1 ft = 0.3048 m
    mixed = fourbar('r1 = { value = 0.328083989501312, unit = "ft" }\nr2 = { value = 0.04, unit = "m" }\n'
                    'r3 = { value = 4.724409448818898, unit = "in" }\nr4 = { value = 8, unit = "cm" }\n'
                    "theta1 = 0")
    m = from_text(mixed, "<test>")
    lengths = {k: m.parameters[k].value for k in ("r1", "r2", "r3", "r4")}
    assert lengths == pytest.approx({"r1": 100.0, "r2": 40.0, "r3": 120.0, "r4": 80.0}, rel=1e-15)
    assert {m.parameters[k].unit for k in lengths} == {"mm"}  # stored in the file's unit
    assert solution(mixed, 30.0) == pytest.approx(list(law_of_cosines(100, 40, 120, 80, 30.0)), abs=1e-9)


@pytest.mark.parametrize(("unit", "to", "exact"), [("in", "mm", 25.4), ("ft", "in", 12.0), ("m", "cm", 100.0),
                                                  ("mm", "in", 1 / 25.4), ("cm", "ft", 1 / 30.48)])
def test_length_factors_are_the_definitions(unit: str, to: str, exact: float) -> None:
    assert length_factor(unit, to) == pytest.approx(exact, rel=2e-16)


def test_a_driver_and_unknowns_without_units_take_their_use() -> None:
    text = fourbar("r1 = 100\nr2 = 40\nr3 = 120\nr4 = 80\ntheta1 = 0",
                   unknowns="theta3 = { guess = 20 }\ntheta4 = { guess = 50 }")
    m = from_text(text, "<test>")
    assert m.driver.unit == "deg" and m.driver.value == pytest.approx(math.radians(30))
    assert [u.unit for u in m.unknowns] == ["deg", "deg"]


@pytest.mark.parametrize(("params", "unit", "message"), [
    ("r1 = 100\nr2 = 40\nr3 = 120\nr4 = 80\ntheta1 = 0\nspare = 5", "mm",
     "parameters.spare: spare is in no loop, so its unit cannot be read from its use: give unit = "
     "one of deg, rad, mm, cm, m, in, ft"),
    ('r1 = 100\nr2 = 40\nr3 = 120\nr4 = { value = 8, unit = "furlong" }\ntheta1 = 0', "mm",
     "parameters.r4.unit: unknown unit 'furlong': use one of deg, rad, mm, cm, m, in, ft"),
    ('r1 = 100\nr2 = 40\nr3 = { value = 4.7, unit = "in" }\nr4 = 80\ntheta1 = 0', "units",
     "parameters.r3.unit: unknown unit 'in': use one of deg, rad, units"),
])
def test_an_unreadable_unit_names_the_key_and_the_units_accepted(params: str, unit: str,
                                                                 message: str) -> None:
    with pytest.raises(InputError) as e:
        from_text(fourbar(params, unit=unit), "<test>")
    assert message in str(e.value)


def test_a_name_used_as_a_length_and_an_angle_needs_its_unit() -> None:
    text = fourbar("r1 = 100\nr2 = 40\nr3 = 120\nr4 = 80\ntheta1 = 0").replace(
        '{ length = "r1", angle = "theta1", sign = -1 }', '{ length = "r1", angle = "r1", sign = -1 }')
    with pytest.raises(InputError, match="r1 is used as angle and as length"):
        from_text(text, "<test>")


def test_every_sample_still_loads_as_before() -> None:
    for path in sorted(SAMPLES.glob("*.toml")):
        load_mechanism(path)


# --- one way to give a unit: a number with its unit, on the command line as in the file -----

LOADED = Path(__file__).resolve().parents[1] / "docs" / "crank_rocker_loads.toml"


def _forces(cli, *args: str, path: Path = LOADED) -> dict:
    import json

    r = cli("solve", str(path), "-f", "json", *args)
    assert r.code == 0, r.err
    return json.loads(r.out)["forces"]


def test_command_line_loads_take_a_unit_as_speed_does(cli) -> None:
    """--speed 600rpm took a unit but --torque rocker=-2Nm and --load P=0,-20N refused one:
    now each reads "number+unit" by the one parser (numbers.parse_quantity), the units the
    file's ``unit =`` names, each exactly its definition (1 lbf = 4.4482216152605 N)."""
    file_loads = _forces(cli)  # the file's: rocker -2 N m, P (0, -20) N
    for args in (("--torque", "rocker=-2Nm", "--load", "P=0,-20N"),
                 ("--torque", "rocker=-2 N m", "--load", "P=0N,-20N"),
                 ("--torque", "rocker=-2000Nmm", "--load", "P=0,-20000mN"),
                 ("--torque", "rocker=-0.002kNm", "--load", "P=0kN,-0.02kN"),
                 ("--torque", "rocker=-4/2", "--load", "P=0,-40/2")):  # bare fractions, as before
        assert _forces(cli, *args)["input"] == pytest.approx(file_loads["input"], rel=1e-15), args
    in_lbf = _forces(cli, "--load", "P=0,-1lbf")
    in_newton = _forces(cli, "--load", "P=0,-4.4482216152605")
    assert in_lbf == in_newton
    in_lbf_in = _forces(cli, "--torque", "rocker=1lbf in")
    assert in_lbf_in == _forces(cli, "--torque", f"rocker={4.4482216152605 * 0.0254!r}")


@pytest.mark.parametrize("args, says", [
    (("--torque", "rocker=-2kg"), "--torque rocker '-2kg': give a number, optionally with one of these "
                                  "units: N m, N mm, kN m, lbf in, lbf ft"),
    (("--load", "P=0,-20Nm"), "--load P '-20Nm': give a number, optionally with one of these units: "
                              "N, kN, mN, lbf"),
    (("--load", "P=1N,-2lbf"), "FX in N and FY in lbf: give one unit, after FY"),
    (("--speed", "600 rpms"), "--speed '600 rpms': give a number, optionally with one of these units"),
])
def test_a_unit_a_load_cannot_take_is_one_line_naming_those_it_can(cli, args, says) -> None:
    r = cli("solve", str(LOADED), *args)
    assert r.code == 2 and r.err.count("\n") == 1 and says in r.err, r.err


def test_mass_takes_unit_as_loads_do(cli, tmp_path: Path) -> None:
    """[loads] took ``unit =`` but [mass] needed ``mass_unit``: now ``unit`` there too
    (mass_unit still read, as its older name; both at once refused)."""
    text = LOADED.read_text()
    assert "coupler = { mass = 0.35," in text
    kg = _forces(cli, "--gravity", "9.81")
    for spelled in ('coupler = { mass = 350, unit = "g",', 'coupler = { mass = 350, mass_unit = "g",'):
        path = tmp_path / "g.toml"
        path.write_text(text.replace("coupler = { mass = 0.35,", spelled))
        grams = _forces(cli, "--gravity", "9.81", path=path)
        assert grams["input"] == pytest.approx(kg["input"], rel=1e-14), spelled
    path.write_text(text.replace("coupler = { mass = 0.35,", 'coupler = { mass = 350, unit = "g", '
                                                             'mass_unit = "g",'))
    r = cli("solve", str(path))
    assert r.code == 2 and "give unit (the mass's), not unit and mass_unit" in r.err
    path.write_text(text.replace("coupler = { mass = 0.35,", 'coupler = { mass = 350, unit = "N",'))
    r = cli("solve", str(path))
    assert r.code == 2 and "mass.coupler.unit: 'N' is not one of kg, g, lb" in r.err
