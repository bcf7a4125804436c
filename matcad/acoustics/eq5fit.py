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
MAX_DOF = 10 ** 6
"""Degrees of freedom past which Student's t is the normal law (an exact, noise-free curve gives no bound)."""
PAPER_CYCLE_SHARE = 1.0 / 15.4
"""Prior between-cycle (hysteresis) standard deviation, as a share of the largest calibrated force: the paper saw
~1 N (24 Hz at 6.4 N) between a cycle to 15.4 N and the next (Sec. V, Fig. 10), so τ₀ = |F|max / 15.4 (1 N over
the paper's range, 0.32 N over 0-5 N). A cap's between-cycle variation grows with the load it is cycled to (stress
softening, seating), so the prior scales with the range rather than staying at 1 N."""
PRIOR_CYCLES = 4
"""Weight of that prior in degrees of freedom (scaled inverse-χ² prior, as if it came from PRIOR_CYCLES + 1
cycles): the estimate used is τ² = (ν₀ τ₀² + (k − 1) τ̂²)/(ν₀ + k − 1) from k measured cycles, with ν₀ + k − 1
degrees of freedom. Checked by simulation (benchmarks/calibration.py, tests/test_calibration_coverage.py): one cycle
covers >= 90 % up to τ = 1 N on the paper's range; three cycles are 1.3 times as wide as needed at τ = 1 N, 1.7 at
0.7 N, and the prior dominates below that (2.2 times at 0.5 N, ~11 with no scatter at all)."""
OUTLIER_LEVEL = 0.05
"""Family-wise level of the outlier test (Bonferroni over the points)."""
ROUND_OFF = 64.0
"""Float64 round-off through the fit, in units of eps·cond(X)·f̄ (Hz): the scatter that an exact, noise-free data
set still leaves (measured ~1e-15·f̄ at cond ~10-100), with a safety factor; no real tone is read that finely."""
FINEST_STEP_HZ = 1e-6
"""The finest decimal step (Hz) at which :func:`_resolution_hz` looks for the digits the frequencies were written to."""


@dataclass(frozen=True)
class Eq5Fit:
    """A fit of Eq. 5 to measured pairs: the fitted law (its covariance, residual and between-cycle scatter, force
    range and temperature in it), whether K was fitted (``k_free``), the data (N, Hz), the outliers (point index,
    studentized residual), the load cycles and the between-cycle scatter in force (N): the one used
    (``cycle_std_n``), the prior (``cycle_prior_n``; ``cycle_prior_given``: by the user, else
    :data:`PAPER_CYCLE_SHARE` of the range) and the cycles' own estimate (None with one cycle), notes and the
    forces left out (N)."""

    law: Eq5
    k_free: bool
    forces_n: np.ndarray
    frequencies_hz: np.ndarray
    outliers: tuple = ()
    cycles: int = 1
    cycle_std_n: float = 0.0
    notes: tuple[str, ...] = ()
    excluded_n: tuple[float, ...] = ()
    cycle_prior_n: float = 0.0
    cycle_prior_given: bool = False
    cycle_std_data_n: float | None = None

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
                "cycle_std_prior_n": self.cycle_prior_n, "cycle_std_data_n": self.cycle_std_data_n,
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
        data = "" if self.cycle_std_data_n is None else f", the cycles' own {self.cycle_std_data_n:.3g} N"
        lines.append(f"  residual RMS {d['residual_rms_hz']:.2f} Hz; between cycles {self.cycle_std_n:.3g} N "
                     f"({self.cycles} cycle(s){data}); at {self.law.temperature_c:g} degC")
        lines += [f"  note: {note}" for note in self.notes]
        return "\n".join(lines)


@dataclass(frozen=True)
class LeastSquares:
    """What :func:`weighted_least_squares` found, in the scaled parameters (V0, b·s, a·s²) of its design matrix:
    the estimate and its covariance, the within-cycle variance σ² (``dof_within`` degrees of freedom), the
    between-cycle variance τ² used and its degrees of freedom (inf: given, not estimated), the cycles' own estimate
    of τ² (None with one cycle), and each point's externally studentized within-cycle residual (judged against
    no less than the noise floor it was given)."""

    coef: np.ndarray
    cov: np.ndarray
    sigma2: float
    dof_within: int
    tau2: float
    dof_tau: float
    tau2_data: float | None
    student: np.ndarray


def _per_cycle(index, k: int, values) -> np.ndarray:
    """Sums of ``values`` (n, or n × m) over the points of each of ``k`` cycles: (k,) or (k, m); O(n)."""
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        return np.bincount(index, values, minlength=k)
    return np.stack([np.bincount(index, values[:, j], minlength=k) for j in range(values.shape[1])], axis=1)


def weighted_least_squares(force, y, w, scale, index, k: int, tau2_prior: float = 0.0,
                           prior_dof: float = PRIOR_CYCLES, noise_floor: float = 0.0) -> LeastSquares:
    """Eq. 5 in (V0, b, a) by weighted least squares with a random offset per load cycle (a random intercept):
    y_ij = x_ijᵀθ + u_i + e_ij, u_i ~ N(0, τ²), e_ij ~ N(0, σ²/w_ij²); ``index`` gives each point's cycle
    (0 … ``k`` − 1). O(n) time and memory: no n × n matrix is ever formed.

    - σ² and the outlier test come from the within-cycle (fixed-effects) fit, each cycle its own intercept
      (n − 2 − k degrees of freedom); its externally studentized residuals use the exact leave-one-out variance
      ((n−p)s² − e_i²/(1−h_i))/(n−p−1), which cannot go negative, and never below ``noise_floor``² (the
      scatter the data cannot resolve, in the units of y·w): a perfect fit leaves only round-off, and round-off
      judged by round-off would name a point of it an outlier.
    - τ²: with k >= 2 cycles, the spread of the cycles' weighted mean residuals beyond what σ² explains (method of
      moments, k − 1 degrees of freedom), pooled with the prior ``tau2_prior`` worth ``prior_dof`` degrees of
      freedom (:data:`PRIOR_CYCLES`; ``prior_dof`` inf: τ² taken as known). One cycle: the prior alone.
    - θ by generalised least squares with V = σ²I + τ²ZZᵀ through the Woodbury identity, per-cycle sums only;
      with one cycle that is the weighted fit, and the offset of the calibration's own cycle sits in V0:
      Cov θ = σ²(XᵀWX)⁻¹ + τ² e₁e₁ᵀ.
    ``force`` N, ``y`` mm³ (K/f² or 1/f²), ``w`` the square roots of the weights, ``scale`` N (F/scale in X)."""
    n = len(force)
    x = np.column_stack([np.ones(n), -force / scale, -(force / scale) ** 2])
    xw, yw = x * w[:, None], y * w
    w2 = _per_cycle(index, k, w * w)  # Σ w² per cycle
    sums_x, sums_y = _per_cycle(index, k, xw * w[:, None]), _per_cycle(index, k, yw * w)
    # within-cycle (fixed effects): each cycle's weighted mean removed; the intercept column vanishes
    xd = xw - w[:, None] * (sums_x / w2[:, None])[index]
    yd = yw - w * (sums_y / w2)[index]
    slopes, *_ = np.linalg.lstsq(xd[:, 1:], yd, rcond=None)
    e = yd - xd[:, 1:] @ slopes
    dof_w = n - 2 - k
    if dof_w < 1:
        raise LoopError(f"too few points for {k} load cycles: {n} points leave {dof_w} degrees of freedom within "
                        "the cycles (needs >= 1: each cycle its own offset, plus b and a)")
    rss = float(e @ e)
    sigma2 = rss / dof_w
    gram = xd[:, 1:].T @ xd[:, 1:]
    hat = w * w / w2[index] + np.einsum("ij,jk,ik->i", xd[:, 1:], np.linalg.pinv(gram), xd[:, 1:])
    room = np.clip(1.0 - hat, 0.0, None)
    with np.errstate(divide="ignore", invalid="ignore"):
        deleted = np.where(room > 1e-12, e * e / room, 0.0)
        s2_others = np.maximum(np.maximum(rss - deleted, 0.0) / max(dof_w - 1, 1), noise_floor ** 2)
        student = np.where((room > 1e-12) & (s2_others > 0), e / np.sqrt(s2_others * room), 0.0)
    tau2_data = None
    if k >= 2:
        # the cycles' weighted mean residuals about the common fit scatter as τ² + σ²/Σw²
        pooled, *_ = np.linalg.lstsq(xw, yw, rcond=None)
        means = _per_cycle(index, k, w * (yw - xw @ pooled)) / w2
        tau2_data = max(0.0, float(np.var(means, ddof=1) - np.mean(sigma2 / w2)))
    if not np.isfinite(prior_dof):
        tau2, dof_tau = tau2_prior, math.inf
    elif tau2_data is None:
        tau2, dof_tau = tau2_prior, float(prior_dof)
    else:
        dof_tau = prior_dof + k - 1
        tau2 = (prior_dof * tau2_prior + (k - 1) * tau2_data) / dof_tau
    s2 = max(sigma2, np.finfo(float).tiny)
    if k == 1:
        # one cycle: weighted least squares; the cycle's offset u moves V0 alone (X e₁ = 1)
        gram_full = xw.T @ xw
        coef = np.linalg.solve(gram_full, xw.T @ yw)
        cov = s2 * np.linalg.inv(gram_full)
        cov[0, 0] += tau2
    else:
        # Woodbury, split stably: XᵀV⁻¹X = (within + Σ_c q_c S_c S_cᵀ / W_c) / σ², q_c = σ²/(σ² + τ² W_c)
        q = s2 / (s2 + tau2 * w2)
        between = (sums_x * (q / w2)[:, None]).T
        a_mat = xd.T @ xd + between @ sums_x
        rhs = xd.T @ yd + between @ sums_y
        coef = np.linalg.solve(a_mat, rhs)
        cov = s2 * np.linalg.inv(a_mat)
    return LeastSquares(coef, cov, sigma2, dof_w, float(tau2), dof_tau, tau2_data, student)


def fit(forces_n, frequencies_hz, k_mm3_hz2: float, v0_fixed_mm3: float | None = None, cycles=None,
        temperature_c: float | None = None, cycle_std_n: float | None = None) -> Eq5Fit:
    """Fit Eq. 5; ``v0_fixed_mm3`` switches to the K-free fit. ``cycles`` labels each point's load cycle: with
    two or more, the between-cycle (hysteresis) variance is estimated and carried into every force interval;
    with one, ``cycle_std_n`` (N; default :data:`PAPER_CYCLE_SHARE` of the largest force) is assumed, and
    with several the cycles' estimate is pooled with that prior (:data:`PRIOR_CYCLES`). When the fit turns inside the
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
    if result.cycle_prior_given and result.cycles == 1:
        notes.append(f"one load cycle: between-cycle (hysteresis) sd {result.cycle_prior_n:.3g} N as given "
                     "(--cycle-std-n); it counts twice in every force interval: in V0 (this cycle's offset) and in "
                     "the reading's own cycle")
    elif result.cycles == 1:
        notes.append(f"one load cycle: between-cycle (hysteresis) variation not measured; {result.cycle_std_n:.2g} N "
                     f"assumed (the paper's ~1 N over 15.4 N, scaled to this {result.law.force_range_n[1]:g} N "
                     "range); it counts twice in every force interval: give several cycles (a 'cycle' column) to "
                     "measure it")
    else:
        notes.append(f"{result.cycles} load cycles: between-cycle sd {result.cycle_std_data_n:.2g} N from the "
                     f"cycles, pooled with the prior {result.cycle_prior_n:.2g} N (worth {PRIOR_CYCLES} degrees of "
                     f"freedom) to {result.cycle_std_n:.2g} N")
    return replace(result, law=replace(result.law, temperature_c=temperature_c), notes=tuple(notes),
                   excluded_n=tuple(force[~keep]))


class _Turns(Exception):
    def __init__(self, at):
        self.at = at


def _resolution_hz(frequencies_hz) -> float:
    """The step (Hz) the frequencies were written to: the coarsest of 1, 0.1, … :data:`FINEST_STEP_HZ` Hz that each
    is a whole multiple of (4500.25 Hz: 0.01 Hz), 0 when none is (full-precision numbers)."""
    freq = np.asarray(frequencies_hz, dtype=float)
    step = 1.0
    while step >= FINEST_STEP_HZ * 0.5:
        q = freq / step
        if np.all(np.abs(q - np.round(q)) <= 1e-6 + 8 * np.finfo(float).eps * np.abs(q)):
            return step
        step /= 10.0
    return 0.0


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
    condition = float(np.linalg.cond(x_scaled))
    if condition > MAX_CONDITION:
        raise LoopError("degenerate data: the forces cannot separate V0, b and a")
    y = k_mm3_hz2 / freq ** 2 if v0_fixed_mm3 is None else 1.0 / freq ** 2
    # the measurement noise is in f, so y = K/f² scatters as f⁻³: weight by (f/f̄)⁶ (σ then refers to f̄)
    w = np.sqrt((freq / freq.mean()) ** 6)
    # the outlier test credits no scatter finer than the data resolve: their written step (a uniform rounding,
    # sd step/√12) or round-off; a change δf moves y·w by 2(y f²)δf/f̄³ at every f (that is why w = (f/f̄)³)
    floor_hz = max(_resolution_hz(freq) / math.sqrt(12.0), ROUND_OFF * np.finfo(float).eps * condition * freq.mean())
    noise_floor = 2.0 * float(y[0] * freq[0] ** 2) * floor_hz / freq.mean() ** 3
    labels, index = np.unique(cycles, return_inverse=True)
    k_cycles = len(labels)
    unscale = np.diag([1.0, 1.0 / scale, 1.0 / scale ** 2])
    lo, hi = float(force.min()), float(force.max())
    # the prior τ in force becomes one in y through |dy/dF| = |b + 2aF| at mid-range (a first, plain fit)
    first, *_ = np.linalg.lstsq(x_scaled * w[:, None], y * w, rcond=None)
    first = unscale @ first
    dy_df = abs(first[1] + 2 * first[2] * 0.5 * (lo + hi))
    given = cycle_std_n is not None
    tau_prior_n = cycle_std_n if given else PAPER_CYCLE_SHARE * max(abs(lo), abs(hi))
    # one cycle: the prior is all there is, taken as known (a stated assumption); several: pooled with theirs
    ls = weighted_least_squares(force, y, w, scale, index, k_cycles, (tau_prior_n * dy_df) ** 2,
                                math.inf if k_cycles == 1 else PRIOR_CYCLES, noise_floor)
    theta, cov, sigma2, tau2 = unscale @ ls.coef, unscale @ ls.cov @ unscale, ls.sigma2, ls.tau2
    # Welch–Satterthwaite: a new reading's scatter in y is σ² (dof within) plus τ²(1 + 1/k) — its own cycle's
    # offset and the calibration cycles' mean offset that sits in V0 — with the degrees of freedom of τ²
    share_tau = tau2 * (1.0 + 1.0 / k_cycles)
    spread = sigma2 ** 2 / ls.dof_within + share_tau ** 2 / ls.dof_tau
    dof = max(1, int(min((sigma2 + share_tau) ** 2 / spread, MAX_DOF))) if spread > 0 else MAX_DOF
    tau2_data = ls.tau2_data
    if v0_fixed_mm3 is not None:
        # theta = (V0, b, a)/K with K = V0_fixed/theta0. Reading force from 1/f² needs theta alone (K cancels),
        # so holding K at its fitted value and scaling, (v0, b, a) = K·theta and cov = K²·cov(theta), is exact.
        k = v0_fixed_mm3 / theta[0]
        theta, cov, sigma2, tau2, k_mm3_hz2 = k * theta, k * k * cov, sigma2 * k * k, tau2 * k * k, k
        tau2_data = None if tau2_data is None else tau2_data * k * k
    v0, b, a = (float(v) for v in theta)
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
    # externally studentized within-cycle residuals: each point judged by the scatter of the others
    limit = t_quantile(1 - OUTLIER_LEVEL / (2 * n), max(ls.dof_within - 1, 1))
    outliers = tuple((int(i), float(ls.student[i])) for i in np.flatnonzero(np.abs(ls.student) > limit))
    slope_mid = max(abs(b + 2 * a * 0.5 * (lo + hi)), 1e-300)
    law = Eq5(v0, a, b, float(k_mm3_hz2), covariance=tuple(float(x) for x in cov.ravel()),
              residual_std_mm3=math.sqrt(sigma2), dof=dof, force_range_n=(lo, hi), cycle_std_mm3=math.sqrt(tau2))
    return Eq5Fit(law, v0_fixed_mm3 is not None, force, freq, outliers=outliers, cycles=k_cycles,
                  cycle_std_n=math.sqrt(tau2) / slope_mid, cycle_prior_n=tau_prior_n, cycle_prior_given=given,
                  cycle_std_data_n=None if tau2_data is None else math.sqrt(tau2_data) / slope_mid)
