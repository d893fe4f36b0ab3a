"""The labels of rates (``dtheta3/dt``, ``B.v``), apart from :mod:`.rates` so that what
only prints them (a sweep's tables without rates) does not load the rate engine."""

from __future__ import annotations


def rate_label(name: str, order: int, joint: bool = False) -> str:
    """The label of a rate: ``dtheta3/dt``, ``d2theta3/dt2``, ``B.v``, ``B.a``."""
    if joint:
        return f"{name}.v" if order == 1 else f"{name}.a"
    return f"d{name}/dt" if order == 1 else f"d2{name}/dt2"
