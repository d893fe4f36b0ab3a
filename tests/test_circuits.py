"""Circuits (`linkage assemblies --sweep`): which assemblies a mechanism can reach from one
another by moving, against closed forms of the four-bar (the law of cosines; limit
positions where the coupler and rocker line up: Norton, "Design of Machinery", section
4.12) and the loop equations themselves."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from linkage.kinematics.circuits import circuits
from linkage.kinematics.loading import load

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def _fourbar(**lengths: float):
    return load(SAMPLES / "crank_rocker.toml").with_values(lengths, {})


def _limit_deg(r1: float, r2: float, d: float) -> float:
    """The crank angle at which the coupler-rocker diagonal is d (law of cosines)."""
    return math.degrees(math.acos((r1 * r1 + r2 * r2 - d * d) / (2 * r1 * r2)))


def _on_closed_form(r1, r2, r3, r4, theta2, theta3, theta4) -> float:
    """How far (theta3, theta4) is from the nearer of the four-bar's two closed-form
    assemblies at theta2 (rad): the diagonal from A to O4, then the triangle A-B-O4."""
    ax, ay = r2 * math.cos(theta2), r2 * math.sin(theta2)
    dx, dy = r1 - ax, -ay
    d = math.hypot(dx, dy)
    phi = math.atan2(dy, dx)
    best = math.inf
    for sign in (1, -1):
        alpha = sign * math.acos(max(-1.0, min(1.0, (r3 * r3 + d * d - r4 * r4) / (2 * r3 * d))))
        t3 = phi + alpha
        bx, by = ax + r3 * math.cos(t3), ay + r3 * math.sin(t3)
        t4 = math.atan2(by, bx - r1)
        err = max(abs(math.remainder(t3 - theta3, 2 * math.pi)),
                  abs(math.remainder(t4 - theta4, 2 * math.pi)))
        best = min(best, err)
    return best


def test_grashof_crank_rocker_has_two_circuits_each_a_full_turn():
    c = circuits(_fourbar())
    assert [circ.members for circ in c.circuits] == [(0,), (1,)]
    assert all(circ.full_turn and circ.status == "closed" and not circ.limits for circ in c.circuits)
    assert {c.assemblies.real[i].branch for i in (0, 1)} == {"open", "crossed"}
    assert c.circuit_of(0) != c.circuit_of(1)


@pytest.mark.parametrize(("lengths", "start", "limits"), [
    # non-Grashof triple rocker: the two assemblies join at theta2 = +-acos(...) (coupler and
    # rocker in line, r3 + r4 = 120)
    ({"r2": 60, "r3": 60, "r4": 60}, 30,
     lambda: sorted([_limit_deg(100, 60, 120), -_limit_deg(100, 60, 120)])),
    # Grashof double rocker (the coupler is shortest): the input rocks between the folded
    # (|r4 - r3| = 60) and extended (r3 + r4 = 120) diagonals, both assemblies on one circuit
    ({"r2": 80, "r3": 30, "r4": 90}, 60, lambda: sorted([_limit_deg(100, 80, 60), _limit_deg(100, 80, 120)])),
])
def test_rockers_join_their_assemblies_through_limit_positions_at_the_closed_form(lengths, start, limits):
    m = _fourbar(**lengths).with_values({"theta2": start}, {})
    c = circuits(m)
    assert len(c.assemblies.real) == 2
    (circ,) = c.circuits
    assert circ.members == (0, 1) and circ.status == "closed" and not circ.full_turn
    found = sorted(math.degrees(v) for v in circ.limits)
    want = limits()
    assert len(found) == 2
    for f, w in zip(found, want):
        assert abs(f - w) <= 1e-9, (found, want)
    assert abs(math.degrees(circ.driver_low) - want[0]) <= 1e-9
    assert abs(math.degrees(circ.driver_high) - want[1]) <= 1e-9


@pytest.mark.parametrize("lengths", [{}, {"r2": 60, "r3": 60, "r4": 60}, {"r2": 80, "r3": 30, "r4": 90}])
def test_every_traced_configuration_is_a_closed_form_assembly(lengths):
    m = _fourbar(**lengths)
    if lengths.get("r2") == 80:
        m = m.with_values({"theta2": 60}, {})
    r = {k: m.value_of(k).value for k in ("r1", "r2", "r3", "r4")}
    c = circuits(m)
    count = 0
    for circ in c.circuits:
        for d, (t3, t4) in zip(circ.drivers, circ.configurations):
            assert _on_closed_form(r["r1"], r["r2"], r["r3"], r["r4"], d, t3, t4) <= 1e-10
            count += 1
    assert count > 500


@pytest.mark.parametrize("scale", [1e-6, 1e3])
def test_circuits_do_not_depend_on_the_unit_of_length(scale):
    base = {"r1": 100.0, "r2": 60.0, "r3": 60.0, "r4": 60.0}
    m = _fourbar(**{k: v * scale for k, v in base.items()})
    (circ,) = circuits(m).circuits
    want = _limit_deg(100, 60, 120)
    assert sorted(abs(math.degrees(v)) for v in circ.limits) == pytest.approx([want, want], abs=1e-9)


def test_six_bars_follow_every_assembly_to_a_closed_circuit():
    for name in ("watt_sixbar.toml", "stephenson_sixbar.toml"):
        m = load(SAMPLES / name)
        c = circuits(m)
        members = sorted(i for circ in c.circuits for i in circ.members)
        assert members == list(range(len(c.assemblies.real))), name
        assert all(circ.status == "closed" for circ in c.circuits), name
        F = None
        for circ in c.circuits:
            for d, q in list(zip(circ.drivers, circ.configurations))[::25]:
                F, _ = m.model.functions(d)
                assert max(abs(v) for v in F(list(q))) <= 1e-11 * m.length_scale


def test_cli_sweep_prints_the_circuits_and_writes_them(cli, tmp_path):
    out = cli("assemblies", str(SAMPLES / "crank_rocker.toml"), "--set", "r2=60", "--set", "r3=60", "--set",
              "r4=60", "--sweep")
    assert out.code == 0, out.err
    assert "1 circuit through the 2 real assemblies" in out.out
    assert "circuit 1: assemblies 1, 2; theta2 from -93.822554 to 93.822554 deg, 2 limit positions" in out.out
    target = tmp_path / "c.json"
    out = cli("assemblies", str(SAMPLES / "crank_rocker.toml"), "--sweep", "-o", str(target))
    assert out.code == 0, out.err
    doc = json.loads(target.read_text())
    assert doc["circuits"] == 2


def test_cli_plot_needs_sweep_and_a_picture_suffix(cli, tmp_path):
    out = cli("assemblies", str(SAMPLES / "crank_rocker.toml"), "--plot", str(tmp_path / "c.png"))
    assert out.code == 2 and "--sweep" in out.err and len(out.err.strip().splitlines()) == 1
    out = cli("assemblies", str(SAMPLES / "crank_rocker.toml"), "--sweep", "--plot", str(tmp_path / "c.txt"))
    assert out.code == 2
    assert not (tmp_path / "c.txt").exists()


def test_cli_plot_draws_the_circuits(cli, tmp_path):
    pytest.importorskip("matplotlib")
    target = tmp_path / "c.png"
    out = cli("assemblies", str(SAMPLES / "watt_sixbar.toml"), "--sweep", "--plot", str(target))
    assert out.code == 0, out.err
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_plot_without_a_real_assembly_draws_no_legend_warning(cli, tmp_path):
    """The ME581 four-bar at theta2 = 180 has no real assembly, so no circuit: the picture is
    drawn (exit 1) without matplotlib's "No artists with labels" warning on stderr."""
    import warnings

    pytest.importorskip("matplotlib")
    target = tmp_path / "none.png"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = cli("assemblies", str(SAMPLES / "fourbar_me581.toml"), "--set", "theta2=180", "--sweep",
                  "--plot", str(target))
    assert out.code == 1 and "Warning" not in out.err and target.read_bytes()[:4] == b"\x89PNG"


def test_a_plot_without_a_circuit_says_why_on_its_axes(monkeypatch, tmp_path):
    """Empty axes said nothing (a student sees a blank 0..1 grid): each says there is no real
    assembly at the start value, so no circuit to draw."""
    pytest.importorskip("matplotlib")
    from linkage.render import circuits as render

    texts: list[str] = []

    def keep(fig, path):
        texts.extend(t.get_text() for ax in fig.axes for t in ax.texts)

    monkeypatch.setattr("linkage.render.plots.save_figure", keep)
    m = load(SAMPLES / "fourbar_me581.toml").with_values({"theta2": 180.0}, {})
    render.circuits_plot(circuits(m), tmp_path / "none.png")
    assert texts == ["no real assembly at theta2 = 180 deg: no circuit to draw"] * 2
