"""linkage convert."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import NOTED, ForceOpt, MechanismFile, mechanism_output, stdout_errors, write_mechanism
from .root import app


@app.command(
    epilog="Examples:  linkage convert my_fourbar.toml -o my_fourbar_loops.toml  |  "
           "linkage convert sample_inputs/watt_sixbar.toml --form joints",
)
def convert(
    file: MechanismFile,
    *,
    form: Annotated[Optional[str], typer.Option("--form", metavar="FORM", help="The form to write: "
                    "loops (the vector loops a drawing implies) or joints (a loops file drawn as "
                    "joints and links). Default: the form the file is not in.")] = None,
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Write the converted file "
                      "here (.toml) instead of standard output; an existing file is kept unless "
                      "--force.")] = None,
    force: ForceOpt = False,
) -> None:
    """Convert a mechanism file between its two forms: a joints-and-links file to the
    vector loops it implies (each loop under a comment naming its joints), or a loops file
    to joints and links (its loops solved at the driver value, each joint where they place
    it).

    Example: linkage convert my_fourbar.toml
    """
    import sys

    from ..files import parse_toml, read_input
    from ..kinematics.loading import parse_mechanism
    from ..problems.read_loops import is_joints_doc
    from ..problems.toml_text import loops_text

    if form is not None and form.lower() not in ("joints", "loops"):
        raise InputError(f"--form {form!r}: write joints or loops")
    target = mechanism_output(output, force, [file])
    doc = parse_toml(read_input(file), str(file))
    now = "joints" if is_joints_doc(doc) else "loops"
    wanted = (form or ("loops" if now == "joints" else "joints")).lower()
    if wanted == now:
        raise InputError(f"{file} is already in the {now} form: --form "
                         f"{'loops' if now == 'joints' else 'joints'} converts it")
    mechanism = parse_mechanism(doc, str(file))  # refuse what solve refuses: the printed file solves
    if wanted == "loops":
        text = loops_text(doc, str(file), mechanism)
        dropped = [f"[{k}]" for k in ("loads", "mass") if k in doc]
        if dropped:  # loads and masses act on links as bodies, which the loops form has not
            NOTED.append(f"{' and '.join(dropped)} of {file} not written: the loops form has no links as "
                         "bodies to carry them (keep the joints file for forces and simulate)")
    else:
        from ..kinematics.to_joints import joints_text

        text = joints_text(mechanism, str(file))
    if target is None:
        with stdout_errors():
            sys.stdout.write(text)
            sys.stdout.flush()
        return
    write_mechanism(target, text, force, [file])
