"""The progress line of long work: drawn on standard error when it is a terminal (a pty here), never in a pipe or
under --json, erased when the work ends, and never mixed into standard output."""

from __future__ import annotations

import io
import os
import pty
import select
import subprocess
import sys

import numpy as np
import pytest
from scipy.io import wavfile

from matcad import progress
from tests.conftest import ROOT

TEMPLATES = ROOT / "matcad" / "templates"
ERASE = "\x1b[K"
"""What every redraw of the progress line starts with (after a carriage return)."""
SWEEP = ("sweep", TEMPLATES / "mat-laser-only.toml", "--vary", "cavity.length=3:6:4", "--vary",
         "neck.diameter=1.5,2.1", "--workers", "1", "--no-rules")


def run_on_pty(*args, cwd=None) -> tuple[int, str, str]:
    """Run `python -m matcad ARGS` with standard error on a pseudo-terminal and standard output in a pipe:
    (exit code, stdout, what the terminal received)."""
    master, slave = pty.openpty()
    env = {k: v for k, v in os.environ.items() if k != "MATCAD_PROGRESS"}
    proc = subprocess.Popen([sys.executable, "-m", "matcad", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=slave, stdin=subprocess.DEVNULL, cwd=cwd or ROOT, env=env)
    os.close(slave)
    seen, out = b"", b""
    open_fds = {master, proc.stdout.fileno()}
    while open_fds:
        ready, _, _ = select.select(list(open_fds), [], [], 60.0)
        if not ready:  # a minute without a byte: a hung command
            proc.kill()
            break
        for fd in ready:
            try:
                chunk = os.read(fd, 65536)
            except OSError:  # EIO: the child closed its end of the terminal
                chunk = b""
            if not chunk:
                open_fds.discard(fd)
            elif fd == master:
                seen += chunk
            else:
                out += chunk
    proc.wait(timeout=60)
    os.close(master)
    return proc.returncode, out.decode(), seen.decode(errors="replace")


def piped(*args, cwd=None) -> tuple[int, str, str]:
    env = {k: v for k, v in os.environ.items() if k != "MATCAD_PROGRESS"}
    proc = subprocess.run([sys.executable, "-m", "matcad", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, env=env)
    return proc.returncode, proc.stdout, proc.stderr


def test_sweep_draws_progress_on_a_terminal_and_erases_it(tmp_path):
    code, out, tty = run_on_pty(*SWEEP, "--out", tmp_path / "s")
    assert code == 0, tty
    assert "matcad: sweep" in tty and "8/8 variants (100 %)" in tty
    assert tty.rstrip(" \n").endswith("\x1b[K") or "\r\x1b[K" in tty.rsplit("(100 %)", 1)[1]  # erased at the end
    assert "matcad: sweep" not in out and "8 variants" in out  # the command's own output stays clean


def test_sweep_piped_prints_no_progress(tmp_path):
    code, out, err = piped(*SWEEP, "--out", tmp_path / "a")
    assert code == 0 and ERASE not in err and "variants (" not in err


def test_sweep_json_on_a_terminal_prints_no_progress(tmp_path):
    code, out, tty = run_on_pty(*SWEEP, "--out", tmp_path / "b", "--json")
    assert code == 0, tty
    assert ERASE not in tty and "variants (" not in tty


def test_build_draws_progress_and_names_the_report_last(tmp_path):
    code, out, tty = run_on_pty("build", TEMPLATES / "mat-laser-only.toml", "--out", tmp_path / "kit")
    assert code == 0, tty
    assert "matcad: build" in tty and "8/8 stages (100 %)" in tty
    last = out.strip().splitlines()[-1]
    assert last == f"open first: {tmp_path / 'kit' / 'report.html'}" and (tmp_path / "kit" / "report.html").is_file()


def test_analyze_draws_progress_in_seconds_of_recording(tmp_path):
    rate = 8000
    t = np.arange(int(rate * 6.0)) / rate
    wavfile.write(tmp_path / "rec.wav", rate, (0.3 * np.sin(2 * np.pi * 1500 * t) * 32767).astype(np.int16))
    code, out, tty = run_on_pty("analyze", tmp_path / "rec.wav", "--band", "1000", "2000", "--out", tmp_path / "a")
    assert code == 0, tty
    assert "matcad: analyze" in tty and "6/6 s of recording (100 %)" in tty
    code, out, err = piped("analyze", tmp_path / "rec.wav", "--band", "1000", "2000", "--out", tmp_path / "b")
    assert code == 0 and ERASE not in err and "of recording" not in err


def test_design_taxels_draws_progress_in_taxels_placed(tmp_path):
    """`design --taxels` (a FElupe run per new cap, 38 s for the paper's 3 taxels): the taxels placed on a
    terminal; nothing in a pipe or under --json."""
    from tests.test_design import ARRAY_BASE

    spec = tmp_path / "arr.toml"
    spec.write_text(ARRAY_BASE.format(force="5.0"), encoding="utf-8")
    args = ("design", spec, "--taxels", "3", "--band", "3500", "6500")
    code, out, tty = run_on_pty(*args, "--out", tmp_path / "a")
    assert code == 0, tty
    assert "matcad: design arr" in tty and "3/3 taxels (100 %)" in tty and "matcad: design" not in out
    code, out, tty = run_on_pty(*args, "--out", tmp_path / "b", "--json")
    assert code == 0 and ERASE not in tty and "taxels (" not in tty
    code, out, err = piped(*args, "--out", tmp_path / "c")
    assert code == 0 and ERASE not in err and "taxels (" not in err


def test_line_is_quiet_off_a_terminal_and_under_json(monkeypatch):
    """The utility itself: nothing on a non-terminal stream or when quiet; on a terminal the count, the share and
    the erase."""
    monkeypatch.delenv("MATCAD_PROGRESS", raising=False)
    buffer = io.StringIO()
    with progress.line("work", "items", stream=buffer) as tell:
        tell(1, 2)
    assert buffer.getvalue() == ""

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    screen = Terminal()
    with progress.line("work", "items", quiet=True, stream=screen) as tell:
        tell(2, 2)
    assert screen.getvalue() == ""
    with progress.line("work", "items", stream=screen) as tell:
        tell(1, 4)
        tell(4, 4)
    text = screen.getvalue()
    assert "matcad: work 4/4 items (100 %)" in text and text.endswith("\r\x1b[K")
    monkeypatch.setenv("MATCAD_PROGRESS", "0")
    assert not progress.wanted(stream=screen)


def test_compute_code_reports_through_its_callback():
    """sweep() tells its callback every variant (no print of its own), up to the grid's size."""
    from matcad.spec import read_spec_data
    from matcad.sweep import Executor, parse_axes, sweep

    told = []
    axes = parse_axes(["cavity.length=3:6:4", "neck.diameter=1.5,2.1"])
    sweep(read_spec_data(TEMPLATES / "mat-laser-only.toml"), axes, executor=Executor(1), rules=True,
          progress=lambda done, total: told.append((done, total)))
    assert told and told[-1] == (8, 8) and all(a <= b for (a, _), (b, _) in zip(told, told[1:]))


@pytest.mark.slow
@pytest.mark.parametrize("model", ["fem"])
def test_predict_fem_progress_on_terminal_only(tmp_path, model):
    code, out, tty = run_on_pty("predict", TEMPLATES / "mat-laser-only.toml", "--model", model, "--fem-level", "2")
    assert code == 0, tty
    assert "matcad: predict" in tty
    code, out, tty = run_on_pty("predict", TEMPLATES / "mat-laser-only.toml", "--model", model, "--fem-level", "2",
                                "--json")
    assert code == 0 and ERASE not in tty and "matcad: predict" not in tty


@pytest.mark.slow
def test_predict_load_progress_counts_the_cap_steps(tmp_path, monkeypatch):
    """predict --load: the cap's load steps as they converge (a fresh mechanics cache, so FElupe runs)."""
    monkeypatch.setenv("MATCAD_CACHE_DIR", "")  # no cache: FElupe runs
    code, out, tty = run_on_pty("predict", TEMPLATES / "mat-paper.toml", "--load", "2", "5")
    assert code == 0, tty
    assert "matcad: predict" in tty and "steps (" in tty
