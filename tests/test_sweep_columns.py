"""A batch sweep's columns (kinematics.columns): the transmission angles computed on a thread
beside the joints are the ones computed in line, bit for bit; a failure on the thread is
raised in line, as the in-line call raises it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.kinematics import columns
from linkage.kinematics.columns import beside, sweep_columns

CRANK_ROCKER = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"


def test_transmission_beside_the_joints_is_the_in_line_column(monkeypatch) -> None:
    values = np.arange(0.0, 360.0, 0.37)
    r = linkage.sweep(linkage.load_mechanism(str(CRANK_ROCKER)), values, joints=True, batch=True)
    monkeypatch.setattr(columns, "BESIDE_FROM", 1)
    threaded = sweep_columns(r)
    monkeypatch.setattr(columns, "BESIDE_FROM", 10**12)
    in_line = sweep_columns(r)
    assert np.isfinite(in_line.transmission).any() and threaded.joints
    assert threaded.transmission.tobytes() == in_line.transmission.tobytes()
    assert list(threaded.joints) == list(in_line.joints)


def test_a_failure_beside_is_raised_in_line(capfd) -> None:
    calls = []

    def fails(x: int) -> int:
        calls.append(x)
        raise ValueError(f"bad {x}")

    value = beside(fails, 3)
    with pytest.raises(ValueError, match="bad 3"):
        value()
    assert calls == [3, 3]
    assert "Traceback" not in capfd.readouterr().err
    assert beside(lambda a, b: a + b, 2, 5)() == 7
