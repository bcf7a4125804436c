"""Coupled elastic cap + air FEM (scikit-fem, axisymmetric). Lengths mm, frequencies Hz, moduli Pa in the API.

The air is the mesh of :mod:`matcad.acoustics.fem` (neck, drafted cavity, exterior with its radiation condition);
the silicone cap is meshed onto the same node lines so both share nodes on the cavity wall:
- side wall: from the cavity wall r = R(z) out to the cap's outer radius b, for the cavity's height;
- top: the full disc 0 ≤ r ≤ b from the closed end up by the top thickness.
Boundary conditions: base bonded to the plate (u = 0 on z = l), flange held by the clamp (u = 0 on the body's
outer surface below the flange's top, z ≤ l + t_f: the flange itself is clamped top and bottom), u_r = 0 on the
axis, every other outer surface traction-free.

Silicone: linear, fully incompressible (Taylor–Hood P2 displacement / P1 pressure, inf-sup stable, no locking),
density ρ_s and complex shear modulus G(1 + iη). Axisymmetric strain ε = (∂u_r/∂r, ∂u_z/∂z, u_r/r, sym. rz).
Air: P2 pressure, ∇·(r∇p) + k² r p = 0. Coupling on the cavity wall (n from air into silicone): the air's normal
acceleration is the wall's, ∂p/∂n = ω²ρ_a u·n, and the air pushes on the wall with traction p·n. Time e^{iωt}.

Units inside the solver: mm, N, tonne, s (stress MPa, density t/mm³), where every block is O(1). The air
equation is divided by ω²ρ_a so the coupled matrix is complex symmetric:

    [ (K_a + (ik + κ)C_r)/(ω²ρ_a) − M_a/(ρ_a c²)   −C          0 ] [p]   [s]
    [ −Cᵀ                                  2G*E − ω²ρ_s M_s    Bᵀ ] [u] = [0]
    [ 0                                    B                   0  ] [π]   [0]

The resonance "the microphone hears" is the peak over frequency of |p| at the cavity's closed end on the axis,
driven by a ring of normal velocity on the plate underside next to the mouth (where the jet acts); modes of
cavity and wall hybridise, so the peak of the forced response, not one eigenvalue, is reported. Q from the
curvature of 1/|p|² at the peak (exact for one pole). Wall modes: the cap's in-vacuo eigenfrequencies (same mesh,
air removed, lossless).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from matcad.acoustics import fem, fem_blocks
from matcad.acoustics.air import BULK_MODULUS_PA
from matcad.acoustics.wall import UNIT_DENSITY, UNIT_SHEAR_PA

PA_PER_MPA = 1e6
KG_M3_PER_T_MM3 = 1e12
SWEEP = (0.55, 1.8, 14)
"""Coarse sweep: from 0.55 to 1.8 × the guess in 14 log-spaced steps (9 % apart), then Brent on the peak."""
PEAK_XTOL = 1e-6
INTORDER = 4
"""Quadrature order of the solid's forms (P2·P2 products; the same points for its P1 pressure)."""
SOURCE_RING = (1.25, 2.0)
"""Inner and outer radius of the driving ring on the plate underside, in neck radii."""


@dataclass(frozen=True)
class Cap:
    """The silicone cap (mm, Pa, kg/m³): outer radius b, top thickness above the closed end, clamped height of
    the flange above the plate, density, static-or-dynamic shear modulus G and loss factor η (G* = G(1 + iη))."""

    outer_radius: float
    top_thickness: float
    clamp_height: float
    density_kg_m3: float
    shear_modulus_pa: float
    loss_factor: float = 0.0


@dataclass(frozen=True)
class CoupledResult:
    f0_hz: float
    q: float
    wall_modes_hz: tuple[float, ...]
    dofs: int
    level: int
    seconds: float
    solves: int


def cap(d, shear_modulus_pa: float, loss_factor: float) -> Cap:
    """The silicone cap of a :class:`~matcad.acoustics.design.Design` at the given modulus (Pa) and loss factor."""
    return Cap(outer_radius=d.cap_outer_diameter / 2, top_thickness=d.cap_top_thickness,
               clamp_height=d.cap_clamp_height, density_kg_m3=d.wall.density_kg_m3,
               shear_modulus_pa=shear_modulus_pa, loss_factor=loss_factor)


# ---------------------------------------------------------------- mesh
@dataclass(frozen=True)
class CoupledMesh:
    mesh: object
    air: np.ndarray
    solid: np.ndarray
    layout: fem.Layout


def _solid_count(span: float, h: float) -> int:
    return max(2, math.ceil(span / h - 1e-9))


def _cap_wall_nodes(g: fem.FemGeometry, lay: fem.Layout, b: float, h_solid: float) -> np.ndarray:
    """Fractions 0…1 of the way from the cavity wall to the cap's outer radius b (mm) at which the cap's side wall
    has node lines; where a side-volume groove reaches under the cap's base, its node lines come first, so that the
    base over the groove is shared with the air (and loaded by it)."""
    wall = min(g.cavity_radius, g.cavity_tip_radius)
    under = lay.groove_r[lay.groove_r > g.cavity_radius * (1 + 1e-9)]
    if not len(under):
        return np.linspace(0.0, 1.0, _solid_count(b - wall, h_solid) + 1)
    if under[-1] >= b:
        raise ValueError(f"the side volume's groove reaches r = {under[-1]:.3g} mm, beyond the cap's outer radius "
                         f"{b:.3g} mm; the coupled FEM holds at most the volume under the cap")
    inner = (under - g.cavity_radius) / (b - g.cavity_radius)
    rest = np.linspace(inner[-1], 1.0, _solid_count(b - under[-1], h_solid) + 1)
    return np.concatenate([[0.0], inner, rest[1:]])


def coupled_mesh(g: fem.FemGeometry, cap: Cap, level: int = fem.DEFAULT_LEVEL) -> CoupledMesh:
    """Air and cap on one conforming mesh; element index arrays of each subdomain."""
    l, L = g.neck_length, g.cavity_length
    lay = fem.layout(g, level, cavity_breaks=(l + cap.clamp_height,) if 0 < cap.clamp_height < L else ())
    blocks = fem.air_blocks(g, lay)
    n_air = len(blocks)
    b = cap.outer_radius
    h_solid = lay.h_max * fem.DEFAULT_LEVEL / level  # refines with the level like the air away from corners
    s = _cap_wall_nodes(g, lay, b, h_solid)
    blocks.append(fem_blocks.block(lambda s_, z: fem.cavity_wall_radius(g, z) + s_ * (b - fem.cavity_wall_radius(g, z)),
                             lay.z_cavity, s))
    tip = g.cavity_tip_radius
    a = g.neck_radius
    r_top = np.concatenate([lay.r_neck, a + lay.s_annulus[1:] * (tip - a), tip + s[1:] * (b - tip)])
    z_top = np.linspace(l + L, l + L + cap.top_thickness, _solid_count(cap.top_thickness, h_solid) + 1)
    blocks.append(fem_blocks.block(lambda s_, z: s_, z_top, r_top))
    m, starts = fem.merge_blocks(blocks, lay.h)
    cells = np.arange(m.t.shape[1])
    return CoupledMesh(m, cells[:starts[n_air]], cells[starts[n_air]:], lay)


def _facets(cm: CoupledMesh, g: fem.FemGeometry, cap: Cap):
    """(interface, source ring, bonded/clamped, axis-of-solid) facet indices by facet midpoints."""
    m = cm.mesh
    r, z = m.p[:, m.facets].mean(axis=1)
    in_solid = np.zeros(m.t.shape[1], dtype=bool)
    in_solid[cm.solid] = True
    f2t = m.f2t
    side0 = in_solid[f2t[0]]
    side1 = np.where(f2t[1] >= 0, in_solid[np.maximum(f2t[1], 0)], side0)
    interface = np.flatnonzero(side0 != side1)
    boundary = f2t[1] < 0
    tol = 1e-6 * g.neck_radius
    l = g.neck_length
    a = g.mouth_r
    ring = np.flatnonzero(boundary & (np.abs(z) < tol) & (r > SOURCE_RING[0] * a) & (r < SOURCE_RING[1] * a))
    solid_b = boundary & side0
    fixed = np.flatnonzero(solid_b & ((np.abs(z - l) < tol)
                                      | ((r > cap.outer_radius - tol) & (z < l + cap.clamp_height + tol))))
    axis = np.flatnonzero(solid_b & (r < tol))
    return interface, ring, fixed, axis


# ---------------------------------------------------------------- forms
def _forms():
    from skfem import BilinearForm
    from skfem.helpers import dot, grad

    def strain(u, r):
        du = grad(u)
        return du[0, 0], du[1, 1], u[0] / r, 0.5 * (du[0, 1] + du[1, 0])

    @BilinearForm
    def elastic(u, v, w):
        r = w.x[0]
        eu, ev = strain(u, r), strain(v, r)
        return 2.0 * (eu[0] * ev[0] + eu[1] * ev[1] + eu[2] * ev[2] + 2.0 * eu[3] * ev[3]) * r

    @BilinearForm
    def vector_mass(u, v, w):
        return dot(u, v) * w.x[0]

    @BilinearForm
    def divergence(u, q, w):
        r = w.x[0]
        e = strain(u, r)
        return -(e[0] + e[1] + e[2]) * q * r

    @BilinearForm
    def normal_trace(u, q, w):
        n = w.n * np.sign(w.n[0] + w.n[1])  # from the air into the silicone: +r on the side, +z on the top
        return dot(u, n) * q * w.x[0]

    return elastic, vector_mass, divergence, normal_trace


@dataclass(frozen=True)
class _System:
    k_air: object
    m_air: object
    c_rad: object
    kappa: float
    coupling: object
    elastic: object
    m_solid: object
    div: object
    source: np.ndarray
    probe: int
    n_air: int
    n_u: int
    n_pi: int


def _sub(mat, rows, cols):
    return mat.tocsr()[rows][:, cols].tocsc()


def _elastic(b_u, b_pi, u_dofs, pi_dofs) -> dict:
    """Unit-modulus elastic, unit-density mass and divergence matrices on the free dofs (mm units)."""
    from skfem import asm

    elastic, vector_mass, divergence, _ = _forms()
    return {"elastic": _sub(asm(elastic, b_u), u_dofs, u_dofs),
            "m_solid": _sub(asm(vector_mass, b_u), u_dofs, u_dofs),
            "div": _sub(asm(divergence, b_u, b_pi), pi_dofs, u_dofs)}


def plane_strain_tube_modes_hz(inner_radius: float, outer_radius: float, shear_modulus_pa: float,
                               density_kg_m3: float, level: int = 4, count: int = 1) -> list[float]:
    """In-vacuo modes (Hz) of a free thick tube in plane strain from this module's axisymmetric incompressible
    operator: an annulus a ≤ r ≤ b (mm), one element layer of height (b − a)/level, u_z = 0 top and bottom (so
    ε_zz = 0) and both curved faces free. Its first mode is the breathing mode u_r ∝ 1/r, whose exact frequency
    is :func:`matcad.acoustics.models.wall_breathing_hz` — the operator's closed-form check."""
    from scipy.sparse import bmat, csc_matrix
    from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector, MeshTri

    h = (outer_radius - inner_radius) / level
    m = MeshTri.init_tensor(np.linspace(inner_radius, outer_radius, level + 1), np.array([0.0, h]))
    b_u = Basis(m, ElementVector(ElementTriP2()), intorder=INTORDER)
    b_pi = Basis(m, ElementTriP1(), intorder=INTORDER)
    flat = m.facets_satisfying(lambda x: (x[1] < 1e-9 * h) | (x[1] > h * (1 - 1e-9)))
    u_dofs = np.setdiff1d(np.arange(b_u.N), b_u.get_dofs(facets=flat).all(["u^2"]))
    mats = _elastic(b_u, b_pi, u_dofs, np.arange(b_pi.N))
    n_pi = b_pi.N
    k = bmat([[shear_modulus_pa / PA_PER_MPA * mats["elastic"], mats["div"].T], [mats["div"], None]], format="csc")
    mm = bmat([[density_kg_m3 / KG_M3_PER_T_MM3 * mats["m_solid"], None], [None, csc_matrix((n_pi, n_pi))]],
              format="csc")
    return elastic_modes_hz(k, mm, count)


def _assemble(cm: CoupledMesh, g: fem.FemGeometry, cap: Cap) -> _System:
    from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector, FacetBasis, LinearForm, asm

    m = cm.mesh
    p2, vec, p1 = ElementTriP2(), ElementVector(ElementTriP2()), ElementTriP1()
    b_air = Basis(m, p2, elements=cm.air)
    b_u = Basis(m, vec, elements=cm.solid, intorder=INTORDER)
    b_pi = Basis(m, p1, elements=cm.solid, intorder=INTORDER)
    stiffness, mass, _ = fem._forms()
    normal_trace = _forms()[3]
    interface, ring, fixed, axis = _facets(cm, g, cap)
    radiation, kappa = fem._boundary_facets(m, g)

    air_dofs = np.unique(b_air.element_dofs)
    u_all = np.unique(b_u.element_dofs)
    blocked = np.union1d(b_u.get_dofs(facets=fixed).all(), b_u.get_dofs(facets=axis).all(["u^1"]))
    u_dofs = np.setdiff1d(u_all, blocked)
    pi_dofs = np.unique(b_pi.element_dofs)

    sub = _sub
    fb_rad = FacetBasis(m, p2, facets=radiation)
    fb_air_i = FacetBasis(m, p2, facets=interface)
    fb_u_i = FacetBasis(m, vec, facets=interface)
    fb_ring = FacetBasis(m, p2, facets=ring)

    @LinearForm
    def unit(v, w):
        return v * w.x[0]

    xs = b_air.doflocs
    top = np.flatnonzero((np.abs(xs[0]) < 1e-9) & (np.abs(xs[1] - g.neck_length - g.cavity_length) < 1e-9))
    probe = int(np.searchsorted(air_dofs, top[0]))
    return _System(
        k_air=sub(asm(stiffness, b_air), air_dofs, air_dofs), m_air=sub(asm(mass, b_air), air_dofs, air_dofs),
        c_rad=sub(asm(mass, fb_rad), air_dofs, air_dofs), kappa=kappa,
        coupling=sub(asm(normal_trace, fb_u_i, fb_air_i), air_dofs, u_dofs),
        **_elastic(b_u, b_pi, u_dofs, pi_dofs), source=asm(unit, fb_ring)[air_dofs],
        probe=probe, n_air=len(air_dofs), n_u=len(u_dofs), n_pi=len(pi_dofs))


# ---------------------------------------------------------------- solve
def _response(sys_: _System, cap: Cap | None, f_hz: float, c_m_s: float, rho_air_t_mm3: float) -> complex:
    """Cavity-end pressure for unit drive at ``f_hz`` (arbitrary but fixed scale); ``cap`` None: rigid wall."""
    from scipy.sparse import bmat, csc_matrix
    from scipy.sparse.linalg import spsolve

    air, rhs = _air_system(sys_, f_hz, c_m_s, rho_air_t_mm3)
    if cap is None:
        return complex(spsolve(air, rhs)[sys_.probe])
    coupling = bmat([[sys_.coupling, csc_matrix((sys_.n_air, sys_.n_pi))]], format="csc")
    a = bmat([[air, -coupling], [-coupling.T, _solid_operator(sys_, cap, 2 * math.pi * f_hz)]], format="csc")
    full = np.concatenate([rhs, np.zeros(sys_.n_u + sys_.n_pi)])
    return complex(spsolve(a, full)[sys_.probe])


def _air_system(sys_: _System, f_hz: float, c_m_s: float, rho_air_t_mm3: float):
    """The air block (divided by ω²ρ_a) and the drive (a ring of unit normal velocity: ∂p/∂n = −iωρ_a v)."""
    omega = 2 * math.pi * f_hz
    k = omega / (c_m_s * 1e3)
    air = ((sys_.k_air + (1j * k + sys_.kappa) * sys_.c_rad) / (omega**2 * rho_air_t_mm3)
           - sys_.m_air / (BULK_MODULUS_PA / PA_PER_MPA))
    return air.tocsc(), (sys_.source / omega).astype(complex)


def _solid_operator(sys_: _System, cap: Cap, omega: float):
    from scipy.sparse import bmat

    g_star = cap.shear_modulus_pa / PA_PER_MPA * (1 + 1j * cap.loss_factor)
    rho_s = cap.density_kg_m3 / KG_M3_PER_T_MM3
    return bmat([[g_star * sys_.elastic - omega**2 * rho_s * sys_.m_solid, sys_.div.T], [sys_.div, None]],
                format="csc")


def static_wall(sys_: _System, cap: Cap) -> tuple[float, np.ndarray]:
    """The cap's static volume compliance ΔV/p (mm³/MPa) under a uniform cavity pressure and the wall's
    displacement pattern as a load on the air dofs (C·u for unit pressure), from one static solve."""
    from scipy.sparse.linalg import spsolve

    load = np.concatenate([sys_.coupling.T @ np.ones(sys_.n_air), np.zeros(sys_.n_pi)])
    u = spsolve(_solid_operator(sys_, cap, 0.0), load.astype(complex))[:sys_.n_u]
    shape = sys_.coupling @ u
    return float(np.real(np.sum(shape))), shape


def static_response(sys_: _System, cap: Cap, f_hz: float, c_m_s: float, rho_air_t_mm3: float) -> complex:
    """As :func:`_response` with the wall replaced by its static volume compliance acting on the cavity's
    mean pressure (rank one: exact for a uniform cavity pressure), by Sherman–Morrison on the air matrix."""
    from scipy.sparse.linalg import splu

    volume, shape = static_wall(sys_, cap)
    air, rhs = _air_system(sys_, f_hz, c_m_s, rho_air_t_mm3)
    lu = splu(air)
    x, y = lu.solve(rhs), lu.solve(shape)
    x = x + y * (shape @ x) / (volume - shape @ y)
    return complex(x[sys_.probe])


def _peak(response, f_guess_hz: float):
    """(f at the peak of |response|, Q from the curvature of 1/|response|² there, evaluations)."""
    from scipy.optimize import minimize_scalar

    calls = [0]

    def inv2(f):
        calls[0] += 1
        return 1.0 / abs(response(f)) ** 2

    fs = f_guess_hz * np.geomspace(SWEEP[0], SWEEP[1], SWEEP[2])
    values = [inv2(f) for f in fs]
    i = int(np.argmin(values))
    lo, hi = fs[max(i - 1, 0)], fs[min(i + 1, len(fs) - 1)]
    best = minimize_scalar(inv2, bounds=(lo, hi), method="bounded", options={"xatol": PEAK_XTOL * fs[i]})
    f0 = float(best.x)
    d = 1e-3 * f0
    y0, ym, yp = float(best.fun), inv2(f0 - d), inv2(f0 + d)
    curvature = (ym + yp - 2 * y0) / (d * d)  # 1/|p|² ≈ a (f − f0)² + c near one pole: Q = f0 / (2 sqrt(c/a))
    q = f0 / (2 * math.sqrt(max(y0, 0.0) / curvature)) if curvature > 0 and y0 > 0 else math.inf
    return f0, q, calls[0]


def air_density_t_mm3(c_m_s: float) -> float:
    """ρ_a = γP0/c² (the same ρc² as everywhere in matcad), in t/mm³."""
    return BULK_MODULUS_PA / c_m_s**2 / KG_M3_PER_T_MM3


def solve(g: fem.FemGeometry, cap: Cap | None, f_guess_hz: float, level: int = fem.DEFAULT_LEVEL,
          c_m_s: float = 343.0, wall_modes: int = 3) -> CoupledResult:
    """Peak of the cavity pressure driven at the mouth, with the elastic ``cap`` (None: rigid wall), searched from
    ``f_guess_hz`` (e.g. the rigid transmission line); plus the cap's first ``wall_modes`` in-vacuo modes (Hz)."""
    t0 = time.perf_counter()
    ref = cap or Cap(outer_radius=g.cavity_radius * 2, top_thickness=g.cavity_radius, clamp_height=0.0,
                     density_kg_m3=1000.0, shear_modulus_pa=1e6)
    cm = coupled_mesh(g, ref, level)
    sys_ = _assemble(cm, g, ref)
    rho_a = air_density_t_mm3(c_m_s)
    with fem.one_blas_thread():  # multi-threaded BLAS in SuperLU cost ~5x the CPU with a baffled mouth
        f0, q, calls = _peak(lambda f: _response(sys_, cap, f, c_m_s, rho_a), f_guess_hz)
        modes = () if cap is None or not wall_modes else tuple(_wall_modes(sys_, cap, wall_modes))
    dofs = sys_.n_air + (0 if cap is None else sys_.n_u + sys_.n_pi)
    return CoupledResult(f0_hz=f0, q=q, wall_modes_hz=modes, dofs=dofs, level=level,
                         seconds=time.perf_counter() - t0, solves=calls)


@dataclass(frozen=True)
class WallModes:
    """The cap's in-vacuo modes at one (G, ρ_s): frequencies (Hz), each mode's volume compliance c_i = Φ_i²/ω_i²
    (mm³/Pa; Φ_i the cavity volume swept per unit mass-normalised amplitude) and the static volume compliance
    (mm³/Pa) under uniform cavity pressure, which the truncated modal sum is corrected to (mode acceleration)."""

    frequencies_hz: tuple[float, ...]
    compliances_mm3_pa: tuple[float, ...]
    static_mm3_pa: float


def wall_modes(sys_: _System, cap: Cap, count: int) -> WallModes:
    """The first ``count`` in-vacuo modes of the cap (lossless, air removed) and its static compliance."""
    from scipy.sparse import bmat, csc_matrix

    rho_s = cap.density_kg_m3 / KG_M3_PER_T_MM3
    k = _solid_operator(sys_, dataclasses.replace(cap, loss_factor=0.0), 0.0)
    m = bmat([[rho_s * sys_.m_solid, None], [None, csc_matrix((sys_.n_pi, sys_.n_pi))]], format="csc")
    lam, vecs = fem._eigs_near(k.astype(complex), m.astype(complex), 0.0, count)
    order = np.argsort(lam.real)
    lam, vecs = lam.real[order], vecs[:, order]
    freqs, comps = [], []
    swept = np.ones(sys_.n_air) @ sys_.coupling  # volume swept per unit displacement dof, per radian
    for i in range(len(lam)):
        u = vecs[:sys_.n_u, i]
        u = u / np.sqrt(np.real(np.conj(u) @ (rho_s * sys_.m_solid @ u)))
        phi = math.sqrt(2 * math.pi) * abs(swept @ u)  # mm³ per unit amplitude, modal mass 2π·uᵀMu = 1
        freqs.append(math.sqrt(lam[i]) / (2 * math.pi))
        comps.append(phi * phi / lam[i] / PA_PER_MPA)  # mm³/MPa → mm³/Pa
    static = 2 * math.pi * static_wall(sys_, dataclasses.replace(cap, loss_factor=0.0))[0] / PA_PER_MPA
    return WallModes(tuple(freqs), tuple(comps), static)


def _wall_modes(sys_: _System, cap: Cap, count: int) -> list[float]:
    return list(wall_modes(sys_, cap, count).frequencies_hz)


def elastic_modes_hz(k, m, count: int) -> list[float]:
    """Lowest ``count`` frequencies (Hz) of K x = ω² M x in mm-t-s units (M is singular on the pressure rows;
    shift-invert about 0 maps those infinite eigenvalues to 0, away from the ones wanted)."""
    lam, _ = fem._eigs_near(k.astype(complex), m.astype(complex), 0.0, count)
    lam = np.sort(lam.real[np.isfinite(lam.real) & (lam.real > 0)])
    return [float(math.sqrt(x) / (2 * math.pi)) for x in lam[:count]]


TABLE_LEVEL = 6
TABLE_MODES = 20


def unit_cap_modes(outer: float, top: float, length: float, clamp_fraction: float, level: int = TABLE_LEVEL,
                   count: int = TABLE_MODES) -> WallModes:
    """Wall modes of a cap around a cylindrical cavity of radius 1 mm and ``length`` (mm), outer radius ``outer``,
    top ``top`` (mm), clamped over ``clamp_fraction`` of the cavity height, at G = 1 MPa and ρ = 1000 kg/m³.
    Other sizes and materials follow exactly: f ∝ sqrt(G/ρ)/a, compliances ∝ a³/G (linear elasticity)."""
    g = fem.FemGeometry(neck_radius=0.6, neck_length=max(length, 2.0), cavity_radius=1.0, cavity_tip_radius=1.0,
                        cavity_length=length, mouth="baffled")
    cap = Cap(outer_radius=outer, top_thickness=top, clamp_height=clamp_fraction * length,
              density_kg_m3=UNIT_DENSITY, shear_modulus_pa=UNIT_SHEAR_PA)
    cm = coupled_mesh(g, cap, level)
    return wall_modes(_assemble(cm, g, cap), cap, count)
