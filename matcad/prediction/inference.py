"""As-built inference: the lab state (:mod:`matcad.prediction.asbuilt`) that explains the taxels a lab built and
measured ([[measured]], and a [reference]; their data and forward models in :mod:`matcad.prediction.measurements`),
with intervals, what the data cannot tell apart, and predictions of new designs that carry the inference's
uncertainty. Frequencies Hz, lengths mm, volumes mm³.

The state is found where the sum of squared standardised residuals and prior terms is least (maximum a
posteriori; scipy's least_squares, the joined air bounded at zero); its covariance is the inverse of JᵀJ there
(Laplace). A prediction of any design is the model on that design built in that state, times the measured taxels'
f0 over the model's on their own drawings in that state (the model's error is mostly shared between designs); its
band combines the 95 % range of that over states drawn from that posterior, the model's own error, the air
temperature of use, part-to-part scatter and, where a cap mode makes a doublet, the other peak (docs/inference.md).
"""

from __future__ import annotations

import math

from dataclasses import dataclass, field

import numpy as np

from matcad.prediction import asbuilt
from matcad.prediction.measurements import (TEMPERATURE_SD_C, Problem, Residual, Taxel, design_of, drawing,
                                            f0_hz, model_sd, taxels)

PART_NECK_SD_MM = 0.03
"""Part-to-part scatter of one laser's neck holes (sd, mm) that no lab state can carry."""
CONFLICT_Z = 3.0
"""A parameter whose most probable value lies more than this many prior sd from its prior centre is reported as
a conflict: the drawing (or the grade's data) is off by more than shop tolerances."""
TOLD_APART = 0.5
"""A parameter the data pin to below this fraction of its prior sd is determined by the data."""
CORRELATED = 0.8
"""Two parameters whose posterior correlation exceeds this are what the data cannot tell apart."""
WEIGHT_SHOWN = 0.3
"""A parameter's weight in a fixed combination (a unit vector in standard coordinates) that the report names."""
FIT_TOLERANCE = 1e-10
Z95 = 1.959963984540054
"""Standard normal quantile of a 95 % two-sided range."""
SAMPLES = 100
DRAWS = 4
"""Draws made per kept sample (those past a parameter's bound are dropped)."""
PROPOSAL_WIDTH = 1.5
"""The proposal's sd over the Laplace posterior's: wider, so the weights reach the posterior's tails."""
"""Posterior states a prediction is evaluated on (its 95 % range from their 2.5 and 97.5 percentiles)."""
SAMPLE_SEED = 0


@dataclass(frozen=True)
class Inference:
    """What the measured taxels say of the lab: the most probable state, its covariance in standard coordinates
    (:func:`matcad.prediction.asbuilt.priors`), each datum's residual and the closed-form model used."""

    spec: object = field(repr=False)
    taxels: tuple[Taxel, ...]
    prior: np.ndarray = field(repr=False)
    z: np.ndarray = field(repr=False)
    covariance: np.ndarray = field(repr=False)
    information: np.ndarray = field(repr=False)
    residuals: tuple[Residual, ...]
    model: str
    chi2: float
    data_count: int

    @property
    def state(self) -> asbuilt.State:
        return asbuilt.state_at(self.z[:len(asbuilt.PARAMETERS)], self.prior)

    def sd_z(self) -> np.ndarray:
        n = len(asbuilt.PARAMETERS)
        return np.sqrt(np.diag(self.covariance)[:n])

    def intervals(self, level: float = 0.95) -> list[tuple[str, float, float, float]]:
        """(name, most probable, low, high) of every parameter at ``level`` (the Laplace interval in its standard
        coordinate, mapped through the parameter; bounded parameters clipped at their bound)."""
        from scipy.stats import norm

        q = float(norm.ppf(0.5 + level / 2))
        out = []
        for p, zi, sd, (c, s) in zip(asbuilt.PARAMETERS, self.z, self.sd_z(), self.prior):
            lo, hi = max(zi - q * sd, p.lower_z), zi + q * sd
            out.append((p.name, float(p.value(zi, c, s)), float(p.value(lo, c, s)), float(p.value(hi, c, s))))
        return out

    def correlation(self) -> np.ndarray:
        n = len(asbuilt.PARAMETERS)
        cov = self.covariance[:n, :n]
        sd = np.sqrt(np.diag(cov))
        return cov / np.outer(sd, sd)

    def combinations(self) -> list[tuple[float, dict]]:
        """The combinations of the lab's parameters the data fix: eigenvectors of the data's information (in
        standard coordinates) whose eigenvalue is at least the prior's (1), strongest first, as (eigenvalue,
        {parameter: weight} for weights of at least :data:`WEIGHT_SHOWN`)."""
        n = len(asbuilt.PARAMETERS)
        values, vectors = np.linalg.eigh(self.information[:n, :n])
        out = []
        for k in np.argsort(values)[::-1]:
            if values[k] < 1.0:
                break
            v = vectors[:, k] * np.sign(vectors[np.argmax(np.abs(vectors[:, k])), k])
            out.append((float(values[k]), {name: float(w) for name, w in zip(asbuilt.NAMES, v)
                                           if abs(w) >= WEIGHT_SHOWN}))
        return out

    def told_apart(self) -> dict:
        """What the data determine: per parameter its posterior sd over its prior sd; the combinations they fix
        (:meth:`combinations`); the parameters that share a fixed combination but are not each determined (the
        data cannot tell them apart); pairs whose posterior correlation exceeds :data:`CORRELATED`; and the
        parameters further than :data:`CONFLICT_Z` prior sd from the prior's centre."""
        names = asbuilt.NAMES
        shrink = dict(zip(names, (float(x) for x in self.sd_z())))
        rho = self.correlation()
        pairs = [(names[i], names[j], float(rho[i, j])) for i in range(len(names)) for j in range(i + 1, len(names))
                 if abs(rho[i, j]) > CORRELATED]
        combos = self.combinations()
        confounded = [sorted(w for w in weights if shrink[w] >= TOLD_APART) for _, weights in combos]
        return {"posterior_over_prior_sd": shrink,
                "determined": [n for n in names if shrink[n] < TOLD_APART],
                "combinations": [{"information": e, "weights": w} for e, w in combos],
                "not_told_apart": [c for c in confounded if len(c) > 1],
                "correlated": pairs,
                "beyond_tolerance": [n for n, zi in zip(names, self.z) if abs(zi) > CONFLICT_Z]}

    def samples(self) -> tuple[np.ndarray, np.ndarray]:
        """(states in standard coordinates, their normalised weights): :data:`SAMPLES` draws from the Laplace
        approximation widened :data:`PROPOSAL_WIDTH` times (fixed draws, so a prediction is reproducible; draws
        past a bound are dropped), each weighted by the exact posterior over the proposal (importance sampling: the
        prior times the data's likelihood, which the linearisation cannot see where the model jumps between a
        doublet's peaks)."""
        n = len(asbuilt.PARAMETERS)
        lower = np.array([p.lower_z for p in asbuilt.PARAMETERS])
        draws = np.random.default_rng(SAMPLE_SEED).standard_normal((DRAWS * SAMPLES, n))
        root = np.linalg.cholesky(PROPOSAL_WIDTH ** 2 * self.covariance[:n, :n] + 1e-12 * np.eye(n))
        z = self.z[:n] + draws @ root.T
        keep = np.flatnonzero((z >= lower).all(axis=1))[:SAMPLES]
        z, draws = z[keep], draws[keep]
        problem = Problem(self.spec, list(self.taxels))
        log_p = np.array([-0.5 * float(np.sum(problem.residuals(np.concatenate([zi, self.z[n:]])) ** 2))
                          for zi in z])
        log_w = log_p + 0.5 * np.sum(draws ** 2, axis=1)
        w = np.exp(log_w - log_w.max())
        return z, w / w.sum()

    def effective_samples(self) -> float:
        """Kish's effective sample size of :meth:`samples`' weights (1/Σw²): how many of them carry the band."""
        _, w = self.samples()
        return float(1.0 / np.sum(w ** 2))

    def level_factors(self, zs) -> np.ndarray:
        """Per state (rows of standard coordinates ``zs``): the measured taxels' f0 over the model's on their
        drawings built in that state, at their air (inverse-variance mean over the taxels with an f0; 1 where none
        has one). The model's error is mostly shared between designs: in the virtual lab with the hidden state
        known, the model's ratio between two designs misses the FEM by a median 0.69 %, its f0 by 1.37 %
        (docs/inference.md). So a prediction carries what the model misses on the measured taxels, as the
        'relative' model carries a [reference]."""
        with_f0 = [(t, d) for t, d in zip(self.taxels, (design_of(t.spec) for t in self.taxels))
                   if t.f0_hz is not None]
        if not with_f0:
            return np.ones(len(zs))
        weights = np.array([(t.f0_hz / max(t.f0_sd_hz, 1e-9)) ** 2 for t, _ in with_f0])
        ratios = np.array([[t.f0_hz / f0_hz(d, asbuilt.state_at(z, self.prior), self.model) for t, d in with_f0]
                           for z in zs])
        return ratios @ weights / weights.sum()

    def predict(self, spec) -> PredictedF0:
        """f0 of the single-taxel ``spec`` built by this lab (Hz): the posterior median of the model over the
        lab's states times their :meth:`level_factors` (not the most probable state's: near a cap mode one state's
        model may sit on a doublet's other peak), the 95 % range over the posterior's states (importance-weighted
        samples), the model's own error (over every benchmark case when the built design fails one of its checks),
        the air temperature of use, part-to-part scatter, and the doublet's other peak when the built design has
        one. A drawing that was measured is its measurement (the inverse-variance mean of its taxels' f0, at this
        air), not the model."""
        from matcad.acoustics import registry
        from matcad.acoustics.evaluation import Evaluation
        from matcad.acoustics.resonator import elastic_wall_doublet_hz, resonator

        d = design_of(spec)
        zs, weights = self.samples()
        fs = np.array([f0_hz(d, asbuilt.state_at(z, self.prior), self.model) for z in zs]) * self.level_factors(zs)
        f, low, high = weighted_quantiles(fs, weights, (0.5, 0.025, 0.975))
        low, high = low - f, high - f
        temperature = 0.0 if d.air.speed_of_sound_m_s else TEMPERATURE_SD_C / (d.air.temperature_c + 273.15) * f / 2
        built = asbuilt.built(d, self.state)
        up = f0_hz(built.replace(neck_diameter=built.neck_diameter + PART_NECK_SD_MM), asbuilt.State(), self.model)
        part = abs(up - f0_hz(built, asbuilt.State(), self.model))
        checks = registry.model(self.model).result(Evaluation(built)).checks
        failed = tuple(name for name, ok in checks.items() if not ok)
        doublet = None
        if self.model == "elastic_wall":
            shear, loss = registry.model(self.model).wall_arguments(built.wall)
            doublet = elastic_wall_doublet_hz(resonator(built), shear, loss)
        same = [t for t in self.taxels if t.f0_hz is not None and drawing(t.spec) == drawing(spec)]
        if same:  # a drawing that was measured: its measurement, carried to this air (f follows sqrt(T))
            kelvin = d.air.temperature_c + 273.15
            fs = np.array([t.f0_hz * np.sqrt(kelvin / (t.temperature_c + 273.15)) for t in same])
            w = 1.0 / np.array([max(t.f0_sd_hz, 1e-9) ** 2 for t in same])
            f = float(np.sum(w * fs) / np.sum(w))
            half = Z95 / math.sqrt(float(np.sum(w)))
            return PredictedF0(f, -half, half, self.model, 0.0, temperature, part, failed, None,
                               tuple(t.name for t in same))
        return PredictedF0(f, float(min(low, 0.0)), float(max(high, 0.0)), self.model,
                           model_sd(self.model, not failed) * f, temperature, part, failed, doublet)

    def to_dict(self) -> dict:
        return {"model": self.model, "data": self.data_count, "chi2": self.chi2,
                "taxels": [t.name for t in self.taxels],
                "state": {name: {"value": v, "low_95": lo, "high_95": hi}
                          for name, v, lo, hi in self.intervals()},
                "told_apart": self.told_apart(),
                "residuals": [{"taxel": r.taxel, "what": r.what, "measured": r.measured, "modelled": r.modelled,
                               "sd": r.sd, "z": r.z} for r in self.residuals]}

    def to_text(self) -> str:
        """What `matcad infer` prints: the state with 95 % intervals, what the data determine and cannot tell
        apart, and how each datum is fitted."""
        units = {p.name: p.unit for p in asbuilt.PARAMETERS}
        docs = {p.name: p.doc for p in asbuilt.PARAMETERS}
        told = self.told_apart()
        lines = [f"as-built state from {len(self.taxels)} measured taxel(s), {self.data_count} data "
                 f"(model {self.model}; chi^2 {self.chi2:.2f}):"]
        for name, v, lo, hi in self.intervals():
            shrink = told["posterior_over_prior_sd"][name]
            lines.append(f"  {name:<22} {v:9.4g} {units[name]:<5} 95 % {lo:.4g} to {hi:.4g}   "
                         f"(sd {100 * shrink:3.0f} % of prior)  {docs[name]}")
        lines.append("  determined by the data: " + (", ".join(told["determined"]) or "none"))
        for combo in told["combinations"]:
            terms = " ".join(f"{w:+.2f} {name}" for name, w in combo["weights"].items())
            lines.append(f"  the data fix: {terms} (information {combo['information']:.3g} x the prior's)")
        for group in told["not_told_apart"]:
            lines.append(f"  cannot tell apart: {', '.join(group)} (they move f together in what was measured)")
        for a, b, rho in told["correlated"]:
            lines.append(f"  correlated: {a} and {b} ({rho:+.2f})")
        for name in told["beyond_tolerance"]:
            lines.append(f"  {name}: further from its prior than shop tolerances allow (> {CONFLICT_Z:g} sd): the "
                         "drawing or the grade's data may be off")
        lines.append("  fit:")
        lines += [f"    {r.taxel:<10} {r.what:<26} measured {r.measured:10.4g}  model {r.modelled:10.4g}  "
                  f"({r.z:+.2f} sd)" for r in self.residuals]
        return "\n".join(lines)


@dataclass(frozen=True)
class PredictedF0:
    """A design's f0 built in an inferred state (Hz) and its uncertainty by source: the 95 % range over the
    posterior's states (offsets, low ≤ 0 ≤ high), the model's own error (sd; over every benchmark case where the
    built design fails one of the model's checks, named in ``failed_checks``), the air temperature of use and
    part-to-part scatter (sd), the other peak of a doublet (None: one peak wins), and the measured taxels whose
    drawing this is (then f0 and its range are theirs)."""

    f0_hz: float
    state_low_hz: float
    state_high_hz: float
    model: str
    model_sd_hz: float
    temperature_sd_hz: float
    part_sd_hz: float
    failed_checks: tuple[str, ...] = ()
    doublet_hz: float | None = None
    measured: tuple[str, ...] = ()


def weighted_quantiles(values, weights, qs) -> np.ndarray:
    """Quantiles ``qs`` (0-1) of ``values`` carrying normalised ``weights`` (the weighted empirical distribution,
    interpolated between the midpoints of the sorted values' weights)."""
    order = np.argsort(values)
    v, w = np.asarray(values, dtype=float)[order], np.asarray(weights, dtype=float)[order]
    cdf = np.cumsum(w) - 0.5 * w
    return np.interp(qs, cdf, v)


_CACHE: dict = {}
"""Inferences by their data: one fit per lab per process (a design search asks for many predictions)."""


def infer(spec, free: tuple[str, ...] | None = None) -> Inference:
    """The as-built inference of ``spec``'s measured taxels ([[measured]], [reference]); ValueError without any.
    ``free`` names the parameters the data may move (default all of :data:`matcad.prediction.asbuilt.PARAMETERS`):
    the others stay at their prior's centre, which tests one explanation against another (docs/paper.md)."""
    data = taxels(spec)
    if not data:
        raise ValueError(f"{spec.name} has no [[measured]] taxel or [reference] to infer an as-built state from")
    unknown = set(free or ()) - set(asbuilt.NAMES)
    if unknown:
        raise ValueError(f"no as-built parameter {', '.join(sorted(unknown))}; they are {', '.join(asbuilt.NAMES)}")
    key = (free, tuple((t.name, t.spec, t.temperature_c, t.temperature_stated, t.f0_hz, t.f0_sd_hz, t.forces_n,
                        t.f_hz, t.displacements_mm, t.displacement_forces_n, t.neck_diameter_mm, t.neck_taper_mm,
                        t.sheet_mm) for t in data))
    if key not in _CACHE:
        _CACHE[key] = _fit(spec, data, free)
    return _CACHE[key]


def _fit(spec, data: list[Taxel], free: tuple[str, ...] | None) -> Inference:
    from scipy.optimize import least_squares

    problem = Problem(spec, data)
    n = len(asbuilt.PARAMETERS)
    moving = np.array([free is None or name in free for name in asbuilt.NAMES] + [True] * (problem.size - n))

    def whole(x):
        z = np.zeros(problem.size)
        z[moving] = x
        return z

    lower = problem.lower[moving]
    x0 = np.where(lower > -np.inf, 0.5, 0.0)  # a bounded parameter starts inside its bound
    result = least_squares(lambda x: problem.residuals(whole(x)), x0, bounds=(lower, np.full(len(x0), np.inf)),
                           x_scale=1.0, xtol=FIT_TOLERANCE, ftol=FIT_TOLERANCE, gtol=FIT_TOLERANCE, diff_step=1e-4)
    jac = np.zeros((len(result.fun), problem.size))
    jac[:, moving] = result.jac
    covariance = np.linalg.pinv(jac.T @ jac)
    z = whole(result.x)
    explained = problem.residuals(z, explain=True)
    data_jac = jac[:len(explained)]
    chi2 = float(sum(r.z ** 2 for r in explained))
    return Inference(spec, tuple(data), problem.prior, z, covariance, data_jac.T @ data_jac,
                     tuple(explained), problem.name, chi2, len(explained))
