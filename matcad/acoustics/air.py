"""Properties of air."""

import numpy as np

GAMMA = 1.4
"""Ratio of specific heats of dry air."""
STANDARD_PRESSURE_PA = 101_325.0
BULK_MODULUS_PA = GAMMA * STANDARD_PRESSURE_PA
"""Adiabatic bulk modulus ρc² = γ P0 (Pa) at standard pressure; independent of temperature."""


def speed_of_sound_m_s(temperature_c):
    """Speed of sound in dry air, c = 331.3·sqrt(1 + T/273.15) (m/s), T in °C (docs/physics.md; ideal gas).

    343.2 m/s at 20 °C; +0.17 %/°C near room temperature.
    """
    return 331.3 * np.sqrt(1.0 + np.asarray(temperature_c, dtype=float) / 273.15)

KINEMATIC_VISCOSITY_M2_S = 1.5e-5
"""Air at 20 °C."""
PRANDTL = 0.71


VISCOUS_REGIME_EPS = 0.3
"""Beyond this ε the boundary layers fill a good part of the neck: the wide-tube result no longer holds."""


def boundary_layer_shift(frequency_hz, neck_radius_mm):
    """Relative drop of the phase speed in a tube of radius a from viscous and thermal boundary layers,
    ε = sqrt(ν/ω)/(a·√2)·(1 + (γ − 1)/√Pr) (Kirchhoff 1868; Pierce, Acoustics, 1989, §10-4); wide-tube limit
    (boundary layer ≪ a). Applied to the neck, where the air moves, it estimates how much lower a real taxel
    sings than the lossless models: ~2 % on the paper's 2.1 mm neck at 5 kHz (docs/physics.md), more on smaller ones.
    """
    omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
    a_m = np.asarray(neck_radius_mm, dtype=float) / 1e3
    return np.sqrt(KINEMATIC_VISCOSITY_M2_S / omega) / (a_m * np.sqrt(2.0)) * (1 + (GAMMA - 1) / np.sqrt(PRANDTL))


def wavenumber_ratio(frequency_hz, radius_mm):
    """k/k₀ of plane waves in a rigid circular tube of radius a (mm) at ``frequency_hz`` (Hz) with its viscous and
    thermal boundary layers (complex, e^{iωt}: the real part the phase speed's fall c/c_φ, the imaginary part, < 0,
    the attenuation per radian): the low-reduced-frequency solution of Zwikker & Kosten (Sound Absorbing Materials,
    1949; Tijdeman 1975, J. Sound Vib. 39:1; Keefe 1984, J. Acoust. Soc. Am. 75:58),
    k/k₀ = √((1 + (γ − 1) F(r_t)) / (1 − F(r_v))), F(r) = 2 J₁(r√−i) / (r√−i J₀(r√−i)), r_v = a √(ω/ν), r_t = r_v √Pr.
    Exact for any r_v (a bore of any width against its boundary layer); tends to 1 + (1 − i) ε, ε of
    :func:`boundary_layer_shift`, as r_v → ∞. Pure scipy (Bessel functions, exponentially scaled: no overflow)."""
    from scipy.special import jve

    omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
    r_v = np.asarray(radius_mm, dtype=float) / 1e3 * np.sqrt(omega / KINEMATIC_VISCOSITY_M2_S)

    def f(r):
        z = r * np.sqrt(-1j)
        return 2 * jve(1, z) / (z * jve(0, z))

    return np.sqrt((1 + (GAMMA - 1) * f(r_v * np.sqrt(PRANDTL))) / (1 - f(r_v)))


def boundary_layer_drop(frequency_hz, neck_radius_mm) -> float:
    """Relative frequency drop from boundary layers, ε/(1 + ε) with ε from :func:`boundary_layer_shift`
    (the phase speed falls to c/(1 + ε)); bounded below 1 however thin the neck."""
    eps = float(boundary_layer_shift(frequency_hz, neck_radius_mm))
    return eps / (1.0 + eps)
