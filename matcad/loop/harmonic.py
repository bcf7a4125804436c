"""Is a harmonic sound (a voice, mains buzz, music) present in a frame? Judged below the taxel's band.

A voice's pitch (80–400 Hz) glides and jitters, so its harmonics in a taxel's band (the 20th–60th) are smeared
over hundreds of Hz in a 93 ms frame and cannot be recognised as a comb there; together with the room's fixed
response peaks they leave short, steady-looking lines that pass a tone detector (benchmarks/analyze.py, speech
and reverberant-noise rows). Its low harmonics (150 Hz–2.5 kHz) stay resolved: the excess spectrum there is
periodic in frequency with the pitch as period. This module measures that periodicity per frame — the largest
normalised autocorrelation of the excess spectrum (dB over :func:`matcad.loop.spectrum.noise_floor`, clipped to
0–30 dB) at frequency lags of 80–400 Hz, the cepstral idea of Noll (1967) in its autocorrelation form — and calls
the frame harmonic when it reaches :data:`THRESHOLD`. Measured per frame (the synth cases of benchmarks/analyze.py,
10 s, 3 seeds, 642 frames each): a taxel alone, with presses, taps, gaps or a neighbouring taxel, white, brown and
reverberant room noise: median 0.15, 99th percentile 0.27–0.28, largest 0.34; synthetic speech median 0.47, 0.79 at
90 %, 64 % of frames ≥ 0.35 (the rest are its syllable gaps); 60 Hz buzz median 0.70, every frame.

A taxel sings far above 2.5 kHz, so it does not trigger this. When the analysis band starts below
:data:`MIN_BAND_LOW_HZ` the detector has no room below it and reports nothing (the voicing then works as
without it). Frequencies Hz.
"""

from __future__ import annotations

import numpy as np

from matcad.loop.spectrum import noise_floor

LOW_HZ = 150.0
HIGH_HZ = 2500.0
"""The detector's band: above mains fundamentals, below every taxel (4–6 kHz) with room to spare."""
BELOW_BAND = 0.8
"""The detector's band ends at this fraction of the analysis band's low edge when that is lower than HIGH_HZ."""
SPACING_HZ = (80.0, 400.0)
"""Pitch range searched (voices; 120 Hz mains buzz lies inside it as well)."""
MIN_SPAN_PERIODS = 3
"""The detector's band must span this many of the longest spacing, else it is off."""
THRESHOLD = 0.35
CLIP_DB = 30.0


def detector_band(analysis_low_hz: float) -> tuple[float, float] | None:
    """(low, high) Hz of the detector for an analysis band starting at ``analysis_low_hz``, or None when there is
    no room below it (the span would hold fewer than MIN_SPAN_PERIODS of the longest pitch period)."""
    high = min(HIGH_HZ, BELOW_BAND * analysis_low_hz)
    return (LOW_HZ, high) if high - LOW_HZ >= MIN_SPAN_PERIODS * SPACING_HZ[1] else None


def periodicity(power: np.ndarray, freqs: np.ndarray, band_hz: tuple[float, float]) -> np.ndarray:
    """Per frame (rows of ``power``, one-sided PSD at ``freqs`` Hz): the largest normalised autocorrelation of the
    excess spectrum inside ``band_hz`` at lags SPACING_HZ (0 for a frame without any excess)."""
    df = float(freqs[1] - freqs[0])
    sel = np.flatnonzero((freqs >= band_hz[0]) & (freqs <= band_hz[1]))
    tiny = np.finfo(float).tiny
    level = 10 * np.log10(power[:, sel] + tiny)
    excess = np.clip(level - 10 * np.log10(noise_floor(power[:, sel], power.max(axis=1)) + tiny), 0.0, CLIP_DB)
    excess -= excess.mean(axis=1, keepdims=True)
    n = excess.shape[1]
    spectrum = np.fft.rfft(excess, n=2 * n, axis=1)
    auto = np.fft.irfft(np.abs(spectrum) ** 2, n=2 * n, axis=1)
    lags = np.arange(int(np.ceil(SPACING_HZ[0] / df)), min(int(SPACING_HZ[1] / df), n - 1) + 1)
    energy = auto[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(energy > 0, auto[:, lags].max(axis=1) / energy, 0.0)


def harmonic_frames(power: np.ndarray, freqs: np.ndarray, analysis_low_hz: float) -> np.ndarray:
    """True per frame where a harmonic sound is present below an analysis band starting at ``analysis_low_hz``
    (Hz); all False when the detector has no room (:func:`detector_band`)."""
    band = detector_band(analysis_low_hz)
    if band is None or len(power) == 0:
        return np.zeros(len(power), dtype=bool)
    return periodicity(power, freqs, band) >= THRESHOLD
