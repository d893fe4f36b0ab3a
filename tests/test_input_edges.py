"""Regressions from the 2026-11-29 adversarial pass (findings 8-10): library calls and
options at the edges of the double range or of the argument rules, each named after the
finding. Bad input: InputError/ParseError in the library, exit 2 and one line at the
command line."""

from __future__ import annotations

from pathlib import Path

import pytest

import linkage
from linkage.errors import InputError, ParseError

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = SAMPLES / "fourbar_me581.toml"


def one_line_exit_2(run) -> None:
    assert run.code == 2, (run.code, run.out, run.err)
    lines = [ln for ln in run.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), run.err
    assert "Traceback" not in run.err and "internal error" not in run.err


@pytest.mark.parametrize("links", [(1e-300, 1e300, 1, 1), (1e-100, 1e100, 1e-100, 1e100)])
def test_coefficients_from_links_with_a_ratio_underflowing_is_an_input_error(links):
    with pytest.raises(InputError, match="too extreme for double precision"):
        linkage.coefficients_from_links(*links)


def test_coefficients_from_links_keeps_a_tiny_coupler():
    # the coupler b only enters squared: a ratio 1e-200 is no reason to refuse (R3 = 1.5)
    r = linkage.coefficients_from_links(1, 1e-200, 1, 1)
    assert (r.r1, r.r2, r.r3) == (1.0, 1.0, 1.5)


def test_load_mechanism_with_a_null_byte_in_the_path_is_a_parse_error():
    with pytest.raises(ParseError, match="null byte"):
        linkage.load_mechanism("a\x00b")


def test_bisection_bracket_as_wide_as_the_double_range_is_valid(cli):
    # b - a overflows for [-1e308, 1e308]; the width b/2 - a/2 does not
    run = cli("solve", "-e", "x-1", "--method", "bisection", "--bracket", "-1e308", "1e308",
              "--max-iter", "1200")
    assert run.code == 0, run.out
    assert "converged:" in run.out
    r = linkage.solve_scalar(lambda x: x - 1.0, method="bisection", bracket=(-1e308, 1e308), max_iter=1200)
    assert r.converged and abs(r.x - 1.0) <= 1e-6


def test_fd_step_has_an_upper_bound(cli):
    # --fd-step 1e300 ran to NaN in max|dq| and det J = 0 beside cond J = 2.79
    one_line_exit_2(cli("solve", str(ME581), "--method", "newton-fd", "--fd-step", "1e300"))
    assert cli("solve", str(ME581), "--method", "newton-fd", "--fd-step", "1").code == 0


def test_negative_literal_vector_length_is_refused_as_parameters_are(tmp_path):
    text = ME581.read_text()
    assert 'length = "r1"' in text
    bad = tmp_path / "neg.toml"
    bad.write_text(text.replace('length = "r1"', "length = -30", 1))
    with pytest.raises(ParseError, match="a length must be > 0, got -30"):
        linkage.load_mechanism(bad)


@pytest.mark.parametrize("methods,why", [("all,foo", "unknown method 'foo'"),
                                         ("foo,all", "unknown method 'foo'"),
                                         ("all,newton", "'all' stands alone")])
def test_method_list_names_the_unknown_entry_not_all(cli, methods, why):
    run = cli("solve", "-e", "x-1", "--x0", "0", "--method", methods)
    one_line_exit_2(run)
    assert why in run.err


@pytest.mark.parametrize("equation", ["9**9**9**9", "exp(1000) + x", "x + 10**400.0"])
def test_overflowing_constant_expression_is_bad_input(cli, equation):
    # it raises OverflowError at every x: exit 2, not a failed run (exit 1)
    run = cli("solve", "-e", equation, "--x0", "1")
    one_line_exit_2(run)
    assert "overflows a double" in run.err


def test_overflow_to_inf_without_an_error_is_still_an_equation(cli):
    # 1e308*10 is inf in IEEE arithmetic, 1/inf = 0: f(x) = x - 1 (no exception, not refused)
    assert cli("solve", "-e", "1/(1e308*10)+x-1", "--x0", "1").code == 0


def test_tolerance_text_table_prints_a_dash_not_nan_where_not_assembled(cli):
    # r3 = 20 +-20 cm: not assembled at some positions (status not_assembled)
    run = cli("tolerance", str(ME581), "--tol", "r3=20", "--samples", "20", "--step", "30")
    assert run.code in (0, 1), run.err
    assert "not_assembled" in run.out
    assert "NaN" not in run.out and "nan" not in run.out
    rows = [ln for ln in run.out.splitlines() if "not_assembled" in ln and "—" in ln]
    assert rows, run.out


def test_refusals_name_the_option_the_command_line_has():
    """--fd-step refused as --fd-step (the library's check named it fd_step), simulate's
    --omega0 as --omega0 (the shared rate parser named it --speed)."""
    import subprocess
    import sys

    def err(*args: str) -> str:
        run = subprocess.run([sys.executable, "-m", "linkage", *args], capture_output=True, text=True,
                             check=False)
        assert run.returncode == 2
        return run.stderr

    assert err("solve", str(ME581), "--method", "newton-fd", "--fd-step", "2").startswith("error: --fd-step ")
    loaded = SAMPLES.parent / "docs" / "crank_rocker_loads.toml"
    assert err("simulate", str(loaded), "--time", "0:1", "--omega0", "1e300").startswith("error: --omega0 ")


def test_a_too_fine_driver_grid_is_refused_with_the_spacing_it_needs(cli):
    """1e-8 deg apart at 112 deg is 700,000 doubles apart: the refusal said "double precision
    resolves only 1.42e-14 there", which reads as if 1e-8 were fine; the rule (a spacing of at
    least GRID_RESOLUTION doubles) is now what it says, with the smallest spacing allowed."""
    run = cli("sweep", str(SAMPLES / "fourbar_me581.toml"), "--from", "112.0243128", "--to", "112.0243129",
              "--step", "1e-8")
    assert run.code == 2 and run.err.count("\n") == 1
    assert "it must be at least 1.42e-08 there" in run.err and "resolves only" not in run.err


@pytest.mark.parametrize("args", [("sweep", "--from", "0", "--to", "1e308", "--points", "361"),
                                  ("sweep", "--from", "-1e308", "--to", "1e308", "--points", "3"),
                                  ("draw", "-o", "sheet.dxf", "--from", "0", "--to", "1e308")])
def test_a_driver_span_near_the_largest_double_meets_the_drivers_bound(cli, tmp_path, monkeypatch, args):
    """The grid's (stop - start) * k overflowed before its division: "values[2] must be finite,
    got inf" named an internal list; the values are now finite and the driver's bound refuses them."""
    monkeypatch.chdir(tmp_path)
    if args[0] == "draw":
        pytest.importorskip("ezdxf")
    run = cli(args[0], str(SAMPLES / "crank_rocker.toml"), *args[1:])
    assert run.code == 2 and run.err.count("\n") == 1 and "an angle must be within +-1e+06 deg" in run.err
