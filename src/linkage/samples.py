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


def sample_dir() -> Path | None:
    here = Path(__file__).resolve().parent
    for base in (here / "sample_inputs", here.parents[1] / "sample_inputs"):
        if base.is_dir():
            return base
    return None


def samples() -> dict[str, str]:
    """Every shipped mechanism: file name -> its first comment line (what it is)."""
    base = sample_dir()
    out = {}
    for path in sorted(base.glob("*.toml")) if base else []:
        words: list[str] = []
        for line in path.read_text(encoding="utf-8").splitlines():
            if not line.startswith("#"):
                break
            text = line.lstrip("#").strip()
            if not text and words:
                break
            words.append(text)
        lead = " ".join(w for w in words if w)
        end = lead.find(". ")
        out[path.name] = lead[: end + 1] if end >= 0 else lead
    return out


def find_sample(name: str) -> Path:
    """A sample by file name, with or without ``.toml``."""
    known = samples()
    key = name if name.endswith(".toml") else f"{name}.toml"
    if key not in known:
        raise InputError(f"no sample mechanism {name!r}; the samples are {', '.join(known) or 'none'}")
    return sample_path(key)
