"""Volumes, areas and ratios of the resonator (lengths mm, areas mm², volumes mm³).

All functions accept floats or numpy arrays (broadcasting) and return the same.
"""

import numpy as np


def circle_area_mm2(diameter_mm):
    """Area of a circle of the given diameter: π d²/4 (mm²)."""
    return np.pi * np.square(diameter_mm) / 4.0


def cavity_volume_mm3(diameter_mm, length_mm):
    """Cylindrical cavity volume V_c = π (D/2)² L (mm³); the paper's taxel gives 37.805 mm³."""
    return circle_area_mm2(diameter_mm) * length_mm


def neck_area_mm2(neck_diameter_mm):
    """Neck cross-section A = π (d/2)² (mm²), paper Eq. 1; 3.4636 mm² for d = 2.10 mm."""
    return circle_area_mm2(neck_diameter_mm)


def neck_air_ratio(neck_diameter_mm, neck_length_mm, cavity_diameter_mm, cavity_length_mm):
    """Air volume in the neck over air volume in the cavity, A·l / V_c (dimensionless).

    The lumped model assumes the neck air is incompressible, which needs this ≪ 1 (0.58 for the paper's taxel).
    """
    return (neck_area_mm2(neck_diameter_mm) * neck_length_mm
            / cavity_volume_mm3(cavity_diameter_mm, cavity_length_mm))


def frustum_volume_mm3(base_diameter_mm, tip_diameter_mm, length_mm):
    """Truncated-cone volume π L (d0² + d0 d1 + d1²) / 12 (mm³)."""
    d0, d1 = base_diameter_mm, tip_diameter_mm
    return np.pi * length_mm * (d0 * d0 + d0 * d1 + d1 * d1) / 12.0


def drafted_tip_diameter_mm(diameter_mm, length_mm, draft_deg):
    """Cavity diameter at the closed end when a core pin of base diameter D has ``draft_deg`` per side (mm)."""
    return diameter_mm - 2.0 * length_mm * np.tan(np.radians(draft_deg))


def drafted_cavity_volume_mm3(diameter_mm, length_mm, draft_deg):
    """As-cast cavity volume with core-pin draft: a frustum from D (neck side) narrowing over L (mm³).

    1° of draft on the paper's taxel removes 5.1 % of the volume: +2.7 % in f by the lumped V^-1/2 law
    (docs/physics.md), +2.1 % by the transmission line.
    """
    tip = drafted_tip_diameter_mm(diameter_mm, length_mm, draft_deg)
    return frustum_volume_mm3(diameter_mm, tip, length_mm)


def equivalent_diameter_mm(volume_mm3, length_mm):
    """Diameter of the cylinder of the same volume and length (mm), for the 1-D models."""
    return np.sqrt(4.0 * volume_mm3 / (np.pi * length_mm))
