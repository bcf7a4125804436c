"""Venting measured from the exported meshes: the caps as they sit in the closed mold (pour orientation), their
ceilings (up-facing silicone surface), the lid's openings found by casting rays straight up through the lid STL,
and the farthest ceiling point from an opening, against what the report claims."""

import json
import math

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from matcad import spec as spec_mod
from matcad.build import build
from matcad.parts.mold_layout import CEILING_TILT_DEG
from tests.conftest import SINGLE_TEMPLATES

MOLD_TEMPLATES = [p for p in SINGLE_TEMPLATES if spec_mod.load(p).outputs.end_cap_mold]
SAMPLE_MM = 0.08


@pytest.fixture(scope="module", params=MOLD_TEMPLATES, ids=lambda p: p.stem)
def built(request, tmp_path_factory):
    spec = spec_mod.load(request.param)
    out = tmp_path_factory.mktemp("vent") / spec.name
    build(spec, out)
    return spec, out, json.loads((out / "report.json").read_text())


def _design_frame(out, report, name):
    mesh = trimesh.load_mesh(out / name)
    mesh.apply_transform(np.linalg.inv(np.array(report["meshes"][name]["design_to_print"])))
    return mesh


def _ceiling_components(cap):
    """Connected groups of up-facing faces (flatter than CEILING_TILT_DEG) of one cap in the mold frame."""
    up = np.flatnonzero(cap.face_normals[:, 2] >= math.cos(math.radians(CEILING_TILT_DEG)))
    sub = cap.submesh([up], append=True, repair=False)
    groups = trimesh.graph.connected_components(sub.face_adjacency, nodes=np.arange(len(sub.faces)),
                                                engine="scipy")
    return [sub.submesh([g], append=True, repair=False) for g in groups]


def _grid_points(component, step):
    """Points on a step-mm grid whose xy falls inside a triangle of the (horizontal) component, at its height."""
    lo, hi = component.bounds[:, :2]
    xs, ys = np.meshgrid(np.arange(lo[0], hi[0] + step, step), np.arange(lo[1], hi[1] + step, step))
    p = np.column_stack([xs.ravel(), ys.ravel()])
    inside = np.zeros(len(p), dtype=bool)
    for a, b, c in component.triangles[:, :, :2]:
        d = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
        u = ((b[1] - c[1]) * (p[:, 0] - c[0]) + (c[0] - b[0]) * (p[:, 1] - c[1])) / d
        v = ((c[1] - a[1]) * (p[:, 0] - c[0]) + (a[0] - c[0]) * (p[:, 1] - c[1])) / d
        inside |= (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9)
    z = component.vertices[:, 2].mean()
    return np.column_stack([p[inside], np.full(inside.sum(), z)])


def measured_reaches(spec, out, report):
    """Farthest distance (mm) from a ceiling point to an opening, per ceiling (per cap: base face, pin end)."""
    from matcad.parts.end_cap_mold import layout

    lid = _design_frame(out, report, "end_cap_mold_lid.stl")
    cap_own = _design_frame(out, report, "end_cap.stl")
    reaches = []
    for x in layout(spec).cap_x:
        cap = cap_own.copy()
        cap.apply_transform(trimesh.transformations.rotation_matrix(math.pi, [1, 0, 0]))
        cap.apply_translation([x, 0, 0])
        for component in _ceiling_components(cap):
            pts = _grid_points(component, SAMPLE_MM)
            assert len(pts) > 50
            rays = pts + [0, 0, 1e-3]
            blocked = lid.ray.intersects_any(rays, np.tile([0.0, 0.0, 1.0], (len(rays), 1)))
            opened = pts[~blocked]
            assert len(opened), f"a ceiling at z = {pts[0, 2]:.2f} with no opening above it"
            gap, _ = cKDTree(opened[:, :2]).query(pts[blocked][:, :2]) if blocked.any() else (np.zeros(1), None)
            reaches.append((round(float(pts[0, 2]), 3), float(gap.max())))
    return reaches


def test_every_ceiling_reaches_an_opening_within_the_stated_distance(built):
    spec, out, report = built
    venting = report["casting"]["venting"]
    reaches = measured_reaches(spec, out, report)
    print(spec.name, "ceiling (z, farthest distance to an opening) mm:", reaches)
    assert len(reaches) == 2 * spec.mold.count  # base face and core-pin end of every cap
    for z, reach in reaches:
        assert reach <= venting["vent_reach_mm"] + SAMPLE_MM, (z, reach)
        claimed = venting["base_face_reach_mm"] if abs(z) < 1e-6 else venting["pin_end_reach_mm"]
        assert reach == pytest.approx(claimed, abs=2 * SAMPLE_MM + 0.02), (z, reach, claimed)
    assert {z for z, _ in reaches} == {0.0, -spec.cavity.length}


def test_pour_guide_in_the_report(built):
    spec, out, report = built
    c = report["casting"]
    md = (out / "report.md").read_text()
    assert c["batch_g"] >= 10.0 and c["batch_g"] >= c["needed_g"]
    assert f"{c['batch_g']:.1f} g" in md and f"{c['pot_life_min']:g} min" in md and "45 °C" in md
    assert "Release" in md and "Trim" in md
    if spec.machine.printer == "sla":
        assert "SLA cure inhibition" in md and "PLA" not in md
    else:
        assert "PLA" in md and "inhibition" not in md
