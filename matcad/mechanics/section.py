"""The end cap's axisymmetric cross-section as matcad builds it (:mod:`matcad.parts.end_cap`), and volumes of
revolved outlines. Pure numpy; lengths mm, volumes mm³. Frame: (r, z), base on the plate at z = 0, axis r = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CapSection:
    """Radii and heights of the cap (mm): drafted cavity from ``cavity_radius`` at z = 0 to ``cavity_tip_radius``
    at z = ``cavity_length``; body of radius ``outer_radius`` up to ``height``; base flange out to
    ``flange_radius``, ``flange_thickness`` thick (clamped by the guide)."""

    cavity_radius: float
    cavity_tip_radius: float
    cavity_length: float
    outer_radius: float
    height: float
    flange_radius: float
    flange_thickness: float

    @property
    def top_thickness(self) -> float:
        return self.height - self.cavity_length

    def cavity_wall_radius(self, z):
        """Undeformed cavity radius at height z (mm), linear in z (core-pin draft)."""
        return self.cavity_radius + (self.cavity_tip_radius - self.cavity_radius) * np.asarray(z) / self.cavity_length


def section_from_spec(spec) -> CapSection:
    """The cap of ``spec`` (mm): the dimension functions :mod:`matcad.parts.end_cap` builds the solid from (the
    drafted tip through :func:`matcad.acoustics.geometry.drafted_tip_diameter_mm`, without the CAD kernel)."""
    from matcad.acoustics.geometry import drafted_tip_diameter_mm
    from matcad.spec import cap_flange_diameter_mm, cap_flange_thickness_mm, cap_height_mm

    tip = float(drafted_tip_diameter_mm(spec.cavity.diameter, spec.cavity.length, spec.mold.draft_deg)) / 2
    return CapSection(cavity_radius=spec.cavity.diameter / 2, cavity_tip_radius=tip,
                      cavity_length=spec.cavity.length, outer_radius=spec.end_cap.outer_diameter / 2,
                      height=cap_height_mm(spec), flange_radius=cap_flange_diameter_mm(spec) / 2,
                      flange_thickness=min(cap_flange_thickness_mm(spec), cap_height_mm(spec)))


def revolved_volume_mm3(outline_rz) -> float:
    """Volume (mm³) swept by revolving a closed polygon (r ≥ 0, mm) about the z axis, by Pappus' theorem:
    V = (π/3)·|Σ (r_i² + r_i r_{i+1} + r_{i+1}²)(z_{i+1} − z_i)| over the closed loop (exact for straight edges)."""
    p = np.asarray(outline_rz, dtype=float)
    r, z = p[:, 0], p[:, 1]
    r1, z1 = np.roll(r, -1), np.roll(z, -1)
    return float(abs(np.sum((r * r + r * r1 + r1 * r1) * (z1 - z))) * math.pi / 3)


def cavity_volume_mm3(outline_rz) -> float:
    """Cavity volume (mm³) bounded by the plate (z = 0), the axis and a cavity outline running from the wall's
    foot on the plate to the axis (mm)."""
    p = np.asarray(outline_rz, dtype=float)
    if len(p) == 0:
        return 0.0
    closed = np.vstack([p, [[0.0, 0.0]]]) if p[-1, 0] == 0.0 else np.vstack([p, [[0.0, p[-1, 1]], [0.0, 0.0]]])
    return revolved_volume_mm3(closed)
