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

from matcad.render.figure import figure

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


def _mesh_axes(ax, mesh, elev: float, azim: float, title: str) -> int:
    """The mesh shaded and its feature edges drawn, seen from (elev, azim); returns the edges drawn."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    triangles = np.asarray(mesh.triangles, dtype=float)
    edges = feature_edges(mesh)
    ax.add_collection3d(Poly3DCollection(triangles, facecolors=_shaded(triangles), edgecolors="none"))
    ax.add_collection3d(Line3DCollection(edges, colors=EDGE_RGB, linewidths=0.5))
    lo, hi = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(np.maximum(hi - lo, 1e-6 * max(hi - lo)), zoom=0.9)  # a long part seen from above stays whole
    ax.view_init(elev=elev, azim=azim)
    ax.set_proj_type("ortho")
    ax.set_title(textwrap.fill(title, 48), fontsize=8)
    ax.set_axis_off()
    return len(edges)


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


def _section_axes(ax, mesh, y0: float, title: str) -> int:
    """The section at y = ``y0`` filled (material) with its holes left open, axes in mm; returns the loops."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    from matcad.parts.flat import even_odd_faces

    loops = section_loops(mesh, y0)

    def ring(points, ccw):
        area = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(points, points[1:] + points[:1]))
        return points if (area > 0) == ccw else points[::-1]

    for outer, inner in even_odd_faces(loops):
        rings = [ring(outer, True)] + [ring(hole, False) for hole in inner]
        vertices = [p for r in rings for p in r + r[:1]]
        codes = [c for r in rings for c in [MplPath.MOVETO] + [MplPath.LINETO] * (len(r) - 1) + [MplPath.CLOSEPOLY]]
        ax.add_patch(PathPatch(MplPath(vertices, codes), facecolor=BASE_RGB, edgecolor=EDGE_RGB, linewidth=0.6))
    pts = np.array([p for loop in loops for p in loop]).reshape(-1, 2)
    if len(pts):
        pad = 0.05 * float(np.ptp(pts, axis=0).max())
        ax.set_xlim(pts[:, 0].min() - pad, pts[:, 0].max() + pad)
        ax.set_ylim(pts[:, 1].min() - pad, pts[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]", fontsize=7)
    ax.set_ylabel("z [mm] (as printed)", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.set_title(textwrap.fill(title, 48), fontsize=8)
    return len(loops)


def printed_preview(name: str, stl: Path, path: Path) -> dict:
    """Isometric view and the face or section that matters of the STL ``stl``, side by side in ``path`` (PNG):
    shaded, with the feature edges drawn, so holes, pockets and bores show; a part whose registry entry names a
    section is cut through it (the cap through its axis, the mount through a needle bore)."""
    import trimesh

    mesh = trimesh.load_mesh(stl, file_type="stl")
    caption, elev, azim = face_view(name)
    plane = section_plane(name)
    size = np.ptp(np.asarray(mesh.vertices), axis=0)
    with figure(path, 7.2, 3.4) as fig:
        _mesh_axes(fig.add_subplot(1, 2, 1, projection="3d"), mesh, *ISOMETRIC, "isometric")
        if plane:
            y0 = bore_plane_y(mesh) if plane == "bore" else 0.0
            caption = f"{caption} (y = {y0 + 0.0:.2f} mm)"
            _section_axes(fig.add_subplot(1, 2, 2), mesh, y0, caption)
        else:
            _mesh_axes(fig.add_subplot(1, 2, 2, projection="3d"), mesh, elev, azim, caption)
        fig.suptitle(f"{name}: {size[0]:.1f} × {size[1]:.1f} × {size[2]:.1f} mm, {len(mesh.faces)} triangles",
                     fontsize=10)
    return {"part": name, "file": path.name, "caption": f"{name}: isometric and {caption}"}


def _rounded_rect(x0, y0, x1, y1, r):
    from matplotlib.patches import FancyBboxPatch

    r = max(0.0, min(r, (x1 - x0) / 2, (y1 - y0) / 2))
    return FancyBboxPatch((x0 + r, y0 + r), x1 - x0 - 2 * r, y1 - y0 - 2 * r, boxstyle=f"round,pad={r}",
                          fill=False, edgecolor=FLAT_COLOURS["outline"], linewidth=1.0)


def flat_preview(plan, path: Path) -> dict:
    """The laser cut plan of one part (kerf-compensated, as in its DXF) with each hole's finished size (mm)."""
    from matplotlib.patches import Circle, Rectangle

    flat = plan.flat
    x0, y0, x1, y1 = plan.extents
    aspect = (y1 - y0 + 4) / max(x1 - x0 + 4, 1e-9)
    width_in = 6.0
    with figure(path, width_in, max(2.2, min(6.0, width_in * aspect + 0.8))) as fig:
        ax = fig.add_subplot(1, 1, 1)
        for outline in plan.outlines:
            ax.add_patch(_rounded_rect(*outline))
        labelled = set()
        sizes: dict = {}
        for c in plan.circles:
            sizes.setdefault(c.purpose, set()).add(c.finished_diameter)
        for c in plan.circles:
            ax.add_patch(Circle((c.x, c.y), c.diameter / 2, fill=False, edgecolor=FLAT_COLOURS["hole"],
                                linewidth=1.0))
            graded = len(sizes[c.purpose]) > 2  # a coupon's row of sizes: one label per row, the sizes engraved
            key = c.purpose if graded else (c.purpose, c.finished_diameter)
            if key not in labelled and c.x <= plan.outlines[0][2]:
                labelled.add(key)
                text = (f"{c.purpose} Ø{min(sizes[c.purpose]):g}–{max(sizes[c.purpose]):g}" if graded
                        else f"{c.purpose} Ø{c.finished_diameter:g}")
                ax.annotate(text, (c.x, c.y + c.diameter / 2), fontsize=7, xytext=(0, 4), textcoords="offset points",
                            ha="left" if graded else "center", color="#102080")
        for t in plan.texts:
            ax.text(t.x, t.y, t.text, fontsize=7, color=FLAT_COLOURS["engrave"])
        if plan.reference_square:
            sx, sy, side = plan.reference_square
            ax.add_patch(Rectangle((sx, sy), side, side, fill=False, edgecolor=FLAT_COLOURS["reference"],
                                   linewidth=0.8, linestyle="--"))
            ax.text(sx + side / 2, sy + side / 2, f"{side:g} mm\nreference", fontsize=6, ha="center",
                    va="center", color=FLAT_COLOURS["reference"])
        ax.set_xlim(x0 - 2, x1 + 2)
        ax.set_ylim(y0 - 2, y1 + 2)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(f"{flat.name}: {flat.quantity} × {flat.width:g} × {flat.depth:g} mm from "
                     f"{flat.thickness:g} mm sheet (cut lines, kerf {plan.kerf:g} mm)", fontsize=9)
    return {"part": flat.name, "file": path.name, "caption": f"{flat.name}: laser cut plan"}
