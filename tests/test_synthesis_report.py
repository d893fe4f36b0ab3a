"""What a person sees from linkage synthesize: the max error of a linkage
that stops at a limit position, the check line, the design file's comments and the
messages when there is no linkage."""

from __future__ import annotations

import math
import re

from linkage.cli import run_cli
from linkage.synthesis import synthesize_function
from linkage.synthesis.function import dense_curve

GRASHOF = ("log10(x)", (1.0, 2.0), (225.0, 315.0), (255.0, 315.0))
"""A triple rocker whose input reaches a limit position at x = 1.965, before x = 2."""

TRANSMISSION = ("x**2", (1.0, 2.0), (270.0, 210.0), (60.0, 150.0))
"""R1, R2 > 0: no link drawn the other way, so the file's crank angle is alpha + 180."""


AT_A_LIMIT_DEG = 10 * math.degrees(math.sqrt(2.0 ** -52))
"""How closely two computations of the output angle at a limit position agree: there the
half-chord is the square root of a discriminant that is zero to rounding, so the angle is
determined to about sqrt(eps) rad (8.5e-7 deg); the linkage's R (LAPACK's solve, whose last
bits depend on the BLAS kernel) moves the limit by as much. Measured 4.2e-7 deg (OpenBLAS
SkylakeX) and 7.7e-7 deg (Sandybridge) between the reported and the plotted maximum."""


def _argv(case) -> list[str]:
    fn, (x0, x1), (a0, a1), (p0, p1) = case
    return ["synthesize", "--function", fn, "--x", f"{x0:g}:{x1:g}", "--alpha", f"{a0:g}:{a1:g}",
            "--phi", f"{p0:g}:{p1:g}"]


def test_max_error_of_a_linkage_stopped_by_a_limit_is_the_largest_reached() -> None:
    s = synthesize_function(*GRASHOF)
    assert "grashof" in s.defect_names
    # the plotted curve (401 steps, the same solver) never exceeds the reported maximum
    plotted = [abs(c.error_deg) for c in dense_curve(s) if c.error_deg is not None]
    assert max(plotted) > 2.0  # the error plunges near the limit (it was reported as 1.515)
    assert s.max_error_deg >= max(plotted) - AT_A_LIMIT_DEG
    # the maximum is at the limit position: A is as far from O4 as coupler + output reach
    # (or as near as their difference), by the linkage's own geometry
    k = s.linkage
    al = math.radians(s.request.alpha(s.at_x) + k.alpha_shift())
    reach = math.hypot(k.d + k.a * math.cos(al), k.a * math.sin(al))
    assert min(abs(reach - (k.b + k.c)), abs(reach - abs(k.b - k.c))) <= 1e-6 * k.b
    assert 1.96 < s.at_x < 1.965
    # the transmission angle there is 0: coupler and output in line
    assert s.transmission[0] < 0.01


def test_max_error_line_says_it_is_over_the_reached_part(capsys) -> None:
    assert run_cli([*_argv(GRASHOF), "-f", "plain"]) == 1
    line = next(t for t in capsys.readouterr().out.splitlines() if t.startswith("max |error|"))
    assert line.endswith("over the part of the range reached")
    assert run_cli(["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150",
                    "--phi", "0:90", "-f", "plain"]) == 0
    line = next(t for t in capsys.readouterr().out.splitlines() if t.startswith("max |error|"))
    assert "reached" not in line


def test_check_line_gives_alpha_in_one_turn(capsys) -> None:
    # alpha 231.03 at point 1, the input drawn the other way: 411.03 was printed
    assert run_cli([*_argv(GRASHOF), "-f", "plain"]) == 1
    line = next(t for t in capsys.readouterr().out.splitlines() if t.startswith("check:"))
    alpha = float(re.search(r"--alpha (\S+)", line).group(1))
    assert 0.0 <= alpha < 360.0
    s = synthesize_function(*GRASHOF)
    p = s.precision_points[0]
    assert abs(math.remainder(alpha - (p.alpha_deg + 180.0), 360.0)) < 1e-8  # the same angle


def test_design_file_comments_say_the_crank_angle_is_alpha_plus_180(tmp_path, capsys) -> None:
    from linkage.render.synthesis import design_text

    # a design with a defect exits 1 and writes no file (tests/test_mechanism_output.py):
    # its text is the one -o would write
    s = synthesize_function(*TRANSMISSION)
    assert s.defects
    text = design_text(s, "mm", "test")
    value = next(t for t in text.splitlines() if t.startswith("value ="))
    rng = next(t for t in text.splitlines() if t.startswith("range ="))
    a1 = s.precision_points[0].alpha_deg
    number = float(value.split("=")[1].split("#")[0])
    assert abs(math.remainder(number - (a1 + 180.0), 360.0)) < 1e-9  # the number is alpha + 180
    assert value.endswith("# alpha + 180 at precision point 1")  # was "alpha at precision point 1"
    assert rng.endswith("# the alpha range 270..210, as alpha + 180")
    # both links drawn the other way: the numbers are alpha's own, and said so
    good = tmp_path / "g.toml"
    assert run_cli(["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150",
                    "--phi", "0:90", "-o", str(good), "-f", "plain"]) == 0
    capsys.readouterr()
    lines = good.read_text().splitlines()
    assert next(t for t in lines if t.startswith("value =")).endswith("# alpha at precision point 1")
    rng = next(t for t in lines if t.startswith("range ="))
    assert rng == "range = [90.0, 150.0]  # the alpha range 90..150"


def test_no_linkage_says_zero_and_that_the_plot_is_not_drawn(tmp_path, capsys) -> None:
    picture, design = tmp_path / "e.png", tmp_path / "d.toml"
    argv = ["synthesize", "--function", "x**2", "--x", "1:2", "--alpha", "135:225", "--phi", "165:255"]
    assert run_cli([*argv, "-o", str(design), "--plot", str(picture), "-f", "plain"]) == 1
    out, err = capsys.readouterr()
    assert "R2 = 0)" in out and "R2 = -0" not in out
    assert f"note: {picture} not drawn: there is no real linkage" in err
    assert f"note: {design} not written: there is no real linkage" in err
    assert not picture.exists() and not design.exists()


def test_csv_holds_the_linkage_itself(capsys) -> None:
    assert run_cli(["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150",
                    "--phi", "0:90", "--ground", "100", "--unit", "cm", "-f", "csv",
                    "--table", "linkage"]) == 0
    block = capsys.readouterr().out.splitlines()
    assert block[0] == "link,length (cm)"
    s = synthesize_function("log10(x)", (1, 2), (90, 150), (0, 90), ground=100.0)
    got = {name: float(v) for name, v in (r.split(",") for r in block[1:])}
    assert got == {name: s.links[name] for name in ("input", "coupler", "output", "ground")}
