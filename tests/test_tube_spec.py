"""kind = "tube": the [tube] table, what a tube spec may carry, and MAT specs unchanged (docs/tube.md)."""

import subprocess
import sys
from pathlib import Path

import pytest

from matcad.spec import SpecError, from_dict, load, schema, to_dict

ROOT = Path(__file__).resolve().parents[1]
TUBE = ROOT / "templates" / "acoustac-tube.toml"
TUBE_DATA = {"name": "t", "kind": "tube", "tube": {"bore_diameter": 6.0, "length": 16.0}}


def test_tube_template_reads_back_and_fills_the_caps_cavity_from_the_bore():
    spec = load(TUBE)
    assert spec.kind == "tube" and spec.neck is None
    assert (spec.cavity.diameter, spec.cavity.length) == (spec.tube.bore_diameter, spec.tube.cap_cavity_depth)
    data = to_dict(spec)
    assert data["kind"] == "tube" and "cavity" not in data and "neck" not in data and "plate" not in data
    assert from_dict(data) == spec


def test_cap_depth_defaults_to_the_bore_and_mat_is_the_default_kind():
    assert from_dict(TUBE_DATA).cavity.length == 6.0
    mat = load(ROOT / "templates" / "mat-paper.toml")
    assert mat.kind == "mat" and mat.tube is None
    assert "kind" not in to_dict(mat) and "tube" not in to_dict(mat)  # MAT outputs keep their bytes


@pytest.mark.parametrize("extra, field, words", [
    ({"neck": {"diameter": 2.0, "length": 3.0}}, "neck", "does not apply to kind = 'tube'"),
    ({"plate": {"width": 20.0}}, "plate", "does not apply"),
    ({"array": {"rows": 2, "columns": 2}}, "array", "does not apply"),
    ({"kind": "pipe"}, "kind", "'mat', 'tube'"),
    ({"tube": {"bore_diameter": 6.0, "length": 16.0, "windway_width": 7.0}}, "tube.windway_width", "<= tube.bore"),
    ({"tube": {"bore_diameter": 6.0, "length": 16.0, "mouth": "transverse", "edge_distance": 6.0}},
     "tube.edge_distance", "< tube.bore_diameter = 6 mm for a transverse mouth"),
    ({"tube": {"bore_diameter": 6.0, "length": 16.0, "windway_height": 3.0}}, "tube.windway_height", "< tube.bore"),
    ({"tube": {"bore_diameter": 6.0, "length": 0.5}}, "tube.length", "2 <= value"),
    ({"tube": {"bore_diameter": 6.0, "length": 16.0, "edge_angle": 80}}, "tube.edge_angle", "<= 60 deg"),
])
def test_tube_spec_refuses_what_does_not_apply_naming_the_field(extra, field, words):
    with pytest.raises(SpecError) as err:
        from_dict({**TUBE_DATA, **extra})
    assert err.value.field == field and words in str(err.value)


def test_a_transverse_window_runs_along_the_bore_so_its_height_may_exceed_the_bore():
    """A transverse mouth's windway width B is the window's height along the bore (matcad.parts.tube.transverse_tube):
    no bound by the bore, which bounds its width W instead."""
    spec = from_dict({**TUBE_DATA, "tube": {"bore_diameter": 6.0, "length": 16.0, "mouth": "transverse",
                                            "windway_width": 7.0, "edge_distance": 3.0}})
    assert spec.tube.mouth == "transverse" and spec.tube.windway_width == 7.0


def test_a_mat_spec_with_a_tube_table_and_a_tube_without_one_are_refused():
    with pytest.raises(SpecError, match="applies only to kind = 'tube'"):
        from_dict({"name": "m", "cavity": {"diameter": 8.0, "length": 24.0}, "neck": {"diameter": 2.0, "length": 3.0},
                   "tube": TUBE_DATA["tube"]})
    with pytest.raises(SpecError, match="required for kind = 'tube'"):
        from_dict({"name": "t", "kind": "tube"})


def test_schema_lists_kind_and_every_tube_field_with_unit_and_range():
    rows = {row["key"]: row for row in schema()}
    assert rows["kind"]["choices"] == ["mat", "tube"] and rows["kind"]["default"] == "mat"
    for key in ("bore_diameter", "length", "cap_depth", "windway_height", "windway_width", "edge_distance",
                "edge_angle", "wall"):
        assert f"tube.{key}" in rows and rows[f"tube.{key}"]["unit"] in ("mm", "deg")


def test_cli_exit_2_and_one_line_for_a_tube_spec_with_a_neck(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(TUBE.read_text() + "\n[neck]\ndiameter = 2.0\nlength = 3.0\n")
    run = subprocess.run([sys.executable, "-m", "matcad", "predict", str(bad)], capture_output=True, text=True,
                         cwd=ROOT, timeout=120)
    assert run.returncode == 2 and "neck" in run.stderr and "does not apply to kind = 'tube'" in run.stderr
    assert "Traceback" not in run.stderr and run.stdout == ""


@pytest.mark.parametrize("argv", [["sweep", "--vary", "tube.length=10:20:3"], ["infer"], ["coupon"]])
def test_commands_for_mat_specs_only_refuse_a_tube_spec_with_exit_2(argv, tmp_path):
    run = subprocess.run([sys.executable, "-m", "matcad", argv[0], str(TUBE), *argv[1:], "--out", str(tmp_path / "o")],
                         capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 2 and "takes MAT specs only" in run.stderr and "Traceback" not in run.stderr
    assert not (tmp_path / "o").exists()
