"""Tetrahedral meshes of 3-D air domains given by a signed distance, the bricks of :mod:`matcad.acoustics.mouth3d`.

A graded tensor grid is split into Kuhn tetrahedra (six per cell); nodes closer to the surface than
``SNAP`` × their cell are moved onto it, unless that flattens a kept tetrahedron; then every tetrahedron that
the surface crosses is cut by marching tetrahedra: its air part (a tetrahedron, a pyramid or a prism whose vertices
are its air nodes and the surface's crossings of its edges, each found on the edge by bisection) is split into
tetrahedra, every quadrilateral face along the diagonal from its lowest-numbered vertex, so that two cut
neighbours share their faces (Dompierre, Labbé, Vallet & Camarero 1999, "How to subdivide pyramids, prisms and
hexahedra into tetrahedra", 8th International Meshing Roundtable). Smooth surfaces are met to O(h²); sharp
edges and corners of the domain are cut off by O(h). Lengths mm. Pure numpy: no mesher, no CAD kernel.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

SNAP = 0.2
"""Nodes within this fraction of their smallest adjacent cell of the surface are moved onto it (no slivers)."""
BISECTIONS = 40
FLAT = 0.1
"""A snap that leaves a kept tetrahedron under this fraction of its volume is undone."""
KUHN = np.array([[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]])
"""The six tetrahedra of a cell around its diagonal 0–7 (corner index = 4 i + 2 j + k): neighbours match."""

Distance = Callable[[np.ndarray], np.ndarray]
"""Points (3, n) mm → signed distance (mm, > 0 in the air, < 0 in the solid; exact near the surface)."""


def graded(core_lo: float, core_hi: float, h: float, lo: float, hi: float, growth: float = 1.25,
           planes: tuple[float, ...] = ()) -> np.ndarray:
    """Node coordinates (mm): uniform ``h`` over [core_lo, core_hi], cells growing by ``growth`` out to lo and hi;
    the nearest node moved onto each of ``planes`` (so planar walls lie on grid planes)."""
    core = list(np.arange(core_lo, core_hi + h / 2, h))
    up, step = [core[-1]], h
    while up[-1] < hi - 1e-9:
        step *= growth
        up.append(min(up[-1] + step, hi) if hi - up[-1] - step > step / 2 else hi)
    down, step = [core[0]], h
    while down[-1] > lo + 1e-9:
        step *= growth
        down.append(max(down[-1] - step, lo) if down[-1] - step - lo > step / 2 else lo)
    return merged(np.array(down[::-1][:-1] + core + up[1:]), h / 4, planes)


def merged(lines: np.ndarray, gap: float, planes: tuple[float, ...] = ()) -> np.ndarray:
    """Sorted grid lines (mm) with ``planes`` among them and no two closer than ``gap`` (a line that close to a
    plane or to the line before it is dropped)."""
    planes_ = np.asarray(planes, float)
    out: list[float] = []
    for v in np.sort(np.concatenate([np.asarray(lines, float), planes_])):
        is_plane = bool(np.any(np.abs(planes_ - v) < 1e-12))
        if out and v - out[-1] < gap:
            if is_plane and not np.any(np.abs(planes_ - out[-1]) < 1e-12):
                out[-1] = v
            continue
        out.append(v)
    return np.array(out)


def volumes(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Signed volumes (mm³) of tetrahedra t (4, n) over points p (3, m)."""
    a, b, c, d = (p[:, t[i]] for i in range(4))
    return np.einsum("ij,ij->j", np.cross(b - a, c - a, axis=0), d - a) / 6


def _tensor(xs, ys, zs):
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    p = np.vstack([X.ravel(), Y.ravel(), Z.ravel()])
    ny, nz = len(ys), len(zs)
    i, j, k = (g.ravel() for g in np.meshgrid(*(np.arange(len(v) - 1) for v in (xs, ys, zs)), indexing="ij"))
    base = (i * ny + j) * nz + k
    corners = np.stack([base + (di * ny + dj) * nz + dk for di in (0, 1) for dj in (0, 1) for dk in (0, 1)])
    t = np.hstack([corners[list(q)] for q in KUHN])
    cell = np.minimum.reduce(np.meshgrid(np.diff(xs), np.diff(ys), np.diff(zs), indexing="ij")).ravel()
    return p, t, np.tile(cell, len(KUHN))


def _project(q: np.ndarray, distance: Distance, steps: int = 8) -> np.ndarray:
    """Points moved onto the surface by Newton steps along the distance's gradient (central differences)."""
    for _ in range(steps):
        d = distance(q)
        grad = np.stack([(distance(q + 1e-7 * e[:, None]) - distance(q - 1e-7 * e[:, None])) / 2e-7
                         for e in np.eye(3)])
        q = q - d * grad / np.maximum((grad**2).sum(0), 1e-12)
    return q


def _snap(p, t, cell, distance):
    """Nodes near the surface moved onto it (their distance set to 0), unless a kept tetrahedron goes flat."""
    d = distance(p)
    near_cell = np.full(p.shape[1], np.inf)
    for row in t:
        np.minimum.at(near_cell, row, cell)
    moved = np.nonzero((np.abs(d) < SNAP * near_cell) & (d != 0))[0]
    q = _project(p[:, moved].copy(), distance)
    landed = (np.abs(distance(q)) < 1e-9) & (np.linalg.norm(q - p[:, moved], axis=0) < 2 * SNAP * near_cell[moved])
    moved, q = moved[landed], q[:, landed]
    snapped = p.copy()
    snapped[:, moved] = q
    on = np.zeros(p.shape[1], bool)
    on[moved] = True
    v0 = volumes(p, t)
    while True:
        dn = np.where(on, 0.0, d)
        kept = (dn[t] >= 0).all(0) & (dn[t] > 0).any(0)
        flat = kept & (volumes(snapped, t) * np.sign(v0) < FLAT * np.abs(v0))
        undo = np.unique(t[:, flat])
        undo = undo[on[undo]]
        if not len(undo):
            return snapped, np.where(on, 0.0, d)
        snapped[:, undo] = p[:, undo]
        on[undo] = False


def _crossings(p, d, edges, distance):
    """The surface's crossing of each edge (2, n) whose ends have distances of opposite signs (bisection)."""
    lo, hi = p[:, edges[0]], p[:, edges[1]]  # lo in the air, hi in the solid
    for _ in range(BISECTIONS):
        mid = (lo + hi) / 2
        air = distance(mid) > 0
        lo = np.where(air, mid, lo)
        hi = np.where(air, hi, mid)
    return (lo + hi) / 2


def mesh(xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, distance: Distance) -> tuple[np.ndarray, np.ndarray]:
    """Points (3, n) and tetrahedra (4, m) of the air {distance > 0} inside the box of the grid xs × ys × zs (mm),
    positively oriented, unused points dropped."""
    p, t, cell = _tensor(xs, ys, zs)
    p, d = _snap(p, t, cell, distance)
    sign = np.sign(d[t]).astype(int)
    pos, neg = (sign > 0).sum(0), (sign < 0).sum(0)
    whole = t[:, (neg == 0) & (pos > 0)]
    cut = t[:, (neg > 0) & (pos > 0)]
    cut_sign = np.sign(d[cut]).astype(int)
    # the crossing points, one per cut edge, numbered after the grid's points
    pairs = [(i, j) for i in range(4) for j in range(i + 1, 4)]
    ends = []
    for i, j in pairs:
        crossing = cut_sign[i] * cut_sign[j] < 0
        a, b = cut[i, crossing], cut[j, crossing]
        air_first = d[a] > 0
        ends.append(np.stack([np.where(air_first, a, b), np.where(air_first, b, a)]))
    ends = np.hstack(ends)
    key = ends[0].astype(np.int64) * p.shape[1] + ends[1]
    key, first = np.unique(key, return_index=True)
    new_points = _crossings(p, d, ends[:, first], distance)
    points = np.hstack([p, new_points])
    n_old = p.shape[1]

    index = dict(zip(key.tolist(), range(n_old, n_old + len(key))))

    def crossing(a, b):
        """Index of the crossing on the edge from air node a to solid node b."""
        return index[a * n_old + b]

    pieces = [whole] + [_air_part(tet, s, crossing) for tet, s in zip(cut.T.tolist(), cut_sign.T.tolist())]
    t_all = np.hstack([np.asarray(x).reshape(4, -1) for x in pieces if np.size(x)])
    v = volumes(points, t_all)
    t_all = t_all[:, np.abs(v) > 1e-12 * np.median(np.abs(v))]
    v = volumes(points, t_all)
    t_all[:, v < 0] = t_all[[0, 2, 1, 3]][:, v < 0]
    used = np.unique(t_all)
    renumber = -np.ones(points.shape[1], int)
    renumber[used] = np.arange(len(used))
    return np.ascontiguousarray(points[:, used]), np.ascontiguousarray(renumber[t_all])


def _quad(a, b, c, d):
    """The two triangles' diagonal of quad a-b-c-d (in order): True if it runs a–c (from its lowest vertex)."""
    return min(a, c) < min(b, d)


def _air_part(tet, s, c):
    """Tetrahedra (4, k) of one cut tetrahedron's air part; s its nodes' signs (+1 air, 0 on the surface, −1 solid)."""
    P = [v for v, x in zip(tet, s) if x > 0]
    Z = [v for v, x in zip(tet, s) if x == 0]
    N = [v for v, x in zip(tet, s) if x < 0]
    if len(P) == 1:  # a tetrahedron: the air node, the surface nodes, the crossings to the solid nodes
        return np.array([[P[0]] + Z + [c(P[0], n) for n in N]]).T
    if len(P) == 2 and len(N) == 1:  # a pyramid: quad p0 p1 c1 c0, apex the surface node
        q = (P[0], P[1], c(P[1], N[0]), c(P[0], N[0]))
        return _pyramid(q, Z[0])
    if len(P) == 2:  # a prism: triangles (p0, c00, c01) and (p1, c10, c11)
        return _prism((P[0], c(P[0], N[0]), c(P[0], N[1])), (P[1], c(P[1], N[0]), c(P[1], N[1])))
    # three air nodes: the tetrahedron less its solid corner, a prism (p0 p1 p2) – (c0 c1 c2)
    return _prism(tuple(P), tuple(c(p_, N[0]) for p_ in P))


def _pyramid(q, apex):
    a, b, c, d = q
    if _quad(a, b, c, d):
        return np.array([[a, b, c, apex], [a, c, d, apex]]).T
    return np.array([[a, b, d, apex], [b, c, d, apex]]).T


def _prism(bottom, top):
    """Three tetrahedra of the prism bottom (a0 a1 a2), top (b0 b1 b2), ai–bi its edges: Dompierre et al.'s rule
    (rotate so the lowest vertex is a0, flipping bottom and top if it is on top)."""
    verts = list(bottom) + list(top)
    k = int(np.argmin(verts))
    if k >= 3:
        bottom, top, k = top, bottom, k - 3
    a = [bottom[(k + i) % 3] for i in range(3)]
    b = [top[(k + i) % 3] for i in range(3)]
    tets = [[a[0], b[1], b[2], b[0]]]  # diagonals a0–b1 and a0–b2 from the lowest vertex
    if min(a[1], b[2]) < min(a[2], b[1]):
        tets += [[a[0], a[1], a[2], b[2]], [a[0], a[1], b[2], b[1]]]
    else:
        tets += [[a[0], a[1], a[2], b[1]], [a[0], b[1], a[2], b[2]]]
    return np.array(tets).T
