"""A board of taxels from a spec: the grid helper, [[taxel]] overrides, defaults, errors and round trips."""

import json
import tomllib
from pathlib import Path

import pytest

from matcad import spec as spec_mod
from matcad.spec import field_path, taxel_spec, taxels

from tests.conftest import SINGLE_TEMPLATES

PAPER = Path(__file__).parents[1] / "templates" / "mat-paper.toml"


def _paper(**extra) -> dict:
    return tomllib.loads(PAPER.read_text()) | extra


@pytest.mark.parametrize("path", SINGLE_TEMPLATES, ids=lambda p: p.stem)
def test_single_taxel_spec_is_one_taxel_at_the_centre(path):
    spec = spec_mod.load(path)
    (t,) = taxels(spec)
    assert (t.name, t.x, t.y) == ("t1", 0.0, 0.0)
    assert (t.cavity, t.neck, t.end_cap, t.needle) == (spec.cavity, spec.neck, spec.end_cap, spec.needle)
    assert taxel_spec(spec, t) == spec


def test_grid_is_centred_row_by_row_from_the_top_left():
    spec = spec_mod.from_dict(_paper(array={"columns": 3, "rows": 2, "pitch_x": 12.0, "pitch_y": 10.0}))
    got = [(t.name, t.x, t.y) for t in taxels(spec)]
    assert got == [("t1", -12.0, 5.0), ("t2", 0.0, 5.0), ("t3", 12.0, 5.0),
                   ("t4", -12.0, -5.0), ("t5", 0.0, -5.0), ("t6", 12.0, -5.0)]
    assert all(t.cavity == spec.cavity and t.end_cap == spec.end_cap for t in taxels(spec))


def test_entries_override_the_shared_tables_and_size_their_own_caps():
    data = _paper(taxel=[{"x": -6.0, "y": 1.0, "cavity_diameter": 4.0, "needle_theta_deg": 60.0},
                         {"x": 6.0, "y": 0.0, "name": "thumb", "neck_diameter": 2.0, "cap_top_thickness": 3.0}])
    del data["end_cap"]  # caps then default to 2.5 D and 0.6 D of each taxel's own cavity
    spec = spec_mod.from_dict(data)
    a, b = taxels(spec)
    assert (a.name, a.x, a.y, b.name) == ("t1", -6.0, 1.0, "thumb")
    assert a.cavity.diameter == 4.0 and a.cavity.length == spec.cavity.length
    assert a.end_cap.outer_diameter == pytest.approx(2.5 * 4.0) and a.end_cap.top_thickness == pytest.approx(2.4)
    assert a.needle.theta_deg == 60.0 and b.needle.theta_deg == spec.needle.theta_deg
    assert b.neck.diameter == 2.0 and b.neck.length == spec.neck.length and b.neck.mouth == spec.neck.mouth
    assert b.end_cap.outer_diameter == pytest.approx(2.5 * spec.cavity.diameter) and b.end_cap.top_thickness == 3.0
    assert taxel_spec(spec, a).cavity.diameter == 4.0 and taxel_spec(spec, a).taxel == ()
    assert field_path(spec, 0, "cavity.diameter") == "taxel[1].cavity_diameter"
    assert field_path(spec, 1, "cavity.diameter") == "cavity.diameter"


def test_a_shared_end_cap_the_user_gave_is_every_taxel_s():
    spec = spec_mod.from_dict(_paper(taxel=[{"x": 0.0, "y": 0.0, "cavity_diameter": 3.6}]))
    assert taxels(spec)[0].end_cap.outer_diameter == spec.end_cap.outer_diameter == 8.0


@pytest.mark.parametrize("extra", [
    {"array": {"columns": 2, "rows": 2, "pitch_x": 12.0, "pitch_y": 12.0}},
    {"taxel": [{"x": -6.0, "y": 0.0, "cavity_length": 5.0}, {"x": 6.0, "y": 0.0, "name": "b", "needle_y": 0.5}]},
    {"taxel": [{"x": -6.0, "y": 0.0, "calibration": {"v0_mm3": 36.0, "a": -0.0086, "b": 0.4626}},
               {"x": 6.0, "y": 0.0, "calibration": {"v0_mm3": 30.0, "a": -0.01, "b": 0.5, "k_mm3_hz2": 7.9e8,
                                                    "force_range_n": [0.0, 15.0], "dof": 8,
                                                    "covariance": [1.0, 0, 0, 0, 0.01, 0, 0, 0, 1e-4]}}]}])
def test_array_specs_round_trip(extra):
    spec = spec_mod.from_dict(_paper(**extra))
    assert spec_mod.from_dict(spec_mod.to_dict(spec)) == spec
    assert spec_mod.from_dict(json.loads(json.dumps(spec_mod.to_dict(spec)))) == spec


@pytest.mark.parametrize("extra, field, words", [
    ({"taxel": [{"x": 0.0}]}, "taxel[1].y", "is required"),
    ({"taxel": [{"x": 0.0, "y": 0.0}, {"x": 1.0, "y": 0.0, "neck_diameter": 5.0}]}, "taxel[2].neck_diameter",
     "<= cavity.diameter"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "cap_outer_diameter": 3.0}]}, "taxel[1].cap_outer_diameter", "> cavity"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "cavity_diamter": 3.0}]}, "taxel[1].cavity_diamter", "did you mean"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "name": "a"}, {"x": 1.0, "y": 0.0, "name": "a"}]}, "taxel[2].name", "unique"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "name": "a/b"}]}, "taxel[1].name", "A-Z"),
    ({"taxel": [{"x": float("nan"), "y": 0.0}]}, "taxel[1].x", "finite"),
    ({"taxel": []}, "taxel", "1 to 64"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "calibration": {"v0_mm3": 36.0, "a": 0.0, "b": 0.5, "k_mm3_hz2": -1.0}}]},
     "taxel[1].calibration.k_mm3_hz2", "0 < value <= 1e+30 mm^3 Hz^2"),
    ({"taxel": [{"x": 0.0, "y": 0.0}, {"x": 1.0, "y": 0.0, "calibration": {"a": 0.0, "b": 0.5}}]},
     "taxel[2].calibration.v0_mm3", "is required"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "calibration": {"v0_mm3": 36.0, "a": 0.0, "b": 0.5,
                                                      "covariance": [1, 2, 3, 4, 5, 6, 7, 8, 9]}}]},
     "taxel[1].calibration.covariance", "symmetric"),
    ({"taxel": [{"x": 0.0, "y": 0.0, "calibration": 3.0}]}, "taxel[1].calibration", "must be a table"),
    ({"taxel": {"x": 0.0, "y": 0.0}}, "taxel", "[[taxel]] tables"),
    ({"taxel": [{"x": float(i), "y": 0.0} for i in range(65)]}, "taxel", "1 to 64"),
    ({"array": {"columns": 2}}, "array.pitch_x", "required"),
    ({"array": {"columns": 9, "rows": 8, "pitch_x": 1.0, "pitch_y": 1.0}}, "array.rows", "<= 64"),
    ({"array": {"columns": 0}}, "array.columns", "whole number"),
    ({"array": {"columns": 2, "pitch_x": 9.0}, "taxel": [{"x": 0.0, "y": 0.0}]}, "array", "not both"),
])
def test_bad_array_input_names_the_field(extra, field, words):
    with pytest.raises(spec_mod.SpecError) as err:
        spec_mod.from_dict(_paper(**extra))
    assert err.value.field == field and words in str(err.value)


def test_schema_lists_the_taxel_entry_fields():
    keys = {row["key"] for row in spec_mod.schema()}
    assert {"array.columns", "array.pitch_x", "taxel[].x", "taxel[].cavity_diameter", "taxel[].name"} <= keys
    # the [taxel.calibration] sub-table: exactly the fields of [calibration], listed from the same declarations
    assert {k.removeprefix("taxel[].") for k in keys if k.startswith("taxel[].calibration.")} == \
        {k for k in keys if k.startswith("calibration.")}
    assert "taxel[].calibration" not in keys
