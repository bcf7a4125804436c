"""Force from sound: a recording's voiced frequency track through an Eq. 5 calibration, with 95 % intervals.

Each frame's frequency gives y = K/f² and F from the quadratic V0 − bF − aF² = y on the calibrated branch.
The interval combines, by the delta method, the calibration's parameter covariance Σ, its residual scatter σ²
and the between-cycle (hysteresis) variance τ² the calibration estimated from several load cycles (or assumed):
Var F = gᵀ Σ g + (σ² + τ²)/(b + 2aF)², with g = ∂F/∂(V0, b, a) = (1, −F, −F²) / (b + 2aF).

Temperature: f = c/(2π)·sqrt(A/(l V)) with c ∝ sqrt(T) (T in kelvin, ideal gas; matcad.acoustics.air), so a
frequency heard at T is the one the calibration would have heard at T_cal times sqrt(T_cal/T). When the air's
temperature now is not given, it may differ from the calibration's by a lab's day-to-day swing
(:data:`matcad.acoustics.uncertainty.TEMPERATURE_TOL_C`, ±3 °C, taken as uniform: sd 3/√3 °C); that term is
carried into every interval (:func:`force_interval`) and a warning says what it costs (issue 24: without it, 74 %
of 95 % intervals held the true force at ±3 °C).

Only voiced frames get a force; frequencies whose force falls outside the calibrated range give NaN with a
reason, never an extrapolation; flagged segments (mode jumps) get none. Forces N, frequencies Hz, °C.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from matcad.acoustics.eq5 import Eq5
from matcad.acoustics.uncertainty import TEMPERATURE_TOL_C
from matcad.errors import LoopError
from matcad.listening import CALIBRATED_MARGIN, listening_band
from matcad.loop.voicing import MIN_RUN_HARMONIC, longest_run


TEMPERATURE_SD_C = TEMPERATURE_TOL_C / np.sqrt(3.0)
"""Standard deviation (°C) of the air's temperature now against the calibration's when it is not given: uniform
over ±TEMPERATURE_TOL_C."""


def force_interval(cal: Eq5, frequency_hz, temperature_c: float | None):
    """(forces, half-widths of their 95 % intervals, warning or '') (N) of frequencies heard (Hz): through
    :meth:`Eq5.force_with_interval` at ``temperature_c`` (°C) when given, else with the unknown temperature's
    :data:`TEMPERATURE_SD_C` in every interval and a warning naming its cost at mid-range."""
    if temperature_c is not None:
        force, half = cal.force_with_interval(frequency_hz, temperature_c=temperature_c)
        return force, half, ""
    force, half = cal.force_with_interval(frequency_hz, temperature_sd_c=TEMPERATURE_SD_C)
    mid = 0.5 * sum(cal.force_range_n)
    f_mid = cal.frequency_hz(mid)
    _, known = cal.force_with_interval([f_mid])
    _, unknown = cal.force_with_interval([f_mid], temperature_sd_c=TEMPERATURE_SD_C)
    at = "" if cal.temperature_c is None else f" {cal.temperature_c:g} degC"
    warning = (f"air temperature not given (--temperature-c): up to +-{TEMPERATURE_TOL_C:g} degC from the "
               f"calibration's{at} assumed, which widens each 95 % interval from +-{known[0]:.2f} to "
               f"+-{unknown[0]:.2f} N at {mid:g} N")
    return force, half, warning


def sensing_law(cal) -> Eq5:
    """The :class:`~matcad.acoustics.eq5.Eq5` that sensing reads forces through, from a spec's or a calibration
    file's [calibration] table; ValueError (exit 2) when the table lacks what only `matcad calibrate` writes."""
    from matcad.acoustics.design import eq5

    missing = [k for k in ("k_mm3_hz2", "covariance", "residual_std_mm3", "dof", "force_range_n")
               if getattr(cal, k) is None]
    if missing:
        raise ValueError(f"calibration lacks {', '.join(missing)}: sensing needs a calibration written by "
                         "`matcad calibrate`")
    return eq5(cal)


@dataclass(frozen=True)
class Reading:
    """Overall force (at the voiced frames' mean frequency), per-frame forces (NaN where unvoiced or out of range)
    and per-segment forces, each with its 95 % interval (N)."""

    force_n: float
    force_interval_n: tuple[float, float]
    frequency_hz: float
    frames_n: np.ndarray = field(repr=False)
    frames_interval_n: np.ndarray = field(repr=False)
    segments_n: np.ndarray = field(repr=False)  # segments × (force, low, high)
    reason: str = ""
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        finite = lambda v: None if not np.isfinite(v) else float(v)  # noqa: E731
        return {"force_n": finite(self.force_n), "force_interval_n": [finite(v) for v in self.force_interval_n],
                "frequency_hz": self.frequency_hz, "reason": self.reason,
                "frames": int(len(self.frames_n)), "frames_with_force": int(np.sum(np.isfinite(self.frames_n))),
                "warnings": list(self.warnings)}

    def report_dict(self, analysis) -> dict:
        """report.json of ``sense`` (beside the recording and calibration names): :meth:`to_dict`, the
        :class:`matcad.loop.analysis.Analysis` this reading came from and the force per segment (N, null where
        none)."""
        return {**self.to_dict(), "analysis": analysis.to_dict(),
                "segment_forces_n": [[None if not np.isfinite(v) else float(v) for v in row]
                                     for row in self.segments_n]}

    def detail_dict(self, analysis) -> dict:
        """``sense --json``: :meth:`to_dict` with the analysis' tone fraction and warnings, and per segment and per
        frame the frequency (Hz) and force with its 95 % interval (N; null where none)."""
        frames = [{"time_s": float(t), "frequency_hz": float(f) if v else None,
                   "force_n": None if np.isnan(force) else float(force),
                   "force_interval_n": None if np.isnan(force) else [float(lo), float(hi)]}
                  for t, f, v, force, (lo, hi) in zip(analysis.times_s, analysis.track_hz, analysis.voiced,
                                                      self.frames_n, self.frames_interval_n)]
        segments = [{**seg.to_dict(), "force_n": None if not np.isfinite(f) else float(f),
                     "force_interval_n": None if not np.isfinite(f) else [float(lo), float(hi)]}
                    for seg, (f, lo, hi) in zip(analysis.segments, self.segments_n)]
        return {**self.to_dict(), "tone_fraction": analysis.tone_fraction,
                "warnings": list(analysis.warnings) + list(self.warnings), "segments": segments, "frames": frames}

    def to_text(self, source: str, analysis) -> str:
        """What ``sense`` prints for the recording named ``source``: the overall force (when in range), the segments
        with their forces, the warnings of the analysis and of the reading."""
        lines = []
        if np.isfinite(self.force_n):
            lo, hi = self.force_interval_n
            lines.append(f"{source}: F = {self.force_n:.3f} N (95 %: {lo:.3f} .. {hi:.3f} N) at "
                         f"{self.frequency_hz:.2f} Hz; {int(np.sum(np.isfinite(self.frames_n)))} of "
                         f"{len(self.frames_n)} frames with a force (tone in {100 * analysis.tone_fraction:.0f} %)")
        lines += analysis.segments_text(self.segments_n)
        lines += [f"  warning: {w}" for w in list(analysis.warnings) + list(self.warnings)]
        return "\n".join(lines)


IN_RANGE_SHARE = 0.5
"""The overall force needs at least this share of the voiced frames inside the calibrated range (issue 24: a
reverberant room's scattered peaks, sd 370 Hz, averaged to "4.47 N")."""
FRAMES_PER_READING = 3.0
"""Frames of a segment per independent reading of its frequency (the 50 % overlap and the ridge's smoothing
correlate neighbours): on the slow-press and 2 N press recordings of benchmarks/wrong_answers.py, segment means
scattered about the truth 1.5 times sd/sqrt(frames), i.e. one reading per ~2.3 frames; 3 is taken."""


def _mean_scatter_n(cal: Eq5, segments, seg_f, temperature_c) -> np.ndarray:
    """Half-width (N) of the 95 % interval that the scatter of each segment's mean frequency adds: 1.96 times
    its sd / sqrt(frames / FRAMES_PER_READING), through dF/df (issue 24: a calibration tighter than the track
    gave segment intervals of +-0.03 N that missed a steady force by the track's own 1 Hz)."""
    if len(seg_f) == 0:
        return np.zeros(0)
    up, _, _ = force_interval(cal, seg_f + 0.5, temperature_c)
    down, _, _ = force_interval(cal, seg_f - 0.5, temperature_c)
    sem = np.array([s.std_hz * np.sqrt(FRAMES_PER_READING / max(s.frames, 1)) for s in segments])
    return np.nan_to_num(1.96 * np.abs(up - down) * sem)


def refusal(analysis) -> str:
    """Why ``sense`` gives no force for an :class:`matcad.loop.analysis.Analysis` ('' when it does): the tracked line
    cannot be told to be the taxel's (:attr:`~matcad.loop.analysis.Analysis.unassigned`), or no voiced stretch
    lasts MIN_RUN_HARMONIC frames (a few frames in noise — a room's response peak, a talker's formant — are not
    evidence of a singing taxel; ``analyze`` warns, ``sense`` refuses: issue 24)."""
    if analysis.unassigned:
        return analysis.unassigned
    longest = longest_run(analysis.voiced)
    if longest < MIN_RUN_HARMONIC:
        return (f"no voiced stretch lasts {MIN_RUN_HARMONIC} frames (the longest: {longest}): too little evidence "
                "of a singing taxel for a force")
    return ""


def sense(analysis, cal: Eq5, temperature_c: float | None = None) -> Reading:
    """Forces of an :class:`matcad.loop.analysis.Analysis` through a calibration (:meth:`Eq5.force_with_interval`):
    per voiced frame, per segment and overall; none at all (NaN, with the reason) when :func:`refusal` says
    so."""
    refused = refusal(analysis)
    track = np.where(analysis.voiced & (not refused), analysis.track_hz, np.nan)
    frames, half, air = force_interval(cal, track, temperature_c)
    seg_f = np.array([s.mean_hz if not (s.flag or refused) else np.nan for s in analysis.segments])
    seg_force, seg_half, _ = force_interval(cal, seg_f, temperature_c)
    seg_half = np.hypot(seg_half, _mean_scatter_n(cal, analysis.segments, seg_f, temperature_c))
    segments = np.column_stack([seg_force, seg_force - seg_half, seg_force + seg_half]).reshape(-1, 3)
    mean_f = analysis.mean_hz
    force, width, _ = force_interval(cal, np.array([np.nan if refused else mean_f]), temperature_c)
    force, width = float(force[0]), float(width[0])
    reason = refused
    f_lo, f_hi = cal.frequency_range_hz()
    voiced, in_range = int(np.sum(analysis.voiced)), int(np.sum(np.isfinite(frames)))
    if not np.isfinite(force) and not refused:
        reason = (f"{mean_f:.1f} Hz lies outside the calibrated {f_lo:.1f}-{f_hi:.1f} Hz "
                  f"({cal.force_range_n[0]:g}-{cal.force_range_n[1]:g} N): no extrapolation")
    elif not refused and in_range < IN_RANGE_SHARE * voiced:
        force, width = np.nan, np.nan
        reason = (f"only {in_range} of {voiced} voiced frames lie in the calibrated {f_lo:.1f}-{f_hi:.1f} Hz: "
                  "their mean is no reading (a tone that wanders over the band is no taxel)")
    warnings = [air] if air else []
    steady = np.isfinite(segments[:, 0])
    if np.sum(steady) >= 2 and np.ptp(segments[steady, 0]) > np.max(segments[steady, 2] - segments[steady, 1]):
        warnings.append(f"the load changed during the recording ({np.sum(steady)} steady segments from "
                        f"{np.min(segments[steady, 0]):.2f} to {np.max(segments[steady, 0]):.2f} N): the overall "
                        "force is a time average; read the segments")
    return Reading(force, (force - width, force + width), mean_f, frames,
                   np.column_stack([frames - half, frames + half]), segments, reason, tuple(warnings))


def listening_band_hz(cal: Eq5) -> tuple[float, float]:
    """The band (Hz) ``sense`` listens in: the calibration's frequency range widened by
    :data:`matcad.listening.CALIBRATED_MARGIN`."""
    return listening_band(cal.frequency_range_hz(), CALIBRATED_MARGIN)


def require_in_range(reading: Reading) -> Reading:
    if not np.isfinite(reading.force_n):
        raise LoopError(reading.reason)
    return reading
