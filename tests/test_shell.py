"""The shell's conventions: version, -h, completion, - for standard input and output,
bare `linkage`, SIGINT."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

from conftest import sigint_as_at_a_terminal

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
LINKAGE = [sys.executable, "-m", "linkage"]


def test_version(cli):
    run = cli("--version")
    assert run.code == 0 and run.out.startswith("linkage ") and run.out.split()[1][0].isdigit()


def test_dash_h_is_help(cli):
    for args in (("-h",), ("solve", "-h"), ("sweep", "-h")):
        run = cli(*args)
        assert run.code == 0 and "Usage:" in run.out


def test_completion_is_offered_and_works():
    help_text = subprocess.run([*LINKAGE, "--help"], capture_output=True, text=True, timeout=60).stdout
    assert "--install-completion" in help_text and "--show-completion" in help_text
    # typer reads --show-completion as a flag and detects the shell from the parent
    # processes, so the test failed when pytest ran without a shell above it (orphaned by
    # `(pytest &)`); with detection off it takes the shell named, as a user's script does
    p = subprocess.run([*LINKAGE, "--show-completion", "bash"], capture_output=True, text=True, timeout=60,
                       env={"PATH": "/usr/bin:/bin", "HOME": "/tmp",
                            "_TYPER_COMPLETE_TEST_DISABLE_SHELL_DETECTION": "1"})
    assert p.returncode == 0 and "complete" in p.stdout and "_linkage_completion" in p.stdout


def test_bare_linkage_shows_help_without_an_error_line():
    p = subprocess.run(LINKAGE, capture_output=True, text=True, timeout=60)
    assert "Usage:" in p.stdout + p.stderr
    assert "error" not in p.stderr.lower() and p.returncode == 0


def test_dash_o_dash_writes_to_standard_output(cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run = cli("solve", "-o", "-", "--format", "json")
    assert run.code == 0 and json.loads(run.out)["converged"]
    assert not (tmp_path / "-").exists()


def test_dash_reads_the_mechanism_from_standard_input():
    text = (SAMPLES / "crank_rocker.toml").read_text()
    for command in (["solve", "-", "--format", "json"], ["sweep", "-", "--step", "90", "--format", "json"]):
        p = subprocess.run([*LINKAGE, *command], input=text, capture_output=True, text=True, timeout=60)
        assert p.returncode == 0, p.stderr
        assert json.loads(p.stdout)


def test_sigint_is_one_line_and_exit_130():
    p = subprocess.Popen([*LINKAGE, "sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "0.001",
                          "--no-batch", "--format", "csv"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True, preexec_fn=sigint_as_at_a_terminal)
    time.sleep(2.0)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130
    assert err.strip() == "error: interrupted"


def test_paths_are_checked_before_any_work(cli, tmp_path, monkeypatch):
    def no_work(*args, **kwargs):
        raise AssertionError("the sweep ran before the paths were checked")

    monkeypatch.setattr("linkage.kinematics.sweep.sweep_mechanism", no_work)
    for option, name in (("--plot", "x.txt"), ("-o", "no/such/dir/out.csv")):
        run = cli("sweep", str(SAMPLES / "crank_rocker.toml"), option, str(tmp_path / name))
        assert run.code == 2 and option in run.err


def test_samples_lists_prints_and_copies_without_replacing(cli, tmp_path):
    listing = cli("samples")
    assert listing.code == 0 and "crank_rocker.toml" in listing.out and "watt_sixbar.toml" in listing.out
    printed = cli("samples", "crank_rocker")
    assert printed.out == (SAMPLES / "crank_rocker.toml").read_text()
    out = tmp_path / "mine.toml"
    assert cli("samples", "crank_rocker.toml", "-o", str(out)).code == 0
    assert out.read_text() == printed.out
    out.write_text("mine")
    again = cli("samples", "crank_rocker", "-o", str(out))
    assert again.code == 2 and out.read_text() == "mine"
    assert cli("samples", "nope").code == 2


def test_help_has_no_type_markers(cli):
    for command in ("solve", "sweep", "draw", "samples"):
        text = cli(command, "--help").out
        for marker in ("<bool>", "<list[str]>", "<str,str", "<str str str str>"):
            assert marker not in text, (command, marker)
