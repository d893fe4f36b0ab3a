"""A report's blocks as a person reads them: rich on a terminal, plain text, or any
tabulate format. LaTeX is a complete ``table`` environment with its caption; the text
lines around a table become LaTeX comments."""

from __future__ import annotations

from typing import Any

from .data import Report
from .report import Table, Text, print_rich, render_text

LATEX = ("latex", "latex_raw", "latex_booktabs", "latex_longtable")
_LATEX_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                  "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\^{}",
                  # in LaTeX's default (OT1) text font | < > print as an em dash and inverted marks
                  "|": r"\textbar{}", "<": r"\textless{}", ">": r"\textgreater{}"}


def latex_escape(text: str) -> str:
    return "".join(_LATEX_SPECIAL.get(c, c) for c in text)


def print_table(report: Report, file: Any = None) -> None:
    print_rich(report.blocks(), file)


def display_text(report: Report, fmt: str) -> str:
    blocks = report.blocks()
    if fmt == "html":
        return html_text(blocks)
    if fmt not in LATEX:
        return render_text(blocks, fmt)
    return latex_text(report.title, blocks, fmt)


def html_text(blocks: Any) -> str:
    """Each table as tabulate's (escaped) HTML table; every line around it (the title,
    which carries the mechanism file's name, the notes) escaped in a paragraph of its own:
    raw, a name such as ``<script>...`` would run in the browser that opens the file."""
    import html

    def para(text: str) -> list[str]:
        return [f"<p>{html.escape(line)}</p>" for line in text.splitlines() if line]

    out: list[str] = []
    for b in blocks:
        if isinstance(b, Text):
            out += para(b.text)
            continue
        out += para(b.title)
        out.append(render_text([Table("", b.headers, b.rows)], "html").rstrip("\n"))
        for n in b.notes:
            out += para(n)
    return "\n".join(out) + "\n"


def latex_text(title: str, blocks: Any, fmt: str) -> str:
    """Each table in a ``table`` float (``longtable`` carries its own caption), captioned by
    its title or the report's, labelled ``tab:linkage-K``; every other line a comment, so
    the text compiles as it is in a document."""
    out: list[str] = []
    k = 0
    for b in blocks:
        if isinstance(b, Text):
            out.extend(f"% {line}" if line else "%" for line in b.text.splitlines() or [""])
            continue
        assert isinstance(b, Table)
        k += 1
        caption = latex_escape(b.title or title)
        body = render_text([Table("", b.headers, b.rows)], fmt).rstrip("\n")
        if fmt != "latex_raw":  # tabulate escapes & % _ ^ but not |: "max|Phi|" read "max—Phi—"
            body = body.replace("|", r"\textbar{}")
        if fmt == "latex_longtable":
            head = f"\\caption{{{caption}}}\\label{{tab:linkage-{k}}}\\\\\n\\hline"
            body = body.replace("\\hline", head, 1)
            out.append(body)
        else:
            out += ["\\begin{table}[htbp]", "\\centering", f"\\caption{{{caption}}}",
                    f"\\label{{tab:linkage-{k}}}", body, "\\end{table}"]
        out.extend(f"% {line}" for n in b.notes for line in n.splitlines() or [""])
    return "\n".join(out) + "\n"
