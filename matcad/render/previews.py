"""Part previews (PNG): printed parts from their STL triangles, laser parts from their cut plan. Units mm.

A printed part gets two views side by side: isometric, and the face that matters for it (its registry entry's
``view``: the mold base from above shows the cap cavities and fill ports, the lid from below its core pins, ...).
A laser part gets its cut plan as the laser sees it (kerf-compensated outline and holes, hole sizes labelled).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from matcad.render.figure import figure

ISOMETRIC = (35.264, -45.0)
"""(elevation, azimuth) in degrees of the isometric view: elevation atan(1/√2)."""
LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
BASE_RGB = np.array([0.35, 0.55, 0.85])
FLAT_COLOURS = {"outline": "#d03030", "hole": "#2040d0", "engrave": "#109010", "reference": "#c000c0"}


def face_view(name: str) -> tuple[str, float, float]:
    """(caption, elevation, azimuth in degrees) of the view that shows what matters on part ``name``."""
    from matcad.parts.registry import DEFAULT_VIEW, parts

    return next((p.view for p in parts() if p.name == name and p.view), DEFAULT_VIEW)


def preview_name(part: str) -> str:
    """File name of a part's preview image."""
    return f"preview_{part}.png"


def read_stl_triangles(path: Path) -> np.ndarray:
    """Triangles of a binary or ASCII STL as an (n, 3, 3) array (mm), read with trimesh."""
    import trimesh

    mesh = trimesh.load_mesh(path, file_type="stl")
    return np.asarray(mesh.triangles, dtype=float)


def _shaded(triangles: np.ndarray) -> np.ndarray:
    """Face colours from a fixed light (Lambert, with ambient), so views are deterministic."""
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    norm = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, norm, out=np.zeros_like(normals), where=norm > 0)
    lum = 0.35 + 0.65 * np.abs(normals @ LIGHT)
    return np.clip(BASE_RGB[None, :] * lum[:, None] + 0.1, 0, 1)


def _mesh_axes(ax, triangles: np.ndarray, elev: float, azim: float, title: str) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax.add_collection3d(Poly3DCollection(triangles, facecolors=_shaded(triangles), edgecolors="none"))
    lo, hi = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(np.maximum(hi - lo, 1e-6 * max(hi - lo)))
    ax.view_init(elev=elev, azim=azim)
    ax.set_proj_type("ortho")
    ax.set_title(title, fontsize=9)
    ax.set_axis_off()


def printed_preview(name: str, stl: Path, path: Path) -> dict:
    """Isometric view and the face that matters of the STL ``stl``, side by side in ``path`` (PNG)."""
    triangles = read_stl_triangles(stl)
    caption, elev, azim = face_view(name)
    size = np.ptp(triangles.reshape(-1, 3), axis=0)
    with figure(path, 7.2, 3.4) as fig:
        _mesh_axes(fig.add_subplot(1, 2, 1, projection="3d"), triangles, *ISOMETRIC, "isometric")
        _mesh_axes(fig.add_subplot(1, 2, 2, projection="3d"), triangles, elev, azim, caption)
        fig.suptitle(f"{name}: {size[0]:.1f} × {size[1]:.1f} × {size[2]:.1f} mm, {len(triangles)} triangles",
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
        for c in plan.circles:
            ax.add_patch(Circle((c.x, c.y), c.diameter / 2, fill=False, edgecolor=FLAT_COLOURS["hole"],
                                linewidth=1.0))
            if (c.purpose, c.finished_diameter) not in labelled and c.x <= plan.outlines[0][2]:
                labelled.add((c.purpose, c.finished_diameter))
                ax.annotate(f"{c.purpose} Ø{c.finished_diameter:g}", (c.x, c.y + c.diameter / 2), fontsize=7,
                            xytext=(0, 4), textcoords="offset points", ha="center", color="#102080")
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
