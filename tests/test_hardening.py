"""Regression suite of issue 10: one case per root cause an independent attack found, each through the real CLI
(a fresh interpreter) or the public API, asserting the README's contract: the exit-code class, one message naming
the field or file, no traceback, and no output or litter left behind."""

from __future__ import annotations

import dataclasses
import json
import os
import struct

import numpy as np
import pytest
from scipy.io import wavfile

from matcad import spec as spec_mod
from matcad.inputs import SPEC_MAX_BYTES
from matcad.spec.measured import Measured
from tests.conftest import MINIMAL, PAPER, run_cli

K = 2.2e8
"""A plausible K = c²A/(4π²l) (mm³ Hz²) for the calibration files below."""


def _assert_clean(code, err, expected, *needles):
    assert code == expected, err
    assert "Traceback" not in err and len(err) < 2000, err
    for needle in needles:
        assert needle in err, (needle, err)


# ---- spec parsing: hostile TOML ---------------------------------------------------------------------------

SPEC_CASES = {
    "deep-nesting-recursion": ("x = " + "[" * 5000 + "]" * 5000 + "\n" + MINIMAL, "spec file"),
    "deep-tables": (MINIMAL + "[cavity.a" + ".b" * 40 + "]\nz = 1\n", "spec file"),
    "int-309-digits-overflow": (MINIMAL.replace("length = 4.76", "length = " + "9" * 320), "cavity.length"),
    "int-beyond-parser-digit-limit": (MINIMAL.replace("length = 4.76", "length = " + "9" * 5000), "cavity.length"),
    "name-trailing-newline": (MINIMAL.replace('name = "t"', 'name = "abc\\n"'), "name"),
    "huge-value-echo-truncated": (MINIMAL.replace('name = "t"', 'name = "' + "x" * 200_000 + '"'), "name"),
}


@pytest.mark.parametrize("cause", SPEC_CASES)
def test_hostile_spec_is_exit_2(cause, write_spec, tmp_path):
    text, field = SPEC_CASES[cause]
    code, _, err = run_cli("predict", write_spec(text), cwd=tmp_path)
    _assert_clean(code, err, 2, field)
    assert len(err) < 600, "the echoed value must be truncated"
    assert not any(tmp_path.glob("out*"))


def test_spec_above_size_limit_refused_before_parsing(write_spec, tmp_path):
    path = write_spec(MINIMAL + "#" * (SPEC_MAX_BYTES + 10) + "\n")
    code, _, err = run_cli("check", path)
    _assert_clean(code, err, 2, "spec file", "larger than")


@pytest.mark.parametrize("target", ["fifo", "/dev/zero", "folder"])
def test_non_regular_spec_refused_without_reading(target, tmp_path):
    if target == "fifo":
        path = tmp_path / "spec.fifo"
        os.mkfifo(path)  # no writer: reading would block forever
    elif target == "folder":
        path = tmp_path
    else:
        path = target
    for command in (["check", path], ["sense", PAPER, "--calibration", path]):
        code, _, err = run_cli(*command)
        _assert_clean(code, err, 2)
        assert "regular file" in err or "folder" in err or "device" in err or "pipe" in err, err


# ---- the Python API cannot bypass validation ------------------------------------------------------------------

def test_replace_on_a_section_validates():
    spec = spec_mod.load(PAPER)
    with pytest.raises(spec_mod.SpecError, match="cavity.diameter"):
        dataclasses.replace(spec.cavity, diameter=-1.0)
    with pytest.raises(spec_mod.SpecError, match="machine.stl_tolerance"):
        dataclasses.replace(spec.machine, stl_tolerance=float("nan"))
    with pytest.raises(spec_mod.SpecError, match="neck.diameter"):  # cross-field rule on the whole spec
        dataclasses.replace(spec, neck=dataclasses.replace(spec.neck, diameter=spec.cavity.diameter + 1))
    with pytest.raises(spec_mod.SpecError, match="name"):
        dataclasses.replace(spec, name="abc\n")


def test_every_section_validates_on_construction():
    assert all(issubclass(cls, spec_mod.Section) for cls in spec_mod.SECTIONS.values())


def test_resolved_spec_round_trips_through_report_json():
    spec = spec_mod.load(PAPER)
    assert spec_mod.from_dict(spec_mod.to_dict(spec)) == spec
    assert spec_mod.from_dict(json.loads(json.dumps(spec_mod.to_dict(spec)))) == spec


# ---- calibration files ------------------------------------------------------------------------------------------

def _calibration_toml(covariance, force_range="[0.0, 20.0]", a=-0.0086):
    cov = ", ".join(repr(float(x)) for x in covariance)
    return (f"[calibration]\nv0_mm3 = 32.0\na = {a}\nb = 0.4626\nk_mm3_hz2 = {K}\nforce_range_n = {force_range}\n"
            f"covariance = [{cov}]\nresidual_std_mm3 = 0.01\ndof = 8\n")


@pytest.mark.parametrize("cause,covariance,force_range,field", [
    ("negative-variance", [-1e-4, 0, 0, 0, 1e-6, 0, 0, 0, 1e-8], "[0.0, 20.0]", "calibration.covariance"),
    ("asymmetric-covariance", [1e-4, 5e-5, 0, 0, 1e-6, 0, 0, 0, 1e-8], "[0.0, 20.0]", "calibration.covariance"),
    ("indefinite-covariance", [1e-4, 1e-3, 0, 1e-3, 1e-4, 0, 0, 0, 1e-8], "[0.0, 20.0]", "calibration.covariance"),
    ("veff-not-positive-in-range", [1e-4, 0, 0, 0, 1e-6, 0, 0, 0, 1e-8], "[0.0, 60.0]", "calibration.force_range_n"),
])
def test_bad_calibration_file_is_exit_2(cause, covariance, force_range, field, tmp_path):
    cal = tmp_path / "calibration.toml"
    cal.write_text(_calibration_toml(covariance, force_range, a=0.0086))
    wav = tmp_path / "r.wav"
    wavfile.write(wav, 44100, np.zeros(4410, np.int16))
    code, _, err = run_cli("sense", wav, "--calibration", cal)
    _assert_clean(code, err, 2, field)


# ---- calibration data (CSV) -------------------------------------------------------------------------------------

CSV_CASES = {
    "field-over-131072-chars": "force_n,frequency_hz\n" + "1" * 200_000 + ",4000\n",
    "nul-byte": "force_n,frequency_hz\n0,4000\n1\x00,4100\n",
    "force-1e154-overflow": "force_n,frequency_hz\n0,4000\n1e154,4100\n2e154,4200\n3e154,4300\n",
    "force-nan": "force_n,frequency_hz\n0,4000\nnan,4100\n2,4200\n3,4300\n",
    "frequency-inf": "force_n,frequency_hz\n0,4000\n1,inf\n2,4200\n3,4300\n",
    "not-utf8": b"force_n,frequency_hz\n0,4000\n\xff\xfe,1\n",
}


@pytest.mark.parametrize("cause", CSV_CASES)
def test_hostile_calibration_csv_is_exit_2(cause, tmp_path):
    data = tmp_path / "cal.csv"
    content = CSV_CASES[cause]
    data.write_bytes(content if isinstance(content, bytes) else content.encode())
    code, _, err = run_cli("calibrate", data, "--spec", PAPER, "--out", tmp_path / "c")
    _assert_clean(code, err, 2, "calibration data")
    assert len(err) < 600 and not (tmp_path / "c").exists()


def test_flat_frequencies_are_no_calibration_exit_1(tmp_path):
    rng = np.random.default_rng(3)
    forces = np.linspace(0, 20, 11)
    data = tmp_path / "flat.csv"
    data.write_text("force_n,frequency_hz\n" + "".join(f"{f},{4500 + rng.normal(0, 2)}\n" for f in forces))
    code, _, err = run_cli("calibrate", data, "--spec", PAPER, "--out", tmp_path / "c")
    _assert_clean(code, err, 1, "do not change with force")
    assert not (tmp_path / "c").exists()


# ---- WAV headers --------------------------------------------------------------------------------------------------

def _riff(*chunks, form=b"WAVE"):
    body = form + b"".join(cid + struct.pack("<I", len(data) if size is None else size) + data
                           for cid, data, size in chunks)
    return b"RIFF" + struct.pack("<I", len(body)) + body


def _fmt(tag=1, channels=1, rate=44100, bits=16, align=None):
    align = channels * bits // 8 if align is None else align
    return (b"fmt ", struct.pack("<HHIIHH", tag, channels, rate, rate * align, align, bits), None)


SAMPLES = np.zeros(100, np.int16).tobytes()
WAV_CASES = {
    "empty-file": b"",
    "riff-only": b"RIFF",
    "truncated-fmt": _riff((b"fmt ", b"\x01\x00\x01", None)),
    "fmt-size-lies": _riff((b"fmt ", b"\x01\x00", 16)),
    "no-data-chunk": _riff(_fmt()),
    "data-before-fmt": _riff((b"data", SAMPLES, None), _fmt()),
    "zero-channels-division": _riff(_fmt(channels=0, align=2), (b"data", SAMPLES, None)),
    "zero-rate": _riff(_fmt(rate=0), (b"data", SAMPLES, None)),
    "zero-block-align": _riff(_fmt(align=0), (b"data", SAMPLES, None)),
    "12-bit-samples": _riff(_fmt(bits=12, align=2), (b"data", SAMPLES, None)),
    "unknown-format-tag": _riff(_fmt(tag=0x55), (b"data", SAMPLES, None)),
    "huge-fmt-chunk": _riff((b"fmt ", b"\0" * 16, 0xFFFFFFF0)),
    "empty-data": _riff(_fmt(), (b"data", b"", None)),
    "extensible-without-subformat": _riff(_fmt(tag=0xFFFE), (b"data", SAMPLES, None)),
    "float-nan-samples": _riff(_fmt(tag=3, bits=32), (b"data", np.full(100, np.nan, np.float32).tobytes(), None)),
}


@pytest.mark.parametrize("cause", WAV_CASES)
def test_broken_wav_header_is_exit_2(cause, tmp_path):
    wav = tmp_path / "bad.wav"
    wav.write_bytes(WAV_CASES[cause])
    code, _, err = run_cli("analyze", wav, "--band", "4000", "5500", "--out", tmp_path / "a")
    _assert_clean(code, err, 2, "recording")
    assert not (tmp_path / "a").exists()


def test_wav_truncated_data_reads_the_whole_frames_present(tmp_path):
    from matcad.loop.wav import read_info, read_mono

    x = (np.sin(np.arange(1000) * 0.3) * 20000).astype(np.int16)
    wav = tmp_path / "cut.wav"
    wavfile.write(wav, 8000, np.column_stack([x, x]))
    wav.write_bytes(wav.read_bytes()[:-1001])  # cut mid-frame: 250 frames and one byte missing
    info = read_info(wav)
    samples, rate = read_mono(wav)
    assert (info.frames, rate) == (1000 - 251, 8000.0)
    np.testing.assert_allclose(samples, x[:749] / 32768.0)


# ---- numeric fields at the open ends of their ranges ------------------------------------------------------------

EXTREME_CASES = {
    "speed-of-sound-1e-300": ("[air]\nspeed_of_sound = 1e-300\n", "air.speed_of_sound"),
    "speed-of-sound-subnormal": ("[air]\nspeed_of_sound = 5e-324\n", "air.speed_of_sound"),
    "v0-subnormal": ("[calibration]\nv0_mm3 = 5e-324\na = 0.0\nb = 0.1\n", "calibration.v0_mm3"),
    "stl-angular-tolerance-tiny": ("[machine]\nstl_angular_tolerance = 0.001\n", "machine.stl_angular_tolerance"),
}


@pytest.mark.parametrize("cause", EXTREME_CASES)
def test_open_range_end_refused_naming_the_field(cause, write_spec):
    text, field = EXTREME_CASES[cause]
    code, _, err = run_cli("predict", write_spec(MINIMAL + text), "--json", "--force", "1")
    _assert_clean(code, err, 2, field)


@pytest.mark.parametrize("force", ["nan", "inf", "1e154", "-1e7", "x"])
def test_cli_force_must_be_finite_and_bounded(force):
    code, _, err = run_cli("predict", PAPER, "--force", force)
    _assert_clean(code, err, 2, "--force")


ENTRIES = {"taxel[]": (spec_mod.TaxelEntry, "taxel", {"x": 0.0, "y": 0.0}),
           "measured[]": (Measured, "measured", {"f0_hz": 4000.0})}
"""Array-of-tables sections → (their entry class, their key, the smallest entry that carries a field)."""


def test_every_numeric_field_at_its_extremes_gives_finite_json_or_exit_2(tmp_path):
    """Each number field at its bounds, one ulp inside them, and at 5e-324, 1e-300, 1e300: predict (with a load
    curve) answers with finite JSON or refuses naming the field — never an internal error, nor a numpy warning on
    the user's terminal (silicone.density_g_cm3 = 1e-300 printed 'overflow encountered in square')."""
    import contextlib
    import io
    import math
    import warnings

    from matcad.cli import main

    base = dict(PAPER_TABLES)
    tried = 0
    for row in spec_mod.schema():
        section, _, name = row["key"].partition(".")
        if not name or not isinstance(row["default"], (float, type(None))) or "a finite number" not in row["allowed"]:
            continue
        if "." in name:  # a sub-table's field (taxel[].calibration.*): the same declaration is tried at its table
            continue
        entry = ENTRIES.get(section)  # a [[taxel]] or [[measured]] field: one entry carrying it
        cls = entry[0] if entry else spec_mod.SECTIONS[section]
        meta = dict(next(f for f in dataclasses.fields(cls) if f.name == name).metadata)
        if meta["kind"] != "number":
            continue
        for value in {meta["lo"], math.nextafter(meta["lo"], math.inf), meta["hi"], 5e-324, 1e-300, 1e300}:
            doc = {k: dict(v) if isinstance(v, dict) else v for k, v in base.items()}
            if entry:
                doc[entry[1]] = [entry[2] | {name: value}]
            else:
                doc.setdefault(section, {})[name] = value
            doc["outputs"] = {"end_cap_mold": False, "needle_mount": False, "assembly": False}
            path = tmp_path / "s.toml"
            path.write_text(_toml(doc))
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
                warnings.simplefilter("error", RuntimeWarning)  # a leaked warning becomes exit 70 here
                code = main(["predict", str(path), "--json"])
            tried += 1
            assert code in (0, 2), (row["key"], value, err.getvalue())
            if code == 2:
                assert section.replace("[]", "[") in err.getvalue(), err.getvalue()  # the field or its section's
            else:
                json.loads(out.getvalue())  # allow_nan=False upstream: parses only if finite
    assert tried > 150


def _toml(doc: dict) -> str:
    from tests.test_fuzz import to_toml

    return to_toml(doc)


PAPER_TABLES = __import__("tomllib").loads(PAPER.read_text())


# ---- needle rules that make a bore impossible -------------------------------------------------------------------

@pytest.mark.parametrize("needle", ["theta_deg = 1e-6", "y = 1e5", "y = -1e5"])
def test_needle_that_misses_the_mount_is_an_unforceable_error(needle, write_spec, tmp_path):
    path = write_spec(PAPER.read_text() + f"\n[needle]\n{needle}\n")
    code, out, err = run_cli("check", path)
    _assert_clean(code, err, 1)
    assert "needle.bore" in out
    code, out, err = run_cli("build", path, "--force", "--out", tmp_path / "k")
    _assert_clean(code, err, 1)
    assert not (tmp_path / "k").exists()


# ---- the exit-code table ----------------------------------------------------------------------------------------

def test_broken_stdout_pipe_exits_0_quietly():
    import subprocess
    import sys

    proc = subprocess.run(f"{sys.executable} -m matcad schema | head -1; exit ${{PIPESTATUS[0]}}", shell=True,
                          executable="/bin/bash", capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0 and proc.stderr == "" and proc.stdout.count("\n") == 1, proc.stderr


def test_unexpected_exception_is_exit_70_with_a_log_outside_home(tmp_path):
    import subprocess
    import sys

    home = tmp_path / "home"
    home.mkdir()
    code = ("import sys, matcad.acoustics.predict as p\n"
            "def boom(*a, **k): raise ZeroDivisionError('simulated bug')\n"
            "p.predict = boom\n"
            "from matcad.cli import main\n"
            f"sys.exit(main(['predict', {str(PAPER)!r}]))\n")
    env = {**os.environ, "HOME": str(home), "TMPDIR": str(tmp_path)}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    assert proc.returncode == 70, proc.stderr
    assert "internal error, please report" in proc.stderr and "Traceback" not in proc.stderr
    assert proc.stderr.count("\n") == 1
    log = proc.stderr.split(" with the log ")[1].split(" (")[0]
    assert log.startswith(str(tmp_path)) and "ZeroDivisionError: simulated bug" in open(log).read()
    assert not any(home.iterdir())


def test_caches_are_never_written_under_home(tmp_path):
    import subprocess
    import sys

    home = tmp_path / "home"
    home.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("XDG_CACHE_HOME", "MPLCONFIGDIR")}
    env |= {"HOME": str(home), "TMPDIR": str(tmp_path)}
    laser_only = PAPER.read_text() + "\n[outputs]\nend_cap_mold = false\nneedle_mount = false\nassembly = false\n"
    spec = tmp_path / "s.toml"
    spec.write_text(laser_only)
    proc = subprocess.run([sys.executable, "-m", "matcad", "build", spec, "--out", tmp_path / "k"],
                          capture_output=True, text=True, cwd=ROOT, env=env)
    assert proc.returncode == 0, proc.stderr
    assert not any(home.iterdir()), list(home.rglob("*"))


ROOT = PAPER.parents[1]


# ---- crash-safe output --------------------------------------------------------------------------------------------

LASER_ONLY = PAPER.read_text() + "\n[outputs]\nend_cap_mold = false\nneedle_mount = false\nassembly = false\n"


def _kit_intact(folder) -> bool:
    """Every file the manifest lists is there with its sha256, and nothing else."""
    import hashlib

    from matcad.output import MANIFEST

    listed = json.loads((folder / MANIFEST).read_text())["files"]
    present = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()} - {MANIFEST}
    return present == set(listed) and all(
        hashlib.sha256((folder / name).read_bytes()).hexdigest() == info["sha256"] for name, info in listed.items())


@pytest.fixture
def kit(tmp_path):
    """A laser-only kit at tmp_path/out/k built through the CLI; returns (spec path, kit folder)."""
    spec = tmp_path / "s.toml"
    spec.write_text(LASER_ONLY)
    code, _, err = run_cli("build", spec, "--out", tmp_path / "out" / "k")
    assert code == 0, err
    return spec, tmp_path / "out" / "k"


def test_report_json_spec_reloads(kit):
    spec, folder = kit
    report = json.loads((folder / "report.json").read_text())
    assert spec_mod.from_dict(report["spec"]) == spec_mod.load(spec)


def test_user_file_next_to_report_survives_and_build_refuses(kit):
    spec, folder = kit
    (folder / "notes.txt").write_text("my notes")
    code, _, err = run_cli("build", spec, "--out", folder)
    _assert_clean(code, err, 2, "notes.txt", "not written by matcad")
    assert (folder / "notes.txt").read_text() == "my notes"
    (folder / "notes.txt").unlink()
    (folder / "report.md").write_text("edited by hand")
    code, _, err = run_cli("build", spec, "--out", folder)
    _assert_clean(code, err, 2, "report.md", "changed")


def test_folder_without_manifest_is_never_replaced(tmp_path, write_spec):
    folder = tmp_path / "k"
    folder.mkdir()
    (folder / "report.json").write_text("{}")  # looks like an output, but matcad did not write it
    code, _, err = run_cli("build", write_spec(LASER_ONLY), "--out", folder)
    _assert_clean(code, err, 2, "no .matcad-manifest.json")
    assert (folder / "report.json").read_text() == "{}"


def test_kit_honours_the_umask(tmp_path):
    import subprocess
    import sys

    spec = tmp_path / "s.toml"
    spec.write_text(LASER_ONLY)
    code = f"import os, sys; os.umask(0o027); from matcad.cli import main; sys.exit(main(['build', {str(spec)!r}, " \
           f"'--out', {str(tmp_path / 'a' / 'k')!r}]))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "a" / "k").stat().st_mode & 0o777 == 0o750
    assert (tmp_path / "a").stat().st_mode & 0o777 == 0o750
    assert {p.stat().st_mode & 0o777 for p in (tmp_path / "a" / "k").iterdir()} == {0o640}


def test_failed_build_leaves_no_parents_no_temp(tmp_path):
    from matcad.output import staged_output

    with pytest.raises(RuntimeError):
        with staged_output(tmp_path / "a" / "b" / "k") as tmp:
            (tmp / "part.dxf").write_text("half")
            raise RuntimeError("disk full")
    assert list(tmp_path.iterdir()) == []


def test_death_between_renames_is_recovered_by_the_next_run(kit):
    """A process killed after moving the old kit aside and before moving the new one in: the next run finds
    the backup of a dead writer without its target and restores it before anything else."""
    from matcad.output import staged_output

    _, folder = kit
    backup = folder.parent / ".k.old-999999999-1-abcd1234"  # pid 999999999 cannot run (pid_max <= 2**22)
    folder.rename(backup)
    stale_tmp = folder.parent / ".k.tmp-999999999-1-0123abcd"
    stale_tmp.mkdir()
    (stale_tmp / "neck_plate.dxf").write_text("half")
    with pytest.raises(RuntimeError):
        with staged_output(folder):
            raise RuntimeError("this run fails too")
    assert _kit_intact(folder)
    assert sorted(p.name for p in folder.parent.iterdir()) == ["k"]


def test_live_writers_leftovers_are_left_alone(kit):
    from matcad.output import _owner, _sweep

    _, folder = kit
    mine = folder.parent / f".k.tmp-{_owner()}-00000000"
    mine.mkdir()
    _sweep(folder.parent)
    assert mine.is_dir()


def test_out_dot(tmp_path, write_spec):
    spec = write_spec(LASER_ONLY)
    work = tmp_path / "kitdir"
    work.mkdir()
    for _ in range(2):  # an empty folder, then matcad's own kit: both replaced
        code, _, err = run_cli("build", spec, "--out", ".", cwd=work)
        assert code == 0, err
        assert _kit_intact(work)
    (work / "notes.txt").write_text("mine")
    code, _, err = run_cli("build", spec, "--out", ".", cwd=work)
    _assert_clean(code, err, 2, "notes.txt")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kitdir", "spec.toml"]


# ---- fault injection: kill a build at random points ---------------------------------------------------------------

def _inject_faults(tmp_path, trials: int, seed: int):
    """Rebuild over a kit and kill the build with SIGINT, SIGTERM or SIGKILL after a random delay; each time the
    target must be a whole kit (the previous or the new one, every file matching its manifest), the exit code
    that of the signal (or 0 if the build won), never a traceback; a following build leaves no litter.
    Returns the counts per signal: (tried, held)."""
    import random
    import signal
    import subprocess
    import sys
    import time

    rng = random.Random(seed)
    full = tmp_path / "full.toml"
    full.write_text(PAPER.read_text().replace('name = "mat-paper"', 'name = "mat-paper-2"'))
    laser = tmp_path / "laser.toml"
    laser.write_text(LASER_ONLY)
    target = tmp_path / "out" / "k"
    assert run_cli("build", laser, "--out", target)[0] == 0
    expected = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGKILL: -9}
    counts = {}
    for _ in range(trials):
        sig = rng.choice(list(expected))
        spec = rng.choice([full, laser])
        proc = subprocess.Popen([sys.executable, "-m", "matcad", "build", str(spec), "--out", str(target)],
                                cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(0.0, 4.0 if spec == full else 1.5))
        proc.send_signal(sig)
        err = proc.communicate(timeout=120)[1]
        # a signal during interpreter start-up, before matcad's first line runs, gets the OS default (-2, -15),
        # or, for SIGINT while Python imports its `site` module, the interpreter's own "Fatal Python error:
        # init_import_site" (exit 1): nothing has been touched then, so it holds too as long as the kit is intact
        early = (proc.returncode == -sig and err == "") or (
            sig == signal.SIGINT and proc.returncode == 1 and err.startswith("Fatal Python error: init_import_site"))
        held = (proc.returncode in (0, expected[sig]) or early) and ("Traceback" not in err or early) \
            and _kit_intact(target)
        tried, ok = counts.get(sig.name, (0, 0))
        counts[sig.name] = (tried + 1, ok + held)
        assert held, (sig, proc.returncode, err)
    code, _, err = run_cli("build", laser, "--out", target)
    assert code == 0, err
    assert sorted(p.name for p in target.parent.iterdir()) == ["k"] and _kit_intact(target)
    return counts


def test_fault_injection_short(tmp_path):
    _inject_faults(tmp_path, trials=4, seed=10)


@pytest.mark.slow
def test_fault_injection_long(tmp_path):
    _inject_faults(tmp_path, trials=40, seed=11)


def test_an_interrupt_as_the_handlers_go_in_is_an_interrupt(monkeypatch):
    """A SIGINT that lands the instant main() routes SIGINT to its handler (the long fault injection hit it: exit -2
    and a KeyboardInterrupt traceback, 1 run in ~150 by hand) is held until the handlers are in, then ends the run
    as any interrupt does: exit 130, no traceback."""
    import signal

    from matcad import cli

    real = signal.signal

    def signal_then_interrupt(sig, handler):
        previous = real(sig, handler)
        if sig == signal.SIGINT and handler is cli._on_signal:
            os.kill(os.getpid(), signal.SIGINT)
        return previous

    before = signal.getsignal(signal.SIGINT)
    monkeypatch.setattr(cli.signal, "signal", signal_then_interrupt)
    try:
        code = cli.main(["--version"])
    except KeyboardInterrupt:
        code = "a KeyboardInterrupt out of main()"
    finally:
        real(signal.SIGINT, before)
    assert code == 130


def test_an_interrupt_while_python_builds_the_signal_module_leaves_quietly():
    """`python -m matcad` interrupted while its first line imports the signal module (Python's own handler still in
    place: a KeyboardInterrupt traceback and exit -2 before): exit 130 and nothing on stderr."""
    import subprocess
    import sys

    code = ("import builtins, runpy\nreal = builtins.__import__\n"
            "def interrupted(name, *a, **k):\n    if name == 'signal':\n        raise KeyboardInterrupt\n"
            "    return real(name, *a, **k)\nbuiltins.__import__ = interrupted\n"
            "runpy.run_module('matcad', run_name='__main__', alter_sys=True)")
    proc = subprocess.run([sys.executable, "-c", code, "--version"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 130 and proc.stderr == "", (proc.returncode, proc.stderr)


# ---- bounded tessellation and export failures ---------------------------------------------------------------------

def test_chordal_tolerance_is_floored_by_part_size():
    from build123d import Box

    from matcad.export.mesh import CHORDAL_FLOOR_PER_SIZE, effective_tolerance_mm

    box = Box(30, 40, 120)  # diagonal 130 mm
    assert effective_tolerance_mm(box, 1e-5) == pytest.approx(130 * CHORDAL_FLOOR_PER_SIZE)
    assert effective_tolerance_mm(box, 0.5) == 0.5


def test_stl_tolerance_1e5_builds_within_the_floor_triangles(tmp_path, write_spec):
    """The attack's ~1e-5 mm (12 GB, or a segfault): now the same triangles as at the floor, and the report says
    which tolerance was used."""
    text = PAPER.read_text() + ("\n[outputs]\nend_cap_mold = false\nneedle_mount = true\nassembly = false\n"
                                "neck_plate = false\nguides = false\nspacers = false\n")
    fine = write_spec(text + "[machine]\nstl_tolerance = 2e-5\n", "fine.toml")
    code, out, err = run_cli("build", fine, "--out", tmp_path / "fine", "--json")
    assert code == 0, err
    mesh = json.loads((tmp_path / "fine" / "report.json").read_text())["meshes"]["needle_mount.stl"]
    assert mesh["chordal_tolerance_mm"] > 1e-3 and mesh["triangles"] < 50_000 and mesh["watertight"]


def test_export_failure_is_an_os_error_not_a_runtime_error(tmp_path, monkeypatch):
    import build123d
    from build123d import Box

    from matcad.export import mesh

    monkeypatch.setattr(build123d, "export_stl", lambda *a, **k: False)
    monkeypatch.setattr(build123d, "export_step", lambda *a, **k: False)
    monkeypatch.setattr("shutil.disk_usage", lambda p: type("U", (), {"free": 0})())
    with pytest.raises(OSError, match="no space left"):
        mesh.write_stl(Box(1, 1, 1), tmp_path / "a.stl", 0.01, 0.1)
    with pytest.raises(OSError, match="no space left"):
        mesh.write_step(Box(1, 1, 1), tmp_path / "a.step")


# ---- issue 21: --set obeys the spec file's limits and refuses text after its value ----------------------------

@pytest.mark.parametrize("value,needles", [
    ("9" * 5000, ["neck.diameter", "5000 digits"]),
    ("[" * 3000 + "]" * 3000, ["--set neck.diameter", "deeper than 32"]),
    ("2.0\n[air]\ntemperature_c=-20", ["--set neck.diameter", "text after its value", "temperature_c=-20"]),
])
def test_set_values_obey_the_file_limits(value, needles):
    code, out, err = run_cli("check", PAPER, "--set", f"neck.diameter={value}")
    _assert_clean(code, err, 2, *needles)
    assert len(err) < 600 and out == ""


def test_set_comment_after_a_value_is_no_trailing_text():
    from matcad.spec.io import parse_assignment

    assert parse_assignment("neck.diameter=2.0  # calipered") == (["neck", "diameter"], 2.0)
    assert parse_assignment("wall.model=silicone") == (["wall", "model"], "silicone")


def test_file_integer_beyond_the_digit_limit_names_its_field(write_spec):
    code, _, err = run_cli("check", write_spec(MINIMAL.replace("length = 4.76", "length = " + "9" * 5000)))
    _assert_clean(code, err, 2, "cavity.length", "5000 digits", "line 4")
    assert "ValueError" not in err


# ---- issue 21: files from the user's world --------------------------------------------------------------------

def test_utf8_bom_spec_and_csv_are_read_as_without_it(tmp_path):
    spec = tmp_path / "bom.toml"
    spec.write_bytes(b"\xef\xbb\xbf" + LASER_ONLY.encode())
    plain = tmp_path / "plain.toml"
    plain.write_text(LASER_ONLY)
    code_bom, out_bom, err = run_cli("predict", spec, "--json")
    assert code_bom == 0, err
    assert json.loads(out_bom)["f0_hz"] == json.loads(run_cli("predict", plain, "--json")[1])["f0_hz"]
    rows = "force_n,frequency_hz\n" + "".join(f"{f},{4500 + 9 * f + 0.1 * f * f}\n" for f in range(0, 20, 2))
    data = tmp_path / "bom.csv"
    data.write_bytes(b"\xef\xbb\xbf" + rows.encode())
    plain_csv = tmp_path / "plain.csv"
    plain_csv.write_text(rows)
    code, out, err = run_cli("calibrate", data, "--spec", PAPER, "--out", tmp_path / "c", "--json")
    assert code == 0, err
    want = json.loads(run_cli("calibrate", plain_csv, "--spec", PAPER, "--out", tmp_path / "d", "--json")[1])
    got = json.loads(out)
    assert got["points"] == 10 and (got["a"], got["b"]) == (want["a"], want["b"])


@pytest.mark.parametrize("rows", ["force_n;frequency_hz\n0;4500,5\n2;4520,1\n",
                                  "force_n,frequency_hz\n0,\"4500,5\"\n2,\"4520,1\"\n"])
def test_european_csv_is_named_as_such(rows, tmp_path):
    data = tmp_path / "eu.csv"
    data.write_text(rows)
    code, _, err = run_cli("calibrate", data, "--spec", PAPER, "--out", tmp_path / "c")
    _assert_clean(code, err, 2, "European", "';' between columns", "decimal mark")
    assert not (tmp_path / "c").exists()


def test_spec_in_inches_gets_a_unit_note(write_spec):
    inches = 'name = "t"\n[cavity]\ndiameter = 0.125\nlength = 0.1875\n[neck]\ndiameter = 0.0827\nlength = 0.25\n'
    code, _, err = run_cli("predict", write_spec(inches))
    assert code == 0, err
    assert "inches?" in err and "cavity.diameter = 3.175" in err and "neck.length = 6.35" in err
    code, _, err = run_cli("predict", PAPER)
    assert "inches" not in err


def test_band_in_khz_gets_a_hint(tmp_path):
    wav = tmp_path / "r.wav"
    wavfile.write(wav, 44100, (np.sin(2 * np.pi * 4600 * np.arange(44100) / 44100) * 2e4).astype(np.int16))
    code, _, err = run_cli("analyze", wav, "--band", "4.5", "5.5", "--out", tmp_path / "a")
    _assert_clean(code, err, 2, "kHz", "--band 4500 5500")
    assert not (tmp_path / "a").exists()
    code, _, err = run_cli("analyze", wav, "--band", "0.001", "0.01", "--out", tmp_path / "a")  # 1-10 Hz in kHz:
    _assert_clean(code, err, 2, "--band 0.001 0.01", "below 100 Hz as well")  # still below 100 Hz, no suggestion
    assert "did you mean" not in err and not (tmp_path / "a").exists()


@pytest.mark.parametrize("target", ["C:\\Users\\lab\\out", "D:/kits", "kits\\paper"])
def test_windows_out_path_is_refused_on_posix(target, tmp_path):
    code, _, err = run_cli("build", ROOT / "templates" / "mat-laser-only.toml", "--out", target, cwd=tmp_path)
    _assert_clean(code, err, 2, "Windows path", "--out")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv,code,field", [
    (["predict", PAPER, "--set", "neck.diameter=-1"], 2, "neck.diameter"),
    (["check", "missing.toml"], 2, "spec file"),
    (["calibrate", "missing.csv", "--spec", PAPER], 2, None),
])
def test_json_error_object_on_stdout(argv, code, field):
    got, out, err = run_cli(*argv, "--json")
    assert got == code, err
    error = json.loads(out)["error"]
    assert error["exit_code"] == code and error["field"] == field and error["message"] in err
    assert error["written"] == []


@pytest.mark.parametrize("argv,field", [(["build", PAPER, "--out", "C:\\kits"], "--out"),
                                        (["predict", PAPER, "--nosuch"], None), (["predict", PAPER, "--load"], "--load")])
def test_json_error_object_for_a_usage_error(argv, field):
    """argparse's own refusals (an --out refused by its type, an unknown option, a missing value) exit 2 before a
    command runs: with --json they print the JSON error object too (stdout was empty before; found by
    benchmarks/fuzz.py world)."""
    code, out, err = run_cli(*argv, "--json")
    assert code == 2 and "error:" in err
    error = json.loads(out)["error"]
    assert error["exit_code"] == 2 and error["field"] == field and error["message"] in err


def test_json_error_object_for_a_loop_refusal(tmp_path):
    wav = tmp_path / "silence.wav"
    wavfile.write(wav, 44100, np.zeros(44100, np.int16))
    code, out, err = run_cli("analyze", wav, "--band", "4000", "5500", "--json", "--out", tmp_path / "a")
    assert code == 1 and json.loads(out)["error"]["message"] in err


@pytest.mark.parametrize("text,field", [("name = 't'\n[cavity]\ndiameter = 3\nlength = 4\n", "neck"),
                                        (MINIMAL.replace("length = 6.35\n", ""), "neck.length"),
                                        ("[cavity]\ndiameter = 3\n", "name")])
def test_missing_table_or_field_is_named_without_none(text, field, write_spec):
    code, _, err = run_cli("check", write_spec(text))
    _assert_clean(code, err, 2, f"{field}: is required")
    assert "None" not in err


# ---- issue 21: partly fixed before ----------------------------------------------------------------------------

def test_full_stdout_says_truthfully_what_was_written(tmp_path):
    """`> /dev/full`: the kit is written whole, then the summary cannot be printed; the message says so (exit 2),
    never that nothing was written. A command that writes nothing says that."""
    import subprocess
    import sys

    spec = tmp_path / "s.toml"
    spec.write_text(LASER_ONLY)
    kit = tmp_path / "k"
    for extra in ([], ["--json"]):
        with open("/dev/full", "w") as full:
            proc = subprocess.run([sys.executable, "-m", "matcad", "build", spec, "--out", kit, *extra], cwd=ROOT,
                                  stdout=full, stderr=subprocess.PIPE, text=True)
        _assert_clean(proc.returncode, proc.stderr, 2, "standard output", "written and is complete", str(kit))
        assert _kit_intact(kit)
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "matcad", "check", spec], cwd=ROOT, stdout=full,
                              stderr=subprocess.PIPE, text=True)
    _assert_clean(proc.returncode, proc.stderr, 2, "standard output", "nothing was written")


def test_float_wav_at_1e300_is_refused_without_numpy_warnings(tmp_path):
    wav = tmp_path / "f.wav"
    wavfile.write(wav, 44100, np.array([1e300, -1e300, 0.5] * 3000, np.float64))
    code, _, err = run_cli("analyze", wav, "--band", "4000", "5500", "--out", tmp_path / "a")
    _assert_clean(code, err, 2, "recording", "1e+300")
    assert "Warning" not in err and "nan" not in err


def test_subnormal_calibration_frequencies_are_refused_cleanly(tmp_path):
    data = tmp_path / "sub.csv"
    data.write_text("force_n,frequency_hz\n0,1e-319\n1,1.02e-319\n2,1.04e-319\n3,1.03e-319\n")
    code, _, err = run_cli("calibrate", data, "--spec", PAPER, "--out", tmp_path / "c")
    _assert_clean(code, err, 2, "calibration data", "row 2", "frequency")
    assert "Warning" not in err and "did you mean" not in err
    from matcad.spec import frequency_notes

    assert frequency_notes([1e-300]) == [] and frequency_notes([4.5, 4.6])  # kHz still gets its note


def test_force_on_an_unforceable_rule_says_it_cannot_be_forced(write_spec, tmp_path):
    path = write_spec(PAPER.read_text() + "\n[needle]\ntheta_deg = 1e-6\n")
    code, out, err = run_cli("build", path, "--force", "--out", tmp_path / "k")
    _assert_clean(code, err, 1, "--force cannot override", "needle.bore")
    assert "use --force" not in err
    code, out, err = run_cli("build", path, "--force", "--json", "--out", tmp_path / "k")
    assert code == 1 and json.loads(out)["unforceable"] == ["needle.bore"]
    code, _, err = run_cli("build", path, "--out", tmp_path / "k")
    _assert_clean(code, err, 1, "--force cannot override needle.bore")
    assert not (tmp_path / "k").exists()


@pytest.mark.parametrize("seconds", [0.094, 0.12, 0.138])
def test_short_clean_tone_says_it_is_too_short(seconds, tmp_path):
    wav = tmp_path / "short.wav"
    t = np.arange(int(44100 * seconds)) / 44100
    wavfile.write(wav, 44100, (np.sin(2 * np.pi * 4600 * t) * 2e4).astype(np.int16))
    code, _, err = run_cli("analyze", wav, "--band", "4000", "5500", "--out", tmp_path / "a")
    _assert_clean(code, err, 1, "too short for a run of 2 frames", "record longer")


@pytest.mark.parametrize("seconds", [0.15, 0.3, 0.46])
def test_clean_tone_too_short_near_a_harmonic_sound_says_so(seconds, tmp_path):
    """A synthesised tone of 2-9 frames: its rounding error repeats every 441 samples (4600/44100 Hz = 46/441), a
    100 Hz comb below the band that the harmonic detector hears as a voice, so a run needs 10 frames. The message
    says that, never "no frame has a line >= 15 dB" beside a best frame of 65.9 dB; with a little noise (3 LSB)
    the same tone is found."""
    t = np.arange(int(44100 * seconds)) / 44100
    tone = np.sin(2 * np.pi * 4600 * t) * 2e4
    wav = tmp_path / "clean.wav"
    wavfile.write(wav, 44100, tone.astype(np.int16))
    code, _, err = run_cli("analyze", wav, "--band", "4000", "5500", "--out", tmp_path / "a")
    _assert_clean(code, err, 1, "harmonic sound", "was heard below the band", "a run of 10 frames", "record longer")
    assert "no frame has a line" not in err
    noisy = tmp_path / "noisy.wav"
    wavfile.write(noisy, 44100, (tone + np.random.default_rng(0).normal(0, 3, len(t))).astype(np.int16))
    code, _, err = run_cli("analyze", noisy, "--band", "4000", "5500", "--out", tmp_path / "b")
    assert code == 0, err


# ---- issue 21: numbers inside their range that crashed ---------------------------------------------------------

@pytest.mark.parametrize("setting,field", [("wall.khz_modulus_factor=[1e-300, 1e-300]", "wall.khz_modulus_factor"),
                                           ("wall.khz_modulus_factor=[0.5, 1.0]", "wall.khz_modulus_factor"),
                                           ("wall.shear_modulus_mpa=[1e-300, 1e-300]", "wall.shear_modulus_mpa")])
@pytest.mark.parametrize("command", ["check", "predict"])
def test_unphysical_wall_moduli_are_refused_at_the_spec(setting, field, command):
    """G = G_static × factor underflowed to 0 (exit 70): an elastomer's storage modulus never falls with frequency
    (factor >= 1) and no cast silicone is softer than ~1 kPa, so both are refused naming the field."""
    code, _, err = run_cli(command, PAPER, "--set", setting)
    _assert_clean(code, err, 2, field)


@pytest.mark.parametrize("template", ["mat-paper.toml", "mat-array-4.toml"])
def test_lossless_wall_follows_the_helmholtz_branch(template):
    """η → 0 (loss_factor = [0, 0] is allowed): the resonance stays the taxel's, continuous with a lightly damped
    wall, never an undamped wall mode's spike (the paper's taxel gave 3033 Hz for 5288 Hz before)."""
    from matcad.prediction import predict

    base = spec_mod.load(ROOT / "templates" / template)
    base = spec_mod.taxel_spec(base, spec_mod.taxels(base)[0])
    f = {}
    for eta in (0.0, 1e-9, 1e-3, 0.01, 0.05):
        f[eta] = predict(dataclasses.replace(base, wall=dataclasses.replace(base.wall, loss_factor=(eta, eta))))
    assert f[0.0].f0_hz == pytest.approx(f[0.01].f0_hz, rel=0.005)
    assert f[0.0].f0_hz == pytest.approx(f[1e-9].f0_hz, rel=1e-6)
    for eta, p in f.items():
        assert p.band_hz[0] > 0.85 * f[0.05].band_hz[0] and p.band_hz[1] < 1.15 * f[0.05].band_hz[1], (eta, p.band_hz)


def test_rigid_fem_whose_cavity_energy_check_fails_is_told_and_its_band_reaches_the_transmission_line():
    """`predict --model fem` on a rigid wall where the FEM's mode keeps too little of its energy in the cavity
    (mat-array-4's taxel t4, 0.24 < 0.3): the FEM's f0 is the one asked for, marked invalid with a warning naming
    the check (matcad.acoustics.checks 'mode_in_cavity'), and since the mode it solved may not be the taxel's its
    band reaches the transmission line's f0 (it was 9017-9263 Hz around 9172 Hz, +-0.1 % model error, leaving out
    the transmission line's 8630 Hz; exit 70 before that, KeyError: 'mode_in_cavity'). A FEM whose checks pass
    (t3) keeps its own tight band."""
    from matcad.prediction import predict

    board = spec_mod.load(ROOT / "templates" / "mat-array-4.toml")
    board = dataclasses.replace(board, wall=dataclasses.replace(board.wall, model="rigid"))
    taxel = {t.name: spec_mod.taxel_spec(board, t) for t in spec_mod.taxels(board)}
    p = predict(taxel["t4"], model="fem", fem_level=2)
    fem, line = p.models["fem"], p.models["transmission_line"]
    assert p.model == "fem" and p.f0_hz == fem.f0_hz and not fem.valid and line.valid
    assert any("keeps less than 0.3 of its energy in the cavity" in w for w in p.warnings), p.warnings
    assert p.band_hz[0] <= line.f0_hz < 0.97 * fem.f0_hz < fem.f0_hz < p.band_hz[1], (p.band_hz, line.f0_hz)
    assert "its checks fail" in p.budget[0].tolerance and "transmission_line" in p.budget[0].tolerance
    passing = predict(taxel["t3"], model="fem", fem_level=2)
    assert passing.models["fem"].valid
    assert passing.models["transmission_line"].f0_hz < 0.97 * passing.band_hz[0]


# ---- issue 21: cap mechanics step cuts recover ------------------------------------------------------------------

def _paper_cap(steps: int, displacement_mm: float = 2.0, **end_cap):
    from matcad.mechanics.case import cap_case
    from matcad.mechanics.solver import cap_curve

    spec = spec_mod.load(PAPER)
    spec = dataclasses.replace(spec, end_cap=dataclasses.replace(spec.end_cap, **end_cap), mechanics=dataclasses.replace(
        spec.mechanics, steps=steps, displacement_mm=displacement_mm))
    return spec, cap_curve(cap_case(spec))


def test_a_cut_step_restores_the_condensed_state_so_steps_do_not_set_the_end():
    """A failed Newton step restored the displacements but not the nearly-incompressible solid's condensed pressure
    and volume ratio: the paper cap's curve stopped at 0 mm with 1 step (budget spent, "df/dF = 0.0 Hz/N") and at
    1.5 mm with 4. Restored (FElupe checkpoint/restore), 1 and 10 steps both reach 2 mm at the same force."""
    _, one = _paper_cap(1)
    _, ten = _paper_cap(10)
    for curve in (one, ten):
        assert curve.complete and curve.column("displacement_mm")[-1] == pytest.approx(2.0), curve.message
    assert one.column("force_n")[-1] == pytest.approx(ten.column("force_n")[-1], rel=0.01)


def test_df_dF_at_0_is_the_curve_tangent_not_a_one_step_difference():
    """df/dF at 0 N from the parabola through the first three states: 4 and 10 steps agree to 1 % (a one-step
    difference gave 54.5 and 57.4 Hz/N); the same curve's one-step difference lies below it (f(F) is concave)."""
    from matcad.acoustics.design import design
    from matcad.mechanics.frequency import force_curve

    slopes = {}
    for steps in (4, 10):
        spec, curve = _paper_cap(steps)
        fc = force_curve(design(spec), curve)
        slopes[steps] = fc.sensitivity_hz_per_n[0]
        one_step = (fc.states[1].f_hz - fc.states[0].f_hz) / (fc.states[1].force_n - fc.states[0].force_n)
        assert one_step < slopes[steps]
    assert slopes[4] == pytest.approx(slopes[10], rel=0.01)


def test_tangent_is_exact_on_a_parabola_and_none_without_a_step():
    """The tangent at 0 N is exact for f = a + bF + cF² on uneven states (a one-step difference is off by c·F1);
    with one state (no step converged) it is NaN, told as None / "n/a", never "df/dF = 0.0 Hz/N"."""
    from matcad.mechanics.frequency import tangent_hz_per_n

    forces = np.array([0.0, 0.7, 1.9, 3.2])
    slope = tangent_hz_per_n(forces, 4000 + 57 * forces - 0.8 * forces ** 2)
    assert slope == pytest.approx(57 - 1.6 * forces, rel=1e-12)
    assert np.isnan(tangent_hz_per_n([0.0], [4000.0])).all()


@pytest.mark.slow
def test_curve_end_does_not_depend_on_steps_or_travel():
    """Paper cap: 1/2/3/4/10 steps all reach 2 mm (0/1.0/1.33/1.5/2.0 mm before); asking 3 mm does not stop it
    short of 2 mm (1.5 mm before); the Ø6 cap with a 1 mm top reaches 1.5 mm (a 'crease' stop at 1.2 mm before)."""
    for steps in (1, 2, 3, 4, 10):
        _, curve = _paper_cap(steps)
        assert curve.complete, (steps, curve.message)
    _, longer = _paper_cap(10, 3.0)
    assert longer.column("displacement_mm")[-1] > 2.0, longer.message
    _, small = _paper_cap(10, 1.5, outer_diameter=6.0, top_thickness=1.0)
    assert small.complete, small.message
