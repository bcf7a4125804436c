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
