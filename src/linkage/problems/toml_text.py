"""Mechanism files written as TOML text: a value, a key, and a drawing's loops form
(``linkage convert --form loops``, derived by :func:`.joints.loops_doc`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..units import degrees
from .joints import loops_doc


def toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v).__name__)


def toml_key(k: str) -> str:
    """A key as TOML reads it back: bare when it can be, else quoted (a joint may be named
    "B'" or "joint 1")."""
    return k if k and all(c.isascii() and (c.isalnum() or c in "_-") for c in k) else toml_value(k)


def loops_text(doc: Mapping[str, Any], source: str = "<mechanism>", mechanism: Any = None) -> str:
    """The derived loops-form file of a drawing, as TOML text: each loop under a comment
    naming its joints, so the loop-closure equations the drawing implies can be read.
    ``mechanism``: the drawing as read (kinematics.loading.parse_mechanism); when its [driver]
    value is off the drawing, its guesses (the drawing's branch there) are written."""
    d = loops_doc(doc, source)
    out = [f"# the vector loops of {source}, derived from its joints and links (linkage convert)",
           f"name = {toml_value(d['name'])}"]
    note = None if mechanism is None else mechanism.drawing_note
    if note is not None:  # guesses on the drawing's branch at [driver] value
        for u in mechanism.unknowns:
            d["unknowns"][u.name]["guess"] = degrees(u.value) if u.kind == "angle" else u.value
        out.insert(1, f"# {note.removeprefix(source + ': ')}: the guesses are there")
    if d.get("description"):
        out.append(f"description = {toml_value(d['description'])}")
    first = d["loops"][0]["joints"][0] if d["loops"] else "the first joint"
    out += [f"length_unit = {toml_value(d['length_unit'])}",
            f"origin = {toml_value(d['origin'])}  # where {first} is drawn",
            "", "[parameters]  # the drawn lengths (and the ground's angles; e_: a slider line's offset)"]
    out += [f"{toml_key(k)} = {toml_value(v)}" for k, v in d["parameters"].items()]
    out += ["", "[driver]"] + [f"{k} = {toml_value(v)}" for k, v in d["driver"].items()]
    out += ["", "[unknowns]  # each moving link's angle (s_: a slider's travel), guessed from the drawing"]
    out += [f"{toml_key(k)} = {toml_value(v)}" for k, v in d["unknowns"].items()]
    for loop in d["loops"]:
        names = loop["joints"]
        shown = [n or "(foot)" for n in names]
        out += ["", f"# {' -> '.join([*shown, shown[0]])}: the sum of these vectors is zero",
                "[[loops]]", f"name = {toml_value(loop['name'])}", f"joints = {toml_value(names)}",
                "vectors = ["]
        out += [f"  {toml_value(v)},  # {a} -> {b}"
                for v, a, b in zip(loop["vectors"], shown, [*shown[1:], shown[0]])]
        out.append("]")
    for name, p in d.get("points", {}).items():
        out += ["", f"[points.{toml_key(name)}]  # on a link, nothing else attached",
                f"from = {toml_value(p['from'])}", f"vectors = {toml_value(p['vectors'])}"]
    return "\n".join(out) + "\n"
