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


def diameter_ratio(neck_diameter_mm, cavity_diameter_mm):
    """ξ = d/D (dimensionless), paper nomenclature."""
    return np.divide(neck_diameter_mm, cavity_diameter_mm)


def neck_air_ratio(neck_diameter_mm, neck_length_mm, cavity_diameter_mm, cavity_length_mm):
    """Air volume in the neck over air volume in the cavity, A·l / V_c (dimensionless).

    The lumped model assumes the neck air is incompressible, which needs this ≪ 1 (0.58 for the paper's taxel).
    """
    return (neck_area_mm2(neck_diameter_mm) * neck_length_mm
            / cavity_volume_mm3(cavity_diameter_mm, cavity_length_mm))
