"""The JSON contract of a solve (result_dict) and JSON-safe values; files are written by render.writers."""

from __future__ import annotations

from typing import Any

from ..result import Result, finite_or_none


def clean(v: Any) -> Any:
    """JSON-safe values: NaN and infinities become null, tuples become lists."""
    if isinstance(v, dict):
        return {str(k): clean(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [clean(x) for x in v]
    return finite_or_none(v)


def result_dict(result: Result, solution: dict[str, Any], convergence: dict[str, Any] | None,
                extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """The JSON contract for one solve: method, status, converged, solution,
    iterations (row objects keyed by column label with units), convergence, nfev."""
    out: dict[str, Any] = {
        "method": result.method,
        "status": result.status.value,
        "converged": result.converged,
        "message": result.message,
        "solution": solution if result.converged else None,
        "last_iterate": solution,
        "iterations": result.history.as_dicts() if result.history is not None else [],
        "iterations_elided": result.history.elided if result.history is not None else 0,
        "convergence": convergence or {"order": None},
        "nfev": result.nfev,
        "njev": result.njev,
        "iteration_count": result.iterations,
        "error": result.error,
        "residual": result.residual,
    }
    if extra:
        out.update(extra)
    return clean(out)


def to_json(obj: Any) -> str:
    import json

    return json.dumps(clean(obj), indent=2, allow_nan=False) + "\n"
