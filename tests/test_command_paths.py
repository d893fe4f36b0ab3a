"""files.RUNNING is the running command's record of the files it read and wrote, or None
outside a command (where reading and writing record nothing)."""

from __future__ import annotations

import pytest

from linkage import files
from linkage.errors import InputError


def test_running_is_the_command_s_record_inside_and_none_outside(tmp_path):
    given = tmp_path / "in.toml"
    given.write_text("x")
    files.note_input(given)  # outside a command: recorded nowhere
    assert files.RUNNING is None
    with files.command_paths() as run:
        assert files.RUNNING is run
        files.note_input(given)
        with pytest.raises(InputError, match="the input file"):
            files.claim_output(given)
    assert files.RUNNING is None
    files.claim_output(given)  # outside a command again: a library caller's own business


def test_a_command_that_fails_leaves_no_record_behind():
    with pytest.raises(RuntimeError), files.command_paths():
        raise RuntimeError
    assert files.RUNNING is None
