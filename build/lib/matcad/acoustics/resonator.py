"""A spec's as-built acoustic quantities and the cheap models evaluated on them (mm, mm², mm³, m/s, Hz).

Shared by :mod:`matcad.acoustics.predict` (the ladder) and :mod:`matcad.acoustics.uncertainty` (which re-evaluates
the chosen model on perturbed specs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matcad.acoustics import geometry, models
from matcad.acoustics.air import speed_of_sound_m_s


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

    @property
    def neck_air_ratio(self) -> float:
        return self.neck_area * self.neck_length / self.volume

    @property
    def diameter_ratio(self) -> float:
        return float(np.sqrt(self.neck_area / self.cavity_area))


def resonator(spec) -> Resonator:
    """Derive the as-built acoustic quantities of ``spec``."""
    cav, neck = spec.cavity, spec.neck
    c = float(spec.air.speed_of_sound or speed_of_sound_m_s(spec.air.temperature_c))
    volume = float(geometry.drafted_cavity_volume_mm3(cav.diameter, cav.length, spec.mold.draft_deg))
    cav_diameter = float(geometry.equivalent_diameter_mm(volume, cav.length))
    gap_radius = min(spec.plate.width, spec.plate.depth) / 2.0
    return Resonator(
        c_m_s=c, volume=volume, cavity_diameter=cav_diameter, cavity_length=cav.length,
        neck_area=float(geometry.neck_area_mm2(neck.diameter)),
        cavity_area=float(geometry.circle_area_mm2(cav_diameter)), neck_length=neck.length,
        outer_correction=float(models.mouth_end_correction_mm(neck.mouth, neck.diameter / 2, spec.spacer.height,
                                                               gap_radius)),
        inner_ingard=float(models.ingard_end_correction_mm(neck.diameter, cav_diameter)),
        inner_step=float(models.step_end_correction_mm(neck.diameter, cav_diameter)),
        cap_outer_diameter=spec.end_cap.outer_diameter)


def evaluate(res: Resonator, model: str, shear_modulus_pa=None):
    """f0 (Hz) of one cheap model; ``soft_wall`` takes the shear modulus (Pa, scalar or array)."""
    if model == "lumped":
        return models.lumped_hz(res.c_m_s, res.neck_area, res.volume, res.neck_length)
    if model == "end_corrected":
        return models.end_corrected_hz(res.c_m_s, res.neck_area, res.volume,
                                       res.neck_length + res.outer_correction + res.inner_ingard)
    n, extra = 1.0, 0.0
    if model == "soft_wall":
        n, extra = models.soft_wall_length_scale(shear_modulus_pa, res.cavity_diameter, res.cap_outer_diameter)
    elif model != "transmission_line":
        raise ValueError(f"model {model!r} invalid, must be one of {list(CHEAP_MODELS)}")
    return models.transmission_line_hz(res.c_m_s, res.neck_area, res.cavity_area,
                                       res.neck_length + res.outer_correction + res.inner_step,
                                       res.cavity_length, n, extra)


CHEAP_MODELS = ("lumped", "end_corrected", "transmission_line", "soft_wall")


def shear_moduli_pa(spec) -> tuple[float, float, float]:
    """(low, geometric mean, high) of the spec's shear-modulus range (Pa)."""
    g_lo, g_hi = (x * 1e6 for x in spec.wall.shear_modulus_mpa)
    return g_lo, float(np.sqrt(g_lo * g_hi)), g_hi
