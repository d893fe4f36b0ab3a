"""Drawings and plots are produced and are valid files (matplotlib, the plot extra)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
PNG = b"\x89PNG\r\n\x1a\n"


def assert_png(path: Path) -> None:
    data = path.read_bytes()
    assert data[:8] == PNG and len(data) > 5000, path


def assert_svg(path: Path) -> None:
    root = ET.parse(path).getroot()
    assert root.tag.endswith("svg")
    assert len(list(root.iter())) > 50  # lines, markers and labels, not an empty canvas


def test_sweep_plot(cli, tmp_path):
    out = tmp_path / "sweep.png"
    run = cli("sweep", str(SAMPLES / "fourbar_me581.toml"), "--to", "359", "--step", "2", "--plot", str(out))
    assert run.code == 0 and "wrote" in run.err
    assert_png(out)


def test_sweep_plot_svg_for_a_mechanism_with_gaps(cli, tmp_path):
    out = tmp_path / "offset.svg"
    assert cli("sweep", str(SAMPLES / "offset_slider.toml"), "--step", "5", "--plot", str(out)).code == 0
    assert_svg(out)


@pytest.mark.parametrize("name", ["fourbar_me581", "rapier_drive", "slider_crank", "offset_slider"])
def test_drawings(cli, tmp_path, name):
    png, svg = tmp_path / f"{name}.png", tmp_path / f"{name}.svg"
    assert cli("draw", str(SAMPLES / f"{name}.toml"), "-o", str(png)).code == 0
    assert cli("draw", str(SAMPLES / f"{name}.toml"), "-o", str(svg)).code == 0
    assert_png(png)
    # a drawing's .svg is the CAD sheet (render/cad.py, tests/test_cad_export.py): its links
    # and joints, not a canvas of axes
    root = ET.parse(svg).getroot()
    assert root.tag.endswith("svg") and root.get("viewBox")
    assert len([e for e in root.iter() if e.tag.endswith(("polyline", "polygon"))]) >= 2


def test_drawing_labels_the_joints(cli, tmp_path):
    svg = tmp_path / "rapier.svg"
    cli("draw", str(SAMPLES / "rapier_drive.toml"), "-o", str(svg))
    labels = {e.text for e in ET.parse(svg).getroot().iter() if e.tag.endswith("text")}
    assert {"A0", "C0"} <= labels


def test_animation_gif(cli, tmp_path):
    gif = tmp_path / "crank.gif"
    run = cli("draw", str(SAMPLES / "crank_rocker.toml"), "--animate", str(gif), "--step", "30")
    assert run.code == 0 and "13 frames" in run.err and "Ignoring" not in run.err
    data = gif.read_bytes()
    assert data[:6] in (b"GIF87a", b"GIF89a") and len(data) > 5000


@pytest.mark.parametrize("args", [["--method", "all"], ["--method", "newton"],
                                  [str(SAMPLES / "fourbar_me581.toml")]])
def test_convergence_plot(cli, tmp_path, args):
    out = tmp_path / "conv.png"
    run = cli("solve", *args, "--plot", str(out))
    assert run.code == 0, run.err
    assert_png(out)


@pytest.mark.parametrize("args,message", [
    (["draw", str(SAMPLES / "crank_rocker.toml")], "give -o PATH"),
    (["draw", str(SAMPLES / "crank_rocker.toml"), "-o", "x.bmp"], "use one of .png, .svg, .pdf"),
    (["draw", str(SAMPLES / "crank_rocker.toml"), "--animate", "x.png"], "use one of .gif"),
])
def test_plot_bad_input(cli, tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    run = cli(*args)
    assert run.code == 2 and message in run.err


def test_drawing_a_position_that_cannot_be_assembled_is_refused(cli, tmp_path):
    """Bad input, as centres refuses it: one line, exit 2, no picture (it was exit 1)."""
    run = cli("draw", str(SAMPLES / "fourbar_me581.toml"), "--set", "theta2=180",
              "-o", str(tmp_path / "x.png"))
    assert run.code == 2 and "cannot be assembled at theta2 = 180 deg" in run.err
    assert len(run.err.strip().splitlines()) == 1 and not (tmp_path / "x.png").exists()
