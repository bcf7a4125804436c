"""Ecosystem conventions: the calibration TOML written by the project's TOML writer, FLAC/OGG recordings through
the optional soundfile extra (and a clear exit 2 without it)."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
import tomli_w

from tests.conftest import ROOT, run_cli

PAPER = ROOT / "matcad" / "templates" / "mat-paper.toml"


def test_calibration_toml_is_tomli_w_output_and_reads_back(tmp_path):
    forces = np.linspace(0.0, 20.0, 11)
    freqs = 2750.0 + 9.0 * forces - 0.12 * forces**2 + np.random.default_rng(3).normal(0, 2.0, forces.size)
    data = tmp_path / "cal.csv"
    data.write_text("force_n,frequency_hz\n" + "".join(f"{a},{b}\n" for a, b in zip(forces, freqs)))
    code, out, err = run_cli("calibrate", data, "--spec", PAPER, "--out", tmp_path / "c", "--json")
    assert code == 0, err
    fitted = json.loads(out)
    text = (tmp_path / "c" / "calibration.toml").read_text()
    table = tomllib.loads(text)["calibration"]
    for key in ("v0_mm3", "a", "b"):
        assert table[key] == fitted[key]  # floats round-trip exactly
    assert len(table["covariance"]) == 9 and isinstance(table["dof"], int) and table["area_convention"] == "pi_d2/4"
    body = text.split("\n", 1)[1]  # after the one comment line
    assert body == tomli_w.dumps({"calibration": table})


def _tone(path, rate=16000, seconds=3.0, f_hz=2000.0):
    import soundfile

    t = np.arange(int(rate * seconds)) / rate
    noise = 0.01 * np.random.default_rng(0).normal(size=t.size)  # a real microphone's floor
    soundfile.write(path, 0.3 * np.sin(2 * np.pi * f_hz * t) + noise, rate)


@pytest.mark.parametrize("suffix", [".flac", ".ogg"])
def test_flac_and_ogg_recordings_are_analysed(tmp_path, suffix):
    pytest.importorskip("soundfile")  # the dev extra installs it (matcad[audio])
    rec = tmp_path / f"tone{suffix}"
    _tone(rec)
    code, out, err = run_cli("analyze", rec, "--band", "1500", "2500", "--out", tmp_path / "a", "--json")
    assert code == 0, err
    assert json.loads(out)["median_hz"] == pytest.approx(2000.0, abs=5.0)


def test_compressed_recording_without_the_library_is_bad_input(tmp_path):
    pytest.importorskip("soundfile")
    rec = tmp_path / "tone.flac"
    _tone(rec)
    blocker = tmp_path / "block"
    blocker.mkdir()
    (blocker / "soundfile.py").write_text("raise ImportError('soundfile is not installed')\n")
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": f"{blocker}{os.pathsep}{ROOT}"}
    proc = subprocess.run([sys.executable, "-m", "matcad", "analyze", str(rec), "--band", "1500", "2500", "--out",
                           str(tmp_path / "a")], capture_output=True, text=True, cwd=ROOT, env=env)
    assert proc.returncode == 2 and "pip install 'matcad[audio]'" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "a").exists()
