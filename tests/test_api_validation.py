"""Issue 18, "the Python API validates its arguments once": every exported function meets
every misuse with one InputError that names the argument (never a TypeError, ValueError or
IndexError from the internals, never a silently wrong result), and the command line
reaches the same checks (one "error: " line, exit 2)."""

from __future__ import annotations

import inspect
import math
import multiprocessing
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import linkage
from linkage.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
FOURBAR = ROOT / "sample_inputs" / "fourbar_me581.toml"
CRANK = ROOT / "sample_inputs" / "crank_rocker.toml"
SLIDER = ROOT / "sample_inputs" / "slider_crank.toml"

M = linkage.load_mechanism(FOURBAR)
Q = linkage.solve_system(M.problem(), record=False).x
GRID = {"r2": (1.0, 1.5, 2)}
TWO = [0.0, 90.0]


def _gen():
    yield from (0.0, 1.0)


def _F(x):
    return [x[0] ** 2 - 2.0, x[1] - 1.0]


def _J(x):
    return [[2.0 * x[0], 0.0], [0.0, 1.0]]


def _links(*lengths):
    return linkage.coefficients_from_links(*lengths)


def _scan(vary=GRID, **options):
    options.setdefault("values", TWO)
    return linkage.scan_designs(M, vary, **options)


def _late(fn, above):
    """fn, until x[0] passes ``above``: then None (a function wrong only away from x0)."""
    return lambda x: fn(x) if x[0] <= above else None


def _bisect_result():
    return linkage.solve_scalar(lambda x: x - 1.0, method="bisection", bracket=(0.0, 3.0))


def _synth(f="log10(x)", x_range=(1, 2), alpha_range=(90, 150), phi_range=(0, 90), **options):
    return linkage.synthesize_function(f, x_range, alpha_range, phi_range, **options)


# (exported function, label, call, the argument the message must name)
JM = linkage.load_mechanism(FOURBAR.parent / "fourbar_me581_joints.toml")
JQ = [u.value for u in JM.unknowns]
SM = linkage.load_mechanism(ROOT / "docs" / "crank_rocker_loads.toml")  # with masses, for simulate

POSES = [(0, 0, 0), (1, 0.2, 10), (2, 0.5, 25), (2.8, 1.2, 40), (3.2, 2, 60)]
"""Five poses of a body (linkage.synthesize_motion)."""
NINE = [(0.25, 0), (0.52, 0.1), (0.8, 0.7), (1.2, 1), (1.4, 1.3), (1.1, 1.48), (0.7, 1.4), (0.2, 1),
        (0.02, 0.4)]
"""Nine points (linkage.synthesize_path): Wampler, Morgan and Sommese's Problem 3."""
TIMED = [(0.0, 0.0, 0.0), (1.0, 0.2, 20.0), (1.5, 1.0, 45.0), (1.0, 2.0, 80.0), (0.0, 2.2, 120.0)]
"""Five points with the crank's angle at each (linkage.synthesize_path, prescribed timing)."""

BATTERY = [
    # sweep: values, rates, options
    ("sweep", "2-D values", lambda: linkage.sweep(M, np.zeros((3, 2))), "values"),
    ("sweep", "None values", lambda: linkage.sweep(M, None), "values"),
    ("sweep", "complex values", lambda: linkage.sweep(M, [1 + 2j, 3j]), "values"),
    ("sweep", "numpy complex values", lambda: linkage.sweep(M, np.array([1 + 1j])), "values"),
    ("sweep", "generator values", lambda: linkage.sweep(M, _gen()), "values"),
    ("sweep", "str values", lambda: linkage.sweep(M, "abc"), "values"),
    ("sweep", "str entries", lambda: linkage.sweep(M, ["a", "b"]), "values"),
    ("sweep", "a number for values", lambda: linkage.sweep(M, 5), "values"),
    ("sweep", "nested values", lambda: linkage.sweep(M, [[1.0], [2.0]]), "values"),
    ("sweep", "bool values", lambda: linkage.sweep(M, [True, False]), "values"),
    ("sweep", "NaN value", lambda: linkage.sweep(M, [0.0, math.nan]), "values"),
    ("sweep", "inf value", lambda: linkage.sweep(M, [0.0, math.inf]), "values"),
    ("sweep", "speed with units", lambda: linkage.sweep(M, TWO, speed="10rpm"), "speed"),
    ("sweep", "speed text", lambda: linkage.sweep(M, TWO, speed="abc"), "speed"),
    ("sweep", "NaN speed", lambda: linkage.sweep(M, TWO, speed=math.nan), "speed"),
    ("sweep", "complex speed", lambda: linkage.sweep(M, TWO, speed=1 + 1j), "speed"),
    ("sweep", "bool speed", lambda: linkage.sweep(M, TWO, speed=True), "speed"),
    ("sweep", "huge speed", lambda: linkage.sweep(M, TWO, speed=1e300), "speed"),
    ("sweep", "accel text", lambda: linkage.sweep(M, TWO, speed=10, accel="x"), "accel"),
    ("sweep", "NaN accel", lambda: linkage.sweep(M, TWO, speed=10, accel=math.nan), "accel"),
    ("sweep", "accel without speed", lambda: linkage.sweep(M, TWO, accel=5.0), "accel"),
    ("sweep", "tol text", lambda: linkage.sweep(M, TWO, tol="x"), "tol"),
    ("sweep", "negative tol", lambda: linkage.sweep(M, TWO, tol=-1), "tol"),
    ("sweep", "max_iter 2.7", lambda: linkage.sweep(M, TWO, max_iter=2.7), "max_iter"),
    ("sweep", "max_iter True", lambda: linkage.sweep(M, TWO, max_iter=True), "max_iter"),
    ("sweep", "batch text", lambda: linkage.sweep(M, TWO, batch="yes"), "batch"),
    ("sweep", "progress not callable", lambda: linkage.sweep(M, TWO, progress=3), "progress"),
    ("sweep", "joints text", lambda: linkage.sweep(M, TWO, joints="x"), "joints"),
    ("sweep", "branch a number", lambda: linkage.sweep(M, TWO, branch=3), "branch"),
    ("sweep", "mechanism None", lambda: linkage.sweep(None, TWO), "mechanism"),
    ("sweep", "loads a dict", lambda: linkage.sweep(JM, TWO, loads={"rocker": 5}), "loads"),
    ("sweep", "loads on a loops-form mechanism", lambda: linkage.sweep(M, TWO, loads=linkage.Loads()),
     "joints form"),
    ("sweep", "mechanism a number", lambda: linkage.sweep(3, TWO), "mechanism"),
    # position_rates: q, rates, driver, mechanism
    ("position_rates", "q too short", lambda: linkage.position_rates(M, Q[:1], speed=1.0), "q"),
    ("position_rates", "q too long", lambda: linkage.position_rates(M, (*Q, 1.0), speed=1.0), "q"),
    ("position_rates", "q None", lambda: linkage.position_rates(M, None), "q"),
    ("position_rates", "q text", lambda: linkage.position_rates(M, "ab"), "q"),
    ("position_rates", "q NaN", lambda: linkage.position_rates(M, (math.nan, 0.0)), "q"),
    ("position_rates", "q inf", lambda: linkage.position_rates(M, (math.inf, 0.0)), "q"),
    ("position_rates", "q complex", lambda: linkage.position_rates(M, (1j, 0.0)), "q"),
    ("position_rates", "q 2-D", lambda: linkage.position_rates(M, np.zeros((2, 2))), "q"),
    ("position_rates", "q generator", lambda: linkage.position_rates(M, _gen()), "q"),
    ("position_rates", "q a number", lambda: linkage.position_rates(M, 1.0), "q"),
    ("position_rates", "speed with units", lambda: linkage.position_rates(M, Q, speed="10rpm"), "speed"),
    ("position_rates", "NaN speed", lambda: linkage.position_rates(M, Q, speed=math.nan), "speed"),
    ("position_rates", "complex speed", lambda: linkage.position_rates(M, Q, speed=1j), "speed"),
    ("position_rates", "accel text", lambda: linkage.position_rates(M, Q, speed=1.0, accel="x"), "accel"),
    ("position_rates", "inf accel", lambda: linkage.position_rates(M, Q, speed=1.0, accel=math.inf), "accel"),
    ("position_rates", "driver text", lambda: linkage.position_rates(M, Q, driver="x"), "driver"),
    ("position_rates", "NaN driver", lambda: linkage.position_rates(M, Q, driver=math.nan), "driver"),
    ("position_rates", "mechanism None", lambda: linkage.position_rates(None, Q), "mechanism"),
    # scan_designs: the specs and every option
    ("scan_designs", "vary None", lambda: linkage.scan_designs(M, None, values=TWO), "vary"),
    ("scan_designs", "loads a number",
     lambda: linkage.scan_designs(JM, {"coupler": (100, 120, 2)}, values=TWO, loads=3), "loads"),
    ("scan_designs", "loads on a loops-form mechanism",
     lambda: linkage.scan_designs(M, {"r3": (100, 120, 2)}, values=TWO,
                                  loads=linkage.Loads(torques={"r4": 1.0})),
     "joints form"),
    ("scan_designs", "text speed",
     lambda: linkage.scan_designs(JM, {"coupler": (100, 120, 2)}, values=TWO, speed="10rpm"), "speed"),
    # forces: each argument by its own name
    ("forces", "a path for the mechanism", lambda: linkage.forces("x.toml", [0.0, 0.0]), "mechanism"),
    ("forces", "a loops-form mechanism", lambda: linkage.forces(M, Q), "joints form"),
    ("forces", "loads a dict", lambda: linkage.forces(JM, JQ, {"rocker": 5}), "loads"),
    ("forces", "NaN speed", lambda: linkage.forces(JM, JQ, speed=math.nan), "speed"),
    ("forces", "text accel", lambda: linkage.forces(JM, JQ, accel="fast"), "accel"),
    # synthesize_function: each argument by its own name
    ("synthesize_function", "no function",
     lambda: linkage.synthesize_function(None, (1, 2), (90, 150), (0, 90)), "function"),
    ("synthesize_function", "x_range of one",
     lambda: linkage.synthesize_function("x", (1,), (90, 150), (0, 90)), "x_range"),
    ("synthesize_function", "text alpha_range",
     lambda: linkage.synthesize_function("x", (1, 2), "a:b", (0, 90)), "alpha_range"),
    ("synthesize_function", "NaN phi_range",
     lambda: linkage.synthesize_function("x", (1, 2), (90, 150), (0, math.nan)), "phi_range"),
    ("synthesize_function", "two points",
     lambda: linkage.synthesize_function("x", (1, 2), (90, 150), (0, 90), points=2), "points"),
    ("synthesize_function", "unknown spacing",
     lambda: linkage.synthesize_function("x", (1, 2), (90, 150), (0, 90), spacing="best"), "spacing"),
    ("synthesize_function", "negative ground",
     lambda: linkage.synthesize_function("x", (1, 2), (90, 150), (0, 90), ground=-1.0), "ground"),
    ("synthesize_path", "points None", lambda: linkage.synthesize_path(None), "points"),
    ("synthesize_path", "four points", lambda: linkage.synthesize_path(NINE[:4]), "points"),
    ("synthesize_path", "ten points", lambda: linkage.synthesize_path([*NINE, (3, 3)]), "points"),
    ("synthesize_path", "one via point for six",
     lambda: linkage.synthesize_path(NINE[:6], via=NINE[6:7]), "via"),
    ("synthesize_path", "a via point on a point",
     lambda: linkage.synthesize_path(NINE[:6], via=[NINE[0], *NINE[6:8]]), "via"),
    ("synthesize_path", "a NaN via point",
     lambda: linkage.synthesize_path(NINE[:6], via=[(math.nan, 0), *NINE[6:8]]), "via"),
    ("synthesize_path", "orbits 0", lambda: linkage.synthesize_path(NINE, orbits=0), "orbits"),
    ("search_path", "points None", lambda: linkage.search_path(None), "points"),
    ("search_path", "four points", lambda: linkage.search_path(NINE[:4]), "points"),
    ("search_path", "samples 0", lambda: linkage.search_path(NINE[:6], samples=0), "samples"),
    ("search_path", "samples of nine points", lambda: linkage.search_path(NINE, samples=2), "samples"),
    ("search_path", "samples with via", lambda: linkage.search_path(NINE[:6], samples=2, via=NINE[6:]),
     "samples"),
    ("search_path", "via text", lambda: linkage.search_path(NINE[:6], via="abc"), "via"),
    ("search_path", "seed 1.5", lambda: linkage.search_path(NINE[:6], seed=1.5), "seed"),
    ("search_path", "min_transmission 100",
     lambda: linkage.search_path(NINE[:6], min_transmission=100), "min_transmission"),
    ("search_path", "workers 0", lambda: linkage.search_path(NINE[:6], workers=0), "workers"),
    ("synthesize_path", "a NaN point", lambda: linkage.synthesize_path([*NINE[:8], (math.nan, 0)]), "points"),
    ("synthesize_path", "a point twice", lambda: linkage.synthesize_path([*NINE[:8], NINE[0]]), "points"),
    ("synthesize_path", "seed -1", lambda: linkage.synthesize_path(NINE, seed=-1), "seed"),
    ("synthesize_path", "workers 0", lambda: linkage.synthesize_path(NINE, workers=0), "workers"),
    ("synthesize_path", "scheduler 3", lambda: linkage.synthesize_path(NINE, scheduler=3), "scheduler"),
    ("synthesize_path", "six timed points", lambda: linkage.synthesize_path([*TIMED, (3, 3, 150)]), "points"),
    ("synthesize_path", "four timed points", lambda: linkage.synthesize_path(TIMED[:4]), "points"),
    ("synthesize_path", "timed and untimed points", lambda: linkage.synthesize_path([*TIMED[:4], (3, 3)]),
     "points"),
    ("synthesize_path", "a NaN crank angle", lambda: linkage.synthesize_path([*TIMED[:4], (3, 3, math.nan)]),
     "points"),
    ("synthesize_path", "a text crank angle", lambda: linkage.synthesize_path([*TIMED[:4], (3, 3, "x")]),
     "points"),
    ("synthesize_path", "timed, workers 2", lambda: linkage.synthesize_path(TIMED, workers=2), "workers"),
    ("synthesize_path", "timed, seed -1", lambda: linkage.synthesize_path(TIMED, seed=-1), "seed"),
    ("synthesize_path", "timed, min_transmission 100",
     lambda: linkage.synthesize_path(TIMED, min_transmission=100), "min_transmission"),
    ("synthesize_motion", "poses None", lambda: linkage.synthesize_motion(None), "poses"),
    ("synthesize_motion", "two poses", lambda: linkage.synthesize_motion(POSES[:2]), "poses"),
    ("synthesize_motion", "a NaN pose",
     lambda: linkage.synthesize_motion([*POSES[:4], (0, math.nan, 1)]), "poses"),
    ("synthesize_motion", "a pose twice", lambda: linkage.synthesize_motion([*POSES[:4], POSES[0]]), "poses"),
    ("synthesize_motion", "min_transmission True",
     lambda: linkage.synthesize_motion(POSES, min_transmission=True), "min_transmission"),
    ("synthesize_motion", "seed -1", lambda: linkage.synthesize_motion(POSES, seed=-1), "seed"),
    ("scan_designs", "vary a list", lambda: linkage.scan_designs(M, [("r2", 1, 2, 3)], values=TWO), "vary"),
    ("scan_designs", "spec of one", lambda: linkage.scan_designs(M, {"r2": (1,)}, values=TWO), "vary"),
    ("scan_designs", "spec text", lambda: linkage.scan_designs(M, {"r2": "abc"}, values=TWO), "vary"),
    ("scan_designs", "spec None", lambda: linkage.scan_designs(M, {"r2": None}, values=TWO), "vary"),
    ("scan_designs", "spec NaN", lambda: _scan({"r2": (math.nan, 2, 3)}), "vary"),
    ("scan_designs", "n 2.7", lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5, 2.7)}, values=TWO), "vary"),
    ("scan_designs", "n -3", lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5, -3)}, values=TWO), "vary"),
    ("scan_designs", "n text", lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5, "x")}, values=TWO), "vary"),
    ("scan_designs", "n True", lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5, True)}, values=TWO), "vary"),
    ("scan_designs", "complex lo", lambda: linkage.scan_designs(M, {"r2": (1j, 2, 2)}, values=TWO), "vary"),
    ("scan_designs", "name a number", lambda: linkage.scan_designs(M, {3: (1, 2, 2)}, values=TWO), "vary"),
    ("scan_designs", "workers -1", lambda: linkage.scan_designs(M, GRID, values=TWO, workers=-1), "workers"),
    ("scan_designs", "workers 0", lambda: linkage.scan_designs(M, GRID, values=TWO, workers=0), "workers"),
    ("scan_designs", "workers 2.5", lambda: _scan(workers=2.5), "workers"),
    ("scan_designs", "workers 100000",
     lambda: linkage.scan_designs(M, GRID, values=TWO, workers=100_000), "workers"),
    ("scan_designs", "workers text", lambda: _scan(workers="x"), "workers"),
    ("scan_designs", "1000 processes",
     lambda: linkage.scan_designs(M, GRID, values=TWO, scheduler="processes", workers=1000), "workers"),
    ("scan_designs", "chunk -3", lambda: linkage.scan_designs(M, GRID, values=TWO, chunk=-3), "chunk"),
    ("scan_designs", "chunk 1.5", lambda: linkage.scan_designs(M, GRID, values=TWO, chunk=1.5), "chunk"),
    ("scan_designs", "top -1", lambda: linkage.scan_designs(M, GRID, values=TWO, top=-1), "top"),
    ("scan_designs", "top 1.5", lambda: linkage.scan_designs(M, GRID, values=TWO, top=1.5), "top"),
    ("scan_designs", "tol -1", lambda: linkage.scan_designs(M, GRID, values=TWO, tol=-1), "tol"),
    ("scan_designs", "seed -1", lambda: linkage.scan_designs(M, GRID, values=TWO, seed=-1), "seed"),
    ("scan_designs", "seed 1.5", lambda: linkage.scan_designs(M, GRID, values=TWO, seed=1.5), "seed"),
    ("scan_designs", "seed text", lambda: linkage.scan_designs(M, GRID, values=TWO, seed="x"), "seed"),
    ("scan_designs", "samples 2.5",
     lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5)}, values=TWO, samples=2.5), "samples"),
    ("scan_designs", "samples text",
     lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5)}, values=TWO, samples="x"), "samples"),
    ("scan_designs", "sampling text",
     lambda: linkage.scan_designs(M, {"r2": (1.0, 1.5)}, values=TWO, samples=3, sampling="x"), "sampling"),
    ("scan_designs", "NaN value", lambda: linkage.scan_designs(M, GRID, values=[0.0, math.nan]), "values"),
    ("scan_designs", "values text", lambda: linkage.scan_designs(M, GRID, values="abc"), "values"),
    ("scan_designs", "values 2-D", lambda: linkage.scan_designs(M, GRID, values=[[1.0]]), "values"),
    ("scan_designs", "values complex", lambda: linkage.scan_designs(M, GRID, values=[1j]), "values"),
    ("scan_designs", "values generator", lambda: linkage.scan_designs(M, GRID, values=_gen()), "values"),
    ("scan_designs", "sort a number", lambda: linkage.scan_designs(M, GRID, values=TWO, sort=3), "sort"),
    ("scan_designs", "where a number", lambda: linkage.scan_designs(M, GRID, values=TWO, where=3), "where"),
    ("scan_designs", "descending text",
     lambda: linkage.scan_designs(M, GRID, values=TWO, descending="x"), "descending"),
    ("scan_designs", "scheduler a number",
     lambda: linkage.scan_designs(M, GRID, values=TWO, scheduler=3), "scheduler"),
    ("scan_designs", "scheduler unknown",
     lambda: linkage.scan_designs(M, GRID, values=TWO, scheduler="bogus"), "scheduler"),
    ("scan_designs", "mechanism None", lambda: linkage.scan_designs(None, GRID), "mechanism"),
    # solve_system: callables that return the wrong thing, starts, options
    ("solve_system", "F returns None", lambda: linkage.solve_system(lambda x: None, (1.0, 1.0), jac=_J), "F"),
    ("solve_system", "F returns text", lambda: linkage.solve_system(lambda x: "ab", (1.0, 1.0), jac=_J), "F"),
    ("solve_system", "F returns complex",
     lambda: linkage.solve_system(lambda x: [1j, 1j], (1.0, 1.0), jac=_J), "F"),
    ("solve_system", "F returns None (fd)",
     lambda: linkage.solve_system(lambda x: None, (1.0, 1.0), method="newton-fd"), "F"),
    ("solve_system", "F returns None (lm)",
     lambda: linkage.solve_system(lambda x: None, (1.0, 1.0), method="lm"), "F"),
    ("solve_system", "F reads past x",
     lambda: linkage.solve_system(lambda x: [x[0], x[1], x[2]], (1.0, 1.0), method="newton-fd"), "F"),
    ("solve_system", "jac returns None",
     lambda: linkage.solve_system(_F, (1.0, 1.0), jac=lambda x: None), "jac"),
    ("solve_system", "jac returns None (recorded)",
     lambda: linkage.solve_system(_F, [1.0, 1.0], jac=lambda x: None), "jac"),
    ("solve_system", "F returns None after x0",
     lambda: linkage.solve_system(_late(_F, 1.2), (1.0, 1.0), jac=_J, record=False), "F"),
    ("solve_system", "F returns None after x0 (lm)",
     lambda: linkage.solve_system(_late(_F, 1.2), (1.0, 1.0), method="lm"), "F"),
    ("solve_system", "jac returns None after x0",
     lambda: linkage.solve_system(_F, (1.0, 1.0), jac=_late(_J, 1.2)), "jac"),
    ("solve_system", "jac not callable", lambda: linkage.solve_system(_F, (1.0, 1.0), jac=3), "jac"),
    ("solve_system", "x0 text", lambda: linkage.solve_system(_F, "ab", jac=_J), "x0"),
    ("solve_system", "x0 complex", lambda: linkage.solve_system(_F, (1j, 1.0), jac=_J), "x0"),
    ("solve_system", "x0 NaN", lambda: linkage.solve_system(_F, (math.nan, 1.0), jac=_J), "x0"),
    ("solve_system", "x0 2-D", lambda: linkage.solve_system(_F, np.ones((2, 2)), jac=_J), "x0"),
    ("solve_system", "x0 generator", lambda: linkage.solve_system(_F, _gen(), jac=_J), "x0"),
    ("solve_system", "x0 a number", lambda: linkage.solve_system(_F, 1.0, jac=_J), "x0"),
    ("solve_system", "x0 short for a mechanism", lambda: linkage.solve_system(M.problem(), (1.0,)), "x0"),
    ("solve_system", "tol -1", lambda: linkage.solve_system(_F, (1.0, 1.0), jac=_J, tol=-1), "tol"),
    ("solve_system", "max_iter 2.7",
     lambda: linkage.solve_system(_F, (1.0, 1.0), jac=_J, max_iter=2.7), "max_iter"),
    ("solve_system", "fd_step text",
     lambda: linkage.solve_system(_F, (1.0, 1.0), method="newton-fd", fd_step="x"), "fd_step"),
    ("solve_system", "fd_step beyond the bound",
     lambda: linkage.solve_system(_F, (1.0, 1.0), method="newton-fd", fd_step=1e300), "fd_step"),
    ("solve_system", "F None", lambda: linkage.solve_system(None, (1.0, 1.0)), "F"),
    # solve_scalar: g and the bracket
    ("solve_scalar", "g returns None",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="fixed-point", x0=1.5, g=lambda x: None), "g"),
    ("solve_scalar", "g returns None after x0",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="fixed-point", x0=3.0,
                                  g=lambda x: 0.5 * x + 0.5 if x > 1.2 else None), "g"),
    ("solve_scalar", "f returns None after x0",
     lambda: linkage.solve_scalar(lambda x: x - 1 if x < 0.7 else None, method="secant",
                                  x0=0.1, x1=0.2), "f"),
    ("solve_scalar", "g returns text",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="fixed-point", x0=1.5, g=lambda x: "a"), "g"),
    ("solve_scalar", "g not callable",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="fixed-point", x0=1.0, g=3), "g"),
    ("solve_scalar", "fprime not callable",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="newton", x0=1.0, fprime=3), "fprime"),
    ("solve_scalar", "bracket a number",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="bisection", bracket=3), "bracket"),
    ("solve_scalar", "bracket generator",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="bisection", bracket=_gen()), "bracket"),
    ("solve_scalar", "bracket of three",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="bisection", bracket=(0, 1, 2)), "bracket"),
    ("solve_scalar", "x0 complex",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="secant", x0=1j, x1=2.0), "x0"),
    ("solve_scalar", "f None", lambda: linkage.solve_scalar(None, method="newton", x0=1.0), "f"),
    ("solve_scalar", "tol -1",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="bisection", bracket=(0, 2), tol=-1), "tol"),
    # the rest of the exports
    ("fourbar_equation", "alpha text", lambda: linkage.fourbar_equation("x"), "alpha"),
    ("fourbar_equation", "alpha None", lambda: linkage.fourbar_equation(None), "alpha"),
    ("fourbar_equation", "R1 complex", lambda: linkage.fourbar_equation(40.0, 1j), "R1"),
    ("coefficients_from_links", "a text", lambda: _links("a", 1, 1, 1), "link length a"),
    ("coefficients_from_links", "b None", lambda: _links(1, None, 1, 1), "link length b"),
    ("coefficients_from_links", "c complex", lambda: _links(1, 1, 1j, 1), "link length c"),
    ("equation_problem", "equation None", lambda: linkage.equation_problem(None), "equation"),
    ("equation_problem", "equation a number", lambda: linkage.equation_problem(3), "equation"),
    ("equation_problem", "g a number", lambda: linkage.equation_problem("x - 1", g=3), "g"),
    ("load_mechanism", "path None", lambda: linkage.load_mechanism(None), "path"),
    ("load_mechanism", "path a number", lambda: linkage.load_mechanism(3), "path"),
    ("analyze", "result None", lambda: linkage.analyze(None), "result"),
    ("analyze", "result text", lambda: linkage.analyze("x"), "result"),
    ("analyze", "problem a number", lambda: linkage.analyze(_bisect_result(), 3), "problem"),
    ("synthesize_function", "at a number", lambda: _synth(at=3), "at"),
    ("synthesize_function", "samples 2.5", lambda: _synth(samples=2.5), "samples"),
    ("assemblies", "mechanism None", lambda: linkage.assemblies(None), "mechanism"),
    ("assemblies", "driver text", lambda: linkage.assemblies(M, "abc"), "driver"),
    ("assemblies", "driver NaN", lambda: linkage.assemblies(M, math.nan), "driver"),
    ("assemblies", "driver True", lambda: linkage.assemblies(M, True), "driver"),
    ("assemblies", "driver 1e300 deg", lambda: linkage.assemblies(M, 1e300), "driver"),
    ("assemblies", "seed -1", lambda: linkage.assemblies(M, seed=-1), "seed"),
    ("assemblies", "seed 1.5", lambda: linkage.assemblies(M, seed=1.5), "seed"),
    # bools are not numbers, anywhere (arguments.check_number, the one rule)
    ("forces", "bool speed", lambda: linkage.forces(JM, JQ, speed=True), "speed"),
    ("forces", "bool accel", lambda: linkage.forces(JM, JQ, accel=False), "accel"),
    ("forces", "bool driver", lambda: linkage.forces(JM, JQ, driver=True), "driver"),
    ("forces", "bool torque",
     lambda: linkage.forces(JM, JQ, linkage.Loads(torques={"rocker": True})), "torque"),
    ("forces", "bool force",
     lambda: linkage.forces(JM, JQ, linkage.Loads(forces={"B": (True, 0.0)})), "force"),
    ("forces", "bool mass", lambda: linkage.forces(JM, JQ, linkage.Loads(masses={
        "rocker": linkage.Mass(True, (0.0, 0.0), 0.0)})), "mass"),
    ("forces", "bool gravity",
     lambda: linkage.forces(JM, JQ, linkage.Loads(torques={"rocker": 1.0}, gravity=(False, True))),
     "gravity"),
    ("forces", "torque beyond the float range",
     lambda: linkage.forces(JM, JQ, linkage.Loads(torques={"rocker": 10**400})), "torque"),
    ("forces", "gravity beyond the float range",
     lambda: linkage.forces(JM, JQ, linkage.Loads(torques={"rocker": 1.0}, gravity=(10**400, 0.0))),
     "gravity"),
    ("synthesize_function", "bool ground", lambda: _synth(ground=True), "ground"),
    ("synthesize_function", "bool x_range", lambda: _synth(x_range=(False, True)), "x_range"),
    ("synthesize_function", "bool alpha_range", lambda: _synth(alpha_range=(False, 150)), "alpha_range"),
    ("synthesize_function", "bool min_transmission",
     lambda: _synth(min_transmission=True), "min_transmission"),
    ("synthesize_function", "bool at", lambda: _synth(at=[True, 1.5, 2.0]), "at"),
    ("sweep", "bool tol", lambda: linkage.sweep(M, TWO, tol=True), "tol"),
    ("position_rates", "bool driver", lambda: linkage.position_rates(M, Q, driver=True), "driver"),
    ("position_rates", "bool speed", lambda: linkage.position_rates(M, Q, speed=True), "speed"),
    ("scan_designs", "bool lo", lambda: linkage.scan_designs(M, {"r2": (True, 1.5, 2)}, values=TWO), "vary"),
    ("scan_designs", "bool speed",
     lambda: linkage.scan_designs(JM, {"coupler": (100, 120, 2)}, values=TWO, speed=True), "speed"),
    ("solve_scalar", "bool x0",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="newton", x0=True, fprime=lambda x: 1.0), "x0"),
    ("solve_scalar", "bool tol",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="bisection", bracket=(0, 3), tol=True), "tol"),
    ("solve_scalar", "bool bracket",
     lambda: linkage.solve_scalar(lambda x: x - 1, method="bisection", bracket=(False, 3)), "bracket"),
    ("solve_system", "bool x0", lambda: linkage.solve_system(M.problem(), (True, 1.0)), "x0"),
    ("solve_system", "bool tol", lambda: linkage.solve_system(M.problem(), tol=True), "tol"),
    ("fourbar_equation", "bool alpha", lambda: linkage.fourbar_equation(True), "alpha"),
    ("fourbar_equation", "bool R1", lambda: linkage.fourbar_equation(40.0, True), "R1"),
    ("coefficients_from_links", "bool a", lambda: _links(True, 1, 1, 1), "link length a"),
    # the methods a user calls with numbers: Mechanism.with_values, Loads.merged
    ("Mechanism.with_values", "text value",
     lambda: JM.with_values({"coupler": "5"}, {}), "overrides['coupler']"),
    ("Mechanism.with_values", "bool value",
     lambda: JM.with_values({"coupler": True}, {}), "overrides['coupler']"),
    ("Mechanism.with_values", "None overrides", lambda: JM.with_values(None, {}), "overrides"),
    ("Mechanism.with_values", "bool guess", lambda: M.with_values({}, {"theta3": True}), "guesses['theta3']"),
    ("Mechanism.with_values", "guesses a list",
     lambda: M.with_values({}, [("theta3", 1.0)]), "guesses"),
    ("Loads.merged", "None", lambda: linkage.Loads().merged(None), "Loads"),
    ("Loads.merged", "a dict", lambda: linkage.Loads().merged({"torques": {"rocker": 1.0}}), "Loads"),
    # instant_centres and centrodes: each argument by its own name
    ("instant_centres", "mechanism None", lambda: linkage.instant_centres(None), "mechanism"),
    ("instant_centres", "mechanism a number", lambda: linkage.instant_centres(3), "mechanism"),
    ("instant_centres", "driver_value text", lambda: linkage.instant_centres(JM, "abc"), "driver_value"),
    ("instant_centres", "NaN driver_value", lambda: linkage.instant_centres(JM, math.nan), "driver_value"),
    ("instant_centres", "complex driver_value", lambda: linkage.instant_centres(JM, 1j), "driver_value"),
    ("instant_centres", "branch a number", lambda: linkage.instant_centres(JM, branch=3), "branch"),
    ("instant_centres", "a pose that does not assemble", lambda: linkage.instant_centres(JM, 150.0),
     "cannot be assembled"),
    ("centrodes", "mechanism None", lambda: linkage.centrodes(None, TWO), "mechanism"),
    ("centrodes", "values None", lambda: linkage.centrodes(JM, None), "values"),
    ("centrodes", "generator values", lambda: linkage.centrodes(JM, _gen()), "values"),
    ("centrodes", "NaN value", lambda: linkage.centrodes(JM, [0.0, math.nan]), "values"),
    ("centrodes", "body a number", lambda: linkage.centrodes(JM, TWO, 3), "body"),
    ("centrodes", "body unknown", lambda: linkage.centrodes(JM, TWO, "wheel"), "body"),
    ("centrodes", "branch a number", lambda: linkage.centrodes(JM, TWO, branch=3), "branch"),
    # tolerance: the tolerances by name, and every option
    ("tolerance", "mechanism None", lambda: linkage.tolerance(None, {"r2": 0.1}, TWO), "mechanism"),
    ("tolerance", "tolerances None", lambda: linkage.tolerance(M, None, TWO), "tolerances"),
    ("tolerance", "tolerances empty", lambda: linkage.tolerance(M, {}, TWO), "tolerances"),
    ("tolerance", "tolerances a list", lambda: linkage.tolerance(M, [("r2", 0.1)], TWO), "tolerances"),
    ("tolerance", "a negative tolerance",
     lambda: linkage.tolerance(M, {"r2": -0.1}, TWO), "tolerances['r2']"),
    ("tolerance", "a zero tolerance", lambda: linkage.tolerance(M, {"r2": 0.0}, TWO), "tolerances['r2']"),
    ("tolerance", "a text tolerance", lambda: linkage.tolerance(M, {"r2": "0.1"}, TWO), "tolerances['r2']"),
    ("tolerance", "a bool tolerance", lambda: linkage.tolerance(M, {"r2": True}, TWO), "tolerances['r2']"),
    ("tolerance", "a NaN tolerance", lambda: linkage.tolerance(M, {"r2": math.nan}, TWO), "tolerances['r2']"),
    ("tolerance", "an unknown parameter", lambda: linkage.tolerance(M, {"r9": 0.1}, TWO), "tolerances['r9']"),
    ("tolerance", "an angle", lambda: linkage.tolerance(M, {"theta1": 0.1}, TWO), "tolerances['theta1']"),
    ("tolerance", "the driver", lambda: linkage.tolerance(M, {"theta2": 0.1}, TWO), "tolerances['theta2']"),
    ("tolerance", "a key a number", lambda: linkage.tolerance(M, {3: 0.1}, TWO), "tolerances"),
    ("tolerance", "a joint of a Mechanism", lambda: linkage.tolerance(JM, {"O4.x": 0.1}, TWO), "O4.x"),
    ("tolerance", "zero samples", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, samples=0), "samples"),
    ("tolerance", "samples 2.5", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, samples=2.5), "samples"),
    ("tolerance", "samples True", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, samples=True), "samples"),
    ("tolerance", "seed -1", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, seed=-1), "seed"),
    ("tolerance", "values None is the default; values text",
     lambda: linkage.tolerance(M, {"r2": 0.1}, "abc"), "values"),
    ("tolerance", "NaN value", lambda: linkage.tolerance(M, {"r2": 0.1}, [0.0, math.nan]), "values"),
    ("tolerance", "no values", lambda: linkage.tolerance(M, {"r2": 0.1}, []), "values"),
    ("tolerance", "distribution beta",
     lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, distribution="beta"), "distribution"),
    ("tolerance", "distribution None",
     lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, distribution=None), "distribution"),
    ("tolerance", "branch a number", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, branch=3), "branch"),
    ("tolerance", "tol -1", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, tol=-1.0), "tol"),
    ("tolerance", "workers 0", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, workers=0), "workers"),
    ("tolerance", "scheduler 7", lambda: linkage.tolerance(M, {"r2": 0.1}, TWO, scheduler=7), "scheduler"),
    # simulate: each argument by its own name
    ("simulate", "mechanism None", lambda: linkage.simulate(None, "1", (0, 1)), "mechanism"),
    ("simulate", "a mechanism without masses", lambda: linkage.simulate(JM, "1", (0, 1)), "mass"),
    ("simulate", "time reversed", lambda: linkage.simulate(SM, "1", (1, 0)), "time"),
    ("simulate", "time a number", lambda: linkage.simulate(SM, "1", 2.0), "time"),
    ("simulate", "time bools", lambda: linkage.simulate(SM, "1", (False, True)), "time"),
    ("simulate", "drive an unknown variable", lambda: linkage.simulate(SM, "x + 1", (0, 1)), "drive"),
    ("simulate", "drive None", lambda: linkage.simulate(SM, None, (0, 1)), "drive"),
    ("simulate", "drive bool", lambda: linkage.simulate(SM, True, (0, 1)), "drive"),
    ("simulate", "constants NaN", lambda: linkage.simulate(SM, "T0", (0, 1), constants={"T0": math.nan}),
     "constants"),
    ("simulate", "theta0 text", lambda: linkage.simulate(SM, "1", (0, 1), theta0="a"), "theta0"),
    ("simulate", "omega0 bool", lambda: linkage.simulate(SM, "1", (0, 1), omega0=True), "omega0"),
    ("simulate", "negative viscous friction",
     lambda: linkage.simulate(SM, "1", (0, 1), friction_viscous=-1.0), "friction_viscous"),
    ("simulate", "coulomb friction at no pin",
     lambda: linkage.simulate(SM, "1", (0, 1), friction_coulomb={"Z": 0.1}), "friction_coulomb"),
    ("simulate", "negative flywheel", lambda: linkage.simulate(SM, "1", (0, 1), flywheel=-1.0), "flywheel"),
    ("simulate", "samples 1", lambda: linkage.simulate(SM, "1", (0, 1), samples=1), "samples"),
    ("simulate", "rtol 0", lambda: linkage.simulate(SM, "1", (0, 1), rtol=0.0), "rtol"),
    ("simulate", "loads a dict", lambda: linkage.simulate(SM, "1", (0, 1), loads={"rocker": 1}), "loads"),
]


def test_the_battery_covers_every_exported_function():
    """A new public function joins the battery, or this fails (methods, "Class.method", too)."""
    functions = {name for name in linkage.__all__
                 if inspect.isfunction(getattr(linkage, name)) or inspect.isbuiltin(getattr(linkage, name))}
    methods = {row[0] for row in BATTERY if "." in row[0]}
    assert functions == {row[0] for row in BATTERY} - methods
    for method in methods:
        owner, name = method.split(".")
        assert owner in linkage.__all__ and callable(getattr(getattr(linkage, owner), name))


def test_bools_are_not_numbers_anywhere_in_the_api():
    """speed=True, ground=True and x_range=(False, True) were read as 1 and 0, while
    Loads(torques={"r": True}) was refused: one rule (arguments.check_number) refuses them all."""
    from linkage.arguments import check_number, is_real

    for value in (True, False, np.bool_(True), "5", b"5", 1j, np.complex128(1.0)):
        assert not is_real(value)
        with pytest.raises(InputError, match=r"must be a (real )?number"):
            check_number("x", value)
    for value, expected in ((5, 5.0), (2.5, 2.5), (np.float32(0.5), 0.5), (np.int64(3), 3.0)):
        assert check_number("x", value) == expected


def test_with_values_of_text_and_merged_of_none_are_input_errors():
    """m.with_values({"coupler": "5"}, {}) raised TypeError; Loads().merged(None) AttributeError."""
    with pytest.raises(InputError, match=r"overrides\['coupler'\] must be a number, got '5'"):
        JM.with_values({"coupler": "5"}, {})
    with pytest.raises(InputError, match=r"other: give a linkage.Loads to merge, got None"):
        linkage.Loads().merged(None)
    assert JM.with_values({"coupler": np.float64(130.0)}, {}).parameters["coupler"].value == 130.0


@pytest.mark.parametrize("function,label,call,argument", BATTERY, ids=[f"{r[0]}: {r[1]}" for r in BATTERY])
def test_each_misuse_raises_input_error_naming_the_argument(function, label, call, argument):
    with pytest.raises(InputError) as caught:
        call()
    message = str(caught.value)
    assert argument in message, message
    assert "\n" not in message


def test_api_misuses_are_input_errors_not_type_value_or_index_errors():
    """Issue 18's examples, each once more by name: sweep with a 2-D array, None, complex
    values or a generator; speed="10rpm"; position_rates with a q of the wrong length; bad
    scan_designs specs; an F or g that returns None."""
    examples = [
        lambda: linkage.sweep(M, np.zeros((3, 2))), lambda: linkage.sweep(M, None),
        lambda: linkage.sweep(M, [1j]), lambda: linkage.sweep(M, _gen()),
        lambda: linkage.sweep(M, TWO, speed="10rpm"), lambda: linkage.position_rates(M, Q[:1], speed=1.0),
        lambda: linkage.scan_designs(M, {"r2": None}, values=TWO),
        lambda: linkage.solve_system(lambda x: None, (1.0, 1.0), jac=_J),
        lambda: linkage.solve_scalar(lambda x: x - 1, method="fixed-point", x0=1.5, g=lambda x: None),
    ]
    for call in examples:
        with pytest.raises(InputError):
            call()


# --- the seven silent misuses ------------------------------------------------------------------

def test_scan_designs_workers_minus_one_is_refused_not_run():
    # it returned no records at all, silently
    with pytest.raises(InputError, match=r"workers must be a whole number from 1 to \d+.*got -1"):
        linkage.scan_designs(M, GRID, values=TWO, workers=-1)


def test_scan_designs_chunk_minus_three_is_refused_not_run():
    with pytest.raises(InputError, match=r"chunk must be a whole number from 1 to .*got -3"):
        linkage.scan_designs(M, GRID, values=TWO, chunk=-3)


def test_scan_designs_top_minus_one_is_refused_not_an_empty_result():
    # top=-1 returned no records at all, silently (as did workers=-1 and chunk=-3)
    with pytest.raises(InputError, match=r"top must be a whole number >= 1, got -1"):
        linkage.scan_designs(M, GRID, values=TWO, top=-1)
    assert len(linkage.scan_designs(M, GRID, values=TWO, top=1)["design"]) == 1


def test_scan_designs_tol_minus_one_is_refused():
    with pytest.raises(InputError, match=r"tol must be > 0, got -1"):
        linkage.scan_designs(M, GRID, values=TWO, tol=-1)


def test_scan_designs_nan_driver_values_are_refused_not_counted_infeasible():
    with pytest.raises(InputError, match=r"values\[1\] must be finite, got nan"):
        linkage.scan_designs(M, GRID, values=[0.0, math.nan, 90.0])


def test_scan_designs_grid_n_2_7_is_refused_not_truncated():
    with pytest.raises(InputError, match=r"vary\['r2'\] n must be a whole number.*got 2\.7"):
        linkage.scan_designs(M, {"r2": (1.0, 1.5, 2.7)}, values=TWO)


def test_sweep_nan_speed_is_refused_not_nan_rates():
    # NaN speed gave every position NaN velocities, silently
    with pytest.raises(InputError, match=r"speed must be finite, got nan"):
        linkage.sweep(M, TWO, speed=math.nan)


def test_position_rates_q_too_long_is_refused_not_truncated():
    with pytest.raises(InputError, match=r"q needs 2 values \(theta3, theta4\), got 3"):
        linkage.position_rates(M, (*Q, 1.0), speed=1.0)


# --- valid input unchanged ------------------------------------------------------------------------

def test_valid_arguments_still_give_the_same_answers():
    """numpy arrays, ranges, numpy scalars and ints are still read as before."""
    a = linkage.sweep(M, [0.0, 10.0, 20.0], speed=2.0, accel=1.0)
    b = linkage.sweep(M, np.array([0.0, 10.0, 20.0]), speed=np.float64(2.0), accel=1)
    c = linkage.sweep(M, range(0, 30, 10), speed=2, accel=np.int64(1))
    for other in (b, c):
        assert [p.solution for p in other.positions] == [p.solution for p in a.positions]
        assert [p.rates for p in other.positions] == [p.rates for p in a.positions]
    r = linkage.position_rates(M, list(Q), speed=2.0)
    assert r == linkage.position_rates(str(FOURBAR), np.array(Q), speed=2.0)
    rows = linkage.scan_designs(CRANK, {"r2": (20.0, 30.0, np.int64(3))}, values=[0.0, 90.0, 180.0],
                                workers=1, chunk=2, top=3)
    assert list(rows["design"]) == [0, 1, 2]


def test_workers_are_bounded_by_a_limit_the_message_states():
    from linkage.arguments import MAX_PROCESSES, MAX_THREADS, check_workers

    cores = os.cpu_count() or 1
    assert MAX_THREADS == min(256, 4 * cores) and MAX_PROCESSES == max(2, cores)
    assert check_workers("workers", MAX_THREADS, "threads") == MAX_THREADS
    with pytest.raises(InputError, match=f"from 1 to {MAX_THREADS} .*this machine has {cores} cores"):
        check_workers("workers", MAX_THREADS + 1, None)
    with pytest.raises(InputError, match=f"from 1 to {MAX_PROCESSES} .*one process per core"):
        check_workers("workers", MAX_PROCESSES + 1, "processes")


# --- the command line reaches the same checks -------------------------------------------------------

def _one_error_line(r, *needles):
    assert r.code == 2, (r.code, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.err
    assert "internal error" not in r.err and "Traceback" not in r.err
    for needle in needles:
        assert needle in lines[0], lines[0]


def test_cli_scan_seed_minus_one_is_one_error_line_exit_2(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:30", "--samples", "3", "--seed", "-1")
    _one_error_line(r, "--seed", "got -1")


def test_cli_scan_workers_100000_is_refused_with_the_limit_not_a_thread_error(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:30:3", "--chunk", "1", "--workers", "100000")
    _one_error_line(r, "--workers", "got 100000", "threads per core")


def test_cli_scan_processes_workers_1000_is_refused_before_any_process_starts(cli):
    before = len(multiprocessing.active_children())
    r = cli("scan", str(CRANK), "--vary", "r2=20:30:3", "--chunk", "1", "--scheduler", "processes",
            "--workers", "1000")
    _one_error_line(r, "--workers", "got 1000", "one process per core")
    assert len(multiprocessing.active_children()) == before


# --- fuzz: only a result or InputError --------------------------------------------------------------

JUNK = st.one_of(
    st.none(), st.booleans(), st.integers(-3, 4), st.text(max_size=4),
    st.floats(allow_nan=True, allow_infinity=True), st.complex_numbers(max_magnitude=10),
    st.lists(st.floats(-400, 400), max_size=3),
    st.lists(st.one_of(st.none(), st.text(max_size=2), st.floats(allow_nan=True)), max_size=3),
    st.just(np.zeros((2, 2))), st.just(np.array([1 + 1j])), st.builds(lambda: iter([1.0, 2.0])),
)
VALUES = st.one_of(JUNK, st.lists(st.floats(-360, 360), min_size=1, max_size=4))
SMALL_FLOAT = st.one_of(JUNK, st.floats(-5, 5))
FUZZ = settings(max_examples=40, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])


def _only_result_or_input_error(call):
    try:
        call()
    except InputError as exc:
        assert str(exc) and "\n" not in str(exc)


@FUZZ
@given(values=VALUES, speed=st.one_of(st.none(), SMALL_FLOAT), accel=SMALL_FLOAT,
       tol=st.one_of(JUNK, st.just(1e-10)), joints=JUNK,
       branch=st.one_of(JUNK, st.sampled_from(["open", "crossed"])))
def test_fuzz_sweep_gives_a_result_or_input_error(values, speed, accel, tol, joints, branch):
    _only_result_or_input_error(lambda: linkage.sweep(M, values, speed=speed, accel=accel, tol=tol,
                                                      joints=joints, branch=branch))


@FUZZ
@given(q=st.one_of(JUNK, st.lists(st.floats(-10, 10), min_size=2, max_size=2)),
       speed=st.one_of(st.none(), SMALL_FLOAT), accel=SMALL_FLOAT,
       driver=st.one_of(st.none(), SMALL_FLOAT), slider=st.booleans())
def test_fuzz_position_rates_gives_a_result_or_input_error(q, speed, accel, driver, slider):
    m = linkage.load_mechanism(SLIDER) if slider else M
    _only_result_or_input_error(lambda: linkage.position_rates(m, q, speed=speed, accel=accel, driver=driver))


SPEC = st.one_of(JUNK, st.tuples(st.floats(20, 30), st.floats(30, 40)),
                 st.tuples(st.floats(20, 30), st.floats(30, 40), st.one_of(JUNK, st.integers(1, 3))))


@FUZZ
@given(vary=st.one_of(JUNK, st.dictionaries(st.sampled_from(["r2", "r4", "zz"]), SPEC, max_size=2)),
       samples=st.one_of(st.none(), JUNK), seed=st.one_of(JUNK, st.integers(0, 9)),
       values=st.one_of(st.none(), VALUES), top=st.one_of(st.none(), JUNK), chunk=st.one_of(st.none(), JUNK),
       workers=st.one_of(st.none(), JUNK),
       scheduler=st.one_of(st.none(), JUNK, st.sampled_from(["synchronous", "bogus"])))
def test_fuzz_scan_designs_gives_a_result_or_input_error(vary, samples, seed, values, top, chunk, workers,
                                                        scheduler):
    if values is None:
        values = TWO  # a full default cycle per design would only slow the fuzz down
    _only_result_or_input_error(lambda: linkage.scan_designs(
        CRANK, vary, samples=samples, seed=seed, values=values, top=top, chunk=chunk, workers=workers,
        scheduler=scheduler))


RETURNS = st.one_of(JUNK, st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=2, max_size=2))
ROWS = st.lists(st.floats(-3, 3), min_size=2, max_size=2)
MATRICES = st.one_of(JUNK, st.lists(ROWS, min_size=2, max_size=2))


@FUZZ
@given(phi=RETURNS, jac=st.one_of(st.none(), MATRICES), x0=st.one_of(JUNK, st.tuples(st.floats(-3, 3),
                                                                                     st.floats(-3, 3))),
       method=st.sampled_from(["newton", "newton-fd", "lm"]), record=st.booleans(),
       tol=st.one_of(JUNK, st.just(1e-8)))
def test_fuzz_solve_system_gives_a_result_or_input_error(phi, jac, x0, method, record, tol):
    J = None if jac is None else (lambda x: jac)
    if method == "newton" and J is None:
        J = _J
    _only_result_or_input_error(lambda: linkage.solve_system(lambda x: phi, x0, jac=J, method=method,
                                                             record=record, tol=tol))


SCALAR_RETURNS = st.one_of(JUNK, st.floats(-5, 5))


@FUZZ
@given(fx=SCALAR_RETURNS, gx=SCALAR_RETURNS,
       method=st.sampled_from(["bisection", "hybrid", "secant", "newton", "fixed-point"]),
       x0=st.one_of(st.none(), SMALL_FLOAT),
       bracket=st.one_of(st.none(), JUNK, st.tuples(st.floats(-3, 0), st.floats(0.5, 3))),
       record=st.booleans())
def test_fuzz_solve_scalar_gives_a_result_or_input_error(fx, gx, method, x0, bracket, record):
    def f(x):
        return x - 0.25 if x < 0.0 else fx  # a real function near the start, then the drawn value

    _only_result_or_input_error(lambda: linkage.solve_scalar(
        f, method=method, x0=x0, x1=None if x0 is None else 2.0, bracket=bracket,
        fprime=lambda x: gx, g=lambda x: gx, record=record))
