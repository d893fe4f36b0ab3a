"""Where the sample mechanisms are: inside an installed package, or in a source checkout."""

from __future__ import annotations

from pathlib import Path

from .errors import InputError


def sample_path(name: str) -> Path:
    """The path of a sample mechanism file such as ``fourbar_me581.toml``."""
    here = Path(__file__).resolve().parent
    for base in (here / "sample_inputs", here.parents[1] / "sample_inputs"):
        candidate = base / name
        if candidate.exists():
            return candidate
    raise InputError(f"sample mechanism {name} is not installed with this copy of linkage")
