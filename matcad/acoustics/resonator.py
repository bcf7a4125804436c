"""A spec's as-built acoustic quantities and the cheap models evaluated on them (mm, mm², mm³, m/s, Hz).

Shared by :mod:`matcad.acoustics.predict` (the ladder) and :mod:`matcad.acoustics.uncertainty` (which re-evaluates
the chosen model on perturbed specs).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from matcad.acoustics import geometry, models, registry, wall
from matcad.acoustics.air import speed_of_sound_m_s
from matcad.parts.features import cap_flange_thickness_mm


@dataclass(frozen=True)
class Resonator:
    """The as-built acoustic quantities of a spec (mm, mm², mm³, m/s): drafted cavity as its equal-volume
    cylinder, neck, end corrections."""

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
    cap_outer_diameter: float
    cap_top_thickness: float
    cap_clamp_height: float
    silicone_density: float

    @property
    def neck_air_ratio(self) -> float:
        return self.neck_area * self.neck_length / self.volume

    @property
    def diameter_ratio(self) -> float:
        return float(np.sqrt(self.neck_area / self.cavity_area))


def as_built(c_m_s, cavity_diameter, cavity_length, neck_diameter, neck_length, draft_deg, mouth, gap_mm,
             gap_radius_mm) -> Resonator:
    """The acoustic quantities of as-built geometry (mm, m/s), broadcast over numpy arrays (a sweep's variants):
    the drafted cavity as its equal-volume cylinder, the neck and its end corrections. The cap fields are NaN;
    :func:`resonator` fills them from a spec."""
    volume = geometry.drafted_cavity_volume_mm3(cavity_diameter, cavity_length, draft_deg)
    cav_diameter = geometry.equivalent_diameter_mm(volume, cavity_length)
    nan = float("nan")
    return Resonator(
        c_m_s=c_m_s, volume=volume, cavity_diameter=cav_diameter, cavity_length=cavity_length,
        neck_area=geometry.neck_area_mm2(neck_diameter), cavity_area=geometry.circle_area_mm2(cav_diameter),
        neck_length=neck_length,
        outer_correction=models.mouth_end_correction_mm(mouth, neck_diameter / 2, gap_mm, gap_radius_mm),
        inner_ingard=models.ingard_end_correction_mm(neck_diameter, cav_diameter),
        inner_step=models.step_end_correction_mm(neck_diameter, cav_diameter),
        cap_outer_diameter=nan, cap_top_thickness=nan, cap_clamp_height=nan, silicone_density=nan)


def resonator(spec) -> Resonator:
    """Derive the as-built acoustic quantities of ``spec`` (:func:`as_built` plus the cap, as floats)."""
    cav, neck = spec.cavity, spec.neck
    c = float(spec.air.speed_of_sound or speed_of_sound_m_s(spec.air.temperature_c))
    res = as_built(c, cav.diameter, cav.length, neck.diameter, neck.length, spec.mold.draft_deg, neck.mouth,
                   spec.spacer.height, min(spec.plate.width, spec.plate.depth) / 2.0)
    values = {f.name: float(getattr(res, f.name)) for f in fields(Resonator)}
    values.update(cap_outer_diameter=spec.end_cap.outer_diameter, cap_top_thickness=spec.end_cap.top_thickness,
                  cap_clamp_height=cap_flange_thickness_mm(spec), silicone_density=spec.silicone.density_g_cm3 * 1000.0)
    return Resonator(**values)


def cap_shape(res: Resonator) -> wall.CapShape:
    """The silicone cap around the as-built cavity (its equal-volume cylinder), mm."""
    return wall.CapShape(cavity_radius=res.cavity_diameter / 2, cavity_length=res.cavity_length,
                         outer_radius=res.cap_outer_diameter / 2, top_thickness=res.cap_top_thickness,
                         clamp_height=res.cap_clamp_height)


def wall_modes(res: Resonator, shear_modulus_pa: float) -> wall.Modes:
    """The cap's wall modes at the given (dynamic) shear modulus, Pa."""
    return wall.modes(cap_shape(res), shear_modulus_pa, res.silicone_density)


def lumped_hz(res: Resonator, shear_modulus_pa=None, loss_factor: float = 0.0):
    """Paper Eq. 1 with c_f = 0 on the as-built resonator (Hz); the wall arguments are unused."""
    return models.lumped_hz(res.c_m_s, res.neck_area, res.volume, res.neck_length)


def end_corrected_hz(res: Resonator, shear_modulus_pa=None, loss_factor: float = 0.0):
    """Eq. 1 with the mouth's outer and Ingard's inner end correction (Hz)."""
    return models.end_corrected_hz(res.c_m_s, res.neck_area, res.volume,
                                   res.neck_length + res.outer_correction + res.inner_ingard)


def _step_neck_length_mm(res: Resonator) -> float:
    """Neck length with the outer and the step (Kergomard & Garcia 1987) inner correction (mm)."""
    return res.neck_length + res.outer_correction + res.inner_step


def transmission_line_hz(res: Resonator, shear_modulus_pa=None, loss_factor: float = 0.0):
    """Selamet et al. 1997 transmission line with rigid walls (Hz)."""
    return models.transmission_line_hz(res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
                                       res.cavity_length, 1.0, 0.0)


def soft_wall_hz(res: Resonator, shear_modulus_pa, loss_factor: float = 0.0):
    """The transmission line with a quasi-static silicone wall at shear modulus ``shear_modulus_pa`` (Pa, scalar
    or array) (Hz)."""
    n, extra = models.soft_wall_length_scale(shear_modulus_pa, res.cavity_diameter, res.cap_outer_diameter)
    return models.transmission_line_hz(res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
                                       res.cavity_length, n, extra)


def elastic_wall_hz(res: Resonator, shear_modulus_pa, loss_factor: float = 0.0):
    """The transmission line coupled to the cap's wall modes at the (dynamic) shear modulus (Pa, scalar) and
    loss factor: peak of the driven response (Hz)."""
    f_tl = transmission_line_hz(res)
    return f_tl * wall.peak_ratio(float(f_tl), res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
                                  res.cavity_length, wall_modes(res, shear_modulus_pa), loss_factor)


def evaluate(res: Resonator, model: str, shear_modulus_pa=None, loss_factor: float = 0.0):
    """f0 (Hz) of one cheap model of :mod:`matcad.acoustics.registry`; ``soft_wall`` takes the shear modulus
    (Pa, scalar or array), ``elastic_wall`` the (dynamic) shear modulus (Pa, scalar) and the loss factor."""
    if model not in CHEAP_MODELS:
        raise ValueError(f"model {model!r} invalid, must be one of {list(CHEAP_MODELS)}")
    return registry.model(model).function()(res, shear_modulus_pa, loss_factor)


CHEAP_MODELS = registry.cheap_models()


def shear_moduli_pa(spec) -> tuple[float, float, float]:
    """(low, geometric mean, high) of the spec's static shear-modulus range (Pa)."""
    g_lo, g_hi = (x * 1e6 for x in spec.wall.shear_modulus_mpa)
    return g_lo, float(np.sqrt(g_lo * g_hi)), g_hi


def dynamic_moduli_pa(spec) -> tuple[float, float, float]:
    """(low, geometric mean, high) storage shear modulus at kHz (Pa): the static range times the kHz factor."""
    f_lo, f_hi = spec.wall.khz_modulus_factor
    g_lo, _, g_hi = shear_moduli_pa(spec)
    lo, hi = g_lo * f_lo, g_hi * f_hi
    return lo, float(np.sqrt(lo * hi)), hi


def loss_factors(spec) -> tuple[float, float, float]:
    """(low, mean, high) of the spec's loss-factor range."""
    lo, hi = spec.wall.loss_factor
    return lo, 0.5 * (lo + hi), hi


def wall_arguments(spec, model: str) -> tuple:
    """The (modulus, loss) arguments of :func:`evaluate` at the middle of the spec's ranges for a wall model."""
    if model == "elastic_wall":
        return dynamic_moduli_pa(spec)[1], loss_factors(spec)[1]
    if model == "soft_wall":
        return shear_moduli_pa(spec)[1], 0.0
    return None, 0.0
