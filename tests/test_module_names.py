"""What a package module lists: the names it imports on first use (PEP 562) included."""

from __future__ import annotations

import subprocess
import sys


def test_dir_of_linkage_solve_lists_the_names_imported_on_first_use() -> None:
    """solve_scalar and certify_root come through the module's __getattr__ (PEP 562); dir()
    lists them without importing them."""
    code = ("import sys, linkage.solve as s; names = dir(s); "
            "print(all(n in names for n in s.__all__), 'linkage.solve.scalar' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "False"]
