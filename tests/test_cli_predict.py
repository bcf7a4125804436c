"""`matcad predict` and `matcad schema` as a user runs them."""

import json
import sys

import pytest

from tests.conftest import MINIMAL, PAPER, run_cli


def test_predict_json_fields():
    code, out, err = run_cli("predict", PAPER, "--json", "--force", "0", "15.4", "30")
    assert code == 0, err
    data = json.loads(out)
    assert data["cavity_volume_mm3"] == pytest.approx(37.805, abs=1e-3)
    assert data["neck_area_mm2"] == pytest.approx(3.4636, abs=1e-4)
    assert data["speed_of_sound_m_s"] == pytest.approx(343.2, abs=0.05)
    assert {"lumped", "end_corrected", "transmission_line"} <= set(data["models"])
    assert all(m["f0_hz"] > 0 for m in data["models"].values())
    lo, hi = data["band_hz"]
    assert lo < data["f0_hz"] < hi
    assert isinstance(data["warnings"], list)
    curve = [p for p in data["load_curve"] if p["source"].startswith("calibration")]
    assert [p["force_n"] for p in curve] == [0.0, 15.4, 30.0]
    assert curve[0]["f_hz"] == pytest.approx(4010, abs=5)
    assert curve[2]["f_hz"] is None and "minimum" in curve[2]["reason"]


def test_predict_table():
    code, out, _ = run_cli("predict", PAPER)
    assert code == 0
    for word in ("lumped", "end_corrected", "transmission_line", "band", "warnings"):
        assert word in out


def test_predict_does_not_import_cad_kernel():
    code = ("import sys; from matcad.cli import main; main(['predict', %r, '--json']); "
            "bad = [m for m in ('build123d', 'OCP', 'trimesh', 'manifold3d', 'ezdxf', 'skfem', 'felupe', 'tensortrax') "
            "if m in sys.modules]; assert not bad, bad" % str(PAPER))
    import subprocess
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_predict_loads_no_board_bands_output_folders_or_threads():
    """One taxel's `predict` writes no folder and has no board: matcad.output (hashlib, shutil) and
    matcad.prediction.bands stay unloaded, and without a terminal no progress line ticks (threading)
    (issue 25: predict near its imports)."""
    code = ("import sys; from matcad.cli import main; assert main(['predict', %r]) == 0; bad = [m for m in "
            "('matcad.output', 'matcad.prediction.bands', 'hashlib', 'threading') if m in sys.modules]; "
            "assert not bad, bad" % str(PAPER))
    import subprocess
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize("text,field", [
    (MINIMAL.replace("diameter = 2.1", "diameter = -2.1"), "neck.diameter"),
    (MINIMAL.replace("diameter = 2.1", "diameter = 5.0"), "neck.diameter"),
    (MINIMAL.replace("length = 4.76", "length = nan"), "cavity.length"),
    (MINIMAL.replace("length = 4.76", 'length = "long"'), "cavity.length"),
    (MINIMAL + "[air]\ntemprature_c = 20\n", "air.temprature_c"),
    (MINIMAL + '[neck2]\nx = 1\n', "neck2"),
    ("name = 'x'\n[cavity]\ndiameter = 3\n", "cavity.length"),
    ("not toml [", "spec file"),
])
def test_bad_spec_exit_2_one_line_naming_field(write_spec, text, field):
    code, out, err = run_cli("predict", write_spec(text))
    assert code == 2
    assert out == ""
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and field in lines[0], err


def test_missing_file(tmp_path):
    """(--force without a calibration is no longer an error: the cap mechanics answers, tests/test_mechanics_cli.py)"""
    code, _, err = run_cli("predict", tmp_path / "nope.toml")
    assert code == 2 and "spec file" in err and "Traceback" not in err


def test_schema_text_and_json():
    code, out, _ = run_cli("schema")
    assert code == 0 and "cavity.diameter [mm]" in out
    code, out, _ = run_cli("schema", "--json")  # a JSON Schema now (tests/test_json_schema.py); rows with --rows
    schema = json.loads(out)
    assert "mount" in schema["properties"]["neck"]["properties"]["mouth"]["enum"]
    code, out, _ = run_cli("schema", "--json", "--rows")
    rows = json.loads(out)
    assert any(r["key"] == "neck.mouth" and "mount" in r["allowed"] for r in rows)
