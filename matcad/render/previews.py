"""Part previews (PNG): printed parts from their STL triangles, laser parts from their cut plan. Units mm.

A printed part gets two views side by side: isometric, and the face or section that matters for it (its registry
entry's ``view`` and ``section``: the mold base from above shows the pockets and keys, the lid its core pins and
vents, the cap is cut through its axis to show the cavity and membrane, the needle mount through a needle's plane to
show its bore at θ). Views are shaded and carry the feature edges, because flat shading alone paints coplanar faces
at different depths one colour and hides what lies inside. A laser part gets its cut plan as the laser sees it
(kerf-compensated outline and holes, hole sizes labelled, engravings drawn).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

ISOMETRIC = (35.264, -45.0)
"""(elevation, azimuth) in degrees of the isometric view: elevation atan(1/√2)."""
LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
BASE_RGB = np.array([0.35, 0.55, 0.85])
EDGE_RGB = (0.08, 0.1, 0.2)
EDGE_ANGLE_DEG = 30.0
"""Faces meeting at more than this are a crease drawn as an edge: a 0.1 mm-chord cylinder's facets meet at a few
degrees, a hole's rim or a step at 90°."""
FLAT_COLOURS = {"outline": "#d03030", "hole": "#2040d0", "engrave": "#109010", "reference": "#c000c0"}


def face_view(name: str) -> tuple[str, float, float]:
    """(caption, elevation, azimuth in degrees) of the view that shows what matters on part ``name``."""
    from matcad.parts.registry import DEFAULT_VIEW, parts

    return next((p.view for p in parts() if p.name == name and p.view), DEFAULT_VIEW)


def section_plane(name: str) -> str:
    """How part ``name``'s second view is drawn: '' (an orthographic view with its edges), 'axis' (a section
    through y = 0, every cap's axis) or 'bore' (a section through the plane of the inclined bore nearest y = 0)."""
    from matcad.parts.registry import parts

    return next((p.section for p in parts() if p.name == name), "")


def preview_name(part: str) -> str:
    """File name of a part's preview image."""
    return f"preview_{part}.png"


def _shaded(triangles: np.ndarray) -> np.ndarray:
    """Face colours from a fixed light (Lambert, with ambient), so views are deterministic."""
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    norm = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, norm, out=np.zeros_like(normals), where=norm > 0)
    lum = 0.35 + 0.65 * np.abs(normals @ LIGHT)
    return np.clip(BASE_RGB[None, :] * lum[:, None] + 0.1, 0, 1)


def feature_edges(mesh, angle_deg: float = EDGE_ANGLE_DEG) -> np.ndarray:
    """The mesh's creases: edges whose two faces meet at more than ``angle_deg`` (the rims of holes, pockets,
    bores and steps; a tessellated cylinder's own facets stay under it), as (n, 2, 3) segments (mm). Drawn over
    the shading they show what flat shading paints one colour: coplanar faces at different depths, bores inside."""
    crease = mesh.face_adjacency_angles > np.radians(angle_deg)
    return np.asarray(mesh.vertices[mesh.face_adjacency_edges[crease]], dtype=float)


def bore_plane_y(mesh) -> float:
    """y of the plane through the inclined bore nearest y = 0: the middle of the y span of the faces whose normal
    leans neither horizontal nor vertical (a bore at θ to the bed), bores told apart by 1 mm gaps in y (mm); 0 when
    there is none."""
    n = mesh.face_normals
    tilted = (np.abs(n[:, 2]) > 0.05) & (np.abs(n[:, 2]) < 0.95) & (np.abs(n[:, 0]) > 0.05)
    if not tilted.any():
        return 0.0
    ys = np.sort(mesh.triangles[tilted][:, :, 1].ravel())
    groups = np.split(ys, np.flatnonzero(np.diff(ys) > 1.0) + 1)
    return float(min(((g[0] + g[-1]) / 2 for g in groups), key=abs))


def section_loops(mesh, y0: float) -> list[list[tuple[float, float]]]:
    """The mesh cut by the plane y = ``y0``: its closed loops as (x, z) points (mm)."""
    section = mesh.section(plane_origin=[0.0, y0, 0.0], plane_normal=[0.0, 1.0, 0.0])
    if section is None:
        return []
    return [[(float(x), float(z)) for x, _, z in loop[:-1]] for loop in section.discrete if len(loop) > 3]


PREVIEW_PX = (792, 374)
"""A printed part's preview: two panels side by side (px)."""


def view_basis(elev: float, azim: float):
    """(right, up, toward the viewer) unit vectors of an orthographic view from elevation ``elev`` and azimuth
    ``azim`` (degrees, as matplotlib's 3-D axes: azimuth about z from +x, elevation above the x-y plane)."""
    e, a = np.radians(elev), np.radians(azim)
    toward = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    return right, np.cross(toward, right), toward


def _mesh_panel(canvas, box, mesh, elev: float, azim: float, title: str) -> int:
    """The mesh seen from (elev, azim), orthographic, true proportions, in the pixel ``box``: faces shaded
    (:func:`_shaded`) and painted far to near, the feature edges drawn over them; returns the edges drawn."""
    triangles = np.asarray(mesh.triangles, dtype=float)
    edges = feature_edges(mesh)
    right, up, toward = view_basis(elev, azim)
    pts = triangles.reshape(-1, 3)
    u, v = pts @ right, pts @ up
    left, top, rgt, bottom = box
    span = max(np.ptp(u), np.ptp(v), 1e-9)
    k = 0.9 * min((rgt - left) / max(np.ptp(u), 1e-9 * span), (bottom - top - 24) / max(np.ptp(v), 1e-9 * span))
    cx, cy = (left + rgt) / 2, (top + 24 + bottom) / 2
    mu, mv = (u.max() + u.min()) / 2, (v.max() + v.min()) / 2
    px = (cx + k * (u - mu)).reshape(-1, 3)
    py = (cy - k * (v - mv)).reshape(-1, 3)
    colours = (_shaded(triangles) * 255).round().astype(int)
    facing = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]) @ toward >= 0
    draw = canvas.draw
    for i in np.argsort((triangles @ toward).mean(axis=1), kind="stable"):
        if facing[i]:
            draw.polygon(list(zip(px[i], py[i])), fill=tuple(colours[i]))
    edge = tuple(round(255 * c) for c in EDGE_RGB)
    eu, ev = edges @ right, edges @ up
    for (u0, u1), (v0, v1) in zip(eu, ev):
        draw.line([(cx + k * (u0 - mu), cy - k * (v0 - mv)), (cx + k * (u1 - mu), cy - k * (v1 - mv))], fill=edge)
    canvas.text((left + rgt) / 2, top + 2, textwrap.fill(title, 48), 10, anchor="ma")
    return len(edges)


def _section_panel(canvas, box, mesh, y0: float, title: str) -> int:
    """The section at y = ``y0`` filled (material) with its holes left open, axes in mm; returns the loops."""
    from matcad.parts.flat import even_odd_faces

    loops = section_loops(mesh, y0)
    pts = np.array([p for loop in loops for p in loop]).reshape(-1, 2)
    if not len(pts):
        return 0
    pad = 0.05 * float(np.ptp(pts, axis=0).max())
    xlim = (pts[:, 0].min() - pad, pts[:, 0].max() + pad)
    ylim = (pts[:, 1].min() - pad, pts[:, 1].max() + pad)
    left, top, right, bottom = box
    ax = canvas.axes((left + 50, top + 34, right - 8, bottom - 40), xlim, ylim, equal=True)
    base = tuple(round(255 * c) for c in BASE_RGB)
    edge = tuple(round(255 * c) for c in EDGE_RGB)

    def area(loop):
        return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(loop, loop[1:] + loop[:1]))) / 2

    for outer, holes in sorted(even_odd_faces(loops), key=lambda region: -area(region[0])):  # islands in holes last
        ax.polygon(outer, base)
        for hole in holes:
            ax.polygon(hole, "white")
    for loop in loops:
        ax.line([x for x, _ in loop + loop[:1]], [z for _, z in loop + loop[:1]], edge, 1)
    ax.frame(xlabel="x [mm]", ylabel="z [mm] (as printed)", title=textwrap.fill(title, 48), size=9)
    return len(loops)


def printed_preview(name: str, stl: Path, path: Path, mesh=None) -> dict:
    """Isometric view and the face or section that matters of the STL ``stl``, side by side in ``path`` (PNG):
    shaded, with the feature edges drawn, so holes, pockets and bores show; a part whose registry entry names a
    section is cut through it (the cap through its axis, the mount through a needle bore). ``mesh``: the STL
    already loaded (trimesh), else it is read. Drawn with :mod:`matcad.canvas` (no matplotlib)."""
    from matcad.canvas import Canvas

    if mesh is None:
        from matcad.export.mesh import load_stl

        mesh = load_stl(stl)  # as read back by the build's mesh checks: not read again
    caption, elev, azim = face_view(name)
    plane = section_plane(name)
    size = np.ptp(np.asarray(mesh.vertices), axis=0)
    w, h = PREVIEW_PX
    canvas = Canvas(w, h)
    _mesh_panel(canvas, (8, 30, w / 2 - 4, h - 8), mesh, *ISOMETRIC, "isometric")
    if plane:
        y0 = bore_plane_y(mesh) if plane == "bore" else 0.0
        caption = f"{caption} (y = {y0 + 0.0:.2f} mm)"
        _section_panel(canvas, (w / 2 + 4, 30, w - 8, h - 8), mesh, y0, caption)
    else:
        _mesh_panel(canvas, (w / 2 + 4, 30, w - 8, h - 8), mesh, elev, azim, caption)
    canvas.text(w / 2, 6, f"{name}: {size[0]:.1f} × {size[1]:.1f} × {size[2]:.1f} mm, {len(mesh.faces)} triangles",
                12, anchor="ma")
    canvas.save(path)
    return {"part": name, "file": path.name, "caption": f"{name}: isometric and {caption}"}


def flat_preview(plan, path: Path) -> dict:
    """The laser cut plan of one part (kerf-compensated, as in its DXF) with each hole's finished size (mm), drawn
    with :mod:`matcad.canvas` at one scale across and up (no matplotlib on a laser-only build's path)."""
    from matcad.canvas import Canvas, font

    flat = plan.flat
    x0, y0, x1, y1 = plan.extents
    aspect = (y1 - y0 + 4) / max(x1 - x0 + 4, 1e-9)
    title = (f"{flat.name}: {flat.quantity} × {flat.width:g} × {flat.depth:g} mm from {flat.thickness:g} mm "
             f"sheet (cut lines, kerf {plan.kerf:g} mm)")
    width = max(660, round(font(11).getlength(title)) + 110)  # a long title widens the picture, never clipped
    height = round(max(242, min(660, 600 * aspect + 88)))
    canvas = Canvas(width, height)
    ax = canvas.axes((70, 34, width - 16, height - 50), (x0 - 2, x1 + 2), (y0 - 2, y1 + 2), equal=True)
    for ox0, oy0, ox1, oy1, r in plan.outlines:
        ax.rounded(ox0, oy0, ox1, oy1, r, FLAT_COLOURS["outline"], 1)
    labelled = set()
    sizes: dict = {}
    for c in plan.circles:
        sizes.setdefault(c.purpose, set()).add(c.finished_diameter)
    for c in plan.circles:
        ax.circle(c.x, c.y, c.diameter / 2, FLAT_COLOURS["hole"], 1)
        graded = len(sizes[c.purpose]) > 2  # a coupon's row of sizes: one label per row, the sizes engraved
        key = c.purpose if graded else (c.purpose, c.finished_diameter)
        if key not in labelled and c.x <= plan.outlines[0][2]:
            labelled.add(key)
            text = (f"{c.purpose} Ø{min(sizes[c.purpose]):g}–{max(sizes[c.purpose]):g}" if graded
                    else f"{c.purpose} Ø{c.finished_diameter:g}")
            canvas.text(ax.x(c.x), ax.y(c.y + c.diameter / 2) - 4, text, 9, "#102080", anchor="ld" if graded else "md")
    for t in plan.texts:
        ax.text(t.x, t.y, t.text, 9, FLAT_COLOURS["engrave"], anchor="ls")
    if plan.reference_square:
        sx, sy, side = plan.reference_square
        ax.line([sx, sx + side, sx + side, sx, sx], [sy, sy, sy + side, sy + side, sy], FLAT_COLOURS["reference"],
                1, dash=3)
        ax.text(sx + side / 2, sy + side / 2, f"{side:g} mm\nreference", 8, FLAT_COLOURS["reference"], anchor="mm")
    ax.frame(xlabel="x [mm]", ylabel="y [mm]", size=10,
             title=title)
    canvas.save(path)
    return {"part": flat.name, "file": path.name, "caption": f"{flat.name}: laser cut plan"}
