"""linkage synthesize -o FILE.toml: the chosen design as a mechanism file, by the one
mechanism-writing rule (options.write_mechanism), for function and motion generation."""

from __future__ import annotations

from pathlib import Path

import typer

from .options import write_mechanism


def write_chosen(result: object, output: Path, unit: str, force: bool) -> None:
    """-o FILE.toml: the design as a mechanism file (the one mechanism-writing rule,
    options.write_mechanism), or a note on stderr saying why it is not written."""
    import shlex
    import sys

    from ..render.synthesis import write_design

    if result.linkage is None:  # type: ignore[attr-defined]
        typer.echo(f"note: {output} not written: there is no real linkage", err=True)
        return
    if result.defects:  # type: ignore[attr-defined]
        typer.echo(f"note: {output} not written: the design has defects "
                   f"({', '.join(result.defect_names)})", err=True)  # type: ignore[attr-defined]
        return
    made_by = (
        " ".join(shlex.quote(w) for w in ["linkage", "synthesize", *sys.argv[2:]])
        if len(sys.argv) > 1 and sys.argv[1] == "synthesize"
        else "linkage synthesize"
    )
    said = f": linkage sweep {shlex.quote(str(output))} runs it over the alpha range"
    why_not = write_design(result, output, unit, made_by,
                           write=lambda path, text: write_mechanism(path, text, force, said=said))
    if why_not is not None:
        typer.echo(f"note: {output} not written: {why_not}", err=True)


def write_motion_design(m: object, chosen: int, output: Path, unit: str, force: bool) -> None:
    """-o FILE.toml: design ``chosen`` by the one mechanism-writing rule (options.write_mechanism)."""
    import shlex
    import sys

    from ..render.motion_synthesis import motion_design_text

    made_by = (" ".join(shlex.quote(w) for w in ["linkage", *sys.argv[1:]])
               if len(sys.argv) > 1 and sys.argv[1] == "synthesize" else "linkage synthesize --motion")
    text = motion_design_text(m, chosen, unit, made_by)
    defects = m.designs[chosen].defect_names  # type: ignore[attr-defined]
    # a design with defects (--design K) is written as asked, its defects said: sweeping it does
    # not carry the body through every pose as the synthesis asked
    said = (f" (design {chosen + 1}, with defects: {', '.join(defects)})" if defects else
            f" (design {chosen + 1}): linkage sweep {shlex.quote(str(output))} runs it through the poses")
    write_mechanism(output, text, force, said=said)
