"""The AcousTac fipple tube's air column: a closed-open quarter-wave resonator whose closed end is the silicone cap.
Pure numpy/scipy. Lengths mm, frequencies Hz, speeds m/s, compliances mm³/Pa. Sources and derivations:
docs/tube.md.

The air column runs from the mouth (x = 0) through the bore (``length``) into the cap's cavity (``cap_depth``, the
same bore) to the cap's inner wall (x = ℓ). Two end conditions close the 1-D Helmholtz equation p'' + k²p = 0:

- at the mouth, the radiating air is a mass: p(0) = δ p'(0), δ the mouth's end correction as a length of bore —
  0.6133 a for an unflanged open end of no wall (Levine & Schwinger 1948; more for the printed wall's end face),
  0.8216 a flanged (Norris & Sheng 1989), and for a
  window in the tube's wall (a fipple's B·W, a transverse mouth's sides and gable) of area S_m, S_p / K_R, with
  K_R = 2 a_m Rayleigh's conductance of an aperture of equal area in a thin wall (Rayleigh, Theory of Sound II
  §306; the flue-pipe mouth as an inertance: Fletcher & Rossing 1998, "The Physics of Musical Instruments",
  §17.4);
- at the cap, the wall's volume compliance C_w (its volume swept per unit pressure, the MAT path's wall model
  :mod:`matcad.acoustics.wall`) is a compliant termination: p'(ℓ) = k² κ p(ℓ), κ = K C_w / S_p the length of air with
  the same compliance (K = ρc² the bulk modulus). A rigid cap is κ = 0.

Three routes to the same resonance: :func:`closed_form_hz` f = (2n−1) c / 4(ℓ + δ + κ), the textbook quarter wave
with its corrections; :func:`line_hz` the exact root of the transmission line's characteristic equation
(1 − k²δκ) cos kℓ = k(δ + κ) sin kℓ; :func:`fem_hz` a 1-D finite-element eigenproblem with the same end conditions
as boundary terms, an independent discretisation that converges to :func:`line_hz` as h² (P1) or h⁴ (P2). Each
route solves the lossless column and then slows it by the bore's viscous and thermal boundary layers
(:func:`boundary_layer_hz`, Zwikker & Kosten), unless the design says ``boundary_layers=False``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from matcad.acoustics import wall as wall_model
from matcad.acoustics.air import BULK_MODULUS_PA
from matcad.acoustics.design import Air, WallMaterial, speed_of_sound
from matcad.spec.tube import WINDOWED, transverse_window_area_mm2

UNFLANGED = 0.6133
"""Open-end correction of an unflanged thin-walled tube, per radius (Levine & Schwinger 1948, ka → 0)."""
FLANGED = 0.8216
"""Open-end correction of a tube in an infinite flange, per radius (Norris & Sheng 1989; Rayleigh's 8/3π ≈ 0.85
is its piston approximation)."""
WALL_FIXED_POINT_TOL = 1e-10
WALL_FIXED_POINT_STEPS = 60
WALL_SCAN_POINTS = 401
BOUNDARY_LAYER_STEPS = 100


@dataclass(frozen=True)
class TubeDesign:
    """One fipple tube as built (mm, deg): bore, length mouth → cap seat, the cap's cavity depth, the open end's
    ``mouth`` (:data:`matcad.spec.tube.MOUTHS`), windway height h and width B, edge distance W, the cap around
    the cavity (outer diameter, top thickness, clamped height), the air, the cap's wall material and the printed
    tube's wall thickness ``tube_wall`` (mm, the spec's ``tube.wall``)."""

    bore_diameter: float
    length: float
    cap_depth: float
    mouth: str
    windway_height: float
    windway_width: float
    edge_distance: float
    cap_outer_diameter: float
    cap_top_thickness: float
    cap_clamp_height: float
    air: Air
    wall: WallMaterial
    tube_wall: float
    edge_angle: float
    """The labium's outer bevel from vertical (deg, the spec's ``tube.edge_angle``)."""
    block_length: float
    """The block under the window (mm, the spec's ``tube.block_length``)."""
    boundary_layers: bool = True
    """Whether the bore's viscous and thermal boundary layers slow the wave (:func:`boundary_layer_hz`); False:
    the lossless column, the one the exterior FEMs solve (their checks compare like with like)."""

    @property
    def column_mm(self) -> float:
        """The air column ℓ from the mouth to the cap's inner wall (mm)."""
        return self.length + self.cap_depth

    @property
    def bore_area_mm2(self) -> float:
        return math.pi * self.bore_diameter**2 / 4


def tube_design(spec) -> TubeDesign:
    """The :class:`TubeDesign` of a ``kind = "tube"`` spec (its [tube], [end_cap], [air], [wall], [silicone]); the
    cap is clamped over its flange's thickness, as a MAT cap."""
    from matcad.spec import cap_flange_thickness_mm

    t, w = spec.tube, spec.wall
    return TubeDesign(
        bore_diameter=t.bore_diameter, length=t.length, cap_depth=t.cap_cavity_depth, mouth=t.mouth,
        windway_height=t.windway_height, windway_width=t.windway_width, edge_distance=t.edge_distance,
        cap_outer_diameter=spec.end_cap.outer_diameter, cap_top_thickness=spec.end_cap.top_thickness,
        cap_clamp_height=cap_flange_thickness_mm(spec), air=Air(spec.air.temperature_c, spec.air.speed_of_sound),
        wall=WallMaterial(w.model, w.shear_modulus_mpa, w.khz_modulus_factor, w.loss_factor,
                          spec.silicone.density_g_cm3 * 1000.0), tube_wall=t.wall,
        edge_angle=t.edge_angle, block_length=t.block_length)


def wall_end_correction(wall_per_radius: float) -> float:
    """The open end's correction per bore radius of a tube whose wall, ``wall_per_radius`` × a thick, ends in a flat
    face out to b = a + w: 0.8216 + (a/b)(0.6133 − 0.8216) + 0.057 (a/b)(1 − (a/b)⁵), between Levine & Schwinger's
    0.6133 (no wall) and Norris & Sheng's 0.8216 (an infinite flange); the interpolation of Dalmont, Nederveen & Joly
    2001 as WWIDesigner's ThickFlangedOpenEndCalculator implements it (the paper not read). The axisymmetric exterior
    FEM of such an end agrees within 0.004 a for w/a 0.01-1 (docs/tube.md)."""
    x = 1 / (1 + wall_per_radius)
    return FLANGED + x * (UNFLANGED - FLANGED) + 0.057 * x * (1 - x**5)


def mouth_correction_mm(td: TubeDesign, factor: float = 1.0) -> float:
    """δ, the open end's correction as a length of bore (mm): unflanged, that of the printed wall's end face
    (:func:`wall_end_correction`: Levine & Schwinger's 0.6133 a for a wall of no thickness), Norris & Sheng's
    0.8216 a flanged, or a window's inertance S_p / (2 a_m), a_m = √(S_m / π) (Rayleigh's conductance of a
    thin-walled aperture of the window's area S_m: B W for a fipple, the sides and gable of a transverse window,
    :func:`matcad.spec.tube.transverse_window_area_mm2`); times ``factor`` (an uncertainty study)."""
    a = td.bore_diameter / 2
    if td.mouth == "unflanged":
        return factor * wall_end_correction(td.tube_wall / a) * a
    if td.mouth == "flanged":
        return factor * FLANGED * a
    area = td.windway_width * td.edge_distance if td.mouth == "fipple" else \
        transverse_window_area_mm2(td.windway_height, td.windway_width, td.edge_distance)
    return factor * td.bore_area_mm2 / (2 * math.sqrt(area / math.pi))


def compliance_length_mm(td: TubeDesign, compliance_mm3_pa: float) -> float:
    """κ = K C_w / S_p (mm): the length of bore air as compliant as the cap (K the air's bulk modulus, Pa)."""
    return BULK_MODULUS_PA * compliance_mm3_pa / td.bore_area_mm2


def boundary_layer_hz(td: TubeDesign, lossless_hz: float) -> float:
    """The resonance (Hz) whose phase wavenumber Re k = (2πf/c) Re(k/k₀) in the bore equals the lossless column's
    wavenumber 2π f_lossless/c: f = f_lossless / Re(k/k₀)(f), the boundary layers' k/k₀ of
    :func:`matcad.acoustics.air.wavenumber_ratio` (Zwikker & Kosten), by fixed-point iteration (it contracts by about
    half the layers' ε per step). ``lossless_hz`` itself when ``td.boundary_layers`` is False. The column is the bore
    throughout (the cap's cavity continues it); the mouth's mass and the cap keep their lossless lengths, the
    layers' smaller change of the line's impedance is left out (docs/tube.md: 0.16 % on a 2 mm bore at 185 Hz
    against the lossy transfer matrix's impedance peak)."""
    if not td.boundary_layers:
        return lossless_hz
    from matcad.acoustics.air import wavenumber_ratio

    radius, f = td.bore_diameter / 2, lossless_hz
    for _ in range(BOUNDARY_LAYER_STEPS):
        f_new = lossless_hz / float(np.real(wavenumber_ratio(f, radius)))
        if abs(f_new - f) <= 1e-14 * f:
            return f_new
        f = f_new
    raise ArithmeticError(f"the boundary layers' fixed point did not settle from {lossless_hz:g} Hz")


def closed_form_hz(td: TubeDesign, kappa_mm: float = 0.0, mode: int = 1) -> float:
    """The quarter-wave closed form f_n = (2n − 1) c_φ / 4(ℓ + δ + κ) (Hz), c_φ the bore's phase speed
    (:func:`boundary_layer_hz`): exact for the rigid cap as kδ → 0."""
    c_mm_s = speed_of_sound(td.air) * 1e3
    return boundary_layer_hz(td, (2 * mode - 1) * c_mm_s / (4 * (td.column_mm + mouth_correction_mm(td) + kappa_mm)))


def _characteristic(k, length, delta, kappa):
    return (1 - k**2 * delta * kappa) * np.cos(k * length) - k * (delta + kappa) * np.sin(k * length)


def line_hz(td: TubeDesign, kappa_mm: float = 0.0, mode: int = 1, correction_factor: float = 1.0) -> float:
    """The transmission line's resonance (Hz): the ``mode``-th root k of (1 − k²δκ) cos kℓ = k(δ + κ) sin kℓ, from
    p'' + k²p = 0 with p(0) = δ p'(0) and p'(ℓ) = k²κ p(ℓ). Raises ValueError when the root is not bracketed (a
    wall so soft that κ < −ℓ). ``correction_factor`` scales δ (an uncertainty study)."""
    from scipy.optimize import brentq

    length, delta = td.column_mm, mouth_correction_mm(td, correction_factor)
    k = np.linspace(1e-9, (mode + 0.5) * math.pi / length, 4000 * (mode + 1))
    g = _characteristic(k, length, delta, kappa_mm)
    roots = np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]
    if len(roots) < mode:
        raise ValueError(f"no resonance of mode {mode} for this tube (kappa = {kappa_mm:g} mm)")
    i = roots[mode - 1]
    root = brentq(_characteristic, k[i], k[i + 1], args=(length, delta, kappa_mm), xtol=1e-14, rtol=1e-14)
    return boundary_layer_hz(td, root * speed_of_sound(td.air) * 1e3 / (2 * math.pi))


def fem_hz(td: TubeDesign, kappa_mm: float = 0.0, elements: int = 64, order: int = 1, mode: int = 1) -> float:
    """The same resonance by a 1-D finite-element eigenproblem (Hz): P1 or P2 Lagrange elements on [0, ℓ], the
    weak form ∫p'v' − k²∫pv − k²κ p(ℓ)v(ℓ) + p(0)v(0)/δ = 0, i.e. (K + e₀e₀ᵀ/δ) p = k² (M + κ e_ℓe_ℓᵀ) p."""
    from scipy.linalg import eig

    length, delta = td.column_mm, mouth_correction_mm(td)
    n = elements * order + 1
    h = length / elements
    if order == 1:
        ke = np.array([[1, -1], [-1, 1]]) / h
        me = np.array([[2, 1], [1, 2]]) * h / 6
    elif order == 2:  # nodes at 0, h/2, h: the element matrices of quadratic Lagrange shape functions
        ke = np.array([[7, -8, 1], [-8, 16, -8], [1, -8, 7]]) / (3 * h)
        me = np.array([[4, 2, -1], [2, 16, 2], [-1, 2, 4]]) * h / 30
    else:
        raise ValueError(f"order must be 1 or 2, not {order}")
    stiff, mass = np.zeros((n, n)), np.zeros((n, n))
    for e in range(elements):
        idx = np.arange(e * order, e * order + order + 1)
        stiff[np.ix_(idx, idx)] += ke
        mass[np.ix_(idx, idx)] += me
    stiff[0, 0] += 1 / delta
    mass[-1, -1] += kappa_mm
    k2 = eig(stiff, mass, right=False)
    k2 = np.sort(k2.real[(np.abs(k2.imag) < 1e-9 * np.abs(k2.real) + 1e-30) & (k2.real > 0)])
    return boundary_layer_hz(td, math.sqrt(k2[mode - 1]) * speed_of_sound(td.air) * 1e3 / (2 * math.pi))


def exterior_fem(td: TubeDesign, level: int | None = None):
    """The rigid-capped tube's f1 by the MAT taxel's axisymmetric P2 FEM (:func:`matcad.acoustics.fem.solve`,
    scikit-fem): the (r, z) half-plane with the bore as its neck (``length``), the cap's cavity as its cavity of the
    same radius (``cap_depth``), and the mouth radiating into an exterior of radius 15 a with the spherical
    radiation condition on its arc: for ``mouth = 'flanged'`` a quarter disc in a rigid baffle (fem's 'baffled'),
    for ``'unflanged'`` the free space around the tube's end, the printed wall (``tube_wall``) running from the
    mouth back to the arc (fem's 'unflanged'). It resolves the radiating mouth instead of assuming δ: flanged, its
    f1 tends to the quarter wave with Norris & Sheng's frequency-dependent correction
    (:func:`flanged_phase_correction_mm`); unflanged with a thin wall, its correction tends to Levine & Schwinger's
    0.6133 a as ka → 0, rising with the wall's thickness towards the flanged value (docs/tube.md). ``level``:
    elements across the bore's radius (default fem's). Returns a :class:`matcad.acoustics.fem.FemResult` (f in Hz,
    lossless: :func:`boundary_layer_hz` adds the bore's boundary layers). Raises ValueError for a window in the
    tube's wall, 'fipple' or 'transverse' (3-D: :func:`window_fem`)."""
    from matcad.acoustics import fem

    exteriors = {"flanged": "baffled", "unflanged": "unflanged"}
    if td.mouth not in exteriors:
        raise ValueError(f"tube.mouth = '{td.mouth}' has no axisymmetric exterior FEM (a window in the tube's wall "
                         f"is 3-D: window_fem), must be one of 'flanged', 'unflanged': docs/tube.md")
    a = td.bore_diameter / 2
    g = fem.FemGeometry(neck_radius=a, neck_length=td.length, cavity_radius=a, cavity_tip_radius=a,
                        cavity_length=td.cap_depth, mouth=exteriors[td.mouth],
                        wall=td.tube_wall if td.mouth == "unflanged" else 0.0)
    c = speed_of_sound(td.air)
    guess = line_hz(dataclasses.replace(td, boundary_layers=False))
    return fem.solve(g, 2 * math.pi * guess / (c * 1e3), level or fem.DEFAULT_LEVEL, speed_of_sound_m_s=c)


def window_fem(td: TubeDesign, level: int | None = None) -> tuple[float, float]:
    """A window's end correction δ (mm) by the 3-D potential-flow FEM of the printed mouth, fipple or transverse
    (:func:`matcad.acoustics.mouth3d.end_correction`, scikit-fem; ``level`` cells across the bore's radius, default
    its own), and the rigid-capped line's f1 (Hz) with that δ in place of Rayleigh's aperture. ValueError for
    another mouth."""
    from matcad.acoustics import mouth3d

    if td.mouth not in WINDOWED:
        raise ValueError(f"tube.mouth = '{td.mouth}' has no window: exterior_fem resolves it")
    delta = mouth3d.end_correction(mouth3d.from_tube(td), level or mouth3d.DEFAULT_LEVEL).delta_mm
    return delta, line_hz(td, correction_factor=delta / mouth_correction_mm(td))


def phase_correction_mm(td: TubeDesign, f_hz: float, mode: int = 1) -> float:
    """The open end's correction (mm) that a rigid-capped resonance at ``f_hz`` (Hz) implies: the length the
    reflection's phase adds, (2n − 1) c / 4f − ℓ (the definition of Norris & Sheng 1989 and Dalmont et al. 2001)."""
    return (2 * mode - 1) * speed_of_sound(td.air) * 1e3 / (4 * f_hz) - td.column_mm


def flanged_phase_correction_mm(td: TubeDesign, f_hz: float) -> float:
    """Norris & Sheng's fit (1989, J. Sound Vib. 135:85, for ka < 3.5) of the flanged open end's phase correction
    at ``f_hz`` (mm): 0.8216 a / (1 + (0.77 ka)² / (1 + 0.77 ka))."""
    a = td.bore_diameter / 2
    x = 0.77 * 2 * math.pi * f_hz / (speed_of_sound(td.air) * 1e3) * a
    return FLANGED * a / (1 + x * x / (1 + x))


def cap_shape(td: TubeDesign) -> wall_model.CapShape:
    """The silicone cap around the cap's cavity (the bore continued), mm: the MAT wall model's cap."""
    return wall_model.CapShape(cavity_radius=td.bore_diameter / 2, cavity_length=td.cap_depth,
                               outer_radius=td.cap_outer_diameter / 2, top_thickness=td.cap_top_thickness,
                               clamp_height=td.cap_clamp_height)


def cap_wall_modes(td: TubeDesign, shear_modulus_pa: float) -> wall_model.Modes:
    """The cap's wall modes at the (dynamic) shear modulus (Pa), from the MAT wall model's table."""
    return wall_model.modes(cap_shape(td), shear_modulus_pa, td.wall.density_kg_m3)


def cap_compliance_mm3_pa(td: TubeDesign, f_hz: float, shear_modulus_pa: float) -> float:
    """The cap's dynamic volume compliance at ``f_hz`` (mm³/Pa, its real part, lossless): the MAT wall model's modal
    sum (:func:`matcad.acoustics.wall.dynamic_compliance_mm3_pa`) on this cap at the shear modulus (Pa)."""
    modes = cap_wall_modes(td, shear_modulus_pa)
    return float(np.real(wall_model.dynamic_compliance_mm3_pa(np.array([f_hz]), modes, 0.0))[0])


def with_wall_hz(td: TubeDesign, shear_modulus_pa: float, route=line_hz, mode: int = 1) -> tuple[float, float]:
    """(f in Hz, κ in mm) of the tube with its silicone cap at the (dynamic) shear modulus (Pa): a root of
    h(f) = route(κ(C_w(f))) − f, by the fixed point f ← route(κ(C_w(f))) started from the rigid cap, and where that
    does not settle (a cap mode near the tube's pulls κ through a pole) the sign change of h nearest the rigid f on
    a grid of ±50 % (Brent), skipping the poles. Raises ValueError when h has no root there."""
    f_rigid = f = route(td, 0.0, mode=mode)
    for _ in range(WALL_FIXED_POINT_STEPS):
        kappa = compliance_length_mm(td, cap_compliance_mm3_pa(td, f, shear_modulus_pa))
        f_new = route(td, kappa, mode=mode)
        if abs(f_new - f) <= WALL_FIXED_POINT_TOL * f:
            return f_new, kappa
        f = 0.5 * (f + f_new)
    return _scanned_root(td, shear_modulus_pa, route, mode, f_rigid)


def _scanned_root(td: TubeDesign, shear_modulus_pa: float, route, mode: int, f_rigid: float) -> tuple[float, float]:
    from scipy.optimize import brentq

    def h(f):
        try:
            return route(td, compliance_length_mm(td, cap_compliance_mm3_pa(td, f, shear_modulus_pa)), mode=mode) - f
        except ValueError:  # κ beyond the line's bracket: no root here
            return math.nan

    grid = np.linspace(0.5 * f_rigid, 1.5 * f_rigid, WALL_SCAN_POINTS)
    values = np.array([h(f) for f in grid])
    jump_limit = 0.05 * f_rigid  # a sign change across a pole of κ jumps by far more than the grid's step
    roots = [i for i in range(len(grid) - 1) if np.isfinite(values[i]) and np.isfinite(values[i + 1])
             and values[i] * values[i + 1] < 0 and abs(values[i + 1] - values[i]) < jump_limit]
    if not roots:
        raise ValueError(f"the cap's compliance and the tube's resonance have no common root within +-50 % of "
                         f"{f_rigid:.0f} Hz (a cap mode near the tube's: two resonances compete)")
    i = min(roots, key=lambda j: abs(grid[j] - f_rigid))
    f = brentq(h, grid[i], grid[i + 1], xtol=1e-9, rtol=1e-13)
    return f, compliance_length_mm(td, cap_compliance_mm3_pa(td, f, shear_modulus_pa))
