"""`matcad coupon`: the swept sizes, read back from the DXF and STL."""

import json

import ezdxf
import pytest
import trimesh

from matcad import spec as spec_mod
from matcad.parts.coupon import DOWEL_SWEEP_MM, NECK_SWEEP_MM, NEEDLE_SWEEP_MM, PRINTED_DOWEL_SWEEP_MM
from tests.conftest import PAPER, run_cli


def test_coupon_sizes_read_back(tmp_path):
    spec = spec_mod.load(PAPER)
    code, out, err = run_cli("coupon", PAPER, "--out", tmp_path / "c", "--json")
    assert code == 0, err
    folder = tmp_path / "c"
    doc = ezdxf.readfile(folder / "coupon_laser.dxf")
    assert doc.header["$INSUNITS"] == 4 and not doc.audit().has_errors
    drawn = sorted(round(2 * c.dxf.radius, 6) for c in doc.modelspace().query("CIRCLE"))
    finished = [spec.neck.diameter + d for d in NECK_SWEEP_MM] + [spec.fasteners.dowel_diameter + d
                                                                 for d in DOWEL_SWEEP_MM]
    assert drawn == pytest.approx(sorted(f - spec.machine.laser_kerf for f in finished), abs=1e-6)
    labels = {t.dxf.text for t in doc.modelspace().query("TEXT[layer=='ENGRAVE']")}
    assert {f"{f:.2f}" for f in finished} == labels
    mesh = trimesh.load_mesh(folder / "coupon_printed.stl")
    assert mesh.is_watertight and mesh.is_volume
    table = json.loads((folder / "report.json").read_text())
    bores = [h["diameter_mm"] for h in table["printed_holes"] if h["purpose"] == "needle"]
    assert bores == pytest.approx([spec.needle.outer_diameter + d for d in NEEDLE_SWEEP_MM])
    assert len(table["printed_holes"]) == len(NEEDLE_SWEEP_MM) + len(PRINTED_DOWEL_SWEEP_MM)
    # the printed bar really has those holes: its volume is the bar minus the cylinders
    assert mesh.volume == pytest.approx(table["mesh"]["brep_volume_mm3"], rel=1e-3)
