"""A Result made on a solve's hot path keeps its meta and history raw and builds them on
first read: every reader (attributes, equality, replace, copy, pickle) sees the Result an
ordinary construction gives."""

from __future__ import annotations

import copy
import dataclasses
import pickle

from linkage import fourbar_equation, solve_scalar, solve_system
from linkage.result import Result


def _ordinary(r: Result) -> Result:
    return Result(**{name: getattr(r, name) for name in r.__dataclass_fields__})


def test_a_fast_results_fields_read_as_an_ordinary_results():
    p = fourbar_equation(70.0)
    for record in (False, True):
        for method, start in (("newton", {"x0": 50.0}), ("secant", {"x0": 50.0, "x1": 60.0}),
                              ("bisection", {"bracket": (40.0, 60.0)})):
            r = solve_scalar(p, method=method, tol=1e-12, record=record, **start)
            assert "meta" not in vars(r)  # kept raw until read
            expected = {"var": "phi", "unit": "deg", "title": p.title, "tol": 1e-12, "rtol": 0.0,
                        "ftol": None, **start}
            assert {k: r.meta[k] for k in expected} == expected
            assert (r.history is not None) == record
            if record:
                assert len(r.records) == len(r.history.rows) > 0
            plain = _ordinary(r)
            assert plain == r and repr(plain) == repr(r)
            assert dataclasses.replace(r, detail="x").meta == r.meta


def test_a_fast_result_copies_and_pickles_as_its_fields():
    r = solve_scalar(fourbar_equation(70.0), method="newton", x0=50.0, tol=1e-12, record=True)
    for twin in (copy.copy(r), copy.deepcopy(r), pickle.loads(pickle.dumps(r))):
        assert twin == r and twin.history == r.history and twin.meta == r.meta
        assert not any(name.startswith("raw_") for name in vars(twin))


def test_a_system_solves_meta_is_built_on_read():
    def F(q: list[float]) -> list[float]:
        return [q[0] * q[0] + q[1] * q[1] - 4.0, q[0] - q[1]]

    def J(q: list[float]) -> list[list[float]]:
        return [[2.0 * q[0], 2.0 * q[1]], [1.0, -1.0]]

    fast = solve_system(F, (1.0, 2.0), jac=J, tol=1e-12, record=False)
    full = solve_system(F, [1.0, 2.0], jac=J, tol=1e-12, record=False)
    assert fast.converged and "meta" not in vars(fast)
    assert fast.meta == full.meta == {"tol": 1e-12, "rtol": 0.0, "ftol": 1e-12, "names": ("x1", "x2"),
                                      "kinds": ("", ""), "title": ""}
    assert fast == full and fast.njev == full.njev > 0


def test_an_ordinary_result_holds_its_own_fields():
    from linkage.result import Status

    r = Result("newton", 1.0, Status.CONVERGED_STEP, 1, 3, 0.0, 0.0, meta={"tol": 1.0})
    assert r.meta == {"tol": 1.0} and r.history is None
    assert Result("newton", 1.0, Status.CONVERGED_STEP, 1, 3, 0.0, 0.0).meta is None


def test_the_statements_of_fast_source_make_what_result_fast_makes():
    """A generated loop builds its Result from fast_source's statements instead of calling
    Result.fast: the same type, the same namespace (raw fields included), equal fields."""
    from linkage.result import FAST_NAMES, Status, fast_source

    for detail, history in (("", None), ("why", None), ("", "(tuple, ())")):
        lines = fast_source('"newton"', "1.5", "_status", "3", "7", "1e-9", "2e-17", "detail",
                            "(dict, ())", history)
        namespace = {**FAST_NAMES, "_status": Status.CONVERGED_STEP}
        exec("def build(detail):\n" + "".join(f"    {line}\n" for line in lines), namespace)
        made = namespace["build"](detail)
        fast = Result.fast("newton", 1.5, Status.CONVERGED_STEP, 3, 7, 1e-9, 2e-17, detail, 0, (dict, ()),
                           None if history is None else (tuple, ()))
        assert type(made) is type(fast) is Result
        assert vars(made) == vars(fast)
        assert made == fast and made.meta == fast.meta == {} and made.history == fast.history


def test_fast_source_with_njev_makes_what_result_fast_makes():
    """The system loops' Result (with Jacobian evaluations, or none) from fast_source's
    statements: the namespace of Result.fast's, njev stored only where it is not 0."""
    from linkage.result import FAST_NAMES, Status, fast_source

    for detail, njev in (("", 0), ("", 4), ("why", 2)):
        lines = fast_source('"newton"', "(1.5, 2.5)", "_status", "3", "7", "1e-9", "2e-17", "detail",
                            "(dict, ())", None, "njev")
        namespace = {**FAST_NAMES, "_status": Status.CONVERGED_STEP}
        exec("def build(detail, njev):\n" + "".join(f"    {line}\n" for line in lines), namespace)
        made = namespace["build"](detail, njev)
        fast = Result.fast("newton", (1.5, 2.5), Status.CONVERGED_STEP, 3, 7, 1e-9, 2e-17, detail, njev,
                           (dict, ()))
        assert type(made) is type(fast) is Result
        assert vars(made) == vars(fast)
        assert made == fast and made.njev == fast.njev == njev
