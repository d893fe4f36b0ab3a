"""The output formats are one registry (render.formats.FORMATS): the command line's --format
choices, -o suffix detection and help are read from it, so a new format is one entry and
its sink in that one file."""

from __future__ import annotations

from pathlib import Path

import pytest

from linkage.render import formats, writers
from linkage.render.cells import Sink

CRANK = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"


def _installed(spec: formats.Format) -> bool:
    if spec.needs is None:
        return True
    try:
        __import__(spec.needs[0])
    except ImportError:
        return False
    return True


@pytest.mark.parametrize("name", [f.name for f in formats.FORMATS.values() if f.streams])
def test_every_registered_format_is_reachable_by_format_and_by_suffix(cli, tmp_path, name):
    spec = formats.FORMATS[name]
    if not _installed(spec):
        pytest.skip(f"{spec.needs[0]} is not installed")  # type: ignore[index]
    for suffix in spec.suffixes:
        by_suffix = tmp_path / f"by_suffix{suffix}"
        run = cli("sweep", str(CRANK), "--to", "20", "--step", "10", "-o", str(by_suffix))
        assert run.code == 0, run.err
        assert by_suffix.stat().st_size > 0
        assert writers.choose_format(None, by_suffix) == name
    by_name = tmp_path / "by_name.out"
    run = cli("sweep", str(CRANK), "--to", "20", "--step", "10", "-f", name.upper(), "-o", str(by_name))
    assert run.code == 0, run.err
    if spec.binary:  # a parquet file names itself in its metadata; a workbook holds its time
        assert by_name.stat().st_size > 0
    else:
        assert by_name.read_bytes() == (tmp_path / f"by_suffix{spec.suffixes[0]}").read_bytes()


def test_the_help_and_the_refusals_name_every_registered_format(cli):
    shown = " ".join(cli("sweep", "--help").out.split())
    for f in formats.FORMATS.values():
        assert f.name in shown
        for suffix in f.suffixes:
            assert not suffix or suffix in shown
    refused = cli("sweep", str(CRANK), "-f", "nope")
    assert refused.code == 2 and all(f in refused.err for f in formats.FORMATS)


class ProbeSink(Sink):
    """A format made up here: one line per row, its cells joined by '|'."""

    @classmethod
    def modules(cls, rows):
        return tuple(f.needs[0] for f in formats.FORMATS.values() if f.sink is cls and f.needs)

    def begin(self, name, columns, rows=None):
        super().begin(name, columns, rows)

    def rows(self, values):
        for row in zip(*values):
            self.out.write("|".join(str(v) for v in row) + "\n")  # type: ignore[union-attr]
        self.count += len(values[0]) if values else 0


def test_a_format_added_to_the_registry_alone_is_chosen_and_written(monkeypatch, tmp_path):
    """The one entry is all the writers need: chosen by name and by suffix, written through
    the same streaming path, refused for standard output where it is binary."""
    from linkage.render.data import Column, DataTable, Report

    monkeypatch.setitem(formats.FORMATS, "probe", formats.Format("probe", (".probe",), ProbeSink))
    assert writers.choose_format("probe", None) == "probe"
    out = tmp_path / "t.probe"
    assert writers.choose_format(None, out) == "probe" and writers.is_data("probe")
    report = Report("t", (DataTable("rows", (Column("a", "", [1, 2]), Column("b", "", [3, 4]))),), lambda: ())
    writers.write(report, "probe", out)
    assert out.read_text() == "1|3\n2|4\n"
    assert "probe" in writers.data_formats()


def test_a_format_whose_package_is_missing_or_broken_is_refused_in_one_line(monkeypatch, tmp_path):
    """choose_format finds the package without importing it (the import runs beside the
    command's computing, writers.prefetch); a package found that fails to import is
    refused where the writer opens, and nothing is written."""
    from linkage.errors import InputError
    from linkage.render.data import Column, DataTable, Report

    monkeypatch.setitem(formats.FORMATS, "gone", formats.Format(
        "gone", (".gone",), ProbeSink, needs=("linkage_test_no_such_package", "pip install it")))
    with pytest.raises(InputError, match="gone output needs linkage_test_no_such_package: pip install it"):
        writers.choose_format("gone", tmp_path / "t.gone")
    (tmp_path / "linkage_test_broken").mkdir()
    (tmp_path / "linkage_test_broken" / "__init__.py").write_text("raise ImportError('broken')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(formats.FORMATS, "gone", formats.Format(
        "gone", (".gone",), ProbeSink, needs=("linkage_test_broken", "pip install it")))
    assert writers.choose_format("gone", tmp_path / "t.gone") == "gone"
    writers.prefetch("gone", 10)  # a failing import on the prefetch thread is quiet
    report = Report("t", (DataTable("rows", (Column("a", "", [1]),)),), lambda: ())
    with pytest.raises(InputError, match="gone output needs linkage_test_broken"):
        writers.write(report, "gone", tmp_path / "t.gone")
    assert not (tmp_path / "t.gone").exists()


