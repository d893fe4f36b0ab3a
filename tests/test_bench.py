"""Smoke tests for ``linkage bench``: the real benchmark is not part of the test run."""

from __future__ import annotations

import json
import sys

import pytest


def test_bench_quick_on_one_problem(cli, tmp_path):
    pytest.importorskip("matplotlib")
    plot = tmp_path / "wp.png"
    run = cli("bench", "--quick", "--problem", "freudenstein", "--repeats", "1", "--no-cold",
              "--format", "json",
              "--plot", str(plot))
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    contenders = {m["contender"] for m in doc["measurements"]}
    assert "hand-written Newton (10 lines)" in contenders
    assert "linkage newton (history off)" in contenders and "linkage newton (history on)" in contenders
    for m in doc["measurements"]:
        assert m["time per solve (us)"] > 0 and m["error"] >= 0
        if m["contender"].startswith("linkage newton") and m["tol"] <= 1e-8:
            assert m["error"] < 1e-8  # the benchmark measures errors against mpmath, not against itself
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert any(t["target"].startswith("1. scalar Newton") for t in doc["targets"])


def test_bench_without_scipy_skips_its_rows_with_a_note(cli, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)
    run = cli("bench", "--quick", "--problem", "quadratic", "--repeats", "1", "--no-cold")
    assert run.code == 0, run.err
    assert "scipy is not installed: its rows are skipped" in run.out
    doc = json.loads(cli("bench", "--quick", "--problem", "quadratic", "--repeats", "1", "--no-cold",
                         "--format", "json").out)
    contenders = {m["contender"] for m in doc["measurements"]}
    assert not any(c.startswith("scipy") for c in contenders) and "linkage newton (history off)" in contenders
    assert doc["scipy"] is False


def test_bench_bad_input(cli):
    run = cli("bench", "--problem", "nope")
    assert run.code == 2 and "unknown problem" in run.err


def test_sample_mechanisms_ship_with_the_package():
    """Regression: an installed linkage looked for sample_inputs/ beside its source tree,
    so `linkage bench` failed outside a checkout. They are package data now."""
    from linkage.samples import sample_path

    for name in ("fourbar_me581.toml", "rapier_drive.toml"):
        assert sample_path(name).read_text().startswith("#")


def test_targets_judge_the_batch_only_at_a_million_positions():
    """--quick sweeps 100,000 positions; target 4 is stated at 1,000,000, so a quick run
    shows its ratio under its own size and does not call it met or not."""
    from linkage.bench import targets

    def row4(sweeps):
        return next(r for r in targets([], {}, sweeps) if r[0].startswith("4."))

    full = row4({"numpy closed form 1,000,000 positions": 0.1,
                 "linkage.sweep 1,000,000 positions (batch)": 0.18})
    assert full[2] == pytest.approx(1.8) and full[3] is True
    quick = row4({"numpy closed form 100,000 positions": 0.01,
                  "linkage.sweep 100,000 positions (batch)": 0.025})
    assert "100,000 positions" in quick[0] and quick[2] == pytest.approx(2.5) and quick[3] is None
