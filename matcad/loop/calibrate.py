"""Fit paper Eq. 5 to force/frequency pairs, with uncertainty. Forces N, frequencies Hz, volumes mm³.

Eq. 5 is linear in disguise: y = K/f² = V0 − b·F − a·F² with K = c²A/(4π²l) from the as-built geometry
(physical area πd²/4). Least squares in (V0, b, a) is closed-form; because the noise is in f, y's scatter
grows as f⁻³ and the fit weights each point by (f/f̄)⁶; the parameter covariance is σ²(XᵀWX)⁻¹ with
σ² = weighted RSS/(n − 3); intervals use Student's t. Because f = sqrt(K/y) is monotone in y, the
confidence and prediction bands in y map straight onto bands in f.

``k_free``: fix V0 to the as-built cavity volume and fit K instead (1/f² = V0/K − (b/K)F − (a/K)F²), so that K
absorbs what the geometry's K misses (end corrections, soft walls).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from matcad.loop import LoopError

MIN_POINTS = 4
MIN_DISTINCT_FORCES = 3
MAX_CONDITION = 1e12


@dataclass(frozen=True)
class CalibrationFit:
    v0_mm3: float
    b: float
    a: float
    covariance: np.ndarray  # of (v0, b, a)
    k_mm3_hz2: float
    residual_std_mm3: float
    dof: int
    force_range_n: tuple[float, float]
    k_free: bool
    forces_n: np.ndarray
    frequencies_hz: np.ndarray

    @property
    def standard_errors(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    def interval_95(self) -> np.ndarray:
        """95 % confidence intervals of (v0, b, a), rows [low, high]."""
        t = t_quantile(0.975, self.dof)
        theta = np.array([self.v0_mm3, self.b, self.a])
        return np.column_stack([theta - t * self.standard_errors, theta + t * self.standard_errors])

    def to_dict(self) -> dict:
        se = self.standard_errors
        ci = self.interval_95()
        return {"v0_mm3": self.v0_mm3, "a": self.a, "b": self.b, "v0_se": float(se[0]), "b_se": float(se[1]),
                "a_se": float(se[2]), "v0_ci95": ci[0].tolist(), "b_ci95": ci[1].tolist(), "a_ci95": ci[2].tolist(),
                "k_mm3_hz2": self.k_mm3_hz2, "k_free": self.k_free, "residual_std_mm3": self.residual_std_mm3,
                "dof": self.dof, "points": int(len(self.forces_n)), "force_range_n": list(self.force_range_n),
                "residual_rms_hz": float(np.sqrt(np.mean((self.frequencies_hz - self.frequency_hz(self.forces_n)) ** 2)))}

    def to_toml(self) -> str:
        """A [calibration] table that a spec accepts as it is."""
        cov = ", ".join(repr(float(x)) for x in self.covariance.ravel())
        return ("# written by `matcad calibrate`: paper Eq. 5, V_eff = v0 - a F^2 - b F\n[calibration]\n"
                f"v0_mm3 = {self.v0_mm3!r}\na = {self.a!r}\nb = {self.b!r}\narea_convention = \"pi_d2/4\"\n"
                f"k_mm3_hz2 = {self.k_mm3_hz2!r}\nforce_range_n = [{self.force_range_n[0]!r}, "
                f"{self.force_range_n[1]!r}]\ncovariance = [{cov}]\n"
                f"residual_std_mm3 = {self.residual_std_mm3!r}\ndof = {self.dof}\n")

    def frequency_hz(self, forces_n):
        """Fitted f(F) (Hz)."""
        f = np.asarray(forces_n, dtype=float)
        return np.sqrt(self.k_mm3_hz2 / (self.v0_mm3 - self.b * f - self.a * f * f))

    def bands_hz(self, forces_n, level: float = 0.95):
        """(confidence low, high, prediction low, high) of f at ``forces_n`` (Hz)."""
        f = np.asarray(forces_n, dtype=float)
        x = np.column_stack([np.ones_like(f), -f, -f * f])
        y = x @ np.array([self.v0_mm3, self.b, self.a])
        var_mean = np.einsum("ij,jk,ik->i", x, self.covariance, x)
        t = t_quantile(0.5 + level / 2, self.dof)
        half_c = t * np.sqrt(var_mean)
        half_p = t * np.sqrt(var_mean + self.residual_std_mm3 ** 2)
        to_f = lambda v: np.sqrt(self.k_mm3_hz2 / np.maximum(v, 1e-300))  # noqa: E731  (f falls as y grows)
        return to_f(y + half_c), to_f(y - half_c), to_f(y + half_p), to_f(y - half_p)


def t_quantile(p: float, dof: int) -> float:
    """Student's t quantile."""
    from scipy.special import stdtrit

    return float(stdtrit(dof, p))


FORCE_LIMIT_N = 1e6
"""|F| above this is not a taxel load (and F² would overflow the fit): the spec's calibration.force_range_n bound."""
FREQUENCY_LIMIT_HZ = 1e7
"""The spec's microphone.sample_rate_hz bound: no recorded tone lies above it."""


def read_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Force (N) and frequency (Hz) columns: a header naming force_n and frequency_hz, or the first two columns.
    The file is size-limited before parsing (:data:`matcad.inputs.CSV_MAX_BYTES`); raises ValueError."""
    from matcad.errors import shorten
    from matcad.inputs import CSV_MAX_BYTES, read_text

    text = read_text(path, "calibration data", CSV_MAX_BYTES)
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as exc:  # a field over csv.field_size_limit() (131 072 characters), a NUL byte
        raise ValueError(f"calibration data {path}: not a readable CSV file ({exc})") from None
    rows = [r for r in rows if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise ValueError(f"calibration data {path}: no rows")
    head = [c.strip().lower() for c in rows[0]]
    i_f, i_hz, start = 0, 1, 0
    if "force_n" in head and "frequency_hz" in head:
        i_f, i_hz, start = head.index("force_n"), head.index("frequency_hz"), 1
    forces, freqs = [], []
    for line, row in enumerate(rows[start:], start + 1):
        try:
            force, freq = float(row[i_f]), float(row[i_hz])
        except (ValueError, IndexError):
            raise ValueError(f"calibration data {path}, row {line}: {shorten(row)} must hold a force (N) and a "
                             "frequency (Hz)") from None
        if not (abs(force) <= FORCE_LIMIT_N and 0 < freq <= FREQUENCY_LIMIT_HZ):
            raise ValueError(f"calibration data {path}, row {line}: force {force!r} must be finite with |F| <= "
                             f"{FORCE_LIMIT_N:g} N and frequency {freq!r} finite, 0 < f <= {FREQUENCY_LIMIT_HZ:g} Hz")
        forces.append(force)
        freqs.append(freq)
    return np.array(forces), np.array(freqs)


def fit(forces_n, frequencies_hz, k_mm3_hz2: float, v0_fixed_mm3: float | None = None) -> CalibrationFit:
    """Fit Eq. 5; ``v0_fixed_mm3`` switches to the K-free fit. Raises LoopError when the data cannot tell."""
    force = np.asarray(forces_n, dtype=float)
    freq = np.asarray(frequencies_hz, dtype=float)
    n = len(force)
    if n < MIN_POINTS:
        raise LoopError(f"too few points: {n} (needs >= {MIN_POINTS}: 3 parameters and at least 1 degree of "
                        "freedom for their uncertainty)")
    if len(np.unique(force)) < MIN_DISTINCT_FORCES:
        raise LoopError(f"degenerate data: only {len(np.unique(force))} distinct forces (needs >= "
                        f"{MIN_DISTINCT_FORCES} for a quadratic in F)")
    scale = max(float(np.max(np.abs(force))), 1e-12)
    x_scaled = np.column_stack([np.ones(n), -force / scale, -(force / scale) ** 2])
    if np.linalg.cond(x_scaled) > MAX_CONDITION:
        raise LoopError("degenerate data: the forces cannot separate V0, b and a")
    if v0_fixed_mm3 is None:
        y = k_mm3_hz2 / freq ** 2
    else:
        y = 1.0 / freq ** 2
    # the measurement noise is in f, so y = K/f² scatters as f⁻³: weight by (f/f̄)⁶ (σ then refers to f̄)
    w = np.sqrt((freq / freq.mean()) ** 6)
    coef, *_ = np.linalg.lstsq(x_scaled * w[:, None], y * w, rcond=None)
    resid = (y - x_scaled @ coef) * w
    dof = n - 3
    sigma2 = float(resid @ resid) / dof
    cov_scaled = sigma2 * np.linalg.inv((x_scaled * w[:, None]).T @ (x_scaled * w[:, None]))
    unscale = np.diag([1.0, 1.0 / scale, 1.0 / scale ** 2])
    theta = unscale @ coef
    cov = unscale @ cov_scaled @ unscale
    if v0_fixed_mm3 is not None:
        # theta = (V0, b, a)/K with K = V0_fixed/theta0. Reading force from 1/f² needs theta alone (K cancels),
        # so holding K at its fitted value and scaling, (v0, b, a) = K·theta and cov = K²·cov(theta), is exact.
        k = v0_fixed_mm3 / theta[0]
        theta, cov, sigma2, k_mm3_hz2 = k * theta, k * k * cov, sigma2 * k * k, k
    v0, b, a = (float(v) for v in theta)
    lo, hi = float(force.min()), float(force.max())
    # the README promises exit 1 when the data show no load: the change of y = K/f² across the range,
    # Δy = b·(hi − lo) + a·(hi² − lo²), must stand out of its own 95 % interval
    g = np.array([0.0, hi - lo, hi * hi - lo * lo])
    change = b * g[1] + a * g[2]
    if not abs(change) > max(t_quantile(0.975, dof) * math.sqrt(max(float(g @ cov @ g), 0.0)), 1e-12 * abs(v0)):
        raise LoopError(f"the frequencies do not change with force over {lo:g}-{hi:g} N beyond their scatter: "
                        "no load response to calibrate (check that the cap is loaded and the tone tracked)")
    if a != 0:
        turn = -b / (2 * a)
        if lo <= turn <= hi:
            raise LoopError(f"the fitted V_eff turns at F = {turn:.3g} N, inside the calibrated range {lo:g}-{hi:g} N: "
                            "f is not monotone in F there, so force cannot be read from sound; recalibrate over "
                            "a narrower range")
    return CalibrationFit(v0, b, a, cov, float(k_mm3_hz2), math.sqrt(sigma2), dof, (lo, hi), v0_fixed_mm3 is not None,
                          force, freq)


def fit_from_spec(forces_n, frequencies_hz, spec, k_free: bool = False) -> CalibrationFit:
    """Fit with K (or V0, when ``k_free``) from the spec's as-built geometry and air."""
    from matcad.acoustics.load import LoadCalibration, frequency_constant_mm3_hz2
    from matcad.acoustics.resonator import resonator

    res = resonator(spec)
    k = float(frequency_constant_mm3_hz2(LoadCalibration(0, 0, 0), res.c_m_s, spec.neck.diameter, spec.neck.length))
    return fit(forces_n, frequencies_hz, k, res.volume if k_free else None)


def plot(cal: CalibrationFit, path: Path) -> None:
    """Fit with 95 % confidence and prediction bands, and the residuals (Hz), as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = np.linspace(*cal.force_range_n, 200)
    c_lo, c_hi, p_lo, p_hi = cal.bands_hz(grid)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.5, 6), sharex=True, height_ratios=(2, 1))
    top.fill_between(grid, p_lo, p_hi, alpha=0.2, label="95 % prediction band")
    top.fill_between(grid, c_lo, c_hi, alpha=0.4, label="95 % confidence band")
    top.plot(grid, cal.frequency_hz(grid), label="Eq. 5 fit")
    top.plot(cal.forces_n, cal.frequencies_hz, "ko", ms=4, label="data")
    top.set(ylabel="frequency [Hz]", title="matcad calibrate")
    top.legend(fontsize=8)
    bottom.axhline(0, color="grey")
    bottom.plot(cal.forces_n, cal.frequencies_hz - cal.frequency_hz(cal.forces_n), "ko", ms=4)
    bottom.set(xlabel="force [N]", ylabel="residual [Hz]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
