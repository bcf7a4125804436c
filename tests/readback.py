"""Read a build folder back with the libraries fabricators' software uses; shared by the template tests and
the fuzzer. Every check is an assertion on real file contents."""

from __future__ import annotations

import hashlib
import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import ezdxf
import numpy as np
import pytest

from matcad.export.dxf_svg import LAYERS
from matcad.output import MANIFEST
from matcad.parts.catalogue import laser_parts
from matcad.report import REPORT_FILES

SVG = "{http://www.w3.org/2000/svg}"


def assert_manifest(out: Path) -> dict:
    report = json.loads((out / "report.json").read_text())
    listed = {f["file"]: f for f in report["files"]}
    assert set(listed) == {p.name for p in out.iterdir()} - set(REPORT_FILES) - {MANIFEST}
    for name, row in listed.items():
        data = (out / name).read_bytes()
        assert row["bytes"] == len(data) and row["sha256"] == hashlib.sha256(data).hexdigest()
    return report


def assert_laser_files(spec, out: Path) -> None:
    for flat in laser_parts(spec):
        kerf = flat.kerf
        doc = ezdxf.readfile(out / f"{flat.name}.dxf")
        assert doc.header["$INSUNITS"] == 4
        assert not doc.audit().has_errors
        assert len({doc.layers.get(name).color for name in LAYERS}) == len(LAYERS)
        msp = doc.modelspace()
        assert not msp.query("SPLINE ELLIPSE")
        drawn = sorted(2 * c.dxf.radius for c in msp.query("CIRCLE[layer=='CUT_INNER']"))
        want = sorted([h.diameter - kerf for h in flat.holes] * flat.quantity)
        assert len(drawn) == len(want) and all(abs(a - b) <= 1e-6 for a, b in zip(drawn, want))
        outlines = msp.query("LWPOLYLINE[layer=='CUT_OUTER']")
        assert len(outlines) == flat.quantity and all(p.closed for p in outlines)
        xs = [x for x, *_ in outlines[0].get_points("xyb")]
        assert abs(max(xs) - min(xs) - (flat.width + kerf)) <= 1e-6
        root = ET.parse(out / f"{flat.name}.svg").getroot()
        w, h = (float(re.fullmatch(r"([\d.]+)mm", root.get(k)).group(1)) for k in ("width", "height"))
        vb = [float(v) for v in root.get("viewBox").split()]
        assert abs(vb[2] - w) < 1e-9 and abs(vb[3] - h) < 1e-9
        groups = {g.get("id"): g for g in root.iter(f"{SVG}g")}
        assert groups["CUT_INNER"].get("stroke") == LAYERS["CUT_INNER"][1]
        assert groups["CUT_OUTER"].get("stroke") == LAYERS["CUT_OUTER"][1]


def expected_bodies(spec, stl_name: str) -> int:
    """Separate bodies in an exported STL: one, except a board's cap reference (its distinct caps side by side)."""
    from matcad.parts.mold_layout import cap_groups
    from matcad.spec import taxels

    return len(cap_groups(taxels(spec))) if stl_name == "end_cap.stl" else 1


def assert_meshes(spec, report: dict, out: Path) -> None:
    import trimesh

    for name, checks in report["meshes"].items():
        mesh = trimesh.load_mesh(out / name)
        assert mesh.is_watertight and mesh.is_volume, name
        assert len(mesh.split(only_watertight=False)) == expected_bodies(spec, name), name
        assert abs(mesh.volume / checks["brep_volume_mm3"] - 1) < 1e-3, name


def assert_build_folder(spec, out: Path) -> None:
    """Everything a build wrote reads back correctly."""
    report = assert_manifest(out)
    assert_laser_files(spec, out)
    assert_meshes(spec, report, out)


def section_circles(mesh, z: float) -> list[tuple[float, float, float]]:
    """Closed loops of a mesh's section at height z as circles (x, y, radius, mm): the loop's vertex centroid and
    mean vertex distance (tessellation vertices lie on the true surface, so this is the true radius)."""
    import numpy as np

    section = mesh.section(plane_origin=[0, 0, z], plane_normal=[0, 0, 1])
    if section is None:
        return []
    circles = []
    for loop in section.discrete:
        pts = np.asarray(loop)[:-1, :2]
        centre = pts.mean(axis=0)
        circles.append((float(centre[0]), float(centre[1]), float(np.linalg.norm(pts - centre, axis=1).mean())))
    return circles


def nearest_circle(circles, x: float, y: float) -> tuple[float, float, float]:
    """The circle whose centre is nearest (x, y)."""
    return min(circles, key=lambda c: (c[0] - x) ** 2 + (c[1] - y) ** 2)


def hanging_edge_length_mm(mesh, tol=1e-6) -> dict:
    """z (mm, 3 decimals) → total length (mm) of the mesh's edges where printed material starts in mid-air: a
    horizontal edge that is the lowest edge of a face pointing downward, whose neighbour across it does not reach below
    it. A face merely steeper than the overhang limit is the other check; this one sees a bridge's or a tip's line."""
    n, v, faces = mesh.face_normals, mesh.vertices, mesh.faces
    adj, edges, unshared = mesh.face_adjacency, mesh.face_adjacency_edges, mesh.face_adjacency_unshared
    z0 = v[edges[:, 0], 2]
    flat = np.abs(v[edges[:, 1], 2] - z0) < tol
    hanging = np.zeros(len(adj), bool)
    for k in (0, 1):
        f = adj[:, k]
        lowest = np.abs(v[faces[f]][:, :, 2].min(axis=1) - z0) < tol
        hanging |= (n[f, 2] < -0.05) & lowest & (v[unshared[:, 1 - k], 2] >= z0 - tol)
    hanging &= flat & (z0 > 1e-3)
    length = np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1)
    return {lv: float(length[hanging & (np.round(z0, 3) == lv)].sum()) for lv in np.unique(np.round(z0[hanging], 3))}


SAMPLE_MM = 0.08
"""Grid step of the venting read-back: a reach is measured to within about this much (mm)."""


def design_frame(out: Path, report: dict, name: str):
    """An exported STL moved back from its print pose to the frame it was designed in (the mold frame for the
    mold halves and the cap) (mm)."""
    import trimesh

    mesh = trimesh.load_mesh(out / name)
    mesh.apply_transform(np.linalg.inv(np.array(report["meshes"][name]["design_to_print"])))
    return mesh


def slot_caps(spec, out: Path, report: dict) -> list[tuple[object, float, object]]:
    """(taxel, x, cap mesh) for every cap position of the mold, the cap read from end_cap.stl (the body of that
    taxel's cast volume) and set as it sits in the closed mold: upside down, its base face on the parting plane,
    its axis at (x, 0) (mm)."""
    import math

    import trimesh

    from matcad.parts.end_cap_mold import layout
    from matcad.parts.features import cap_volume_mm3
    from matcad.spec import taxel_spec

    bodies = design_frame(out, report, "end_cap.stl").split(only_watertight=True)
    lay = layout(spec)
    caps = []
    for x, taxel in zip(lay.cap_x, lay.slots):
        want = cap_volume_mm3(taxel_spec(spec, taxel))
        body = min(bodies, key=lambda b: abs(b.volume - want))
        assert abs(body.volume / want - 1) < 5e-3, (taxel.name, body.volume, want)
        cap = body.copy()
        cap.apply_transform(trimesh.transformations.rotation_matrix(math.pi, [1, 0, 0]))
        cap.apply_translation([x - (cap.bounds[0, 0] + cap.bounds[1, 0]) / 2, 0, 0])
        caps.append((taxel, x, cap))
    return caps


def ceiling_components(cap) -> list:
    """Connected groups of up-facing faces (flatter than CEILING_TILT_DEG) of one cap in the mold frame."""
    import math

    import trimesh

    from matcad.parts.mold_layout import CEILING_TILT_DEG

    up = np.flatnonzero(cap.face_normals[:, 2] >= math.cos(math.radians(CEILING_TILT_DEG)))
    sub = cap.submesh([up], append=True, repair=False)
    groups = trimesh.graph.connected_components(sub.face_adjacency, nodes=np.arange(len(sub.faces)),
                                                engine="scipy")
    return [sub.submesh([g], append=True, repair=False) for g in groups]


def grid_points(component, step: float) -> np.ndarray:
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


def rim_points(component, step: float) -> np.ndarray:
    """Points every ``step`` mm along the boundary of a ceiling component (edges owned by one face) (mm)."""
    edges = component.edges_sorted
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    rim = unique[counts == 1]
    pts = []
    for a, b in component.vertices[rim]:
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1)
        pts.append(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a))
    return np.vstack(pts)


def measured_reaches(spec, out: Path, report: dict) -> list[tuple[str, float, float]]:
    """(taxel, z, farthest distance from a ceiling point to an escape) per ceiling of every cap in the closed
    mold (base face, pin end) (mm). The base face escapes through the lid's openings above it; the core pin's
    end face has none (a channel through the pin would cast a thread inside the cavity): its escape is its rim,
    where the pin's side rises."""
    from scipy.spatial import cKDTree

    lid = design_frame(out, report, "end_cap_mold_lid.stl")
    reaches = []
    for taxel, _, cap in slot_caps(spec, out, report):
        for component in ceiling_components(cap):
            pts = grid_points(component, SAMPLE_MM)
            assert len(pts) > 50
            rays = pts + [0, 0, 1e-3]
            blocked = lid.ray.intersects_any(rays, np.tile([0.0, 0.0, 1.0], (len(rays), 1)))
            opened = pts[~blocked]
            z = round(float(pts[0, 2]), 3)
            if z < -1e-6:  # the pin's end face: solid pin above every point of it, escape at its rim
                assert not len(opened), f"{len(opened)} points of the pin end face see an opening through the pin"
                gap, _ = cKDTree(rim_points(component, SAMPLE_MM / 4)[:, :2]).query(pts[:, :2])
            else:
                assert len(opened), f"a ceiling at z = {z:.2f} with no opening above it"
                gap, _ = cKDTree(opened[:, :2]).query(pts[blocked][:, :2]) if blocked.any() else (np.zeros(1), None)
            reaches.append((taxel.name, z, float(gap.max())))
    return reaches


def cast_volumes(spec, out: Path, report: dict) -> list[dict]:
    """What the closed mold casts at each cap position, read from the mold halves' STLs (mm³): ``below`` the
    space left under the parting plane within the cap's flange (base minus lid: the cap, and anything a channel
    into a core pin would add inside its cavity), ``cap`` that cap's own volume in end_cap.stl, ``above`` the
    space in the lid over the flange (its fill port and vents: the sprues)."""
    import trimesh

    from matcad.parts.end_cap_mold import layout
    from matcad.spec import cap_flange_diameter_mm, taxel_spec

    base, lid = (design_frame(out, report, f"end_cap_mold_{half}.stl") for half in ("base", "lid"))
    lay = layout(spec)
    rows = []
    for taxel, x, cap in slot_caps(spec, out, report):
        r = cap_flange_diameter_mm(taxel_spec(spec, taxel)) / 2 + 0.05
        below, above = (trimesh.creation.cylinder(radius=r, height=h, sections=128) for h in
                        (lay.base_height, lay.lid_thickness))
        below.apply_translation([x, 0, -lay.base_height / 2])
        above.apply_translation([x, 0, lay.lid_thickness / 2])
        rows.append({"taxel": taxel.name, "x_mm": x, "cap": cap.volume,
                     "below": trimesh.boolean.difference([below, base, lid], engine="manifold").volume,
                     "above": trimesh.boolean.difference([above, lid], engine="manifold").volume})
    return rows


def assert_vented(spec, out: Path, report: dict) -> list[tuple[str, float, float]]:
    """Every ceiling of every cap in the closed mold, read back from the STLs, lies within ``mold.vent_reach`` of
    an escape and where the plan put it: the base face as far as its slot's vent plan says, the pin's end face
    its tip radius from the rim; the report's venting gives the worst of them. Returns the reaches."""
    from matcad.parts.end_cap_mold import layout
    from matcad.parts.mold_layout import pin_tip_radius_mm
    from matcad.spec import taxel_spec

    venting = report["casting"]["venting"]
    lay = layout(spec)
    plans = {t.name: p for t, p in zip(lay.slots, lay.plans)}
    reaches = measured_reaches(spec, out, report)
    print(spec.name, "ceiling (taxel, z, farthest distance to an escape) mm:", reaches)
    for name, z, reach in reaches:
        assert reach <= venting["vent_reach_mm"] + SAMPLE_MM, (name, z, reach)
        taxel = next(t for t in lay.slots if t.name == name)
        planned = plans[name].reach_base_mm if abs(z) < 1e-6 else pin_tip_radius_mm(taxel_spec(spec, taxel))
        assert reach == pytest.approx(planned, abs=2 * SAMPLE_MM + 0.02), (name, z, reach, planned)
    assert venting["base_face_reach_mm"] == pytest.approx(max(p.reach_base_mm for p in lay.plans))
    assert venting["pin_end_reach_mm"] == pytest.approx(max(pin_tip_radius_mm(taxel_spec(spec, t))
                                                            for t in lay.slots), abs=0.01)
    return reaches


def assert_casts_only_the_caps(spec, out: Path, report: dict) -> list[dict]:
    """The closed mold read back from its STLs casts each cap and nothing else inside it: the space under the
    parting plane at each position is that cap's volume in end_cap.stl (a vent down a core pin would add the
    thread it casts inside the cavity, 3.74 mm³ for the paper's taxel), and the space in the lid over it is the
    sprues the cavity-appendage rule counts, which it reports with 0 mm³ inside the cavity; the casting guide fills
    until silicone stands in the vents the lid has over each cap and trims their sprues and the fill port's off
    the sealing face. Returns the rows."""
    from matcad.parts.mold_layout import appendages

    rows = cast_volumes(spec, out, report)
    for row, rule in zip(rows, appendages(spec)):
        print(spec.name, row)
        assert row["below"] == pytest.approx(row["cap"], abs=0.01), row
        assert row["above"] == pytest.approx(rule["sprue_mm3"], rel=2e-3), (row, rule)
        assert rule["inside_cavity_mm3"] == 0.0
    found = next(f for f in report["findings"] if f["id"] == "mold.cavity_appendage")
    assert found["level"] == "info" and found["value"] == 0.0
    # the pour and trim wording counts what the lid has: the fill port and N vents over each cap, N + 1 sprues
    from matcad.spec import cap_flange_diameter_mm, taxel_spec

    lid = design_frame(out, report, "end_cap_mold_lid.stl")
    holes = section_circles(lid, spec.mold.lid_thickness / 2)
    casting = report["casting"]
    for taxel, x, _ in slot_caps(spec, out, report):
        flange = cap_flange_diameter_mm(taxel_spec(spec, taxel)) / 2
        over = sorted(round(2 * r, 2) for cx, cy, r in holes if np.hypot(cx - x, cy) < flange and r < flange / 2)
        vents = len(over) - 1
        assert over == [round(spec.mold.vent, 2)] * vents + [round(spec.mold.fill_port, 2)], (taxel.name, over)
        assert f"silicone stands in every one of its {vents} vents" in " ".join(casting["steps"])
        assert casting["trim"][0].startswith(f"{vents + 1} sprues per cap (the fill port's and {vents} vents') "
                                             "stand on the cap's base face")
    return rows
