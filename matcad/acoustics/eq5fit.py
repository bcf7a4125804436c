"""Fitting paper Eq. 5 (:class:`matcad.acoustics.eq5.Eq5`) to force/frequency pairs, with uncertainty. Forces N,
frequencies Hz, volumes mm³.

Eq. 5 is linear in disguise: y = K/f² = V0 − b·F − a·F² with K = c²A/(4π²l) from the as-built geometry
(physical area πd²/4). Least squares in (V0, b, a) is closed-form; because the noise is in f, y's scatter
grows as f⁻³ and the fit weights each point by (f/f̄)⁶; the parameter covariance is σ²(XᵀWX)⁻¹ with
σ² = weighted RSS/(n − 3); intervals use Student's t. Because f = sqrt(K/y) is monotone in y, the
confidence and prediction bands in y map straight onto bands in f.

``v0_fixed_mm3`` (the K-free fit): fix V0 to the as-built cavity volume and fit K instead
(1/f² = V0/K − (b/K)F − (a/K)F²), so that K absorbs what the geometry's K misses (end corrections, the elastic
wall). The calibration loop (:mod:`matcad.loop.calibrate`) reads the data and fits with this; the cap mechanics
(:mod:`matcad.mechanics.frequency`) fits its predicted curve the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from matcad.acoustics.eq5 import Eq5, t_quantile
from matcad.errors import LoopError

MIN_POINTS = 4
MIN_DISTINCT_FORCES = 3
MAX_CONDITION = 1e12
PAPER_CYCLE_STD_N = 0.7
"""Between-cycle standard deviation assumed when only one load cycle is given: the paper saw ~1 N (24 Hz at
6.4 N) between two cycles; the difference of two draws has sd √2·τ, so τ ≈ 1/√2 N."""
OUTLIER_LEVEL = 0.05
"""Family-wise level of the outlier test (Bonferroni over the points)."""


@dataclass(frozen=True)
class Eq5Fit:
    """A fit of Eq. 5 to measured pairs: the fitted law (its covariance, residual and between-cycle scatter, force
    range and temperature in it), whether K was fitted (``k_free``), the data (N, Hz), the outliers (point index,
    studentized residual), the load cycles and their scatter in force (N), notes and the forces left out (N)."""

    law: Eq5
    k_free: bool
    forces_n: np.ndarray
    frequencies_hz: np.ndarray
    outliers: tuple = ()
    cycles: int = 1
    cycle_std_n: float = 0.0
    notes: tuple[str, ...] = ()
    excluded_n: tuple[float, ...] = ()

    @property
    def standard_errors(self) -> np.ndarray:
        """Standard errors of (V0, b, a) (mm³, mm³/N, mm³/N²)."""
        return np.sqrt(np.diag(self.law.cov))

    def interval_95(self) -> np.ndarray:
        """95 % confidence intervals of (v0, b, a), rows [low, high]."""
        t = t_quantile(0.975, self.law.dof)
        theta = np.array([self.law.v0_mm3, self.law.b, self.law.a])
        return np.column_stack([theta - t * self.standard_errors, theta + t * self.standard_errors])

    def to_dict(self) -> dict:
        law, se, ci = self.law, self.standard_errors, self.interval_95()
        residual = self.frequencies_hz - law.frequency_hz(self.forces_n)
        return {"v0_mm3": law.v0_mm3, "a": law.a, "b": law.b, "v0_se": float(se[0]), "b_se": float(se[1]),
                "a_se": float(se[2]), "v0_ci95": ci[0].tolist(), "b_ci95": ci[1].tolist(), "a_ci95": ci[2].tolist(),
                "k_mm3_hz2": law.k_mm3_hz2, "k_free": self.k_free, "residual_std_mm3": law.residual_std_mm3,
                "dof": law.dof, "points": int(len(self.forces_n)), "force_range_n": list(law.force_range_n),
                "residual_rms_hz": float(np.sqrt(np.mean(residual ** 2))),
                "cycles": self.cycles, "cycle_std_mm3": law.cycle_std_mm3, "cycle_std_n": self.cycle_std_n,
                "temperature_c": law.temperature_c, "excluded_forces_n": list(self.excluded_n),
                "outliers": [{"point": i + 1, "studentized_residual": r} for i, r in self.outliers],
                "notes": list(self.notes)}

    def to_text(self) -> str:
        """What ``calibrate`` prints: the range fitted, each parameter with its standard error and 95 % interval,
        the residual RMS (Hz), the between-cycle scatter (N), the temperature (°C) and the notes."""
        d = self.to_dict()
        lines = [f"Eq. 5 fit to {d['points']} points, {d['force_range_n'][0]:g}-{d['force_range_n'][1]:g} N "
                 f"({'K free, V0 = as-built cavity' if self.k_free else 'K from the as-built geometry'}):"]
        for name in ("v0", "b", "a"):
            value = d["v0_mm3"] if name == "v0" else d[name]
            lo, hi = d[f"{name}_ci95"]
            lines.append(f"  {name:<3}= {value:.6g} +- {d[name + '_se']:.3g}  (95 %: {lo:.6g} .. {hi:.6g})")
        lines.append(f"  residual RMS {d['residual_rms_hz']:.2f} Hz; between cycles {self.cycle_std_n:.3g} N "
                     f"({self.cycles} cycle(s)); at {self.law.temperature_c:g} degC")
        lines += [f"  note: {note}" for note in self.notes]
        return "\n".join(lines)


def weighted_least_squares(force, y, w, scale, cycles, tau2_fixed=None):
    """Weighted least squares in (V0, b, a) with a random offset per load cycle: returns
    (theta, covariance, σ² within cycles, τ² between cycles, residuals in y (weighted), leverages)."""
    n = len(force)
    x = np.column_stack([np.ones(n), -force / scale, -(force / scale) ** 2])
    xw, yw = x * w[:, None], y * w
    coef, *_ = np.linalg.lstsq(xw, yw, rcond=None)
    resid = yw - xw @ coef
    labels, index = np.unique(cycles, return_inverse=True)
    k = len(labels)
    dof = n - 3
    if k >= 2 and tau2_fixed is None:
        # method of moments: within-cycle scatter from residuals about their cycle means; between-cycle from
        # the spread of those means beyond what the within scatter explains
        means = np.bincount(index, resid) / np.bincount(index)
        within = resid - means[index]
        s2 = float(within @ within) / max(n - 3 - (k - 1), 1)
        counts = np.bincount(index)
        tau2 = max(0.0, float(np.sum(counts * means ** 2) / max(k - 1, 1) - s2) * k / n)
    else:
        s2 = float(resid @ resid) / dof
        tau2 = 0.0 if tau2_fixed is None else tau2_fixed
    z = (index[:, None] == np.arange(k)[None, :]).astype(float) * w[:, None]
    v = s2 * np.eye(n) + (tau2 * z @ z.T if (k >= 2 and tau2_fixed is None) else 0.0)
    vi = np.linalg.inv(v)
    cov = np.linalg.inv(xw.T @ vi @ xw)
    coef = cov @ xw.T @ vi @ yw
    resid = yw - xw @ coef
    hat = np.einsum("ij,jk,ik->i", xw, np.linalg.inv(xw.T @ xw), xw)
    return coef, cov, s2, tau2, resid, hat


def fit(forces_n, frequencies_hz, k_mm3_hz2: float, v0_fixed_mm3: float | None = None, cycles=None,
        temperature_c: float | None = None, cycle_std_n: float | None = None) -> Eq5Fit:
    """Fit Eq. 5; ``v0_fixed_mm3`` switches to the K-free fit. ``cycles`` labels each point's load cycle: with
    two or more, the between-cycle (hysteresis) variance is estimated and carried into every force interval;
    with one, ``cycle_std_n`` (N; default :data:`PAPER_CYCLE_STD_N`) is assumed. When the fit turns inside the
    range (f stops rising: the paper's taxel past ~25 N), the top forces are left out until Eq. 5 holds over
    the rest, and the fit says where it stops. Raises LoopError when the data cannot tell."""
    force = np.asarray(forces_n, dtype=float)
    freq = np.asarray(frequencies_hz, dtype=float)
    cycles = np.zeros(len(force), dtype=int) if cycles is None else np.asarray(cycles)
    if len(cycles) != len(force):
        raise ValueError(f"{len(cycles)} cycle labels for {len(force)} points")
    keep = np.ones(len(force), dtype=bool)
    notes = []
    while True:
        try:
            result = _fit_once(force[keep], freq[keep], k_mm3_hz2, v0_fixed_mm3, cycles[keep], cycle_std_n)
            break
        except _Turns as turn:
            top = float(np.max(force[keep]))
            trimmed = keep & (force < top)
            try:
                _check_points(force[trimmed])
            except LoopError:
                raise LoopError(f"the fitted V_eff turns at F = {turn.at:.3g} N, inside the calibrated range "
                                f"{force.min():g}-{force.max():g} N, and no lower range with enough points "
                                "is monotone: f does not rise steadily with F in these data (check the force "
                                "and frequency columns)") from None
            keep = trimmed
    if not np.all(keep):
        dropped = force[~keep]
        notes.append(f"Eq. 5 holds up to {result.law.force_range_n[1]:g} N: f stops rising with F above it (fit "
                     f"turned inside the range); {len(dropped)} point(s) at {', '.join(f'{v:g}' for v in sorted(set(dropped)))} N "
                     "left out; forces above it cannot be read from sound")
    rows = np.flatnonzero(keep)
    outliers = [(int(rows[i]) + 1, r) for i, r in result.outliers]
    for row, r in outliers:
        notes.append(f"point {row} (F = {force[row - 1]:g} N, f = {freq[row - 1]:g} Hz) is an outlier: "
                     f"studentized residual {r:+.1f}")
    if len(np.unique(cycles[keep])) < 2:
        notes.append(f"one load cycle: between-cycle (hysteresis) variation not measured; "
                     f"{result.cycle_std_n:.2g} N assumed (the paper saw ~1 N between two cycles): give several "
                     "cycles (a 'cycle' column) to estimate it")
    return replace(result, law=replace(result.law, temperature_c=temperature_c), notes=tuple(notes),
                   excluded_n=tuple(force[~keep]))


class _Turns(Exception):
    def __init__(self, at):
        self.at = at


def _check_points(force):
    n = len(force)
    if n < MIN_POINTS:
        raise LoopError(f"too few points: {n} (needs >= {MIN_POINTS}: 3 parameters and at least 1 degree of "
                        "freedom for their uncertainty)")
    if len(np.unique(force)) < MIN_DISTINCT_FORCES:
        raise LoopError(f"degenerate data: only {len(np.unique(force))} distinct forces (needs >= "
                        f"{MIN_DISTINCT_FORCES} for a quadratic in F)")


def _fit_once(force, freq, k_mm3_hz2, v0_fixed_mm3, cycles, cycle_std_n) -> Eq5Fit:
    _check_points(force)
    n = len(force)
    scale = max(float(np.max(np.abs(force))), 1e-12)
    x_scaled = np.column_stack([np.ones(n), -force / scale, -(force / scale) ** 2])
    if np.linalg.cond(x_scaled) > MAX_CONDITION:
        raise LoopError("degenerate data: the forces cannot separate V0, b and a")
    y = k_mm3_hz2 / freq ** 2 if v0_fixed_mm3 is None else 1.0 / freq ** 2
    # the measurement noise is in f, so y = K/f² scatters as f⁻³: weight by (f/f̄)⁶ (σ then refers to f̄)
    w = np.sqrt((freq / freq.mean()) ** 6)
    one_cycle = len(np.unique(cycles)) < 2
    coef, cov_scaled, sigma2, tau2, resid, hat = weighted_least_squares(force, y, w, scale, cycles)
    unscale = np.diag([1.0, 1.0 / scale, 1.0 / scale ** 2])
    theta = unscale @ coef
    if one_cycle:
        # τ assumed in force: in y it is τ_F·|dy/dF| at mid-range
        tau_n = PAPER_CYCLE_STD_N if cycle_std_n is None else cycle_std_n
        mid = 0.5 * (force.min() + force.max())
        tau2 = (tau_n * abs(theta[1] + 2 * theta[2] * mid)) ** 2
    cov = unscale @ cov_scaled @ unscale
    dof = n - 3
    if not one_cycle and tau2 > 0:
        # Welch–Satterthwaite: σ² has n − 3 − (k − 1) degrees of freedom, τ² only k − 1 (k cycles); the
        # intervals use the effective dof of σ² + τ², so that τ from 2-3 cycles widens them as it should
        k_cycles = len(np.unique(cycles))
        dof_w, dof_b = max(n - 3 - (k_cycles - 1), 1), k_cycles - 1
        dof = max(1, int((sigma2 + tau2) ** 2 / (sigma2 ** 2 / dof_w + tau2 ** 2 / dof_b)))
    if v0_fixed_mm3 is not None:
        # theta = (V0, b, a)/K with K = V0_fixed/theta0. Reading force from 1/f² needs theta alone (K cancels),
        # so holding K at its fitted value and scaling, (v0, b, a) = K·theta and cov = K²·cov(theta), is exact.
        k = v0_fixed_mm3 / theta[0]
        theta, cov, sigma2, tau2, k_mm3_hz2 = k * theta, k * k * cov, sigma2 * k * k, tau2 * k * k, k
        resid = resid * k
    v0, b, a = (float(v) for v in theta)
    lo, hi = float(force.min()), float(force.max())
    if a != 0:
        turn = -b / (2 * a)
        if lo <= turn <= hi:
            raise _Turns(turn)
    # the README promises exit 1 when the data show no load: the change of y = K/f² across the range,
    # Δy = b·(hi − lo) + a·(hi² − lo²), must stand out of its own 95 % interval
    g = np.array([0.0, hi - lo, hi * hi - lo * lo])
    change = b * g[1] + a * g[2]
    if not abs(change) > max(t_quantile(0.975, dof) * math.sqrt(max(float(g @ cov @ g), 0.0)), 1e-12 * abs(v0)):
        raise LoopError(f"the frequencies do not change with force over {lo:g}-{hi:g} N beyond their scatter: "
                        "no load response to calibrate (check that the cap is loaded and the tone tracked)")
    # externally studentized residuals: each point judged by the scatter of the others
    var = sigma2 + (0.0 if one_cycle else tau2)
    h = np.clip(1 - hat, 1e-9, None)
    var_others = np.maximum((dof * var - resid ** 2 / h) / max(dof - 1, 1), 1e-300)
    student = resid / np.sqrt(var_others * h)
    limit = t_quantile(1 - OUTLIER_LEVEL / (2 * n), max(dof - 1, 1))
    outliers = tuple((int(i), float(student[i])) for i in np.flatnonzero(np.abs(student) > limit))
    slope_mid = abs(b + 2 * a * 0.5 * (lo + hi))
    law = Eq5(v0, a, b, float(k_mm3_hz2), covariance=tuple(float(x) for x in cov.ravel()),
              residual_std_mm3=math.sqrt(sigma2), dof=dof, force_range_n=(lo, hi), cycle_std_mm3=math.sqrt(tau2))
    return Eq5Fit(law, v0_fixed_mm3 is not None, force, freq, outliers=outliers, cycles=int(len(np.unique(cycles))),
                  cycle_std_n=math.sqrt(tau2) / max(slope_mid, 1e-300))
