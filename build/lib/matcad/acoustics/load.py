"""Paper Eq. 5: frequency under a normal load F and its inverse. Lengths mm, volumes mm³, F in N, f in Hz.

    f(F) = c/(2π)·sqrt(A / (l·V_eff)),   V_eff = V0 − a·F² − b·F      (Eqs. 2–5)

Linear in disguise: K/f² = V0 − bF − aF² with K = c²A/(4π² l), so the inverse is a quadratic root.

The paper's published constants (V0 = 32.21 mm³, a = −0.0086, b = 0.4626) reproduce its measured band only
with A = d²/4 (π dropped); with the physical A = πd²/4 they give ~7.1 kHz. Each calibration therefore carries
its area convention, and the paper's is exposed as :data:`MAT_PAPER_2024` with ``area_convention = "d2/4"``,
never mixed silently with physical volumes.

Outside the fitted model's meaning — past the V_eff minimum at F = −b/(2a) (a < 0), or V_eff ≤ 0 — the
frequency is NaN and :func:`invalid_reason` says why; never an extrapolated number.
"""

from dataclasses import dataclass

import numpy as np

from matcad.acoustics.models import MM_PER_M

AREA_CONVENTIONS = ("pi_d2/4", "d2/4")


@dataclass(frozen=True)
class LoadCalibration:
    """Eq. 5 constants: v0_mm3 (mm³), a (mm³/N²), b (mm³/N) and the neck-area convention they were fit with."""

    v0_mm3: float
    a: float
    b: float
    area_convention: str = "pi_d2/4"
    name: str = "spec"
    k_mm3_hz2: float | None = None

    def __post_init__(self):
        if self.area_convention not in AREA_CONVENTIONS:
            raise ValueError(f"area_convention {self.area_convention!r} invalid, must be one of "
                             f"{AREA_CONVENTIONS}")


MAT_PAPER_2024 = LoadCalibration(v0_mm3=32.21, a=-0.0086, b=0.4626, area_convention="d2/4",
                                 name="mat-paper-2024")
"""The paper's fit (Fig. 9 and §VI), valid below ~26.9 N, with the paper's own A = d²/4 convention."""


def convention_area_mm2(neck_diameter_mm, area_convention):
    """Neck area under a calibration's convention: πd²/4 ('pi_d2/4') or d²/4 ('d2/4') (mm²)."""
    scale = {"pi_d2/4": np.pi / 4.0, "d2/4": 0.25}[area_convention]
    return scale * np.square(neck_diameter_mm)


def frequency_constant_mm3_hz2(cal, speed_of_sound_m_s, neck_diameter_mm, neck_length_mm):
    """K = c²A/(4π² l) in mm³·Hz², so that f² = K / V_eff; a calibration's own fitted K when it has one."""
    if cal.k_mm3_hz2 is not None:
        return cal.k_mm3_hz2
    c = np.asarray(speed_of_sound_m_s, dtype=float) * MM_PER_M
    return c * c * convention_area_mm2(neck_diameter_mm, cal.area_convention) / (4 * np.pi**2 * neck_length_mm)


def force_at_volume_minimum_n(cal):
    """Force where V_eff stops falling, −b/(2a) (N); +inf when a ≥ 0 (no minimum ahead)."""
    return -cal.b / (2.0 * cal.a) if cal.a < 0 else np.inf


def effective_volume_mm3(cal, force_n):
    """V_eff = V0 − aF² − bF (mm³), paper Eqs. 3–4."""
    f = np.asarray(force_n, dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        return cal.v0_mm3 - cal.a * f * f - cal.b * f


def invalid_reason(cal, force_n):
    """Why Eq. 5 has no meaning at this force (str), or '' when it does."""
    f_min = force_at_volume_minimum_n(cal)
    if not np.isfinite(force_n):
        return "force is not finite"
    if force_n > f_min:
        return (f"F = {force_n:g} N is past the V_eff minimum at {f_min:.3g} N, where the fitted model "
                "turns back (frequency would fall with force)")
    if effective_volume_mm3(cal, force_n) <= 0:
        return f"V_eff = {float(effective_volume_mm3(cal, force_n)):.4g} mm^3 <= 0 at F = {force_n:g} N"
    return ""


def frequency_at_force_hz(cal, force_n, speed_of_sound_m_s, neck_diameter_mm, neck_length_mm):
    """Eq. 5: f(F) (Hz), NaN where :func:`invalid_reason` is not empty. Vectorised over ``force_n``."""
    f = np.asarray(force_n, dtype=float)
    v = effective_volume_mm3(cal, f)
    ok = np.isfinite(f) & (f <= force_at_volume_minimum_n(cal)) & (v > 0)
    k = frequency_constant_mm3_hz2(cal, speed_of_sound_m_s, neck_diameter_mm, neck_length_mm)
    return np.where(ok, np.sqrt(k / np.where(ok, v, 1.0)), np.nan)


def force_at_frequency_n(cal, frequency_hz, speed_of_sound_m_s, neck_diameter_mm, neck_length_mm):
    """Inverse of Eq. 5: the force F (N) at which the taxel sings at ``frequency_hz``. Vectorised.

    Solves aF² + bF + C = 0 with C = K/f² − V0 on the branch below the V_eff minimum. For b > 0 it uses the
    cancellation-free form F = −2C / (b + sqrt(b² − 4aC)), which tends to the linear root −C/b as a → 0.
    NaN where no valid force gives that frequency.
    """
    f = np.asarray(frequency_hz, dtype=float)
    k = frequency_constant_mm3_hz2(cal, speed_of_sound_m_s, neck_diameter_mm, neck_length_mm)
    a, b = cal.a, cal.b
    with np.errstate(divide="ignore", invalid="ignore"):
        c = k / (f * f) - cal.v0_mm3
        disc = b * b - 4.0 * a * c
        s = np.sqrt(disc)
        if b > 0:
            force = -2.0 * c / (b + s)
        elif a != 0:
            force = (-b + s) / (2.0 * a)
        elif b != 0:
            force = -c / b
        else:
            force = np.full_like(c, np.nan)
    ok = (f > 0) & np.isfinite(force) & (disc >= 0) & (force <= force_at_volume_minimum_n(cal))
    return np.where(ok, force, np.nan)
