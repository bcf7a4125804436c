"""Drawn sizes (after kerf) are design rules: a hole the laser cannot draw is exit 1 from `check` and `build`
(also with --force) with the spec field named, never a negative radius in a DXF/SVG; the rule's drawn size is
the size the DXF carries."""

import json
import tomllib

import ezdxf
import pytest

from tests.conftest import PAPER, run_cli


def _spec_file(tmp_path, **over):
    data = tomllib.loads(PAPER.read_text())
    for key, value in over.items():
        section, field = key.split("__")
        data.setdefault(section, {})[field] = value
    data["outputs"] = {"end_cap_mold": False, "needle_mount": False, "assembly": False}
    lines = [f"name = {json.dumps(data.pop('name'))}"]
    for section, table in data.items():
        lines.append(f"[{section}]")
        lines += [f"{k} = {json.dumps(v) if not isinstance(v, bool) else str(v).lower()}" for k, v in table.items()]
    path = tmp_path / "spec.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("over,field", [
    ({"neck__diameter": 0.2, "machine__laser_kerf": 0.25}, "neck.diameter"),          # hole smaller than kerf
    ({"plate__neck_pilot": True, "plate__pilot_undersize": 2.1}, "plate.pilot_undersize"),  # pilot >= neck
])
def test_undrawable_hole_is_exit_1_everywhere_and_writes_nothing(tmp_path, over, field):
    spec = _spec_file(tmp_path, **over)
    code, out, _ = run_cli("check", spec, "--json")
    assert code == 1
    found = [f for f in json.loads(out)["findings"] if f["id"] == "laser.drawn_size"]
    assert found and found[0]["level"] == "error" and field in found[0]["message"] and found[0]["value"] <= 0
    for extra in ((), ("--force",)):
        code, out, err = run_cli("build", spec, "--out", tmp_path / "o", "--json", *extra)
        assert code == 1, (extra, err)
        assert not (tmp_path / "o").exists()
        assert any(f["id"] == "laser.drawn_size" for f in json.loads(out)["findings"])


def test_drawn_below_min_feature_is_an_error_whose_value_is_the_drawn_dxf_size(tmp_path):
    spec = _spec_file(tmp_path, machine__laser_min_feature=1.4)  # dowel holes 1.55 mm drawn at 1.30 mm
    code, out, _ = run_cli("check", spec, "--json")
    assert code == 1
    feature = {f["message"].split(":")[0]: f for f in json.loads(out)["findings"] if f["id"] == "laser.feature"}
    assert "neck_plate" in feature and "fasteners.dowel_diameter" in feature["neck_plate"]["message"]
    code, _, err = run_cli("build", spec, "--out", tmp_path / "o", "--force")
    assert code == 0, err
    msp = ezdxf.readfile(tmp_path / "o" / "neck_plate.dxf").modelspace()
    smallest = min(2 * c.dxf.radius for c in msp.query("CIRCLE[layer=='CUT_INNER']"))
    assert smallest == pytest.approx(feature["neck_plate"]["value"], abs=1e-4)


def test_coupon_with_undrawable_sweep_is_a_clear_error(tmp_path):
    spec = _spec_file(tmp_path, neck__diameter=0.3, machine__laser_kerf=0.25, machine__laser_min_feature=0.01)
    code, _, err = run_cli("coupon", spec, "--out", tmp_path / "c")
    assert code in (1, 2) and "Traceback" not in err and "drawn" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "c").exists()


def test_every_written_circle_is_positive_for_the_templates(tmp_path):
    code, _, err = run_cli("build", PAPER, "--out", tmp_path / "p")
    assert code == 0, err
    for dxf in (tmp_path / "p").glob("*.dxf"):
        radii = [c.dxf.radius for c in ezdxf.readfile(dxf).modelspace().query("CIRCLE")]
        assert radii and min(radii) > 0, dxf.name
