"""Which link a force at a shared joint acts on: the one its ``on`` names, else the first link
listing the joint (problems.loads.load_link); the pin forces depend on it, the input does
not, and every report names it (README, "Loads: input torque and joint forces")."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import linkage
from linkage.errors import InputError
from linkage.kinematics.loading import from_text

ROOT = Path(__file__).resolve().parents[1]
CRANK_ROCKER = ROOT / "docs" / "crank_rocker_loads.toml"
MARGHITU = ROOT / "docs" / "marghitu_slider_crank.toml"
R2 = math.sqrt(2.0)
F = (30.0, -40.0)
"""N, at B (the coupler's and the rocker's joint)."""


def _bare(loads: str = "") -> str:
    """docs/crank_rocker_loads.toml without its loads and masses, ``loads`` in their place."""
    text = CRANK_ROCKER.read_text().split("[loads]")[0]
    return text + ("[loads]\n" + loads if loads else "")


def _at_b(on: str | None):
    m = from_text(_bare(), "cr.toml")
    loads = linkage.Loads(forces={"B": F}, on={} if on is None else {"B": on})
    return m, linkage.forces(m, [u.value for u in m.unknowns], loads)


def _pin(f, joint: str):
    return next(p for p in f.pins if p.joint == joint)


def test_a_load_at_a_shared_joint_goes_to_the_link_its_on_names() -> None:
    """Before, a force at B went to the first link listing B (the coupler) with no say.
    Statics by hand with it on the rocker: the coupler carries no load, so it is a
    two-force member: s along A -> B, s from the rocker's moments about O4, the input
    torque from the crank's about O2."""
    m, on_rocker = _at_b("rocker")
    _, default = _at_b(None)
    _, on_coupler = _at_b("coupler")
    assert on_coupler == default  # the default is the first link listing B: the coupler
    d = m.extra["drawing"]
    k = 1e-3  # mm -> m
    (ax, ay), (bx, by), (ox, oy) = d.xy["A"], d.xy["B"], d.xy["O4"]
    length = math.hypot(bx - ax, by - ay)
    u = ((bx - ax) / length, (by - ay) / length)
    rx, ry = (bx - ox) * k, (by - oy) * k
    s = -(rx * F[1] - ry * F[0]) / (rx * u[1] - ry * u[0])  # the rocker's moments about O4
    pin_b = _pin(on_rocker, "B")
    assert (pin_b.on, pin_b.by) == ("rocker", "coupler")
    assert pin_b.fx == pytest.approx(s * u[0], rel=1e-12)
    assert pin_b.fy == pytest.approx(s * u[1], rel=1e-12)
    torque = ax * k * s * u[1] - ay * k * s * u[0]  # the crank's moments about O2
    assert on_rocker.input == pytest.approx(torque, rel=1e-12)
    # on the coupler: the same input (B moves alike on both links), pin B the force more
    assert on_coupler.input == pytest.approx(on_rocker.input, rel=1e-12)
    b = _pin(on_coupler, "B")
    assert b.fx == pytest.approx(pin_b.fx + F[0], rel=1e-12)
    assert b.fy == pytest.approx(pin_b.fy + F[1], rel=1e-12)
    for joint in ("O2", "A", "O4"):
        assert _pin(on_coupler, joint).fx == pytest.approx(_pin(on_rocker, joint).fx, rel=1e-12)


def test_the_textbook_force_on_the_slider_acts_on_the_slider() -> None:
    """docs/marghitu_slider_crank.toml's 100 N is "on the slider", at C, the rod's joint too:
    it went to the rod. With on = "slider", the slider's x balance by hand: the rod's pin
    force + 100 N + its inertia force -m a (a = -sqrt 2 m/s^2, 1 kg) = 0; the book's F12 at
    B and the input are the same either way."""
    m = linkage.load_mechanism(MARGHITU)
    assert m.extra["loads"].on == {"C": "slider"}
    q = [u.value for u in m.unknowns]
    book = m.extra["loads"].merged(linkage.Loads(gravity=(0.0, -10.0)))
    on_rod = linkage.Loads(book.forces, {}, book.masses, book.gravity)
    f_slider = linkage.forces(m, q, book, speed=1.0)
    f_rod = linkage.forces(m, q, on_rod, speed=1.0)
    c = _pin(f_slider, "C")
    assert (c.on, c.by) == ("slider", "rod")
    assert c.fx == pytest.approx(-100.0 - R2, rel=1e-12)
    assert _pin(f_rod, "C").fx == pytest.approx(-R2, rel=1e-12)
    assert _pin(f_slider, "B").fx == pytest.approx(-(400.0 + 7.0 * R2) / 4.0, rel=1e-12)
    assert _pin(f_rod, "B").fx == pytest.approx(_pin(f_slider, "B").fx, rel=1e-12)
    assert f_rod.input == pytest.approx(f_slider.input, rel=1e-12)


@pytest.mark.parametrize("loads, words", [
    ('B = { force = [0, -20], on = "crank" }', "'crank' does not hold B; a force there acts on one of "
                                               "the links at it: coupler, rocker"),
    ('B = { force = [0, -20], on = 3 }', "loads.B.on: 3 does not hold B"),
    ('rocker = { torque = 2, on = "rocker" }', "a torque acts on the link it is named after"),
])
def test_on_must_name_a_link_at_the_joint(cli, tmp_path, loads, words) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(_bare(loads))
    r = cli("solve", str(path))
    assert r.code == 2 and r.err.count("\n") == 1 and r.err.startswith("error: ")
    assert words in r.err, r.err


def test_python_loads_name_their_link_as_a_file_does() -> None:
    m = from_text(_bare(), "cr.toml")
    q = [u.value for u in m.unknowns]
    with pytest.raises(InputError, match=r"loads.B.on: 'crank' does not hold B"):
        linkage.forces(m, q, linkage.Loads(forces={"B": F}, on={"B": "crank"}))
    with pytest.raises(InputError, match=r"on\['P'\]: there is no force at 'P'"):
        linkage.forces(m, q, linkage.Loads(forces={"B": F}, on={"P": "coupler"}))
    with pytest.raises(InputError, match=r"loads: on must be a dict"):
        linkage.forces(m, q, linkage.Loads(forces={"B": F}, on="rocker"))


def test_the_loads_table_says_which_link_each_load_acts_on(cli, tmp_path) -> None:
    path = tmp_path / "named.toml"
    path.write_text(_bare('B = { force = [0, -20], on = "rocker" }\nP = { force = [0, -5] }\n'
                          'rocker = { torque = -2 }\n'))
    r = cli("solve", str(path), "-f", "plain")
    assert r.code == 0, r.err
    assert "loads applied (ground frame; a shared joint's force on the link named)" in r.out
    rows = {line.split()[0]: line.split() for line in r.out.splitlines()
            if line.split()[1:2] in (["force"], ["torque"])}
    assert rows["B"][:3] == ["B", "force", "rocker"]
    assert rows["P"][:3] == ["P", "force", "coupler"]  # a point: its own link
    assert rows["rocker"][:3] == ["rocker", "torque", "rocker"]
    applied = json.loads(cli("solve", str(path), "-f", "json").out)["forces"]["applied"]
    assert [(a["load"], a["on"]) for a in applied] == [("B", "rocker"), ("P", "coupler"),
                                                        ("rocker", "rocker")]
    # the command line's --load at B changes the force, not the link the file names
    r = cli("solve", str(path), "--load", "B=0,-30", "-f", "json")
    applied = json.loads(r.out)["forces"]["applied"]
    assert applied[0] == {"load": "B", "kind": "force", "on": "rocker", "fx": 0.0, "fy": -30.0,
                          "torque": None}
    r = cli("sweep", str(path), "--from", "0", "--to", "20", "--step", "10", "-f", "plain")
    assert r.code == 0 and "loads applied" in r.out
    assert any(line.split()[:3] == ["B", "force", "rocker"] for line in r.out.splitlines())
    r = cli("scan", str(path), "--vary", "coupler=120:125:2", "--from", "0", "--to", "20", "--step", "10",
            "-f", "plain")
    assert r.code == 0, r.err
    assert "2 force(s) (B on rocker, P on coupler)" in r.out + r.err


def test_the_docs_loads_figure_is_what_the_command_prints(cli, monkeypatch) -> None:
    """docs/loads.md's loads figure, its loads applied table with it, is the tail of the output
    of the command above it, line by line."""
    readme = (ROOT / "docs" / "loads.md").read_text()
    command = "linkage solve docs/crank_rocker_loads.toml --speed 300rpm --gravity 9.81 -f plain"
    shown = readme.split(f"$ {command}\n...\n", 1)[1].split("```", 1)[0].rstrip("\n").splitlines()
    assert "  load    kind       on    fx (N)    fy (N)    torque (N m)" in shown
    monkeypatch.chdir(ROOT)
    r = cli(*command.split()[1:])
    assert r.code == 0, r.err
    printed = r.out.rstrip("\n").splitlines()
    assert [line.rstrip() for line in printed[-len(shown):]] == [line.rstrip() for line in shown]
