"""The shortcuts of reading a mechanism file, each held to the full rule it skips: the
shape check's count of dots and openers (files.check_toml_shape) and the control
characters' printable test (read_loops.control_character)."""

from __future__ import annotations

import random
import re
import sys

import pytest

from linkage.errors import ParseError
from linkage.files import MAX_TOML_KEY_PARTS, MAX_TOML_NESTING, check_toml_shape
from linkage.problems.read_loops import CONTROL_CHARACTERS, control_character
from linkage.samples import sample_path


def _full_scan_refuses(text: str) -> bool:
    """check_toml_shape's verdict by its token pass: a last line of a comment (or the end
    of an unclosed string) holding more dots and openers than the shortcut allows forces
    the pass and adds no token the pass counts."""
    return _refused(text + "\n#" + "." * (MAX_TOML_KEY_PARTS + 1) + "[{" * MAX_TOML_NESTING)


def _refused(text: str) -> bool:
    try:
        check_toml_shape(text, "t.toml")
    except ParseError:
        return True
    return False


def test_the_shape_shortcut_never_accepts_what_the_scan_refuses():
    """At the thresholds (a key of MAX parts and one more, nesting MAX deep and one more, in
    headers, keys, arrays, inline tables, strings and comments) and on 3,000 random texts of
    TOML's punctuation, the check refuses exactly what the token pass refuses."""
    k, n = MAX_TOML_KEY_PARTS, MAX_TOML_NESTING
    texts = [
        "[" + ".".join(["a"] * k) + "]\n", "[" + ".".join(["a"] * (k + 1)) + "]\n",
        ".".join(["a"] * (k + 1)) + " = 1\n", "x = " + "[" * n + "]" * n,
        "x = " + "[" * (n + 1) + "]" * (n + 1),
        "x = " + "{ a = " * (n + 1) + "1" + " }" * (n + 1), '# ' + "." * 100 + "\nx = 1\n",
        'x = "' + "." * 100 + '"\n', "x = [" + ", ".join(["1.5"] * 40) + "]\n",
    ]
    rng = random.Random(7)
    alphabet = ["a", ".", "[", "]", "{", "}", " ", "=", "1.5", '"s.t"', "#c.\n", "\n", "'l.'"]
    for _ in range(3000):
        texts.append("".join(rng.choice(alphabet) for _ in range(rng.randint(0, 90))))
    for text in texts:
        assert _refused(text) == _full_scan_refuses(text), text


def test_the_samples_take_the_shape_shortcut_and_pass_the_scan():
    for path in sorted(sample_path("crank_rocker.toml").parent.glob("*.toml")):
        text = path.read_text()
        assert not _full_scan_refuses(text), path.name
        check_toml_shape(text, path.name)


def test_every_control_character_is_not_printable():
    """The reason control_character may skip its search on printable text: each character
    of the class is one str.isprintable refuses."""
    members = [chr(c) for c in range(sys.maxunicode + 1) if re.fullmatch(CONTROL_CHARACTERS, chr(c))]
    assert len(members) == 32 + 33 + 1 + 2 + 5 + 4
    assert not any(c.isprintable() for c in members)


@pytest.mark.parametrize("text", ["plain", "caf\u00e9 \u00a0nbsp", "tab\there", "esc\x1b[31m",
                                  "rlo\u202eevil", "zwj\u200d", "\u2028line", "", "x\x7f",
                                  "emoji \U0001f600"])
def test_control_character_is_the_search(text):
    expected = re.search(CONTROL_CHARACTERS, text)
    got = control_character(text)
    assert (got and got.group()) == (expected and expected.group())
