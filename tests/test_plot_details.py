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
    monkeypatch.setattr(plots, "_save", lambda fig, path: seen.setdefault("fig", fig))
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
    frames = plots.sweep_frames(mechanism, s) if hasattr(plots, "sweep_frames") else [
        (math.radians(p.input), [math.radians(p.solution[u.name]) for u in mechanism.unknowns])
        for p in s.positions if p.solution]
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
