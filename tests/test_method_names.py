"""A method's name is checked in one place (linkage.arguments.check_method): every front door
that takes one (the command line's --method, the library's ``method=``) refuses an unknown
name with the same message shape, listing the names its registry knows."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import linkage
from linkage.arguments import check_method, check_method_list
from linkage.errors import InputError
from linkage.methods import METHODS, SCALAR_METHODS
from linkage.problems.scalar import ScalarProblem
from linkage.solve import SYSTEM_METHODS

SAMPLE = str(Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml")
SRC = Path(linkage.__file__).resolve().parent

SHAPE = re.compile(r"unknown method 'nope' in (--method|method)( for [^;]+)?; choose from (.+)")
"""The one message shape: the name refused, the option or argument, what the methods apply
to, and the names to choose from."""


def choices(message: str) -> list[str]:
    match = SHAPE.fullmatch(message)
    assert match, message
    return match.group(3).split(", ")


def the_refusal(*args: object) -> str:
    with pytest.raises(InputError) as refused:
        check_method(*args)  # type: ignore[arg-type]
    return str(refused.value)


def test_check_method_returns_a_known_name_and_refuses_others_by_one_shape():
    assert check_method("--method", "lm", SYSTEM_METHODS) == "lm"
    assert choices(the_refusal("method", "nope", SYSTEM_METHODS, "for a system")) == list(SYSTEM_METHODS)
    assert the_refusal("--method", "nope", ("a", "b")) == ("unknown method 'nope' in --method; "
                                                           "choose from a, b")


@pytest.mark.parametrize("value", [None, 3, ["newton"], {"newton": 1}, b"newton", "Newton", " newton"])
def test_a_method_that_is_no_known_str_is_an_input_error_not_a_type_error(value):
    message = the_refusal("method", value, METHODS)
    assert message.startswith(f"unknown method {value!r} in method; choose from ")


def test_the_list_parser_refuses_an_entry_through_the_one_check():
    with pytest.raises(InputError) as refused:
        check_method_list("--method", "newton,nope", SCALAR_METHODS)
    assert str(refused.value) == the_refusal("--method", "nope", (*SCALAR_METHODS, "all"))


# every command that takes --method: its arguments, the check it makes, the names it lists
COMMANDS = {
    "solve": (["solve", "--method", "nope"], (*SCALAR_METHODS, "all"), ""),
    "solve FILE": (["solve", SAMPLE, "--method", "nope"], SYSTEM_METHODS, "for a mechanism file"),
    "sweep FILE": (["sweep", SAMPLE, "--method", "nope"], SYSTEM_METHODS, "for a mechanism file"),
    "sweep (equation)": (["sweep", "--method", "nope"], SCALAR_METHODS,
                         "for the four-bar equation (sweep without FILE)"),
    "stress": (["stress", "--quick", "--method", "newton", "--method", "nope"],
               tuple(dict.fromkeys((*SCALAR_METHODS, *SYSTEM_METHODS))), ""),
}


@pytest.mark.parametrize("case", list(COMMANDS))
def test_every_command_refuses_an_unknown_method_by_the_one_check_with_exit_2(cli, case):
    args, known, scope = COMMANDS[case]
    run = cli(*args)
    assert run.code == 2, (run.code, run.out, run.err)
    lines = run.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), run.err
    message = lines[0].removeprefix("error: ")
    assert message == the_refusal("--method", "nope", known, scope)
    assert choices(message) == list(known)  # the registry's names, in its order


def _F(q):
    return [q[0] - 1.0, q[1] - 2.0]


# every library function that takes method=: the call, the names it lists, its scope
LIBRARY = {
    "solve_scalar": (lambda: linkage.solve_scalar(lambda x: x - 1.0, method="nope", x0=0.0), METHODS, ""),
    "solve_scalar ScalarProblem": (lambda: linkage.solve_scalar(
        ScalarProblem(lambda x: x - 1.0, fprime=lambda x: 1.0), method="nope", x0=0.0), METHODS, ""),
    "solve_system": (lambda: linkage.solve_system(_F, (0.0, 0.0), method="nope"), SYSTEM_METHODS,
                     "for a system"),
    "solve_system record off": (lambda: linkage.solve_system(_F, (0.0, 0.0), method="nope", record=False),
                                SYSTEM_METHODS, "for a system"),
    "sweep": (lambda: linkage.sweep(SAMPLE, [0.0, 10.0], method="nope"), SYSTEM_METHODS, "for a mechanism"),
}


@pytest.mark.parametrize("case", list(LIBRARY))
def test_every_library_front_door_refuses_an_unknown_method_by_the_one_check(case):
    call, known, scope = LIBRARY[case]
    with pytest.raises(InputError) as refused:
        call()
    assert str(refused.value) == the_refusal("method", "nope", known, scope)
    assert choices(str(refused.value)) == list(known)


def test_a_registered_method_is_listed_by_the_library_refusal(monkeypatch):
    """solve_scalar reads the registry when called, so a method registered after import is
    listed (a tuple imported before registration would not list it)."""
    from linkage import methods

    entry = methods.METHODS["bisection"]
    monkeypatch.setitem(methods.METHODS, "halving", entry)
    with pytest.raises(InputError) as refused:
        linkage.solve_scalar(lambda x: x - 1.0, method="nope", x0=0.0)
    assert choices(str(refused.value))[-1] == "halving"


def test_unknown_method_is_worded_in_one_module():
    """The refusal is written once (linkage/arguments.py); a second copy is a second rule."""
    homes = sorted(str(p.relative_to(SRC)) for p in SRC.rglob("*.py") if "unknown method" in p.read_text())
    assert homes == ["arguments.py"]
