"""Per-taxel calibrations carried in a board spec ([taxel.calibration]) and `sense --live` for a board: one line
per frame with every taxel on it, in time order, with the numbers of the non-live forces.csv."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.loop import synth
from matcad.prediction.bands import listening_bands as board_bands
from matcad.loop.board import LiveFrames
from matcad.spec import taxels
from tests.conftest import ROOT, run_cli

TAXELS = [("low", -6.0, 10.0), ("high", 6.0, 3.0)]  # name, x (mm), cavity length (mm)
FS, SECONDS = 44100.0, 4.0


def _board_text(tables=None) -> str:
    """The paper's taxel as a two-taxel [[taxel]] board; ``tables`` {name: TOML text} added under its entry."""
    text = (ROOT / "templates" / "mat-paper.toml").read_text()
    for name, x, length in TAXELS:
        text += f'\n[[taxel]]\nname = "{name}"\nx = {x}\ny = 0.0\ncavity_length = {length}\n'
        text += (tables or {}).get(name, "")
    return text


@pytest.fixture(scope="module")
def board(tmp_path_factory):
    """A 4 s recording of the two taxels (low pressed 2 → 10 N, high held at 4 N, room reverb), each taxel's
    calibration from `matcad calibrate --taxel NAME --k-free` on exact Eq. 5 points of its own tone, the plain
    board spec, and the board spec carrying both calibrations as the [taxel.calibration] tables calibrate wrote."""
    from scipy.io import wavfile

    tmp = tmp_path_factory.mktemp("calspec")
    plain = tmp / "board.toml"
    plain.write_text(_board_text())
    bands = board_bands(spec_mod.load(plain))
    f0 = [0.5 * (lo + hi) / 1.04 for _, (lo, hi) in bands]  # the middle of each band's unloaded part
    k_hz2 = [synth.EQ5.v0_mm3 * f**2 for f in f0]
    n = int(FS * SECONDS)
    force = [synth.press_profile(SECONDS, FS, [(0.8, 2.0, 10.0), (2.6, 3.4, 10.0)]), np.full(n, 4.0)]
    x = sum(synth.taxel(synth.frequency_of_force(F, k), FS, 5 + i) for i, (F, k) in enumerate(zip(force, k_hz2)))
    x = synth.room(x, FS, 3)
    pcm = np.round(x / np.max(np.abs(x)) * 30000).astype(np.int16)
    wavfile.write(tmp / "rec.wav", int(FS), pcm)
    points = np.linspace(0.0, 15.0, 11)
    files, tables = {}, {}
    for (name, _, _), k in zip(TAXELS, k_hz2):
        data = tmp / f"{name}.csv"
        data.write_text("force_n,frequency_hz\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in
                                                            zip(points, synth.frequency_of_force(points, k))))
        code, out, err = run_cli("calibrate", data, "--spec", plain, "--taxel", name, "--k-free",
                                 "--out", tmp / f"cal-{name}")
        assert code == 0, err
        assert "taxel_calibration.toml" in out
        files[name] = tmp / f"cal-{name}" / "calibration.toml"
        tables[name] = (tmp / f"cal-{name}" / "taxel_calibration.toml").read_text()
    spec_path = tmp / "board-cal.toml"
    spec_path.write_text(_board_text(tables))
    return {"tmp": tmp, "plain": plain, "spec": spec_path, "files": files, "pcm": pcm, "wav": tmp / "rec.wav"}


def _columns(folder) -> dict[str, list[str]]:
    """forces.csv read back: {column: cells as written}."""
    rows = [r.split(",") for r in (folder / "forces.csv").read_text().splitlines()]
    return {name: [r[i] for r in rows[1:]] for i, name in enumerate(rows[0])}


def test_calibrate_writes_the_table_a_taxel_entry_takes(board):
    """The [taxel.calibration] fragment `calibrate --taxel` writes, pasted under its entry, is the same
    calibration as its calibration.toml; the other taxel's is its own."""
    spec = spec_mod.load(board["spec"])
    low, high = taxels(spec)
    assert low.calibration == spec_mod.load_calibration(board["files"]["low"])
    assert high.calibration == spec_mod.load_calibration(board["files"]["high"])
    assert low.calibration != high.calibration
    assert spec_mod.from_dict(spec_mod.to_dict(spec)) == spec


def test_spec_calibrations_give_the_forces_of_the_same_files_on_the_command_line(board):
    tmp = board["tmp"]
    code, _, err = run_cli("sense", board["wav"], "--spec", board["spec"], "--out", tmp / "from-spec")
    assert code == 0, err
    args = [a for name, f in board["files"].items() for a in ("--calibration", f"{name}={f}")]
    code, _, err = run_cli("sense", board["wav"], "--spec", board["plain"], *args, "--out", tmp / "from-cli")
    assert code == 0, err
    spec_cols, cli_cols = _columns(tmp / "from-spec"), _columns(tmp / "from-cli")
    assert spec_cols == cli_cols  # every frame, every taxel, to the last digit written
    low = [float(v) for v in spec_cols["low_force_n"] if v]
    high = [float(v) for v in spec_cols["high_force_n"] if v]
    assert len(low) > 0.5 * len(spec_cols["time_s"]) and len(high) > 0.8 * len(spec_cols["time_s"])
    assert max(low) == pytest.approx(10.0, abs=0.7) and min(low) == pytest.approx(2.0, abs=0.7)
    assert np.median(high) == pytest.approx(4.0, abs=0.3)


def test_a_command_line_calibration_overrides_only_its_taxel(board):
    """--calibration low=FILE replaces the spec's low table (here: the high taxel's calibration, a wrong one on
    purpose); the high taxel's forces stay to the digit."""
    tmp = board["tmp"]
    code, _, err = run_cli("sense", board["wav"], "--spec", board["spec"], "--out", tmp / "base")
    assert code == 0, err
    code, out, err = run_cli("sense", board["wav"], "--spec", board["spec"], "--calibration",
                             f"low={board['files']['high']}", "--json", "--out", tmp / "override")
    assert code == 0, err
    import json

    assert json.loads(out)["calibrations"] == {"low": str(board["files"]["high"]),
                                               "high": "spec [taxel.calibration]"}
    base, over = _columns(tmp / "base"), _columns(tmp / "override")
    assert base["high_force_n"] == over["high_force_n"] and base["high_force_high_n"] == over["high_force_high_n"]
    assert base["low_frequency_hz"] == over["low_frequency_hz"]
    assert base["low_force_n"] != over["low_force_n"]


def test_bad_or_missing_calibrations_are_exit_2_naming_the_field(board):
    tmp = board["tmp"]
    bad = tmp / "bad.toml"
    bad.write_text(board["spec"].read_text().replace("k_mm3_hz2 = ", "k_mm3_hz2 = -", 1))
    code, _, err = run_cli("sense", board["wav"], "--spec", bad)
    assert code == 2 and "taxel[1].calibration.k_mm3_hz2 = -" in err and "0 < value <= 1e+30 mm^3 Hz^2" in err
    code, _, err = run_cli("sense", board["wav"], "--spec", board["plain"])
    assert code == 2 and "--calibration is required" in err and "[taxel.calibration]" in err
    assert "low, high" in err
    code, _, err = run_cli("sense", board["wav"])
    assert code == 2 and "--calibration FILE is required" in err
    assert not (tmp / "bad").exists()


LINE = re.compile(r"^\s*([0-9.]+) s  (.*)$")
TAXEL = re.compile(r"^(\w+) (?:no tone|([0-9.]+) Hz(?: F=([0-9.-]+)\+-([0-9.]+) N| outside the calibrated range)?)$")


def test_live_board_one_line_per_frame_in_time_order_with_the_forces_csv_numbers(board):
    """Raw PCM on standard input, --live with --out: one line per frame, strictly increasing times, every taxel
    once per line, and each value the forces.csv one (printed to 0.01 Hz and 0.001 N)."""
    out_dir = board["tmp"] / "live"
    proc = subprocess.run([sys.executable, "-m", "matcad", "sense", "-", "--spec", str(board["spec"]), "--live",
                           "--format", "s16le", "--rate", str(int(FS)), "--out", str(out_dir)],
                          input=board["pcm"].astype("<i2").tobytes(), capture_output=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    lines = [m.groups() for m in map(LINE.match, proc.stdout.decode().splitlines()) if m]
    cols = _columns(out_dir)
    assert len(lines) == len(cols["time_s"]) > 50
    times = np.array([float(t) for t, _ in lines])
    assert np.all(np.diff(times) > 0)
    assert np.allclose(times, [float(t) for t in cols["time_s"]], atol=5e-4)
    forces = 0
    for i, (_, body) in enumerate(lines):
        parts = [TAXEL.match(p) for p in body.split(" | ")]
        assert all(parts) and [p.group(1) for p in parts] == ["low", "high"], body
        for p in parts:
            name, freq, force, _ = p.groups()
            assert (freq is None) == (cols[f"{name}_frequency_hz"][i] == ""), (i, body)
            if freq is not None:
                assert abs(float(freq) - float(cols[f"{name}_frequency_hz"][i])) <= 0.0051
            assert (force is None) == (cols[f"{name}_force_n"][i] == ""), (i, body)
            if force is not None:
                assert abs(float(force) - float(cols[f"{name}_force_n"][i])) <= 0.00051
                forces += 1
    assert forces > len(lines)  # most frames carry both taxels' forces


def test_live_frames_join_out_of_step_reports_in_order():
    """LiveFrames: taxels reporting the same frames at different moments give one row per frame, in order, as
    soon as every taxel has it; flush emits the rest with the missing taxel as NaN."""
    rows = []
    live = LiveFrames(2, lambda t, v: rows.append((t, [f for f, _ in v])))
    for i in range(5):
        live(0, 0.1 * i, 100.0 + i, 1.0)  # taxel 0 runs ahead
    assert rows == [] and len(live.rows) == 5
    for i in range(3):
        live(1, 0.1 * i, 200.0 + i, 1.0)
    assert [t for t, _ in rows] == pytest.approx([0.0, 0.1, 0.2]) and rows[2][1] == [102.0, 202.0]
    assert len(live.rows) == 2  # only the frames between the slower and the faster taxel are kept
    live.flush()
    assert len(rows) == 5 and rows[4][1][0] == 104.0 and np.isnan(rows[4][1][1]) and live.rows == {}
