"""Structured quadrilateral mesh of the cap's (r, z) cross-section, with its named boundaries. Pure numpy; mm.

Four mapped blocks share their edges node for node: the cavity wall (z 0..L, r from the drafted wall to the
body's outside), the closed end over the cavity (z L..H, r 0..tip) and beside it (r tip..outside), and the flange
(z 0..flange thickness, r outside..flange edge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from matcad.mechanics.section import CapSection


@dataclass(frozen=True)
class CapMesh:
    """Nodes ``points`` (n, 2) as (r, z) mm, counter-clockwise quads ``cells`` (m, 4), and node index arrays:
    ``base`` (z = 0, bonded to the plate), ``clamp`` (flange top and rim, held by the guide), ``axis`` (r = 0),
    ``top`` (the face the plate presses), ``side`` (free outside of the body, may roll onto the plate),
    ``cavity`` (the cavity outline from the wall's foot on the plate to the axis, in order; ``cavity[corner]`` is the
    corner where the wall meets the closed end)."""

    points: np.ndarray
    cells: np.ndarray
    base: np.ndarray
    clamp: np.ndarray
    axis: np.ndarray
    top: np.ndarray
    side: np.ndarray
    cavity: np.ndarray
    corner: int
    element_size_mm: float


MAX_CELLS = 4000
"""Cap on the default mesh (cells), which bounds the run time of thin-walled or large caps."""


def default_element_size_mm(sec: CapSection) -> float:
    """Element size (mm): 8 across the top, 12 across the wall, 20 along the cavity, 6 across its radius, but no
    finer than :data:`MAX_CELLS` cells over the section allow. On the paper cap this is 0.2 mm, where F(x) sits
    within 2 % of the finest mesh that reaches 1 mm (tests/test_mechanics.py)."""
    wall = sec.outer_radius - max(sec.cavity_radius, sec.cavity_tip_radius)
    area = (sec.outer_radius ** 2 * sec.height + (sec.flange_radius ** 2 - sec.outer_radius ** 2) * sec.flange_thickness
            - sec.cavity_radius ** 2 * sec.cavity_length) / max(sec.outer_radius, sec.flange_radius)
    return max(min(sec.top_thickness / 8, wall / 12, sec.cavity_length / 20, sec.cavity_radius / 6),
               math.sqrt(area / MAX_CELLS))


def _levels(breaks, h: float) -> np.ndarray:
    out = [np.array([breaks[0]])]
    for a, b in zip(breaks[:-1], breaks[1:]):
        n = max(1, math.ceil((b - a) / h - 1e-9))
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def _block(r_left, r_right, zs: np.ndarray, n_r: int):
    s = np.linspace(0.0, 1.0, n_r + 1)
    left, right = np.broadcast_to(r_left(zs), zs.shape), np.broadcast_to(r_right(zs), zs.shape)
    r = left[:, None] + (right - left)[:, None] * s[None, :]
    z = np.repeat(zs[:, None], n_r + 1, axis=1)
    idx = np.arange(z.size).reshape(z.shape)
    cells = np.stack([idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]], axis=-1).reshape(-1, 4)
    return np.stack([r.ravel(), z.ravel()], axis=1), cells


def mesh_section(sec: CapSection, element_size_mm: float | None = None) -> CapMesh:
    """Mesh the cap section with quads of about ``element_size_mm`` (default :func:`default_element_size_mm`)."""
    h = element_size_mm or default_element_size_mm(sec)
    L, H, ro, rf, tf = sec.cavity_length, sec.height, sec.outer_radius, sec.flange_radius, sec.flange_thickness
    zs = _levels(sorted({0.0, tf, L, H}), h)
    tol = 1e-9 * H
    z_wall, z_top, z_flange = zs[zs <= L + tol], zs[zs >= L - tol], zs[zs <= tf + tol]
    tip = sec.cavity_tip_radius
    n_wall = max(2, math.ceil((ro - min(sec.cavity_radius, tip)) / h))
    blocks = [
        _block(sec.cavity_wall_radius, lambda z: ro, z_wall, n_wall),
        _block(lambda z: 0.0, lambda z: tip, z_top, max(2, math.ceil(tip / h))),
        _block(lambda z: tip, lambda z: ro, z_top, n_wall),
    ]
    if rf > ro + tol:
        blocks.append(_block(lambda z: ro, lambda z: rf, z_flange, max(1, math.ceil((rf - ro) / h))))
    points, cells, offset = [], [], 0
    for p, c in blocks:
        points.append(p)
        cells.append(c + offset)
        offset += len(p)
    p = np.vstack(points)
    key = np.round(p / (h * 1e-6)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    p, c = p[first], inverse.ravel()[np.vstack(cells)]
    r, z = p[:, 0], p[:, 1]
    ids = np.arange(len(p))
    on_wall = (np.abs(r - sec.cavity_wall_radius(np.minimum(z, L))) < tol) & (z <= L + tol)
    on_end = (np.abs(z - L) < tol) & (r <= tip + tol)
    wall = ids[on_wall][np.argsort(z[on_wall])]
    end = ids[on_end & ~on_wall][np.argsort(-r[on_end & ~on_wall])]
    return CapMesh(
        points=p, cells=c, base=ids[np.abs(z) < tol],
        clamp=ids[((np.abs(z - tf) < tol) & (r >= ro - tol)) | (np.abs(r - rf) < tol)],
        axis=ids[np.abs(r) < tol], top=ids[np.abs(z - H) < tol],
        side=ids[(np.abs(r - ro) < tol) & (z > tf + tol) & (z < H - tol)],
        cavity=np.concatenate([wall, end]), corner=len(wall) - 1, element_size_mm=h)


def disc_mesh(radius_mm: float, thickness_mm: float, element_size_mm: float) -> CapMesh:
    """A solid disc (mm), base bonded, top pressed, rim free: the classical bonded-block check (Gent 1958)."""
    n_r, n_z = (max(2, math.ceil(x / element_size_mm)) for x in (radius_mm, thickness_mm))
    p, c = _block(lambda z: 0.0, lambda z: radius_mm, np.linspace(0.0, thickness_mm, n_z + 1), n_r)
    r, z = p[:, 0], p[:, 1]
    ids, tol, none = np.arange(len(p)), 1e-9 * thickness_mm, np.zeros(0, dtype=int)
    return CapMesh(points=p, cells=c, base=ids[z < tol], clamp=none, axis=ids[r < tol],
                   top=ids[z > thickness_mm - tol],
                   side=ids[(r > radius_mm - tol) & (z > tol) & (z < thickness_mm - tol)], cavity=none, corner=0,
                   element_size_mm=element_size_mm)
