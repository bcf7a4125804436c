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


def _rim_points(component, step):
    """Points every ``step`` mm along the boundary of a ceiling component (edges owned by one face) (mm)."""
    edges = component.edges_sorted
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    rim = unique[counts == 1]
    pts = []
    for a, b in component.vertices[rim]:
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1)
        pts.append(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a))
    return np.vstack(pts)


def measured_reaches(spec, out, report):
    """Farthest distance (mm) from a ceiling point to an escape, per ceiling (per cap: base face, pin end). The
    base face escapes through the lid's openings above it; the core pin's end face has none (a channel through
    the pin would cast a thread inside the cavity): its escape is its rim, where the pin's side rises."""
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
            z = round(float(pts[0, 2]), 3)
            if z < -1e-6:  # the pin's end face: solid pin above every point of it, escape at its rim
                assert not len(opened), f"{len(opened)} points of the pin end face see an opening through the pin"
                gap, _ = cKDTree(_rim_points(component, SAMPLE_MM / 4)[:, :2]).query(pts[:, :2])
            else:
                assert len(opened), f"a ceiling at z = {z:.2f} with no opening above it"
                gap, _ = cKDTree(opened[:, :2]).query(pts[blocked][:, :2]) if blocked.any() else (np.zeros(1), None)
            reaches.append((z, float(gap.max())))
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


def test_nothing_is_cast_inside_any_cavity(built):
    """The cavity (the acoustic volume) read back from the lid STL: a 0.2 mm grid filling each core pin's footprint
    over its length lies inside the lid's solid, so no silicone can be cast there (a vent through the pin cast a
    Ø1 × 7.8 mm thread, 3.7 mm³, before); the rule reports the same 0 mm³."""
    from matcad.parts.end_cap_mold import layout
    from matcad.parts.mold_layout import pin_tip_radius_mm

    spec, out, report = built
    lid = _design_frame(out, report, "end_cap_mold_lid.stl")
    step, r = 0.2, pin_tip_radius_mm(spec) - 0.05  # the drafted pin is narrowest at its tip
    g = np.arange(-r, r + 1e-9, step)
    xs, ys, zs = np.meshgrid(g, g, np.arange(-spec.cavity.length + 0.05, -0.05, step))
    keep = np.hypot(xs, ys).ravel() <= r
    grid = np.column_stack([xs.ravel(), ys.ravel(), zs.ravel()])[keep]
    for x in layout(spec).cap_x:
        outside = ~lid.contains(grid + [x, 0.0, 0.0])
        silicone = outside.sum() * step ** 3
        print(spec.name, f"cap at x = {x:.2f}: {len(grid)} points in the cavity, {silicone:.3f} mm³ castable")
        assert silicone == 0.0
    rule = next(f for f in report["findings"] if f["id"] == "mold.cavity_appendage")
    assert rule["level"] == "info" and rule["value"] == 0.0


def test_the_cavity_check_sees_a_vent_through_the_core_pin(monkeypatch):
    """Deliberate fault: the old vent along each core pin's axis (Ø mold.vent from the lid's top down to the pin's
    end) put back into the layout the lid is cut from. The lid loses that channel's volume, and the
    cavity-appendage rule turns it into an error measuring the thread it would cast inside the cavity
    (π/4 · 1² · 4.76 = 3.74 mm³ for the paper's taxel)."""
    from matcad.parts import end_cap_mold
    from matcad.parts.mold_layout import MoldLayout, Opening
    from matcad.rules import check
    from tests.conftest import PAPER

    spec = spec_mod.load(PAPER)
    clean = end_cap_mold.mold_lid(spec).volume
    assert [f.level for f in check(spec) if f.id == "mold.cavity_appendage"] == ["info"]
    honest = MoldLayout.openings.fget

    def with_pin_vent(self):
        return honest(self) + tuple(Opening(x, 0.0, self.vent, -spec.cavity.length, self.lid_thickness, "vent")
                                    for x in self.cap_x)

    monkeypatch.setattr(MoldLayout, "openings", property(with_pin_vent))
    thread = math.pi / 4 * spec.mold.vent ** 2 * spec.cavity.length
    lost = clean - end_cap_mold.mold_lid(spec).volume
    assert lost == pytest.approx(math.pi / 4 * spec.mold.vent ** 2 * (spec.cavity.length + spec.mold.lid_thickness),
                                 rel=1e-3)
    found = [f for f in check(spec) if f.id == "mold.cavity_appendage"]
    assert [f.level for f in found] == ["error"] and found[0].value == pytest.approx(thread, rel=1e-3)
