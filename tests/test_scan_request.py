"""A scan is checked once, by one function (linkage.scan.request.open_scan), whoever asks:
the same bad input through ``linkage.scan_designs`` and ``linkage scan`` is refused with the
same message, the option spelt as each spells it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import linkage
from linkage.errors import InputError
from linkage.scan.request import CLI_NAMES

CRANK = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"
GRID = {"r2": (20.0, 30.0, 3)}

# (the API's keywords, the command line's arguments), one bad input each
SAME_INPUT = {
    "unknown sort column": ({"sort": "nope"}, ["--sort", "nope"]),
    "unknown branch": ({"branch": "left"}, ["--branch", "left"]),
    "descending without sort": ({"descending": True}, ["--desc"]),
    "bad filter": ({"where": "r2 >"}, ["--where", "r2 >"]),
    "negative seed": ({"seed": -1}, ["--seed", "-1"]),
    "zero chunk": ({"chunk": 0}, ["--chunk", "0"]),
    "unknown scheduler": ({"scheduler": "fast"}, ["--scheduler", "fast"]),
    "unknown sampling": ({"sampling": "sobol", "samples": 3}, ["--sampling", "sobol", "--samples", "3"]),
    "grid and samples": ({"samples": 5}, ["--samples", "5"]),
    "negative tolerance": ({"tol": -1.0}, ["--tol", "-1"]),
}


def in_cli_spelling(message: str) -> str:
    """The API's message with each option keyword as the command line spells it."""
    for keyword in ("descending", "sort", "seed", "chunk", "scheduler", "sampling", "samples", "tol"):
        message = re.sub(rf"(?<![-\w]){keyword}\b", CLI_NAMES.get(keyword, "--" + keyword), message)
    return message


@pytest.mark.parametrize("case", list(SAME_INPUT))
def test_the_api_and_the_command_refuse_the_same_scan_with_one_message(cli, case):
    keywords, args = SAME_INPUT[case]
    with pytest.raises(InputError) as refused:
        linkage.scan_designs(str(CRANK), GRID, values=[0.0, 90.0], **keywords)
    run = cli("scan", str(CRANK), "--vary", "r2=20:30:3", "--to", "90", "--step", "90", *args)
    assert run.code == 2, (run.out, run.err)
    printed = run.err.strip().removeprefix("error: ")
    api = str(refused.value)
    assert printed in (api, in_cli_spelling(api)), (printed, api)


def test_a_scan_request_spells_options_as_its_asker():
    from linkage.kinematics.loading import load
    from linkage.scan.request import ScanRequest

    m = load(str(CRANK))
    assert ScanRequest(m, (), (0.0,)).name("descending") == "descending"
    assert ScanRequest(m, (), (0.0,), cli=True).name("descending") == "--desc"
    assert ScanRequest(m, (), (0.0,), cli=True).name("sort") == "--sort"
