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
    "int-beyond-parser-digit-limit": (MINIMAL.replace("length = 4.76", "length = " + "9" * 5000), "spec file"),
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
    path = write_spec(MINIMAL + "#" * (spec_mod.SPEC_MAX_BYTES + 10) + "\n")
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
