"""Force from sound: a recording's frequency track through an Eq. 5 calibration, with 95 % intervals.

Each frame's frequency gives y = K/f² and F from the quadratic V0 − bF − aF² = y on the calibrated branch.
The interval combines the calibration's parameter covariance and its residual scatter by the delta method:
Var F = gᵀ Σ g + (∂F/∂y)² σ², with g = ∂F/∂(V0, b, a) = (1, −F, −F²) / (b + 2aF), ∂F/∂y = −1 / (b + 2aF).
Frequencies whose force falls outside the calibrated range give NaN with a reason, never an extrapolation.
Forces N, frequencies Hz.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from matcad.acoustics.load import LoadCalibration, force_at_frequency_n
from matcad.loop import LoopError
from matcad.loop.calibrate import t_quantile

RANGE_TOLERANCE = 0.02
"""Forces within 2 % of the calibrated span beyond its ends still count as inside it."""


@dataclass(frozen=True)
class SensorCalibration:
    """What sensing needs from a calibration (spec [calibration] with the fit's fields)."""

    v0_mm3: float
    b: float
    a: float
    k_mm3_hz2: float
    covariance: np.ndarray
    residual_std_mm3: float
    dof: int
    force_range_n: tuple[float, float]

    @classmethod
    def from_spec_calibration(cls, cal) -> "SensorCalibration":
        missing = [k for k in ("k_mm3_hz2", "covariance", "residual_std_mm3", "dof", "force_range_n")
                   if getattr(cal, k) is None]
        if missing:
            raise ValueError(f"calibration lacks {', '.join(missing)}: sensing needs a calibration written by "
                             "`matcad calibrate`")
        return cls(cal.v0_mm3, cal.b, cal.a, cal.k_mm3_hz2, np.array(cal.covariance).reshape(3, 3),
                   cal.residual_std_mm3, cal.dof, tuple(cal.force_range_n))

    def frequency_range_hz(self) -> tuple[float, float]:
        ends = [float(np.sqrt(self.k_mm3_hz2 / (self.v0_mm3 - self.b * f - self.a * f * f)))
                for f in self.force_range_n]
        return min(ends), max(ends)


@dataclass(frozen=True)
class Reading:
    force_n: float
    force_interval_n: tuple[float, float]
    frequency_hz: float
    frames_n: np.ndarray = field(repr=False)
    frames_interval_n: np.ndarray = field(repr=False)
    reason: str = ""

    def to_dict(self) -> dict:
        finite = lambda v: None if not np.isfinite(v) else float(v)  # noqa: E731
        return {"force_n": finite(self.force_n), "force_interval_n": [finite(v) for v in self.force_interval_n],
                "frequency_hz": self.frequency_hz, "reason": self.reason,
                "frames": int(len(self.frames_n)), "frames_in_range": int(np.sum(np.isfinite(self.frames_n)))}


def force_with_interval(cal: SensorCalibration, frequency_hz, level: float = 0.95):
    """(force, half-width of its ``level`` interval) (N) at each frequency; NaN outside the calibrated range."""
    f = np.asarray(frequency_hz, dtype=float)
    force = force_at_frequency_n(LoadCalibration(cal.v0_mm3, cal.a, cal.b, k_mm3_hz2=cal.k_mm3_hz2), f, 0.0, 1.0, 1.0)
    lo, hi = cal.force_range_n
    slack = RANGE_TOLERANCE * (hi - lo)
    force = np.where((force >= lo - slack) & (force <= hi + slack), force, np.nan)
    slope = cal.b + 2 * cal.a * force  # −∂y/∂F
    grad = np.stack([np.ones_like(force), -force, -force * force]) / slope
    var = np.einsum("i...,ij,j...->...", grad, cal.covariance, grad) + (cal.residual_std_mm3 / slope) ** 2
    return force, t_quantile(0.5 + level / 2, cal.dof) * np.sqrt(var)


def sense(track_hz: np.ndarray, cal: SensorCalibration) -> Reading:
    """Force per frame and overall (at the track's mean frequency), each with its 95 % interval."""
    frames, half = force_with_interval(cal, track_hz)
    mean_f = float(np.mean(track_hz))
    force, width = force_with_interval(cal, np.array([mean_f]))
    force, width = float(force[0]), float(width[0])
    reason = ""
    if not np.isfinite(force):
        f_lo, f_hi = cal.frequency_range_hz()
        reason = (f"{mean_f:.1f} Hz lies outside the calibrated {f_lo:.1f}-{f_hi:.1f} Hz "
                  f"({cal.force_range_n[0]:g}-{cal.force_range_n[1]:g} N): no extrapolation")
    return Reading(force, (force - width, force + width), mean_f, frames,
                   np.column_stack([frames - half, frames + half]), reason)


def require_in_range(reading: Reading) -> Reading:
    if not np.isfinite(reading.force_n):
        raise LoopError(reading.reason)
    return reading
