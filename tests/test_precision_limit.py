"""A zero step where doubles are wider apart than the tolerance is not convergence: at
x = 1e17 deg the doubles are 16 deg apart, Newton's step of a few degrees rounds to nothing,
and f there is far from zero (found by an adversarial pass: `linkage solve --x0 1e17` said
"converged", f = -0.132, exit 0). The open methods' certificate (solve.certify_root) says
PRECISION_LIMIT there unless f is exactly zero."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

import linkage
from linkage.result import Status
from linkage.solve import certify_root


@pytest.mark.parametrize("x0", [1e17, 1e308])
def test_newton_far_out_is_not_converged_but_at_the_precision_limit(x0: float) -> None:
    r = linkage.solve_scalar(linkage.fourbar_equation(), method="newton", x0=x0)
    assert r.status is Status.PRECISION_LIMIT
    assert not r.converged
    assert abs(r.residual) > 1e-3  # the claim it no longer makes


@pytest.mark.parametrize("method", ["secant", "fixed-point"])
def test_the_other_open_methods_share_the_rule(method: str) -> None:
    p = linkage.fourbar_equation()
    kwargs = {"x0": 1e17, "x1": 1e17 + 64.0} if method == "secant" else {"x0": 1e17}
    r = linkage.solve_scalar(p, method=method, **kwargs)
    assert not r.converged


def test_the_certificate_refuses_a_width_no_double_but_x_lies_in() -> None:
    p = linkage.fourbar_equation()
    x = 1e17
    fx = p.f(x)
    status, detail, _ = certify_root(p, x, fx, 1e-6)
    assert status is Status.PRECISION_LIMIT and "16 apart" in detail
    # where the width reaches the next double, the certificate decides as before
    near = 54.887763188779
    status, _, _ = certify_root(p, near, p.f(near), 1e-9)
    assert status is Status.CONVERGED_STEP
    # an exact zero is a root whatever the spacing
    square = linkage.equation_problem("x*x - 4")
    assert certify_root(square, 2.0, 0.0, 1e-300)[0] is Status.CONVERGED_STEP
    assert math.ulp(2.0) > 1e-300


def test_the_command_line_says_so_and_exits_1() -> None:
    run = subprocess.run([sys.executable, "-m", "linkage", "solve", "--x0", "1e17"], capture_output=True,
                         text=True, check=False)
    assert run.returncode == 1
    assert "stopped at the limit of double precision" in run.stdout
    assert "converged" not in run.stdout.split("Convergence")[0].lower().replace("not converged", "")

