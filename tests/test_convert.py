"""`linkage convert`: a drawing's derived loops printed as a loops-form file that solves
as the drawing does, each loop under a comment naming its joints."""

from __future__ import annotations

import math

import pytest

from linkage import solve_system
from linkage.kinematics.loading import from_text
from test_joints_form import me581_drawing, watt_drawing


@pytest.mark.parametrize("drawing", [me581_drawing, watt_drawing])
def test_the_printed_loops_solve_as_the_drawing(cli, tmp_path, drawing) -> None:
    path = tmp_path / "drawn.toml"
    path.write_text(drawing())
    r = cli("convert", str(path))
    assert r.code == 0, r.err
    printed = from_text(r.out, "<printed>")
    drawn = from_text(drawing(), "<drawing>")
    assert [loop.joints for loop in printed.loops] == [loop.joints for loop in drawn.loops]
    for value in (0.0, 45.0, 300.0):  # ME581 cannot be assembled from 112 to 248 deg
        a = solve_system(printed.with_values({"theta_crank": value}, {}).problem(), tol=1e-14)
        b = solve_system(drawn.with_values({"theta_crank": value}, {}).problem(), tol=1e-14)
        assert a.converged and b.converged and list(a.x) == list(b.x)
        assert all(math.isfinite(v) for v in a.x)


def test_each_loop_is_under_a_comment_naming_its_joints(cli, tmp_path) -> None:
    path = tmp_path / "drawn.toml"
    path.write_text(me581_drawing())
    out = cli("convert", str(path)).out
    assert "# O2 -> A -> B -> O4 -> O2: the sum of these vectors is zero" in out
    assert '{ length = "crank", angle = "theta_crank", sign = 1 },  # O2 -> A' in out


def test_convert_refuses_what_it_cannot_do(cli, tmp_path) -> None:
    path = tmp_path / "drawn.toml"
    path.write_text(me581_drawing())
    r = cli("convert", str(path), "-o", str(tmp_path / "x.mat"))
    assert r.code == 2 and "name it with .toml" in r.err and r.err.count("\n") == 1
    loops = tmp_path / "loops.toml"
    loops.write_text(cli("convert", str(path)).out)
    r = cli("convert", str(loops), "--form", "loops")
    assert r.code == 2 and "already in the loops form" in r.err
    r = cli("convert", str(path), "-o", str(tmp_path / "out.toml"))
    assert r.code == 0 and (tmp_path / "out.toml").read_text() == loops.read_text()


def test_converting_a_loaded_file_to_loops_says_the_loads_and_masses_are_not_carried(cli, tmp_path):
    """docs/crank_rocker_loads.toml's [loads] and [mass] need links as bodies: the loops form
    written from it (exit 0) lacks them, and a note says so instead of nothing."""
    from pathlib import Path

    loaded = Path(__file__).resolve().parents[1] / "docs" / "crank_rocker_loads.toml"
    out = tmp_path / "loops.toml"
    run = cli("convert", str(loaded), "--form", "loops", "-o", str(out))
    assert run.code == 0 and "[loads]" not in out.read_text() and "[mass]" not in out.read_text()
    assert "note: [loads] and [mass] of" in run.err and "not written" in run.err
    plain = cli("convert", str(loaded.parent.parent / "sample_inputs" / "crank_rocker_joints.toml"))
    assert plain.code == 0 and "note:" not in plain.err
