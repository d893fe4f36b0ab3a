"""A batch or closed-form sweep's meetings (kinematics.batch.BatchMeetings) are computed
when first read, and are what the one-at-a-time engine lists: equal to its tuple, hashed,
shown and pickled as a tuple. Reference: the one-at-a-time sweep of the same change-point
four-bar (its assemblies meet at theta2 = 0 and 360)."""

from __future__ import annotations

import pickle
from pathlib import Path

import linkage
from linkage.kinematics.batch import BatchMeetings
from linkage.kinematics.loading import load

CRANK_ROCKER = Path(__file__).resolve().parent.parent / "sample_inputs" / "crank_rocker.toml"


def test_a_batch_sweeps_meetings_are_read_when_asked_and_are_the_one_at_a_time_engines():
    m = load(CRANK_ROCKER).with_values({"r2": 40.0, "r4": 60.0}, {})  # r2 + 120 = 100 + r4
    values = [float(k) for k in range(361)]
    one = linkage.sweep(m, values, batch=False)
    fast = linkage.sweep(m, values, batch=True)
    assert isinstance(fast.meetings, BatchMeetings) and fast.meetings.found is None  # not yet read
    assert fast.meetings == one.meetings == (0.0, 360.0) and one.meetings == fast.meetings
    assert fast.meetings.found == (0.0, 360.0)
    assert hash(fast.meetings) == hash((0.0, 360.0)) and repr(fast.meetings) == "(0.0, 360.0)"
    assert list(fast.meetings) == [0.0, 360.0] and len(fast.meetings) == 2 and fast.meetings[1] == 360.0
    assert pickle.loads(pickle.dumps(fast.meetings)) == (0.0, 360.0)
    assert type(pickle.loads(pickle.dumps(fast.meetings))) is tuple


def test_a_sweep_with_no_meetings_reads_as_empty():
    m = load(CRANK_ROCKER)
    result = linkage.sweep(m, [float(k) for k in range(361)])
    assert result.method == "newton (closed form)"
    assert not result.meetings and result.meetings == ()
