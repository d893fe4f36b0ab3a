"""The details a person sees in the plots (issue 20): the stacked rate panels sit under
their title, the driver's speed is in the unit given, the coupler plot says where its
linkage is drawn, an animation says where it cannot be assembled, and --fps sets its
speed. Figures are read back (titles, texts, extents), not pixels."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")

import linkage
from linkage.errors import InputError
from linkage.render import plots

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
CRANK_ROCKER = SAMPLES / "crank_rocker.toml"  # r1 = 100, r2 = 40, r3 = 120, r4 = 80 mm


def _capture(monkeypatch) -> dict:
    """The figure a plot function would save, kept open for reading back."""
    seen: dict = {}
    monkeypatch.setattr(plots, "save_figure", lambda fig, path: seen.setdefault("fig", fig))
    return seen


def _no_solution_limit(r3: float) -> float:
    """Where the crank_rocker's crank stops with coupler ``r3``: A to O4 reaches r3 + r4,
    r2^2 + r1^2 - 2 r1 r2 cos(theta2) = (r3 + r4)^2 (law of cosines), in degrees."""
    r1, r2, r4 = 100.0, 40.0, 80.0
    return math.degrees(math.acos((r2 * r2 + r1 * r1 - (r3 + r4) ** 2) / (2 * r1 * r2)))


def test_the_stacked_rate_panels_start_right_under_the_title(monkeypatch, tmp_path):
    """Six panels (two angles, each with its velocity and acceleration) left about 1.3 in
    of empty figure between the title and the first panel (the default top margin of a
    12.6 in figure). The gap is now a line's spacing."""
    seen = _capture(monkeypatch)
    mechanism = linkage.load_mechanism(CRANK_ROCKER)
    result = linkage.sweep(mechanism, [float(v) for v in range(0, 361, 10)], speed=20 * math.pi)
    plots.sweep_plot(result, tmp_path / "s.png")
    fig = seen["fig"]
    assert len(fig.axes) == 6
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    title = fig._suptitle.get_window_extent(renderer)
    top = max(ax.get_tightbbox(renderer).y1 for ax in fig.axes)
    gap_inches = (title.y0 - top) / fig.dpi
    assert -0.01 < gap_inches < 0.25
    # and nothing is left unused at the bottom either: the x label is near the edge
    bottom = min(ax.get_tightbbox(renderer).y0 for ax in fig.axes)
    assert bottom / fig.dpi < 0.25


def test_the_plot_says_the_speed_as_given(monkeypatch, tmp_path):
    seen = _capture(monkeypatch)
    mechanism = linkage.load_mechanism(CRANK_ROCKER)
    result = linkage.sweep(mechanism, [0.0, 90.0, 180.0], speed=600 * 2 * math.pi / 60)
    plots.sweep_plot(result, tmp_path / "s.png", motion_text="600 rpm")
    title = seen["fig"]._suptitle.get_text()
    assert "driver at 600 rpm" in title and "rad/s" not in title and "62.8" not in title


def test_the_coupler_plot_says_where_its_linkage_is_drawn(monkeypatch, tmp_path):
    """The title names the driver value, and the crank drawn ends where that value puts
    it: A = r2 (cos theta2, sin theta2) with r2 = 40 mm, O2 at the origin."""
    seen = _capture(monkeypatch)
    mechanism = linkage.load_mechanism(CRANK_ROCKER)
    result = linkage.sweep(mechanism, [float(v) for v in range(50, 300, 10)], joints=True)
    plots.path_plot(result, mechanism, ["P"], tmp_path / "p.png")
    ax = seen["fig"].axes[0]
    m = re.search(r"linkage drawn at theta2 = ([-0-9.]+) deg", ax.get_title())
    assert m is not None, ax.get_title()
    theta2 = float(m.group(1))
    assert theta2 == 50.0
    a = (40 * math.cos(math.radians(theta2)), 40 * math.sin(math.radians(theta2)))
    ends = [tuple(xy) for line in ax.lines for xy in line.get_xydata()]
    assert any(math.dist(a, e) < 1e-9 for e in ends)


def test_frame_notes_mark_the_frames_either_side_of_each_gap():
    values = [0.0, 10.0, 20.0, 30.0, 80.0, 90.0, 100.0, 150.0]
    notes = plots.frame_notes(values, [(31.25, 79.5), (101.0, 149.0)], "deg")
    gap1, gap2 = "cannot be assembled from 31.25 to 79.5 deg", "cannot be assembled from 101 to 149 deg"
    assert notes == ["", "", "", gap1, gap1, "", gap2, gap2]
    # a range that starts inside a gap: only its first frame after it says so
    assert plots.frame_notes([40.0, 50.0], [(0.0, 35.0)], "mm") == ["cannot be assembled from 0 to 35 mm", ""]


def _frame_texts(monkeypatch) -> list[list[str]]:
    """Every text on each frame the GIF writer grabs."""
    from matplotlib.animation import PillowWriter

    grabbed: list[list[str]] = []
    original = PillowWriter.grab_frame

    def grab(self, **kw):
        grabbed.append([t.get_text() for ax in self.fig.axes for t in ax.texts])
        return original(self, **kw)

    monkeypatch.setattr(PillowWriter, "grab_frame", grab)
    return grabbed


def test_an_animation_notes_the_gap_on_the_frames_either_side(monkeypatch, tmp_path):
    """With r3 = 50 mm the crank turns only to +-131.49 deg (s + l > p + q): the frames at
    120 and 240 deg (the last before, the first after) say so, no other frame does."""
    from PIL import Image

    grabbed = _frame_texts(monkeypatch)
    mechanism = linkage.load_mechanism(CRANK_ROCKER).with_values({"r3": 50.0}, {})
    s = linkage.sweep(mechanism, [float(v) for v in range(0, 361, 30)])
    frames = plots.sweep_frames(mechanism, s)
    gif = tmp_path / "a.gif"
    plots.animate_sweep(mechanism, frames, gif, fps=5, gaps=plots.assembly_gaps(s))
    limit = _no_solution_limit(50.0)
    note = f"cannot be assembled from {limit:.4g} to {360 - limit:.4g} deg"
    shown = [[t for t in texts if "assembled" in t] for texts in grabbed]
    inputs = [round(math.degrees(d)) for d, _ in frames]
    assert inputs == [0, 30, 60, 90, 120, 240, 270, 300, 330, 360]
    assert shown == [[note] if v in (120, 240) else [] for v in inputs]
    with Image.open(gif) as im:
        assert im.n_frames == len(frames)
        assert im.info["duration"] == 200  # 5 frames per second


@pytest.mark.parametrize("fps", [0, -1, math.nan, math.inf, 1000, "x"])
def test_an_animation_refuses_a_bad_fps(tmp_path, fps):
    mechanism = linkage.load_mechanism(CRANK_ROCKER)
    with pytest.raises(InputError, match="fps"):
        plots.animate_sweep(mechanism, [(0.5, [0.4, 1.0])], tmp_path / "a.gif", fps=fps)


def test_linkage_sweep_plot_says_600_rpm(cli, monkeypatch, tmp_path):
    seen = _capture(monkeypatch)
    run = cli("sweep", str(CRANK_ROCKER), "--speed", "600rpm", "--step", "30",
              "--plot", str(tmp_path / "s.png"))
    assert run.code == 0, run.err
    title = seen["fig"]._suptitle.get_text()
    assert "driver at 600 rpm, 0 rpm/s" in title and "62.8" not in title
    assert len(seen["fig"].axes) == 6


SLIDE = """name = "slide"
length_unit = "mm"
[parameters]
r = { value = 50, unit = "mm" }
[driver]
name = "s"
value = 30
unit = "mm"
[unknowns]
theta = { guess = 50, unit = "deg" }
t = { guess = 40, unit = "mm" }
[[loops]]
name = "L"
vectors = [{ length = "s", angle = 0 }, { length = "t", angle = 90 },
           { length = "r", angle = "theta", sign = -1 }]
"""


@pytest.mark.parametrize("speed,accel,text,internal", [
    ("600rpm", None, "600 rpm, 0 rpm/s", (600 * 2 * math.pi / 60, 0.0)),
    ("90 deg/s", "-45deg/s^2", "90 deg/s, -45 deg/s^2", (math.pi / 2, -math.pi / 4)),
    ("2.5", None, "2.5 rad/s, 0 rad/s^2", (2.5, 0.0)),
    ("3 rad/s", "1", "3 rad/s, 1 rad/s^2", (3.0, 1.0)),
])
def test_motion_text_is_the_speed_as_given(speed, accel, text, internal):
    """The text states what parse_motion reads: 600 rpm is 600 turns of 2 pi a minute."""
    from linkage.arguments import motion_text, parse_motion

    mechanism = linkage.load_mechanism(CRANK_ROCKER)
    assert motion_text(speed, accel, mechanism) == text
    assert parse_motion(speed, accel, mechanism) == pytest.approx(internal, rel=1e-15)


def test_a_sliding_driver_speed_is_in_its_length_unit_per_second(cli, monkeypatch, tmp_path):
    from linkage.arguments import motion_text

    path = tmp_path / "slide.toml"
    path.write_text(SLIDE)
    assert motion_text("2", None, linkage.load_mechanism(path)) == "2 mm/s, 0 mm/s^2"
    assert motion_text("2mm/s", "0.5 mm/s^2", linkage.load_mechanism(path)) == "2 mm/s, 0.5 mm/s^2"
    seen = _capture(monkeypatch)
    run = cli("sweep", str(path), "--from", "0", "--to", "40", "--step", "10", "--speed", "2",
              "--plot", str(tmp_path / "s.png"))
    assert run.code == 0, run.err
    assert "driver at 2 mm/s, 0 mm/s^2" in seen["fig"]._suptitle.get_text()


def test_linkage_draw_notes_the_gap_on_the_frames_either_side(cli, monkeypatch, tmp_path):
    grabbed = _frame_texts(monkeypatch)
    run = cli("draw", str(CRANK_ROCKER), "--set", "r3=50", "--animate", str(tmp_path / "a.gif"),
              "--step", "30")
    assert run.code == 0, run.err
    limit = _no_solution_limit(50.0)
    note = f"cannot be assembled from {limit:.4g} to {360 - limit:.4g} deg"
    shown = [[t for t in texts if "assembled" in t] for texts in grabbed]
    assert shown == [[]] * 4 + [[note], [note]] + [[]] * 4  # 0 to 120 and 240 to 360 deg


@pytest.mark.parametrize("fps,duration", [(None, 80), ("5", 200), ("20", 50), ("0.5", 2000)])
def test_fps_sets_the_frame_duration(cli, tmp_path, fps, duration):
    """A GIF stores a frame's delay in hundredths of a second: 1000 / fps ms, the default
    12 fps's 83.3 ms stored as 80 (truncated, as it always was)."""
    from PIL import Image

    gif = tmp_path / "a.gif"
    args = ["draw", str(CRANK_ROCKER), "--animate", str(gif), "--step", "90"]
    run = cli(*args, *(["--fps", fps] if fps else []))
    assert run.code == 0, run.err
    with Image.open(gif) as im:
        durations = []
        for i in range(im.n_frames):
            im.seek(i)
            durations.append(im.info["duration"])
    assert durations == [duration] * 5


@pytest.mark.parametrize("fps", ["0", "nan", "-2", "inf", "101", "fast"])
def test_linkage_draw_refuses_a_bad_fps(cli, tmp_path, fps):
    gif = tmp_path / "a.gif"
    run = cli("draw", str(CRANK_ROCKER), "--animate", str(gif), "--fps", fps)
    assert run.code == 2
    lines = run.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "--fps" in lines[0]
    assert not gif.exists()


def test_fps_without_an_animation_is_refused(cli, tmp_path):
    run = cli("draw", str(CRANK_ROCKER), "-o", str(tmp_path / "d.png"), "--fps", "5")
    assert run.code == 2 and run.err.startswith("error: ") and "--animate" in run.err
