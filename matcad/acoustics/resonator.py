"""A design's as-built acoustic quantities and the closed-form models evaluated on them (mm, mm², mm³, m/s, Hz).

:func:`resonator` turns a :class:`matcad.acoustics.design.Design` into the quantities every model reads (the
drafted cavity as its equal-volume cylinder, areas, end corrections, the cap around it); the ``*_hz`` functions are
the closed-form rungs the registry (:mod:`matcad.acoustics.registry`) names. Each takes the resonator, the wall's
shear modulus (Pa) and loss factor, and works on floats or on numpy arrays of a sweep's variants (the wall models
also on arrays of moduli and loss factors for one design: the uncertainty budget's samples).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields

import numpy as np

from matcad.acoustics import geometry, models, wall
from matcad.acoustics.design import Design, speed_of_sound


@dataclass(frozen=True)
class Resonator:
    """The as-built acoustic quantities of a design (mm, mm², mm³, m/s, kg/m³): drafted cavity as its equal-volume
    cylinder, neck, end corrections, the cap around the cavity, air joined to the cavity. ``neck_area`` is the area
    of the cylinder with the neck's inertance (a tapered neck's ends' geometric mean) and the corrections are
    lengths of that cylinder; ``neck_mouth_radius`` and ``neck_inner_radius`` are the neck's own end radii."""

    c_m_s: float
    volume: float
    cavity_diameter: float
    cavity_length: float
    neck_area: float
    cavity_area: float
    neck_length: float
    outer_correction: float
    inner_ingard: float
    inner_step: float
    neck_mouth_radius: float
    neck_inner_radius: float
    cap_outer_diameter: float
    cap_top_thickness: float
    cap_clamp_height: float
    silicone_density: float
    side_volume: float = 0.0

    @property
    def neck_air_ratio(self) -> float:
        return self.neck_area * self.neck_length / self.volume

    @property
    def diameter_ratio(self) -> float:
        return float(np.sqrt(self.neck_area / self.cavity_area))


def as_built(c_m_s, cavity_diameter, cavity_length, neck_diameter, neck_length, draft_deg, mouth, gap_mm,
             gap_radius_mm, neck_taper_mm=0.0, side_volume_mm3=0.0) -> Resonator:
    """The acoustic quantities of as-built geometry (mm, m/s), broadcast over numpy arrays (a sweep's variants):
    the drafted cavity as its equal-volume cylinder, the neck and its end corrections, air joined to the cavity.
    A tapered neck (``neck_taper_mm`` = mouth minus cavity-side diameter, ``neck_diameter`` their mean) has the
    inertance of a cylinder of the ends' geometric-mean diameter (∫dx/A(x) = l/(π r₁ r₂) for a cone); each end
    correction is that of the end it sits at, as a length of that cylinder (δ·A/A_end: the same inertance ρδ/A_end).
    The cap fields are NaN; :func:`resonator` fills them from a design."""
    volume = geometry.drafted_cavity_volume_mm3(cavity_diameter, cavity_length, draft_deg)
    cav_diameter = geometry.equivalent_diameter_mm(volume, cavity_length)
    mouth_d, inner_d = neck_diameter + neck_taper_mm / 2, neck_diameter - neck_taper_mm / 2
    uniform = np.asarray(neck_taper_mm) == 0
    inertance_d = np.where(uniform, neck_diameter, np.sqrt(np.abs(mouth_d * inner_d)))
    to_mouth, to_inner = (np.where(uniform, 1.0, (inertance_d / end) ** 2) for end in (mouth_d, inner_d))
    nan = float("nan")
    return Resonator(
        c_m_s=c_m_s, volume=volume, cavity_diameter=cav_diameter, cavity_length=cavity_length,
        neck_area=geometry.neck_area_mm2(inertance_d), cavity_area=geometry.circle_area_mm2(cav_diameter),
        neck_length=neck_length,
        outer_correction=models.mouth_end_correction_mm(mouth, mouth_d / 2, gap_mm, gap_radius_mm) * to_mouth,
        inner_ingard=models.ingard_end_correction_mm(inner_d, cav_diameter) * to_inner,
        inner_step=models.step_end_correction_mm(inner_d, cav_diameter) * to_inner,
        neck_mouth_radius=mouth_d / 2, neck_inner_radius=inner_d / 2,
        cap_outer_diameter=nan, cap_top_thickness=nan, cap_clamp_height=nan, silicone_density=nan,
        side_volume=side_volume_mm3)


def resonator(d: Design) -> Resonator:
    """The as-built acoustic quantities of a :class:`~matcad.acoustics.design.Design` (:func:`as_built` plus the
    cap): floats for a design of scalars, arrays for a design of arrays (a sweep's variants)."""
    res = as_built(speed_of_sound(d.air), d.cavity_diameter, d.cavity_length, d.neck_diameter, d.neck_length,
                   d.draft_deg, d.mouth, d.gap_mm, d.gap_radius_mm, d.neck_taper_mm, d.side_volume_mm3)
    cap = dict(cap_outer_diameter=d.cap_outer_diameter, cap_top_thickness=d.cap_top_thickness,
               cap_clamp_height=d.cap_clamp_height, silicone_density=d.wall.density_kg_m3)
    if np.ndim(d.cavity_diameter) == 0:
        return Resonator(**({f.name: float(getattr(res, f.name)) for f in fields(Resonator)} | cap))
    return dataclasses.replace(res, **cap)


def cap_shape(res: Resonator) -> wall.CapShape:
    """The silicone cap around the as-built cavity (its equal-volume cylinder), mm."""
    return wall.CapShape(cavity_radius=res.cavity_diameter / 2, cavity_length=res.cavity_length,
                         outer_radius=res.cap_outer_diameter / 2, top_thickness=res.cap_top_thickness,
                         clamp_height=res.cap_clamp_height)


def wall_modes(res: Resonator, shear_modulus_pa) -> wall.Modes:
    """The cap's wall modes at the given (dynamic) shear modulus, Pa (arrays of designs or of moduli too)."""
    return wall.modes(cap_shape(res), shear_modulus_pa, res.silicone_density)


def lumped_hz(res: Resonator, shear_modulus_pa=None, loss_factor: float = 0.0):
    """Paper Eq. 1 with c_f = 0 on the as-built resonator, air joined to the cavity included (Hz); the wall
    arguments are unused."""
    return models.lumped_hz(res.c_m_s, res.neck_area, res.volume + res.side_volume, res.neck_length)


def end_corrected_hz(res: Resonator, shear_modulus_pa=None, loss_factor: float = 0.0):
    """Eq. 1 with the mouth's outer and Ingard's inner end correction (Hz)."""
    return models.end_corrected_hz(res.c_m_s, res.neck_area, res.volume + res.side_volume,
                                   res.neck_length + res.outer_correction + res.inner_ingard)


def _step_neck_length_mm(res: Resonator) -> float:
    """Neck length with the outer and the step (Kergomard & Garcia 1987) inner correction (mm)."""
    return res.neck_length + res.outer_correction + res.inner_step


def _cone(res: Resonator):
    """A tapered neck as the cone its end corrections extend (Resonator radii at the effective ends, mm), for
    :func:`matcad.acoustics.models.transmission_line_hz`; None for a straight neck (every variant straight).
    Each correction, a length of the geometric-mean cylinder, is a length (A_end/A)× of its own end's cylinder."""
    if not np.any(res.neck_mouth_radius != res.neck_inner_radius):
        return None
    r_m, r_i, l = res.neck_mouth_radius, res.neck_inner_radius, res.neck_length
    slope = (r_i - r_m) / l
    own = res.neck_area / np.pi
    return r_m - slope * res.outer_correction * r_m**2 / own, r_i + slope * res.inner_step * r_i**2 / own


def transmission_line_hz(res: Resonator, shear_modulus_pa=None, loss_factor: float = 0.0):
    """Selamet et al. 1997 transmission line with rigid walls, a tapered neck as a cone (Hz)."""
    return models.transmission_line_hz(res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
                                       res.cavity_length, 1.0, 0.0, res.side_volume, _cone(res))


def soft_wall_hz(res: Resonator, shear_modulus_pa, loss_factor: float = 0.0):
    """The transmission line with a quasi-static silicone wall at shear modulus ``shear_modulus_pa`` (Pa, scalar
    or array) (Hz)."""
    n, extra = models.soft_wall_length_scale(shear_modulus_pa, res.cavity_diameter, res.cap_outer_diameter)
    return models.transmission_line_hz(res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
                                       res.cavity_length, n, extra, res.side_volume, _cone(res))


@dataclass(frozen=True)
class Branch:
    """Where a design's elastic-wall f0 was found (Hz, floats or arrays of designs): ``f0_hz``, and ``rigid_hz`` the
    rigid network's peak its ratio divides by (:func:`elastic_wall_branch`; None for a model with no peak to follow).
    A design moved a little from it follows both peaks from there (:func:`elastic_wall_hz`'s ``near``) instead of
    searching for them."""

    f0_hz: np.ndarray
    rigid_hz: np.ndarray | None


def elastic_wall_hz(res: Resonator, shear_modulus_pa, loss_factor=0.0, near: Branch | None = None):
    """The transmission line coupled to the cap's wall modes at the (dynamic) shear modulus (Pa) and loss factor:
    peak of the driven response (Hz). Arrays of designs, or one design at arrays of moduli and loss factors, give
    arrays, each entry the same arithmetic as one call (:func:`matcad.acoustics.wall.peak_ratio`). ``near`` (the
    branch of a design this one was moved a little from) follows that design's peaks instead of searching."""
    f_tl, network = _wall_network(res, shear_modulus_pa, loss_factor)
    follow = {} if near is None else {"near": np.asarray(near.f0_hz, dtype=float) / f_tl,
                                      "near_rigid": np.asarray(near.rigid_hz, dtype=float) / f_tl}
    return f_tl * wall.peak_ratio(*network, **follow)


def elastic_wall_branch(res: Resonator, shear_modulus_pa, loss_factor=0.0) -> Branch:
    """:func:`elastic_wall_hz` and the rigid network's peak it divides by (Hz), from the one search of each: what a
    design moved a little from this one follows (its ``near``)."""
    f_tl, network = _wall_network(res, shear_modulus_pa, loss_factor)
    ratio, rigid = wall.peak_ratios(*network)
    return Branch(f_tl * ratio, f_tl * rigid)


def _wall_network(res: Resonator, shear_modulus_pa, loss_factor) -> tuple:
    """(f_TL (Hz), the arguments of :func:`matcad.acoustics.wall.peak_ratio` for ``res`` with its wall)."""
    f_tl = transmission_line_hz(res)
    return f_tl, (f_tl, res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res), res.cavity_length,
                  wall_modes(res, shear_modulus_pa), loss_factor, res.side_volume)


def elastic_wall_doublet_hz(res: Resonator, shear_modulus_pa, loss_factor: float = 0.0) -> float | None:
    """The other resonance of a doublet of :func:`elastic_wall_hz` (Hz; :func:`matcad.acoustics.wall.doublet_hz`),
    or None when one peak clearly wins (one design, scalar moduli)."""
    f_tl = transmission_line_hz(res)
    return wall.doublet_hz(float(f_tl), res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
                           res.cavity_length, wall_modes(res, shear_modulus_pa), loss_factor, res.side_volume)
