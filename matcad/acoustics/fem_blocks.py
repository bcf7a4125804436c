"""Structured triangle blocks in the axisymmetric (r, z) half-plane, the bricks of the acoustic FEM's meshes
(:mod:`matcad.acoustics.fem`, :mod:`matcad.acoustics.fsi`): node lines (uniform, graded), grids of points split
into triangles, and quarter discs mapped onto the exterior. Lengths mm; arrays of nodes and (points, triangles)
pairs, merged into one mesh by :func:`matcad.acoustics.fem.merge_blocks`.
"""

from __future__ import annotations

import math

import numpy as np

GROWTH = 1.25
"""Each graded cell this many times the one before."""


def graded(start: float, stop: float, first: float, growth: float = GROWTH) -> np.ndarray:
    """Nodes from start to stop, first cell ``first`` long, each next one ``growth`` times longer."""
    nodes = [start]
    step = first
    while nodes[-1] + step < stop - 0.5 * step:
        nodes.append(nodes[-1] + step)
        step *= growth
    nodes.append(stop)
    return np.array(nodes)


def uniform(start: float, stop: float, h: float) -> np.ndarray:
    return np.linspace(start, stop, max(1, math.ceil((stop - start) / h - 1e-9)) + 1)


def graded_span(start: float, stop: float, h: float, h_max: float, fine_start=True, fine_end=True) -> np.ndarray:
    """Nodes from start to stop: cells of ``h`` at the fine end(s), growing with the distance d from the nearest
    fine end as h + (GROWTH − 1)·d, capped at ``h_max``; marched, then scaled to end exactly at ``stop``."""
    span = stop - start

    def size(x):
        d = min([x] * fine_start + [span - x] * fine_end, default=span)
        return min(h_max, h + (GROWTH - 1.0) * d)

    nodes = [0.0]
    while nodes[-1] < span * (1 - 1e-9):
        nodes.append(nodes[-1] + size(nodes[-1]))
    return start + np.array(nodes) * (span / nodes[-1])


def grid_cells(points: np.ndarray, split_cross: bool):
    """Triangles of a (nu+1) x (nv+1) grid of points (index i*(nv+1)+j); cross split adds centre points."""
    nu, nv = points.shape[0] - 1, points.shape[1] - 1
    flat = points.reshape(-1, 2)
    idx = np.arange(flat.shape[0]).reshape(nu + 1, nv + 1)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    if not split_cross:
        return flat, np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    centre = (flat[a] + flat[b] + flat[c] + flat[d]) / 4
    m = flat.shape[0] + np.arange(len(a))
    tris = np.vstack([np.column_stack([a, b, m]), np.column_stack([b, c, m]),
                      np.column_stack([c, d, m]), np.column_stack([d, a, m])])
    return np.vstack([flat, centre]), tris


def block(r_of, zs: np.ndarray, s: np.ndarray):
    """Structured block: point (r_of(s_i, z_j), z_j)."""
    ss, zz = np.meshgrid(s, zs, indexing="ij")
    return grid_cells(np.stack([r_of(ss, zz), zz], axis=-1), split_cross=False)


def quarter_disc(radii: np.ndarray, place=lambda x, y: (x, -y)):
    """Quarter disc whose nodes on both axes sit exactly at ``radii`` (Fong's square-to-disc map, then a radial
    remap), below z = 0; cells are cross-split so the arc's corner cell has no sliver. ``place`` maps the disc's
    points (x, y ≥ 0, mm) to (r, z), arrays each; by default (x, −y), the quarter below the mouth."""
    n = len(radii) - 1
    u = np.linspace(0.0, 1.0, n + 1)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    x = uu * np.sqrt(1 - vv * vv / 2)
    y = vv * np.sqrt(1 - uu * uu / 2)
    rho = np.hypot(x, y)
    scale = np.where(rho > 0, np.interp(rho, u, radii) / np.where(rho > 0, rho, 1.0), 0.0)
    return grid_cells(np.stack(place(x * scale, y * scale), axis=-1), split_cross=True)


def beside_wall(b: float, big_r: float):
    """:func:`quarter_disc`'s ``place`` for the air beside a tube's outer wall r = b (mm), z ≥ 0, up to the arc
    of radius ``big_r`` (mm) about the mouth's centre: the disc of radius big_r − b centred on the wall's foot
    (b, 0), stretched along each ray from the foot onto that arc, so its nodes on z = 0 stay at b + x and its
    outer edge is the radiation arc itself."""
    def place(x, y):
        theta = np.arctan2(y, x)
        reach = np.sqrt(big_r**2 - (b * np.sin(theta)) ** 2) - b * np.cos(theta)  # foot to arc along theta
        stretch = reach / (big_r - b)
        return b + x * stretch, y * stretch
    return place
