"""Fit paper Eq. 5 to force/frequency pairs, with uncertainty. Forces N, frequencies Hz, volumes mm³.

Eq. 5 is linear in disguise: y = K/f² = V0 − b·F − a·F² with K = c²A/(4π²l) from the as-built geometry
(physical area πd²/4). Least squares in (V0, b, a) is closed-form; because the noise is in f, y's scatter
grows as f⁻³ and the fit weights each point by (f/f̄)⁶; the parameter covariance is σ²(XᵀWX)⁻¹ with
σ² = weighted RSS/(n − 3); intervals use Student's t. Because f = sqrt(K/y) is monotone in y, the
confidence and prediction bands in y map straight onto bands in f.

``k_free``: fix V0 to the as-built cavity volume and fit K instead (1/f² = V0/K − (b/K)F − (a/K)F²), so that K
absorbs what the geometry's K misses (end corrections, the elastic wall).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, replace
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
    cycle_std_mm3: float = 0.0
    temperature_c: float | None = None
    outliers: tuple = ()  # (index, studentized residual)
    cycles: int = 1
    cycle_std_n: float = 0.0
    notes: tuple[str, ...] = ()
    excluded_n: tuple[float, ...] = ()

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
                "residual_rms_hz": float(np.sqrt(np.mean((self.frequencies_hz - self.frequency_hz(self.forces_n)) ** 2))),
                "cycles": self.cycles, "cycle_std_mm3": self.cycle_std_mm3, "cycle_std_n": self.cycle_std_n,
                "temperature_c": self.temperature_c, "excluded_forces_n": list(self.excluded_n),
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
                     f"({self.cycles} cycle(s)); at {self.temperature_c:g} degC")
        lines += [f"  note: {note}" for note in self.notes]
        return "\n".join(lines)

    def to_toml(self, table: str = "calibration") -> str:
        """A [calibration] table that a spec accepts as it is (``table`` "taxel.calibration": the same fields as
        one [[taxel]] entry's sub-table)."""
        cov = ", ".join(repr(float(x)) for x in self.covariance.ravel())
        return (f"# written by `matcad calibrate`: paper Eq. 5, V_eff = v0 - a F^2 - b F\n[{table}]\n"
                f"v0_mm3 = {self.v0_mm3!r}\na = {self.a!r}\nb = {self.b!r}\narea_convention = \"pi_d2/4\"\n"
                f"k_mm3_hz2 = {self.k_mm3_hz2!r}\nforce_range_n = [{self.force_range_n[0]!r}, "
                f"{self.force_range_n[1]!r}]\ncovariance = [{cov}]\n"
                f"residual_std_mm3 = {self.residual_std_mm3!r}\ndof = {self.dof}\n"
                f"cycle_std_mm3 = {self.cycle_std_mm3!r}\n"
                + (f"temperature_c = {self.temperature_c!r}\n" if self.temperature_c is not None else ""))

    def frequency_hz(self, forces_n):
        """Fitted f(F) (Hz)."""
        f = np.asarray(forces_n, dtype=float)
        return np.sqrt(self.k_mm3_hz2 / (self.v0_mm3 - self.b * f - self.a * f * f))

    def bands_hz(self, forces_n, level: float = 0.95):
        """(confidence low, high, prediction low, high) of f at ``forces_n`` (Hz); the prediction band holds a new
        cycle's point (residual and between-cycle scatter)."""
        f = np.asarray(forces_n, dtype=float)
        x = np.column_stack([np.ones_like(f), -f, -f * f])
        y = x @ np.array([self.v0_mm3, self.b, self.a])
        var_mean = np.einsum("ij,jk,ik->i", x, self.covariance, x)
        t = t_quantile(0.5 + level / 2, self.dof)
        half_c = t * np.sqrt(var_mean)
        half_p = t * np.sqrt(var_mean + self.residual_std_mm3 ** 2 + self.cycle_std_mm3 ** 2)
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


def read_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Force (N), frequency (Hz) and, when the header names one, load-cycle label columns: a header naming force_n
    and frequency_hz (and optionally cycle), or the first two columns. The file is size-limited before parsing
    (:data:`matcad.inputs.CSV_MAX_BYTES`); raises ValueError."""
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
    i_f, i_hz, start, i_c = 0, 1, 0, None
    if "force_n" in head and "frequency_hz" in head:
        i_f, i_hz, start = head.index("force_n"), head.index("frequency_hz"), 1
        i_c = head.index("cycle") if "cycle" in head else None
    forces, freqs, cycles = [], [], []
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
        if i_c is not None:
            label = row[i_c].strip() if i_c < len(row) else ""
            if not label or len(label) > 64:
                raise ValueError(f"calibration data {path}, row {line}: cycle {shorten(label)!r} must name the load "
                                 "cycle (1-64 characters)")
            cycles.append(label)
    return np.array(forces), np.array(freqs), (np.array(cycles) if i_c is not None else None)


PAPER_CYCLE_STD_N = 0.7
"""Between-cycle standard deviation assumed when only one load cycle is given: the paper saw ~1 N (24 Hz at
6.4 N) between two cycles; the difference of two draws has sd √2·τ, so τ ≈ 1/√2 N."""
OUTLIER_LEVEL = 0.05
"""Family-wise level of the outlier test (Bonferroni over the points)."""


def _wls(force, y, w, scale, cycles, tau2_fixed=None):
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
        temperature_c: float | None = None, cycle_std_n: float | None = None) -> CalibrationFit:
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
        notes.append(f"Eq. 5 holds up to {result.force_range_n[1]:g} N: f stops rising with F above it (fit "
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
    return replace(result, temperature_c=temperature_c, notes=tuple(notes), excluded_n=tuple(force[~keep]))


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


def _fit_once(force, freq, k_mm3_hz2, v0_fixed_mm3, cycles, cycle_std_n) -> CalibrationFit:
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
    coef, cov_scaled, sigma2, tau2, resid, hat = _wls(force, y, w, scale, cycles)
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
    return CalibrationFit(v0, b, a, cov, float(k_mm3_hz2), math.sqrt(sigma2), dof, (lo, hi), v0_fixed_mm3 is not None,
                          force, freq, math.sqrt(tau2), None, outliers=outliers,
                          cycles=int(len(np.unique(cycles))), cycle_std_n=math.sqrt(tau2) / max(slope_mid, 1e-300))


def fit_from_spec(forces_n, frequencies_hz, spec, k_free: bool = False, cycles=None,
                  temperature_c: float | None = None, cycle_std_n: float | None = None) -> CalibrationFit:
    """Fit with K (or V0, when ``k_free``) from the spec's as-built geometry and air; ``temperature_c`` (°C)
    is the air's during calibration (default the spec's [air] temperature_c)."""
    from matcad.acoustics.design import design
    from matcad.acoustics.load import LoadCalibration, frequency_constant_mm3_hz2
    from matcad.acoustics.resonator import resonator

    res = resonator(design(spec))
    k = float(frequency_constant_mm3_hz2(LoadCalibration(0, 0, 0), res.c_m_s, spec.neck.diameter, spec.neck.length))
    temp = spec.air.temperature_c if temperature_c is None else temperature_c
    return fit(forces_n, frequencies_hz, k, res.volume if k_free else None, cycles, temp, cycle_std_n)


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
