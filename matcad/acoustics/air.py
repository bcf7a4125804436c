"""Properties of air."""

import numpy as np

GAMMA = 1.4
"""Ratio of specific heats of dry air."""
STANDARD_PRESSURE_PA = 101_325.0
BULK_MODULUS_PA = GAMMA * STANDARD_PRESSURE_PA
"""Adiabatic bulk modulus ρc² = γ P0 (Pa) at standard pressure; independent of temperature."""


def speed_of_sound_m_s(temperature_c):
    """Speed of sound in dry air, c = 331.3·sqrt(1 + T/273.15) (m/s), T in °C (DIGEST; ideal gas).

    343.2 m/s at 20 °C; +0.17 %/°C near room temperature.
    """
    return 331.3 * np.sqrt(1.0 + np.asarray(temperature_c, dtype=float) / 273.15)
