"""No command writes over a file it read or writes one file twice, and ``--poses`` is read as a
mechanism file is: every output path of a run (-o, each FILE.NAME.csv a report's other tables
go to, --plot, --torque-plot) meets one check against every file the run read (the mechanism
file, --poses) and every other output (linkage.files: check_outputs before the work,
claim_output as each file is written); --poses goes through files.read_input (a regular file
of at most files.MAX_INPUT_BYTES). docs/output.md: bad input is one line and exit 2."""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ME581 = ROOT / "sample_inputs" / "fourbar_me581.toml"
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"
POSES = ROOT / "docs" / "motion_poses.txt"
FUNCTION = ("synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150", "--phi", "0:90")


def folder_state(folder: Path) -> dict[str, bytes | str]:
    """Every entry of ``folder``: a file's bytes, a symlink's target."""
    return {p.name: os.readlink(p) if p.is_symlink() else p.read_bytes() for p in folder.iterdir()}


def refused(run, said: str) -> None:
    """One error line saying ``said``, exit 2, no traceback."""
    assert run.code == 2, (run.code, run.err)
    lines = [ln for ln in run.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and said in lines[0], run.err
    assert "Traceback" not in run.err and "internal error" not in run.err


@pytest.fixture
def here(tmp_path, monkeypatch) -> Path:
    """A fresh working folder, so that paths are written as a person types them."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


# --- 1a: the --poses file is an input like any other ------------------------------------------

def _poses_cases(here: Path) -> dict[str, tuple[str, list[str]]]:
    """Each case: the --poses path and the output options naming that file."""
    shutil.copy(POSES, here / "p.txt")
    shutil.copy(POSES, here / "mp.toml")
    shutil.copy(POSES, here / "p.csv")
    (here / "link.toml").symlink_to("mp.toml")
    os.link(here / "mp.toml", here / "hard.toml")
    return {
        "report": ("p.txt", ["-o", "p.txt"]),
        "design_with_force": ("mp.toml", ["-o", "mp.toml", "--force"]),
        "csv": ("p.csv", ["-o", "p.csv"]),
        "symlink": ("mp.toml", ["-o", "link.toml", "--force"]),
        "hard_link": ("mp.toml", ["-o", "hard.toml", "--force"]),
        "dot_and_dotdot": ("./p.txt", ["-o", f"../{here.name}/p.txt"]),
    }


@pytest.mark.parametrize("case", ["report", "design_with_force", "csv", "symlink", "hard_link",
                                  "dot_and_dotdot"])
def test_synthesize_poses_file_is_never_the_output(cli, here, case) -> None:
    poses, outputs = _poses_cases(here)[case]
    before = folder_state(here)
    refused(cli("synthesize", "--motion", "--poses", poses, *outputs), "is the input file")
    assert folder_state(here) == before


# --- 1b: the tables written beside -o FILE.csv are outputs too -----------------------------------

EXTRAS = {
    # command: (the input's name, the run; the input is the table a.NAME.csv beside -o a.csv)
    "assemblies": ("a.paths.csv", ["assemblies", "a.paths.csv", "--sweep", "-o", "a.csv"]),
    "tolerance": ("a.largest.csv", ["tolerance", "a.largest.csv", "--tol", "r2=0.1", "--samples", "20",
                                    "-o", "a.csv"]),
    "synthesize": ("a.designs.csv", ["synthesize", "--motion", "--poses", "a.designs.csv", "-o", "a.csv"]),
    "solve": ("a.joints.csv", ["solve", "a.joints.csv", "-o", "a.csv"]),
    "sweep": ("a.loads.csv", ["sweep", "a.loads.csv", "--step", "30", "-o", "a.csv"]),
    "simulate": ("a.energy.csv", ["simulate", "a.energy.csv", "--time", "0:0.05", "--drive", "1",
                                  "-o", "a.csv"]),
}
SOURCES = {"synthesize": POSES, "sweep": LOADED, "simulate": LOADED}


@pytest.mark.parametrize("command", sorted(EXTRAS))
def test_extra_csv_beside_the_output_is_never_the_input(cli, here, command) -> None:
    name, run = EXTRAS[command]
    shutil.copy(SOURCES.get(command, ME581), here / name)
    before = folder_state(here)
    refused(cli(*run), "the input file")
    assert folder_state(here) == before  # the input as it was, and no a.csv nor any other table


@pytest.mark.parametrize("link", ["symlink", "hard_link"])
def test_assemblies_extra_csv_is_never_the_input_through_a_link(cli, here, link) -> None:
    shutil.copy(ME581, here / "m.toml")
    if link == "symlink":
        (here / "a.paths.csv").symlink_to("m.toml")
    else:
        os.link(here / "m.toml", here / "a.paths.csv")
    before = folder_state(here)
    refused(cli("assemblies", "m.toml", "--sweep", "-o", "a.csv"), "the input file m.toml")
    assert folder_state(here) == before


# --- 1c: two outputs of one run on one path ---------------------------------------------------

def test_synthesize_plot_and_output_are_never_one_file(cli, here) -> None:
    refused(cli(*FUNCTION, "--plot", "s2.png", "-o", "s2.png", "--format", "csv"), "name the same file")
    assert folder_state(here) == {}


def test_sweep_torque_plot_and_plot_are_never_one_file(cli, here) -> None:
    shutil.copy(LOADED, here / "m.toml")
    before = folder_state(here)
    refused(cli("sweep", "m.toml", "--step", "30", "--plot", "t.png", "--torque-plot", "t.png"),
            "name the same file")
    assert folder_state(here) == before


PLOT_ON_A_TABLE = {
    # command: the run, whose --plot is the path of a table written beside -o a.png --format csv
    "synthesize": [*FUNCTION, "--plot", "a.linkage.png"],
    "assemblies": ["assemblies", "m.toml", "--sweep", "--plot", "a.paths.png"],
    "tolerance": ["tolerance", "m.toml", "--tol", "r2=0.1", "--samples", "20", "--plot", "a.largest.png"],
    "solve": ["solve", "m.toml", "--plot", "a.joints.png"],
    "sweep": ["sweep", "m.toml", "--step", "30", "--plot", "a.loads.png"],
    "sweep --torque-plot": ["sweep", "m.toml", "--step", "30", "--torque-plot", "a.loads.png"],
    "simulate": ["simulate", "m.toml", "--time", "0:0.05", "--drive", "1", "--plot", "a.energy.png"],
}


@pytest.mark.parametrize("command", sorted(PLOT_ON_A_TABLE))
def test_a_table_beside_the_output_on_the_plot_s_path_writes_neither(cli, here, command) -> None:
    """The tables beside -o are named only once the report is made: they are checked with
    --plot then, before the report or the picture is written (the picture was drawn, then
    the run refused at the table, in synthesize; the tables written, then the picture
    refused, elsewhere)."""
    shutil.copy(LOADED if command.startswith(("sweep", "simulate")) else ME581, here / "m.toml")
    before = folder_state(here)
    refused(cli(*PLOT_ON_A_TABLE[command], "-o", "a.png", "--format", "csv"), "name the same file")
    assert folder_state(here) == before


# --- 2: --poses is read as a mechanism file is ------------------------------------------------

def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))


@pytest.mark.parametrize("special", ["fifo", "/dev/zero"])
def test_synthesize_poses_special_file_is_refused_at_once(tmp_path, special) -> None:
    """In a child of bounded memory and time: before the fix a FIFO waited for a writer and
    /dev/zero was read until memory ran out."""
    if special == "fifo":
        special = str(tmp_path / "fifo")
        os.mkfifo(special)
    try:
        run = subprocess.run([sys.executable, "-m", "linkage", "synthesize", "--motion", "--poses", special],
                             capture_output=True, text=True, timeout=60, preexec_fn=_limited)
    except subprocess.TimeoutExpired:
        pytest.fail(f"--poses {special} did not return within 60 s")
    assert run.returncode == 2, run.stderr
    lines = [ln for ln in run.stderr.splitlines() if ln.strip()]
    assert lines == [f"error: --poses: {special} is not a regular file (a FIFO, a device or a socket); "
                     "give the poses file itself"]


def test_synthesize_poses_file_has_the_mechanism_size_cap(cli, here) -> None:
    from linkage.files import MAX_INPUT_BYTES

    (here / "big.txt").write_text(POSES.read_text() + "#" * MAX_INPUT_BYTES + "\n")
    refused(cli("synthesize", "--motion", "--poses", "big.txt"), f"at most {MAX_INPUT_BYTES:,}")


def test_synthesize_poses_directory_is_refused(cli, here) -> None:
    refused(cli("synthesize", "--motion", "--poses", "."), "is a directory")
