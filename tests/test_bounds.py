"""Issue 18, bounds: every input bounded in time and memory, every failure one line and
exit 2, SIGTERM handled like Ctrl-C. Each test is named after the finding.

Sizes are just over the limits, not the findings' huge ones; where the finding was a hang
or a memory blow-up, the run is in a child limited to 1 GB of address space, with a
timeout that only guards against a hang.
"""

from __future__ import annotations

import cmath
import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import CliRun, sigint_as_at_a_terminal
from linkage import load_mechanism, solve_system
from linkage.errors import InputError, ParseError
from linkage.files import MAX_TOML_KEY_PARTS, MAX_TOML_NESTING
from linkage.problems.loops import MAX_LOOPS, MAX_POINTS, MAX_VECTORS
from test_hardening import bounded, one_line_exit_2

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
CRANK_ROCKER = SAMPLES / "crank_rocker.toml"
R1, R2, R3, R4, THETA2 = 100.0, 40.0, 120.0, 80.0, 30.0


def chain(loops: int, points: int = 0, extra_vectors: int = 0) -> str:
    """``loops`` copies of the crank-rocker's loop on one driver, each with its own two
    unknowns; ``points`` coupler points; ``extra_vectors`` pairs of opposite unit vectors
    added to the first loop (they cancel)."""
    out = ['name = "chain"', 'length_unit = "mm"', "[parameters]",
           f'r1 = {{ value = {R1}, unit = "mm" }}', f'r2 = {{ value = {R2}, unit = "mm" }}',
           f'r3 = {{ value = {R3}, unit = "mm" }}', f'r4 = {{ value = {R4}, unit = "mm" }}',
           'theta1 = { value = 0, unit = "deg" }',
           "[driver]", 'name = "theta2"', f"value = {THETA2}", 'unit = "deg"', "[unknowns]"]
    out += [f'{s}{k} = {{ guess = {g}, unit = "deg" }}'
            for k in range(loops) for s, g in (("a", 20), ("b", 50))]
    for k in range(loops):
        pad = "{ length = 1, angle = 0 }, { length = 1, angle = 180 }, " * (extra_vectors if k == 0 else 0)
        out += ["[[loops]]"]
        if k == 0:
            out += ['joints = ["O2", "A", ' + '"", "", ' * extra_vectors + '"B", "O4"]']
        out += [f'vectors = [ {{ length = "r2", angle = "theta2" }}, {{ length = "r3", angle = "a{k}" }}, '
                f'{pad}{{ length = "r4", angle = "b{k}", sign = -1 }}, '
                '{ length = "r1", angle = "theta1", sign = -1 } ]']
    for p in range(points):
        out += [f"[points.P{p}]", 'from = "A"', f'vectors = [ {{ length = {p + 1}, angle = "a0" }} ]']
    return "\n".join(out) + "\n"


def in_child(*args: str, stdin: str | None = None) -> CliRun:
    """``linkage ARGS`` in a child limited to 1 GB (test_hardening.bounded)."""
    r = bounded(*args, stdin=stdin)
    return CliRun(r.returncode, r.stdout, r.stderr)


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def fourbar_reference() -> list[tuple[float, float]]:
    """(theta3, theta4) in degrees of both assemblies at THETA2: the coupler's end B is
    where the circles about A (radius r3) and O4 (radius r4) meet."""
    a = R2 * cmath.exp(1j * math.radians(THETA2))
    o4 = complex(R1, 0.0)
    d = abs(o4 - a)
    along = (R3 ** 2 - R4 ** 2 + d ** 2) / (2 * d)
    h = math.sqrt(R3 ** 2 - along ** 2)
    u = (o4 - a) / d
    out = []
    for side in (1, -1):
        b = a + along * u + side * h * 1j * u
        out.append((math.degrees(cmath.phase(b - a)), math.degrees(cmath.phase(b - o4))))
    return out


# --- size ---------------------------------------------------------------------------------------

def test_a_file_with_1000_unknowns_is_refused_before_any_solve(tmp_path, monkeypatch):
    import linkage.methods.newton_system as ns

    monkeypatch.setattr(ns, "newton_direction", lambda *a: pytest.fail("solved before refusing"))
    path = write(tmp_path, "big.toml", chain(500))
    with pytest.raises(ParseError, match=r"1,000 unknowns; at most 24 \(12 loops\)"):
        load_mechanism(path)
    r = in_child("solve", str(path))
    one_line_exit_2(r)


def test_200_unknowns_solve_and_scan_are_refused_and_the_limit_itself_solves(cli, tmp_path):
    over = write(tmp_path, "over.toml", chain(MAX_LOOPS + 1))
    for args in (("solve", str(over)), ("scan", str(over), "--vary", "r2=30:40:2")):
        run = cli(*args)
        one_line_exit_2(run)
        assert f"{2 * MAX_LOOPS + 2} unknowns; at most {2 * MAX_LOOPS}" in run.err
    # 13 loops with 13 unknown pairs but only the check on loops left: still refused
    text = chain(MAX_LOOPS + 1).replace('b12 = { guess = 50, unit = "deg" }\n', "")
    text = text.replace('a12 = { guess = 20, unit = "deg" }\n', "")
    one_line_exit_2(cli("solve", str(write(tmp_path, "loops.toml", text))))
    # at the limit: 12 identical loops, each the crank-rocker, each at its closed form
    m = load_mechanism(write(tmp_path, "limit.toml", chain(MAX_LOOPS)))
    r = solve_system(m.problem(), tol=1e-12)
    assert r.converged
    ref = fourbar_reference()
    for k in range(MAX_LOOPS):
        got = (math.degrees(r.x[2 * k]), math.degrees(r.x[2 * k + 1]))
        assert min(max(abs(g - w) for g, w in zip(got, want)) for want in ref) < 1e-9, (k, got, ref)


def test_more_vectors_than_the_limit_in_a_loop_or_a_point_are_refused(cli, tmp_path):
    ok = load_mechanism(write(tmp_path, "ok.toml", chain(1, extra_vectors=(MAX_VECTORS - 4) // 2)))
    assert len(ok.loops[0].vectors) == MAX_VECTORS
    run = cli("solve", str(write(tmp_path, "v.toml", chain(1, extra_vectors=(MAX_VECTORS - 4) // 2 + 1))))
    one_line_exit_2(run)
    assert f"at most {MAX_VECTORS}" in run.err
    point = (chain(1) + '[points.Q]\nfrom = "A"\nvectors = [ '
             + "{ length = 1, angle = 0 }, " * (MAX_VECTORS + 1) + "]\n")
    one_line_exit_2(cli("solve", str(write(tmp_path, "p.toml", point))))


def test_a_toml_header_of_160k_parts_is_refused_before_parsing(tmp_path, monkeypatch):
    import tomllib

    from linkage.files import parse_toml

    huge = write(tmp_path, "huge.toml", "[" + ".".join(["a"] * 160_000) + "]\n")
    one_line_exit_2(in_child("solve", str(huge)))
    monkeypatch.setattr(tomllib, "loads", lambda *a, **k: pytest.fail("parsed before the check"))
    for text in ("[" + ".".join(["a"] * (MAX_TOML_KEY_PARTS + 1)) + "]\n",
                 ".".join(f'"k{i}"' for i in range(MAX_TOML_KEY_PARTS + 1)) + " = 1\n",
                 "x = " + "[" * (MAX_TOML_NESTING + 1) + "]" * (MAX_TOML_NESTING + 1) + "\n",
                 "x = " + "{ a = " * (MAX_TOML_NESTING + 1) + "1" + " }" * (MAX_TOML_NESTING + 1) + "\n"):
        with pytest.raises(ParseError, match=r"line 1: .*(more than 32 parts|nested more than 32)"):
            parse_toml(text, "f.toml")


def test_the_toml_shape_check_passes_what_a_mechanism_file_holds(tmp_path):
    from linkage.files import parse_toml

    text = ("x = " + "[" * (MAX_TOML_NESTING - 1) + "1.5" + "]" * (MAX_TOML_NESTING - 1) + "\n"
            's = "a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t.u.v.w.x.y.z.0.1.2.3.4.5.6.7" # x.y.z\n'
            "t = '''[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[['''\n"
            "d = 1979-05-27T07:32:00.999999-07:00\n"
            "[" + ".".join(["a"] * MAX_TOML_KEY_PARTS) + "]\n")
    doc = parse_toml(text, "f.toml")
    assert doc["d"].microsecond == 999999 and doc["t"].count("[") == 37
    for f in SAMPLES.glob("*.toml"):
        load_mechanism(f)


def test_a_scan_of_a_file_with_1000_points_is_refused_and_a_task_stays_bounded(cli, tmp_path):
    from linkage.scan.task import CHUNK_CELLS, chunk_size, pick_chunk

    pts = write(tmp_path, "pts.toml", chain(1, points=MAX_POINTS + 1))
    run = cli("scan", str(pts), "--vary", "r2=30:40:2")
    one_line_exit_2(run)
    assert f"at most {MAX_POINTS}" in run.err
    m = load_mechanism(write(tmp_path, "limit.toml", chain(MAX_LOOPS, points=MAX_POINTS)))
    width = 1 + 2 * MAX_LOOPS + 2 * MAX_POINTS
    for positions in (1, 360, 100_000):
        for branch in (None, "open"):
            if branch and m.closed_form is None:
                continue
            assert chunk_size(m, positions, branch) * positions * width <= max(CHUNK_CELLS, positions * width)
    with pytest.raises(InputError, match=r"--chunk 1,000: 1,000 designs x 360 positions x 73 numbers"):
        pick_chunk(m, 360, None, 1000, 10**6)
    assert pick_chunk(m, 360, None, 1000, 2) == 1000  # only 2 designs: a task of 2


def test_a_sorted_scan_that_would_hold_every_record_is_refused_before_solving(cli, monkeypatch):
    import linkage.scan as scan
    import linkage.scan.engine as engine

    monkeypatch.setattr(engine, "run_chunk", lambda *a: pytest.fail("solved before refusing"))
    big = ["--vary", "r2=20:60:3000", "--vary", "r3=80:160:1000", "--sort", "theta4_range"]
    run = cli("scan", str(CRANK_ROCKER), *big, "-f", "csv")
    one_line_exit_2(run)
    assert "3,000,000 designs x 20 columns is 60,000,000 values" in run.err
    with pytest.raises(InputError, match="give top of at most"):
        scan.scan(str(CRANK_ROCKER), {"r2": (20, 60, 3000), "r3": (80, 160, 1000)})


def test_ten_million_samples_of_ten_parameters_are_refused_before_drawing(cli, monkeypatch):
    import linkage.scan.designs as scan

    r = in_child("scan", str(CRANK_ROCKER), *[f"--vary={k}=1:2" for k in ("r1", "r2", "r3", "r4")],
                "--samples", "10000000")
    one_line_exit_2(r)
    assert "--samples 10,000,000 x 4 varied parameters is 40,000,000 values" in r.err
    monkeypatch.setattr(scan, "draw_designs", lambda *a: pytest.fail("drawn before refusing"))
    run = cli("scan", str(CRANK_ROCKER), "--vary", "r2=30:40", "--vary", "r3=100:120",
              "--samples", str(scan.MAX_SAMPLE_VALUES // 2 + 1))
    one_line_exit_2(run)


def test_samples_drawn_in_place_are_the_same_designs():
    """The in-place draw keeps every bit of lo + u * (hi - lo)."""
    import numpy as np

    from linkage.scan import DesignPlan, Vary

    varies = [Vary("r2", 20.0, 60.0, None), Vary("r3", 80.5, 160.25, None)]
    for method in ("lhs", "random"):
        got = DesignPlan(varies, 1000, 7, method).chunk(0, 1000)
        rng = np.random.default_rng(7)
        u = rng.random((1000, 2))
        if method == "lhs":
            for j in range(2):
                u[:, j] = (rng.permutation(1000) + u[:, j]) / 1000
        want = np.array([20.0, 80.5]) + u * (np.array([60.0, 160.25]) - np.array([20.0, 80.5]))
        assert np.array_equal(got, want)


# --- internal errors ------------------------------------------------------------------------------

def _closed(fd: int, *args: str) -> subprocess.CompletedProcess:
    args = args or ("solve", str(CRANK_ROCKER) if fd == 1 else "-")
    return subprocess.run([sys.executable, "-m", "linkage", *args], capture_output=True, text=True,
                          timeout=60, preexec_fn=lambda: os.close(fd))


@pytest.mark.parametrize("args", [(), ("--version",)])
def test_solve_with_a_closed_stdout_is_one_line_not_a_traceback(args):
    r = _closed(1, *args)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().startswith("error: cannot write to standard output")
    assert len(r.stderr.strip().splitlines()) == 1


def test_solve_dash_with_a_closed_stdin_is_one_line_not_an_internal_error():
    r = _closed(0)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip() == "error: standard input is closed: give a FILE, or - with input piped in"


@pytest.mark.parametrize("address", ["tls://127.0.0.1:1", "ucx://127.0.0.1:1", "tcp://127.0.0.1:65536",
                                     "tcp://127.0.0.1:99999", "tcp://127.0.0.1", "inproc://x",
                                     "tcp://127.0.0.1:port"])
def test_scheduler_tls_ucx_and_ports_beyond_65535_are_one_line(cli, address, monkeypatch):
    pytest.importorskip("distributed")
    import distributed

    monkeypatch.setattr(distributed, "Client", lambda *a, **k: pytest.fail("client started"))
    run = cli("scan", str(CRANK_ROCKER), "--vary", "r2=30:40:2", "--chunk", "1", "--scheduler", address)
    one_line_exit_2(run)
    assert "--scheduler" in run.err


def test_a_closed_loopback_port_is_reported_without_waiting_for_the_client(cli, monkeypatch):
    pytest.importorskip("distributed")
    import distributed

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    # nothing listens there now: the refusal must come from the one quick try, never from
    # the client's retries for its whole timeout
    monkeypatch.setattr(distributed, "Client", lambda *a, **k: pytest.fail("client started"))
    run = cli("scan", str(CRANK_ROCKER), "--vary", "r2=30:40:2", "--chunk", "1",
              "--scheduler", f"tcp://127.0.0.1:{port}")
    one_line_exit_2(run)
    assert f"cannot reach the dask scheduler at tcp://127.0.0.1:{port}" in run.err


# --- input handling -------------------------------------------------------------------------------

def test_scan_dash_reads_standard_input_once(cli):
    args = ["scan", "--vary", "r2=30:40:3", "--format", "csv"]
    piped = in_child(args[0], "-", *args[1:], stdin=CRANK_ROCKER.read_text())
    direct = cli(args[0], str(CRANK_ROCKER), *args[1:])
    assert piped.code == 0, piped.err
    assert piped.out == direct.out and piped.out.count("\n") >= 4


@pytest.mark.parametrize("char", ["\\u001b", "\\r", "\\u0000", "\\u009b", "\\t", "\\n"])
@pytest.mark.parametrize("where", ["name", "key", "unit"])
def test_a_mechanism_name_with_esc_cr_or_nul_is_refused(cli, tmp_path, char, where):
    text = CRANK_ROCKER.read_text()
    if where == "name":
        text = text.replace('name = "Grashof crank-rocker"', f'name = "crank{char}[2J"')
    elif where == "key":
        text = text.replace("theta1 = { value = 0",
                            f'"theta{char}9" = {{ value = 1, unit = "mm" }}\ntheta1 = {{ value = 0')
    else:
        text = text.replace('length_unit = "mm"', f'length_unit = "m{char}m"')
    run = cli("solve", str(write(tmp_path, "c.toml", text)))
    one_line_exit_2(run)
    assert "control character" in run.err
    assert not any(c in run.err + run.out for c in "\x1b\r\x00\x9b")


def test_description_may_have_newlines_and_tabs(cli, tmp_path):
    text = CRANK_ROCKER.read_text().replace('name = "Grashof crank-rocker"',
                                            'name = "c"\ndescription = """two\n\tlines"""')
    assert cli("solve", str(write(tmp_path, "c.toml", text))).code == 0


def test_empty_accel_is_refused_not_taken_as_zero(cli):
    run = cli("solve", str(CRANK_ROCKER), "--speed", "10", "--accel", "")
    one_line_exit_2(run)
    assert "--accel ''" in run.err
    one_line_exit_2(cli("sweep", "--accel", ""))  # the equation sweep has no driver to accelerate


# --- signals ----------------------------------------------------------------------------------------

@pytest.mark.parametrize(("sig", "code", "line"), [(signal.SIGTERM, 143, "error: terminated"),
                                                   (signal.SIGINT, 130, "error: interrupted")])
def test_sigterm_during_a_scan_leaves_no_part_files(tmp_path, sig, code, line):
    out = tmp_path / "designs.csv"
    child = subprocess.Popen(
        [sys.executable, "-m", "linkage", "scan", str(CRANK_ROCKER), "--vary", "r2=20:60:2000",
         "--vary", "r3=80:160:1000", "--chunk", "50", "-o", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=sigint_as_at_a_terminal)
    try:
        deadline = time.monotonic() + 60  # guards against a hang only
        while not any(p.name.startswith(".designs.csv.") for p in tmp_path.iterdir()):
            assert child.poll() is None and time.monotonic() < deadline, child.communicate()
            time.sleep(0.05)
        child.send_signal(sig)
        _, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == code, err
    assert err.strip().splitlines() == [line], err
    assert list(tmp_path.iterdir()) == []
