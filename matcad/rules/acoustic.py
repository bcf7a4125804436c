"""Rules on the predicted sound: inside the microphone's band, above the floor, models valid."""

from __future__ import annotations

from matcad.rules.finding import Finding

NYQUIST_MARGIN = 0.45
"""Keep the band below 0.45 × sample rate: anti-alias filters roll off above ~0.45 fs."""


def band_too_high(band_high_hz, sample_rate_hz):
    """Where the band's top reaches :data:`NYQUIST_MARGIN` × the sample rate (Hz; floats or arrays)."""
    return band_high_hz >= NYQUIST_MARGIN * sample_rate_hz


def band_too_low(band_low_hz, floor_hz):
    """Where the band's bottom reaches the microphone's floor (Hz; floats or arrays)."""
    return band_low_hz <= floor_hz


def microphone_band(spec, p) -> list[Finding]:
    limit = NYQUIST_MARGIN * spec.microphone.sample_rate_hz
    out = []
    if band_too_high(p.band_hz[1], spec.microphone.sample_rate_hz):
        out.append(Finding("acoustic.band_high", "error", round(p.band_hz[1], 1), limit,
                           f"predicted band reaches {p.band_hz[1]:.0f} Hz, above 0.45 x "
                           f"{spec.microphone.sample_rate_hz:g} Hz: the microphone cannot hear it",
                           "enlarge the cavity or lengthen the neck, or record at a higher sample rate"))
    if band_too_low(p.band_hz[0], spec.microphone.floor_hz):
        out.append(Finding("acoustic.band_low", "warning", round(p.band_hz[0], 1), spec.microphone.floor_hz,
                           f"predicted band starts at {p.band_hz[0]:.0f} Hz, at or below the "
                           f"{spec.microphone.floor_hz:g} Hz floor (room noise, hum)",
                           "shrink the cavity or widen the neck"))
    return out


def model_validity(spec, p) -> list[Finding]:
    out = [Finding("acoustic.model_validity", "warning", p.model, "validity checks", w,
                   "treat the band as indicative; calibrate with `matcad calibrate` after casting")
           for w in p.warnings if w.startswith(p.model)]
    out.append(Finding("acoustic.prediction", "info", round(p.f0_hz, 1), [round(b, 1) for b in p.band_hz],
                       f"f0 = {p.f0_hz:.0f} Hz ({p.model}), band {p.band_hz[0]:.0f}-{p.band_hz[1]:.0f} Hz; "
                       f"A*l/V = {p.neck_air_ratio:.2f}, xi = {p.diameter_ratio:.2f}", ""))
    return out


RULES = (microphone_band, model_validity)


def array_counts(sample_rate_hz, floor_hz, band_low_hz, band_high_hz, model_warnings) -> dict:
    """What :data:`RULES` find on arrays of predictions: {(rule id, level): count per variant} of the findings at
    error and warning level, in the order the rules list them (``model_warnings``: each variant's count of its
    prediction's warnings, which :func:`model_validity` turns into one finding each). Hz."""
    import numpy as np

    return {("acoustic.band_high", "error"): np.asarray(band_too_high(band_high_hz, sample_rate_hz), dtype=int),
            ("acoustic.band_low", "warning"): np.asarray(band_too_low(band_low_hz, floor_hz), dtype=int),
            ("acoustic.model_validity", "warning"): np.asarray(model_warnings, dtype=int)}
