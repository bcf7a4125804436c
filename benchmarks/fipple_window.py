"""A second route to the fipple window's end correction: potential flow on voxel grids, against Rayleigh's aperture.

The fipple's δ (:func:`matcad.acoustics.tube.mouth_correction_mm`) is Rayleigh's conductance of a thin-walled
aperture of the window's area. The printed window is a hole through a wall ``tube.wall`` thick (0.6 a in the
template), with the labium's bevels above it and the bore's funnel below. As ka → 0 (the template's f1 has
ka ≈ 0.16) δ is the excess inertance of the incompressible flow out of the bore through the window:
∇²φ = 0 in the air, unit flux into the bore across a plane 6 a from the edge, φ = 0 far away; then
δ = S φ̄_plane / Q − (the plane's distance from the edge), as a length of bore (Rayleigh, Theory of Sound II §303-306).

Discretised with cell-centred finite volumes (7-point) on a graded Cartesian grid whose cells are air or solid by
their centres (staircased walls), solved by conjugate gradients; half the domain (the window's plane of symmetry
y = 0). The far field is φ = 0 on a box of half-size L; δ is extrapolated as L → ∞ from L and 2L (the monopole's
1/L). Not modelled: the windway slot (0.5 mm, closed by the supply: a dead end at ka → 0). No FEM: the window in a
curved wall needs a 3-D mesh, which no dependency of the project makes (docs/tube.md).

Calibration of the method on a closed form: the same code on a pipe ending in an infinite rigid baffle against
Norris & Sheng's 0.8216 a (1989). Prints, per grid step h (mm): δ of the baffled pipe per a, the template's window δ
(mm), Rayleigh's thin-aperture δ, their ratio, and the template's f1 by the line with each δ (rigid cap).
Run: .venv/bin/python benchmarks/fipple_window.py [--fine]   (--fine adds h = 0.1 mm: ~1 min and ~2 GB)
"""

import math
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.acoustics import tube as T  # noqa: E402
from matcad.parts.tube import EDGE_LAND_MM, SEAT_CONE_DEG  # noqa: E402
from matcad.spec import load  # noqa: E402

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "acoustac-tube.toml"
GROWTH = 1.25
"""Cell growth outside the uniform core."""
PLANE_PER_A = 6.0
"""The driven plane's distance from the edge, in bore radii: the flow there is plane to < 1e-4."""
NORRIS_SHENG = 0.8216


def graded(core_lo, core_hi, h, lo, hi):
    """Cell faces (mm): uniform h over [core_lo, core_hi], growing by GROWTH out to lo and hi."""
    core = list(np.arange(core_lo, core_hi + h / 2, h))
    up, d = [core[-1]], h
    while up[-1] < hi:
        d *= GROWTH
        up.append(up[-1] + d)
    down, d = [core[0]], h
    while down[-1] > lo:
        d *= GROWTH
        down.append(down[-1] - d)
    return np.array(down[::-1][:-1] + core + up[1:])


def window_air(X, Y, Z, a, wall, B, W, edge_angle_deg):
    """Air of the fipple tube's mouth as printed (matcad.parts.tube), window bottom at z = 0, edge at z = W, the bore
    running up (+z) and the window on +x: True where a cell centre is air."""
    outer, tip = a + wall, a + EDGE_LAND_MM
    r = np.hypot(X, Y)
    t_cone = math.tan(math.radians(SEAT_CONE_DEG))
    body = r <= outer
    carved = (r < a) & (Z > 0)  # the bore
    carved |= (Z <= 0) & (r < (Z + a / t_cone) * t_cone)  # the funnel in the block's face
    carved |= (np.abs(Y) < B / 2) & (X > 0) & (Z > 0) & (Z < W)  # the window
    above = (np.abs(Y) < B / 2) & (Z >= W)
    carved |= above & (X > tip + (Z - W) * math.tan(math.radians(edge_angle_deg)))  # the labium's outer bevel
    carved |= above & (X > 0) & (X < tip - (Z - W) * t_cone)  # its inner bevel
    return ~body | carved


def baffled_air(X, Y, Z, a, *_):
    """A pipe of radius a opening at z = 0 into the half space z < 0 (an infinite rigid baffle), the pipe up (+z)."""
    return (Z < 0) | ((np.hypot(X, Y) < a) & (Z > 0))


def end_correction_mm(air_of, h, L, a, wall, B, W, edge_angle_deg, edge_z):
    """δ (mm) of the mouth whose air ``air_of`` gives, by finite volumes with core cell h (mm) and far box L (mm)."""
    outer = a + wall
    z_plane = edge_z + PLANE_PER_A * a
    xe = graded(-outer - 0.6, outer + 1.0, h, -L, L)
    ye = graded(0.0, outer + 0.6, h, 0.0, L)
    ze = graded(-a * 2.0, z_plane, h, -L, z_plane + L)
    xc, yc, zc = ((e[1:] + e[:-1]) / 2 for e in (xe, ye, ze))
    dx, dy, dz = np.diff(xe), np.diff(ye), np.diff(ze)
    X, Y, Z = np.meshgrid(xc, yc, zc, indexing="ij")
    air = air_of(X, Y, Z, a, wall, B, W, edge_angle_deg)
    k_plane = np.searchsorted(zc, z_plane) - 1
    bore_cells = (np.hypot(X, Y) < a)[:, :, k_plane]
    air[:, :, k_plane + 1:] &= np.hypot(X, Y)[:, :, k_plane + 1:] > outer  # the bore ends at the driven plane
    index = -np.ones(air.shape, int)
    index[air] = np.arange(air.sum())
    n = int(air.sum())
    diag, rows, cols, vals = np.zeros(n), [], [], []
    areas = (dy[None, :, None] * dz[None, None, :], dx[:, None, None] * dz[None, None, :],
             dx[:, None, None] * dy[None, :, None])
    for axis, (width, area) in enumerate(zip((dx, dy, dz), areas)):
        lo, hi = [slice(None)] * 3, [slice(None)] * 3
        lo[axis], hi[axis] = slice(0, -1), slice(1, None)
        shape = [1, 1, 1]
        shape[axis] = -1
        g = np.broadcast_to(area / ((width[:-1] + width[1:]) / 2).reshape(shape), index[tuple(lo)].shape)
        i, j = index[tuple(lo)], index[tuple(hi)]
        both = (i >= 0) & (j >= 0)
        rows += [i[both], j[both]]
        cols += [j[both], i[both]]
        vals += [-g[both], -g[both]]
        np.add.at(diag, i[both], g[both])
        np.add.at(diag, j[both], g[both])
        for end in ((0, -1) if axis != 1 else (-1,)):  # φ = 0 on the far box; y = 0 is the symmetry plane
            face = [slice(None)] * 3
            face[axis] = end
            cell, a_end = index[tuple(face)], np.broadcast_to(area, air.shape)[tuple(face)]
            np.add.at(diag, cell[cell >= 0], (a_end / (width[end] / 2))[cell >= 0])
    K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    K = K + sp.diags(diag)
    cell_area = (dx[:, None] * dy[None, :])[bore_cells]
    s_plane = cell_area.sum()
    rhs = np.zeros(n)
    rhs[index[:, :, k_plane][bore_cells]] = cell_area / s_plane  # unit flux, uniform over the plane
    phi, info = spla.cg(K, rhs, rtol=1e-10, maxiter=50000, M=sp.diags(1 / K.diagonal()))
    if info:
        raise RuntimeError(f"CG did not converge ({info})")
    phi_plane = (phi[index[:, :, k_plane][bore_cells]] * cell_area).sum() / s_plane
    return s_plane * phi_plane - (zc[k_plane] - edge_z), n


def extrapolated(air_of, h, L, *geometry):
    """δ (mm) at L → ∞ from boxes L and 2L (the far field's monopole makes the error ∝ 1/L), and the cell count."""
    d1, n = end_correction_mm(air_of, h, L, *geometry)
    d2, _ = end_correction_mm(air_of, h, 2 * L, *geometry)
    return 2 * d2 - d1, n


def main(fine: bool):
    spec = load(TEMPLATE)
    td = T.tube_design(spec)
    a, wall = td.bore_diameter / 2, td.tube_wall
    B, W = td.windway_width, td.edge_distance
    rayleigh = T.mouth_correction_mm(td)
    f_model = T.line_hz(td)
    print(f"template: bore a = {a} mm, wall {wall} mm ({wall / a:.2f} a), window B x W = {B} x {W} mm, "
          f"Rayleigh's thin-aperture delta {rayleigh:.3f} mm, line f1 {f_model:.0f} Hz (rigid cap)")
    print(f"{'h mm':>5} {'cells':>9} {'baffled d/a':>11} {'vs 0.8216':>9} {'window d mm':>11} {'/Rayleigh':>9} "
          f"{'line f1 Hz':>10} {'vs model':>8} {'s':>5}")
    for h in (0.4, 0.25, 0.15) + ((0.1,) if fine else ()):
        t0 = time.process_time()
        baffled, _ = extrapolated(baffled_air, h, 30.0, a, 0.0, 0.0, 0.0, 0.0, 0.0)
        window, n = extrapolated(window_air, h, 30.0, a, wall, B, W, spec.tube.edge_angle, W)
        f1 = T.line_hz(td, correction_factor=window / rayleigh)
        print(f"{h:5.2f} {n:9d} {baffled / a:11.4f} {baffled / a / NORRIS_SHENG - 1:+9.1%} {window:11.3f} "
              f"{window / rayleigh:9.3f} {f1:10.0f} {f1 / f_model - 1:+8.1%} {time.process_time() - t0:5.0f}",
              flush=True)


if __name__ == "__main__":
    main("--fine" in sys.argv[1:])
