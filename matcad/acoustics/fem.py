"""Axisymmetric acoustic FEM reference (scikit-fem, P2 triangles). Lengths mm, wavenumbers 1/mm, f in Hz.

Solves ∇·(r∇p) + k² r p = 0 in the (r, z) half-plane over the neck (0..l), the cavity (l..l+L, with core-pin
draft) and the exterior below the plate (z < 0):
- ``baffled``: a quarter disc of radius R around the mouth in a rigid baffle (the plate underside), with the
  spherical radiation condition ∂p/∂n = −(ik + 1/R) p on the arc (exact for the monopole near field);
- ``mount``: the spacer gap of height h between plate and mount out to the gap radius R_g, with the
  cylindrical condition ∂p/∂n = −(ik + 1/(2R_g)) p on r = R_g;
- ``unflanged``: the open end of a tube in free space: a half disc of radius R around the mouth, less the tube's
  rigid wall (bore radius a to a + w, ``wall`` = w) running from the mouth back along the tube to the arc, with the
  same spherical condition on the arc (Levine & Schwinger 1948's geometry for w → 0).
As built, the neck may taper (its mouth radius differs from its radius at the cavity, linearly along it) and air may
be joined to the cavity at the plate (gaps in the stack): a groove in the plate from halfway between the neck and the
cavity wall outwards, open to the cavity's floor, at most half the plate deep and reaching under the cap's base as far
as the side volume needs (it leaves the neck's length untouched).
All other walls are rigid here; :mod:`matcad.acoustics.fsi` couples the elastic silicone cap to this air mesh.

The radiation term depends on k, so the eigenproblem K + (ik + κ)C = k²M is solved by fixed-point iteration
on k in the boundary term, each step a shift-invert Arnoldi solve near the current k. Of the modes found, the
Helmholtz mode is the one with the largest share of its energy in the cavity (spurious exterior "box" modes
have almost none), with Q = Re k / (2 |Im k|) above ``MIN_Q`` and within ``GUESS_WINDOW`` of the guess.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from matcad.acoustics.fem_blocks import beside_wall, block, graded, graded_span, quarter_disc, uniform
from matcad.acoustics.models import MM_PER_M

DEFAULT_LEVEL = 8
"""Elements across the neck radius; the paper taxel converges to < 0.1 % here (benchmarks/error_vs_runtime.py)."""
EXTERIOR_RADIUS_PER_A = 15.0
MIN_Q = 1.0
FIXED_POINT_ITERATIONS = 6


@dataclass(frozen=True)
class FemGeometry:
    """Everything the FEM needs (mm, Pa); build it from a design with :func:`geometry`."""

    neck_radius: float
    neck_length: float
    cavity_radius: float
    cavity_tip_radius: float
    cavity_length: float
    mouth: str
    gap: float = 0.0
    gap_radius: float = 0.0
    mouth_radius: float | None = None
    side_volume: float = 0.0
    wall: float = 0.0
    """The tube's wall thickness at an ``unflanged`` mouth (mm, > 0 there; unused by the other mouths)."""

    @property
    def mouth_r(self) -> float:
        """The neck's radius at the mouth (mm): ``mouth_radius``, else the neck's own."""
        return self.neck_radius if self.mouth_radius is None else self.mouth_radius

    def neck_radius_at(self, z):
        """The neck's radius at height z (mm; 0 at the mouth, the neck length at the cavity), linear between."""
        return self.mouth_r + (self.neck_radius - self.mouth_r) * np.asarray(z) / self.neck_length



@dataclass(frozen=True)
class FemResult:
    f0_hz: float
    q: float
    k_per_mm: complex
    cavity_energy_fraction: float
    dofs: int
    triangles: int
    level: int
    seconds: float


def geometry(d) -> FemGeometry:
    """The FEM geometry of a :class:`~matcad.acoustics.design.Design`'s air (drafted cavity, neck with its taper,
    mouth, gap, air joined to the cavity as a groove in its floor), mm. ``neck_radius`` is the neck's radius at the cavity."""
    from matcad.acoustics.geometry import drafted_tip_diameter_mm

    tip = float(drafted_tip_diameter_mm(d.cavity_diameter, d.cavity_length, d.draft_deg))
    taper = d.neck_taper_mm
    return FemGeometry(neck_radius=(d.neck_diameter - taper / 2) / 2, neck_length=d.neck_length,
                       cavity_radius=d.cavity_diameter / 2, cavity_tip_radius=tip / 2,
                       cavity_length=d.cavity_length, mouth=d.mouth, gap=d.gap_mm, gap_radius=d.gap_radius_mm,
                       mouth_radius=(d.neck_diameter + taper / 2) / 2 if taper else None,
                       side_volume=d.side_volume_mm3)


# ---------------------------------------------------------------- mesh
@dataclass(frozen=True)
class Layout:
    """The node lines the air mesh is built on (mm); the coupled cap mesh reuses them so both meshes share
    nodes on the cavity wall."""

    h: float
    h_max: float
    r_neck: np.ndarray
    z_neck: np.ndarray
    z_cavity: np.ndarray
    s_annulus: np.ndarray
    groove_r: np.ndarray = field(default_factory=lambda: np.zeros(0))
    groove_depth: float = 0.0


def cavity_wall_radius(g: FemGeometry, z):
    """Radius of the drafted cavity wall at height z (mm; z from the plate underside, cavity from l to l + L)."""
    return g.cavity_radius + (z - g.neck_length) / g.cavity_length * (g.cavity_tip_radius - g.cavity_radius)


def layout(g: FemGeometry, level: int = DEFAULT_LEVEL, cavity_breaks: tuple[float, ...] = ()) -> Layout:
    """Node lines at ``level`` elements across the neck radius; ``cavity_breaks`` are heights (mm) that must be
    node heights in the cavity (e.g. the top of the clamped flange); the nearest node line moves onto each."""
    a, l, L = g.neck_radius, g.neck_length, g.cavity_length
    h = a / level
    # away from the two re-entrant corners (mouth edge, neck-to-cavity step) cells grow to a size set by the
    # geometry's own scale, with P2 that keeps the smooth regions as accurate as the corners
    h_max = max(h, min(l, L, 2 * g.cavity_radius) / 6)
    z_cav = graded_span(l, l + L, h, h_max, fine_end=False)
    for z in cavity_breaks:
        z_cav[1 + int(np.argmin(np.abs(z_cav[1:-1] - z)))] = z
    width = max(float(np.max(cavity_wall_radius(g, z_cav))) - a, 0.0)
    s = (graded_span(0.0, width, min(h, width), max(min(h, width), h_max), fine_end=False) / width
         if width > 1e-9 * a else np.zeros(0))
    groove_r, groove_depth = np.zeros(0), 0.0
    if g.side_volume and len(s):  # the groove's inner wall, halfway from neck to wall, is a node line at any level
        s = np.unique(np.append(s, 0.5 * (float(cavity_wall_radius(g, l)) - a) / width))
        groove_r, groove_depth = _floor_groove(g, s, h, h_max)
    return Layout(h, h_max, np.linspace(0.0, a, level + 1), graded_span(0.0, l, h, h_max), z_cav, s,
                  groove_r, groove_depth)


GROOVE_DEPTH_PER_PLATE = 0.5
"""The side volume's groove is at most this fraction of the plate (neck length) deep."""


def _floor_groove(g: FemGeometry, s_annulus: np.ndarray, h: float, h_max: float) -> tuple[np.ndarray, float]:
    """Radial node lines (mm) and depth (mm) of the groove holding ``side_volume`` (mm³): from halfway between neck
    and wall (a node line of the floor, :func:`layout`) out to the wall on the floor's own nodes, then under the cap's
    base as far as a groove ``GROOVE_DEPTH_PER_PLATE`` of the plate deep needs."""
    a, l, big_r = g.neck_radius, g.neck_length, g.cavity_radius
    floor = a + s_annulus * (float(cavity_wall_radius(g, l)) - a)
    floor = floor[floor >= 0.5 * (a + big_r) * (1 - 1e-12)]
    depth_max = GROOVE_DEPTH_PER_PLATE * l
    inside = math.pi * (big_r ** 2 - floor[0] ** 2)
    if g.side_volume <= inside * depth_max:
        return floor, g.side_volume / inside
    outer = math.sqrt(floor[0] ** 2 + g.side_volume / (math.pi * depth_max))
    return np.concatenate([floor, graded_span(big_r, outer, min(h, outer - big_r), h_max, fine_end=False)[1:]]), \
        depth_max


def air_blocks(g: FemGeometry, lay: Layout) -> list:
    """The air's structured blocks (neck, cavity core, cavity annulus, exterior) as (points, triangles)."""
    a = g.neck_radius
    r_neck, z_cav = lay.r_neck, lay.z_cavity
    neck_r = (lambda s, z: s) if g.mouth_radius is None else (lambda s, z: s / a * g.neck_radius_at(z))
    blocks = [block(neck_r, lay.z_neck, r_neck), block(lambda s, z: s, z_cav, r_neck)]
    if len(lay.s_annulus):
        blocks.append(block(lambda s_, z: a + s_ * (cavity_wall_radius(g, z) - a), z_cav, lay.s_annulus))
    if lay.groove_depth:
        z = uniform(g.neck_length - lay.groove_depth, g.neck_length, min(lay.h_max, max(lay.h, lay.groove_depth / 4)))
        blocks.append(block(lambda r, z_: r, z, lay.groove_r))
    a_m = g.mouth_r
    r_mouth = r_neck * (a_m / a)
    if g.mouth == "mount":
        radii = np.concatenate([r_mouth, graded(a_m, g.gap_radius, lay.h)[1:]])
        z_gap = uniform(-g.gap, 0.0, max(lay.h, g.gap / 16))
        blocks.append(block(lambda s, z: s, z_gap, radii))
    elif g.mouth == "baffled":
        radii = np.concatenate([r_mouth, graded(a_m, EXTERIOR_RADIUS_PER_A * a_m, lay.h)[1:]])
        blocks.append(quarter_disc(radii))
    elif g.mouth == "unflanged":
        blocks += _unflanged_exterior(g, r_mouth, lay.h)
    else:
        raise ValueError(f"mouth {g.mouth!r} invalid for the FEM, must be one of 'baffled', 'mount', 'unflanged'")
    return blocks


def _unflanged_exterior(g: FemGeometry, r_mouth: np.ndarray, h: float) -> list:
    """The free-space exterior of an unflanged tube end (two blocks): the quarter disc below the mouth, its z = 0
    edge on the mouth's nodes ``r_mouth``, across the wall's end face (cells ≤ h, one cell of w when w < h) and on
    out to R graded from the wall's outer edge as the baffled exterior from the mouth's (first cell h, so every
    cell but the end face's shrinks as 1/level); and the air beside the tube's outer wall (:func:`beside_wall`)
    on the same nodes of z = 0. R = ``EXTERIOR_RADIUS_PER_A`` mouth radii. Raises ValueError unless 0 < w < R − a."""
    a_m, w = g.mouth_r, g.wall
    big_r = EXTERIOR_RADIUS_PER_A * a_m
    if not 0 < w < big_r - a_m:
        raise ValueError(f"FemGeometry.wall = {w:g} mm invalid for mouth 'unflanged': must be > 0 and < "
                         f"{big_r - a_m:g} mm (the tube's wall thickness, inside the exterior's radius)")
    b = a_m + w
    outside = graded(b, big_r, h)
    radii = np.concatenate([r_mouth, uniform(a_m, b, h)[1:], outside[1:]])
    return [quarter_disc(radii), quarter_disc(outside - b, beside_wall(b, big_r))]


def merge_blocks(blocks: list, h: float):
    """One skfem MeshTri from (points, triangles) blocks, coincident nodes merged; also the first triangle index
    of each block (so callers can tell subdomains apart)."""
    from skfem import MeshTri

    points, tris, offset, starts, count = [], [], 0, [], 0
    for p, t in blocks:
        points.append(p)
        tris.append(t + offset)
        offset += len(p)
        starts.append(count)
        count += len(t)
    p = np.vstack(points)
    key = np.round(p / (h * 1e-6)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    t = inverse.ravel()[np.vstack(tris)]
    return MeshTri(p[first].T.copy(), t.T.copy()), starts


def mesh(g: FemGeometry, level: int = DEFAULT_LEVEL):
    """The taxel's (r, z) mesh at ``level`` elements across the neck radius; returns a skfem MeshTri."""
    lay = layout(g, level)
    return merge_blocks(air_blocks(g, lay), lay.h)[0]


def _arc_param(curve: np.ndarray) -> np.ndarray:
    seg = np.hypot(*np.diff(curve, axis=0).T)
    t = np.concatenate([[0.0], np.cumsum(seg)])
    return t / t[-1]


def deform_cavity(m, g: FemGeometry, wall_rz, end_rz):
    """The mesh ``m`` of :func:`mesh` with its cavity (z > neck length) mapped onto a deformed cavity outline.

    ``wall_rz`` (k, 2): the wall from its foot on the plate to the closed end's corner; ``end_rz`` (j, 2): the
    closed end from that corner to the axis; both (r, z) in mm in the cap's frame (plate face z = 0), e.g. from
    :mod:`matcad.mechanics`. Each cavity node at (s = r / wall radius, t = height / L) goes to the transfinite
    (Coons) interpolation of the four sides (plate, axis, wall and end, each by normalised arc length).
    Raises ValueError when the map folds a triangle (an outline too distorted for it).
    """
    from skfem import MeshTri

    wall, end = np.asarray(wall_rz, dtype=float), np.asarray(end_rz, dtype=float)[::-1]
    l, L = g.neck_length, g.cavity_length
    r, z = m.p
    inside = z > l + 1e-9 * L
    t = (z[inside] - l) / L
    s = r[inside] / (g.cavity_radius + t * (g.cavity_tip_radius - g.cavity_radius))

    def on(curve, u):
        param = _arc_param(curve)
        return np.stack([np.interp(u, param, curve[:, 0]), np.interp(u, param, curve[:, 1])], axis=-1)

    foot, corner, top_axis = wall[0], wall[-1], end[0]
    bottom = np.stack([s * foot[0], np.zeros_like(s)], axis=-1)
    axis = np.stack([np.zeros_like(t), t * top_axis[1]], axis=-1)
    ss, tt = s[:, None], t[:, None]
    mapped = ((1 - tt) * bottom + tt * on(end, s) + (1 - ss) * axis + ss * on(wall, t)
              - (ss * (1 - tt) * foot + (1 - ss) * tt * top_axis + ss * tt * corner))
    p = m.p.copy()
    p[0, inside], p[1, inside] = mapped[:, 0], l + mapped[:, 1]
    def signed_areas(q):
        a, b, c = (q[:, m.t[i]] for i in range(3))
        return (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])

    if np.any(signed_areas(p) * np.sign(signed_areas(m.p)) <= 0):
        raise ValueError("the deformed cavity outline folds the acoustic mesh (outline too distorted)")
    return MeshTri(p, m.t)


# ---------------------------------------------------------------- solve
def _forms():
    from skfem import BilinearForm
    from skfem.helpers import dot, grad

    @BilinearForm
    def stiffness(u, v, w):
        return dot(grad(u), grad(v)) * w.x[0]

    @BilinearForm
    def mass(u, v, w):
        return u * v * w.x[0]

    @BilinearForm
    def weighted_mass(u, v, w):
        return u * v * w.x[0] * w["weight"]

    return stiffness, mass, weighted_mass


def _boundary_facets(m, g: FemGeometry):
    """(radiation facets, κ) by facet midpoints."""
    mid = m.p[:, m.facets].mean(axis=1)
    boundary = np.zeros(m.facets.shape[1], dtype=bool)
    boundary[m.boundary_facets()] = True
    r, z = mid
    a = g.mouth_r
    tol = 1e-6 * a
    if g.mouth in ("baffled", "unflanged"):  # the arc: not the baffle (z = 0), nor the tube's outer wall r = a + w
        big_r = EXTERIOR_RADIUS_PER_A * a
        off_wall = z < -tol  # below the mouth; beside an unflanged tube, also off its outer wall
        if g.mouth == "unflanged":
            off_wall |= r > a + g.wall + tol
        radiation = boundary & (np.hypot(r, z) > 0.9 * big_r) & off_wall
        kappa = 1.0 / big_r
    else:
        radiation = boundary & (r > g.gap_radius - tol)
        kappa = 1.0 / (2.0 * g.gap_radius)
    return np.flatnonzero(radiation), kappa


GUESS_WINDOW = 2.0
"""The resonance is sought within this factor of the guess: a side volume's groove has its own modes, well above,
in which the cavity's share of the energy can exceed the Helmholtz mode's."""


def in_cavity(g: FemGeometry, lay: Layout, r, z):
    """Whether points (r, z in mm) are in the cavity's air: above the neck, or in the side volume's groove."""
    above = np.asarray(z) > g.neck_length
    if not lay.groove_depth:
        return above
    return above | ((np.asarray(z) > g.neck_length - lay.groove_depth) & (np.asarray(r) > lay.groove_r[0] * (1 - 1e-9)))


def one_blas_thread():
    """A context in which BLAS runs on one thread. SuperLU hands its dense supernodes to BLAS; a multi-threaded
    OpenBLAS on 2 shared cores then spent ~5x the CPU of one thread (coupled FEM, baffled mouth: 12.8 s vs 2.3 s
    CPU for the same numbers; benchmarks/floors.py's fem row)."""
    import scipy.sparse.linalg  # noqa: F401  (loads scipy's own BLAS, so that the limit reaches it)
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def _eigs_near(a_mat, m_mat, sigma, count):
    from scipy.sparse.linalg import LinearOperator, eigs, splu

    lu = splu((a_mat - sigma * m_mat).tocsc())
    op = LinearOperator(a_mat.shape, matvec=lambda x: lu.solve(m_mat @ x), dtype=complex)
    nu, vecs = eigs(op, k=count, which="LM", tol=1e-12)
    return sigma + 1.0 / nu, vecs


def _fixed_point(k_mat, c_mat, m_mat, m_cav, kappa, k, k_guess_per_mm, modes):
    """:func:`solve`'s fixed-point iteration on k in the radiation term: (k, (k, cavity fraction, Q) of the best)."""
    best = None
    for _ in range(FIXED_POINT_ITERATIONS):
        a_mat = (k_mat + (1j * k + kappa) * c_mat).astype(complex)
        lam, vecs = _eigs_near(a_mat, m_mat, k * k, modes)
        ks = np.sqrt(lam)
        ks = np.where(ks.real < 0, -ks, ks)
        energy = np.real(np.einsum("ij,ij->j", vecs.conj(), m_mat @ vecs))
        fraction = np.real(np.einsum("ij,ij->j", vecs.conj(), m_cav @ vecs)) / energy
        q = ks.real / (2 * np.abs(ks.imag) + 1e-300)
        near = (ks.real > k_guess_per_mm / GUESS_WINDOW) & (ks.real < k_guess_per_mm * GUESS_WINDOW)
        fraction = np.where(near & (q > MIN_Q), fraction, -np.inf)
        i = int(np.argmax(fraction))
        converged = abs(ks[i] - k) <= 1e-10 * abs(k)
        k, best = ks[i], (ks[i], float(fraction[i]), float(q[i]))
        if converged:
            break
    return k, best


def solve(g: FemGeometry, k_guess_per_mm: float, level: int = DEFAULT_LEVEL, speed_of_sound_m_s: float = 343.0,
          modes: int = 6, cavity_outline=None) -> FemResult:
    """The Helmholtz mode nearest ``k_guess_per_mm`` (e.g. the transmission-line estimate); with
    ``cavity_outline`` = (wall_rz, end_rz), on that deformed cavity (:func:`deform_cavity`, rigid walls)."""
    from skfem import Basis, ElementTriP2, FacetBasis, asm

    t0 = time.perf_counter()
    lay = layout(g, level)
    m = merge_blocks(air_blocks(g, lay), lay.h)[0]
    if cavity_outline is not None:
        m = deform_cavity(m, g, *cavity_outline)
    element = ElementTriP2()
    basis = Basis(m, element)
    stiffness, mass, weighted_mass = _forms()
    k_mat = asm(stiffness, basis)
    m_mat = asm(mass, basis)
    radiation, kappa = _boundary_facets(m, g)
    c_mat = asm(mass, FacetBasis(m, element, facets=radiation))
    cavity = in_cavity(g, lay, *np.asarray(basis.global_coordinates())).astype(float)
    m_cav = asm(weighted_mass, basis, weight=cavity)

    with one_blas_thread():
        k, best = _fixed_point(k_mat, c_mat, m_mat, m_cav, kappa, complex(k_guess_per_mm), k_guess_per_mm, modes)
    k, fraction, q = best
    f = speed_of_sound_m_s * MM_PER_M * k.real / (2 * math.pi)
    return FemResult(f0_hz=float(f), q=q, k_per_mm=complex(k), cavity_energy_fraction=fraction, dofs=basis.N,
                     triangles=m.t.shape[1], level=level, seconds=time.perf_counter() - t0)
