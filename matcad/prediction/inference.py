"""As-built inference: the lab state (:mod:`matcad.prediction.asbuilt`) that explains the taxels a lab built and
measured ([[measured]], and a [reference]), with intervals, what the data cannot tell apart, and predictions of new
designs that carry the inference's uncertainty. Frequencies Hz, forces N, lengths mm, volumes mm³.

Data and their forward models (docs/inference.md):
- unloaded f0 of a measured taxel: the registry's chosen closed-form model for the wall
  (:data:`matcad.acoustics.registry.CHOSEN`) on the built design, at the measurement's air temperature; sd² =
  its stated sd² + (model error · f)² (the model's max |error| against the FEM, taken as 2 sd) + (air temperature
  · df/dT)² when the temperature was not stated;
- f(F) pairs: the ratios f(F)/f(F_first) along the cap mechanics' curve of that taxel with forces scaled by the
  static modulus (exact for these hyperelastic laws) and the transmission line on the deformed cavity with the
  state's neck and joined air (the joined air dilutes the shift); sd of a ratio from two points' sd and
  :data:`SHIFT_SD` of the shift (the mechanics' mesh and route);
- force–displacement pairs: the curve's F(x − x₀) times the static scale, x₀ the stage's unknown zero per series
  (prior sd :data:`STAGE_ZERO_SD_MM`); sd :data:`FORCE_SD` (relative and absolute, in quadrature);
- measured dimensions of a taxel: its neck (pin gauges), taper, calipered sheet.
The state is found where the sum of squared standardised residuals and prior terms is least (maximum a
posteriori; scipy's least_squares, the joined air bounded at zero); its covariance is the inverse of JᵀJ there
(Laplace). A prediction of any design is the model on that design built in that state; its band combines the
95 % range of the model over states drawn from that posterior, the model's own error, the air temperature of use,
part-to-part scatter and, where a cap mode makes a doublet, the other peak.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from matcad.prediction import asbuilt

SHIFT_SD = 0.10
"""Relative sd of a predicted frequency shift under load: the cap mechanics' default mesh is 2–2.5 % stiff and the
transmission line on the deformed cavity's equivalent cylinder is a route, not the FEM (docs/mechanics.md)."""
FORCE_SD = (0.05, 0.2)
"""sd of a measured force: 5 % (seating, the plate's tilt) and 0.2 N (load cell), in quadrature."""
STAGE_ZERO_SD_MM = 0.5
"""Prior sd of where a force–displacement series' zero lies from first contact (mm)."""
TEMPERATURE_SD_C = 3.0 / 1.96
"""sd of the air temperature of a measurement that did not state one: the budget's ±3 °C day-to-day swing taken as
its 95 % range."""
PART_NECK_SD_MM = 0.03
"""Part-to-part scatter of one laser's neck holes (sd, mm) that no lab state can carry."""
MODEL_ERROR_SIGMAS = 2.0
"""A model's max |error| against the FEM (model_errors.json) is taken as this many sd of its error."""
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
SAMPLES = 100
"""Posterior states a prediction is evaluated on (its 95 % range from their 2.5 and 97.5 percentiles)."""
SAMPLE_SEED = 0


@dataclass(frozen=True)
class Taxel:
    """One measured taxel's data: its name, the spec of its drawing (:func:`matcad.spec.measured.measured_spec`),
    the air temperature (°C) it was measured at and whether that was stated, f0 ± sd (Hz), f(F) pairs, F(x) pairs
    and what was measured of its dimensions (mm; None: not measured)."""

    name: str
    spec: object
    temperature_c: float
    temperature_stated: bool
    f0_hz: float | None = None
    f0_sd_hz: float = 0.0
    forces_n: tuple[float, ...] = ()
    f_hz: tuple[float, ...] = ()
    displacements_mm: tuple[float, ...] = ()
    displacement_forces_n: tuple[float, ...] = ()
    neck_diameter_mm: float | None = None
    neck_taper_mm: float | None = None
    sheet_mm: float | None = None

    @property
    def mechanics(self) -> bool:
        return bool(self.forces_n) or bool(self.displacements_mm)


def taxels(spec) -> list[Taxel]:
    """The measured taxels of ``spec``: each [[measured]] entry, then the [reference] (its f0 ± tolerance as a
    standard uncertainty)."""
    import dataclasses

    from matcad.spec import reference_spec
    from matcad.spec.measured import measured_spec

    out = []
    for i, e in enumerate(spec.measured, 1):
        s = measured_spec(spec, e)
        stated = e.temperature_c is not None
        if stated:
            s = dataclasses.replace(s, air=dataclasses.replace(s.air, temperature_c=e.temperature_c))
        out.append(Taxel(e.name or f"m{i}", s, s.air.temperature_c, stated, e.f0_hz, e.f0_tolerance_hz,
                         e.force_n or (), e.f_hz or (), e.displacement_mm or (), e.displacement_force_n or (),
                         e.measured_neck_diameter, e.measured_neck_taper, e.measured_sheet))
    if spec.reference is not None:
        ref = reference_spec(spec)
        out.append(Taxel("reference", dataclasses.replace(ref, measured=()), ref.air.temperature_c, False,
                         spec.reference.f0_hz, spec.reference.f0_tolerance_hz))
    return out


# ---------------------------------------------------------------- forward models
def model_name(spec) -> str:
    """The closed-form model the inference uses for ``spec``'s wall: the registry's choice."""
    from matcad.acoustics.registry import CHOSEN

    return CHOSEN[spec.wall.model]


def model_sd(name: str, valid: bool = True) -> float:
    """Relative sd of model ``name``'s f0 against the FEM: its max |error| over the benchmark geometries (where its
    checks pass, or all of them) over :data:`MODEL_ERROR_SIGMAS`."""
    from matcad.acoustics.registry import model_errors
    from matcad.acoustics.uncertainty import model_error_share

    return float(model_error_share(model_errors()[name], valid)) / MODEL_ERROR_SIGMAS


def design_of(spec):
    """The :class:`~matcad.acoustics.design.Design` of a single-taxel spec."""
    from matcad.acoustics.design import design

    return design(spec)


def f0_hz(d, state: asbuilt.State, name: str) -> float:
    """f0 (Hz) of design ``d`` built in ``state`` by the closed-form model ``name``."""
    from matcad.acoustics import registry
    from matcad.acoustics.resonator import resonator

    b = asbuilt.built(d, state)
    return float(registry.model(name).f0_hz(resonator(b), b.wall))


def shift_ratios(d, state: asbuilt.State, curve, forces_n) -> np.ndarray:
    """f(F)/f(0) at ``forces_n`` (N) of design ``d`` built in ``state``, along the grade's cap ``curve`` scaled to
    the state's static modulus: the transmission line on the deformed cavity's equivalent cylinder with the
    state's neck and joined air (:func:`matcad.mechanics.frequency.force_curve`'s route); past the curve's last
    force, extrapolated along its last segment."""
    from matcad.acoustics import registry
    from matcad.acoustics.resonator import resonator
    from matcad.mechanics.frequency import deformed_resonator, equivalent_length_mm

    b = asbuilt.built(d, state)
    scaled = asbuilt.built_curve(curve, state)
    res = resonator(b)
    line = registry.model("transmission_line")
    outlines = [curve.unloaded_outline] + [s.cavity_outline for s in curve.steps]
    forces = scaled.column("force_n")
    volumes = scaled.column("cavity_volume_mm3")
    lengths = np.array([equivalent_length_mm(curve.split(o)[1]) for o in outlines])
    f = np.array([float(line.f0_hz(deformed_resonator(res, v, le, b.neck_diameter)))
                  for v, le in zip(volumes, lengths)])
    return _interp(np.asarray(forces_n, dtype=float), forces, f) / f[0]


def forces_at(curve, state: asbuilt.State, displacements_mm, zero_mm: float) -> np.ndarray:
    """The plate force (N) at plate travel ``displacements_mm`` read from a stage whose zero lies ``zero_mm``
    before first contact: the grade's ``curve`` scaled to the state's static modulus, 0 before contact."""
    scaled = asbuilt.built_curve(curve, state)
    x = np.asarray(displacements_mm, dtype=float) + zero_mm
    return np.where(x > 0, _interp(x, scaled.column("displacement_mm"), scaled.column("force_n")), 0.0)


def _interp(x, xp, fp) -> np.ndarray:
    """Linear interpolation on increasing ``xp``, extended linearly past both ends."""
    x = np.asarray(x, dtype=float)
    y = np.interp(x, xp, fp)
    if len(xp) > 1:
        hi = x > xp[-1]
        y = np.where(hi, fp[-1] + (x - xp[-1]) * (fp[-1] - fp[-2]) / (xp[-1] - xp[-2]), y)
    return y


def _curve(taxel: Taxel):
    """The grade's cap curve of a measured taxel, its travel extended to cover its data (computed once per case)."""
    import dataclasses

    from matcad.mechanics.case import cap_case
    from matcad.prediction.taxel import cap_curve

    case = cap_case(taxel.spec)
    need = max(taxel.displacements_mm, default=0.0) * 1.2 + 0.5
    if need > case.displacement_mm:
        free = case.section.height - case.section.flange_thickness
        case = dataclasses.replace(case, displacement_mm=min(need, 0.9 * free))
    return cap_curve(case)


# ---------------------------------------------------------------- the fit
@dataclass(frozen=True)
class Residual:
    """One datum's standardised residual, for the report: which taxel, what, measured, modelled, sd."""

    taxel: str
    what: str
    measured: float
    modelled: float
    sd: float

    @property
    def z(self) -> float:
        return (self.modelled - self.measured) / self.sd


class _Problem:
    """The data of a lab and the residual vector of a standard-coordinate state (the state's z, then one stage
    zero per force–displacement series)."""

    def __init__(self, spec, data: list[Taxel]):
        from matcad.acoustics.design import design

        self.spec = spec
        self.data = data
        self.prior = asbuilt.priors(spec)
        from matcad.acoustics import registry
        from matcad.acoustics.evaluation import Evaluation

        self.name = model_name(spec)
        self.designs = [design(t.spec) for t in data]
        # each taxel's model error: over every benchmark case where its drawing fails one of the model's checks
        self.sd_model = [model_sd(self.name, registry.model(self.name).result(Evaluation(d)).valid)
                         for d in self.designs]
        self.curves = [_curve(t) if t.mechanics else None for t in data]
        self.zeros = [i for i, t in enumerate(data) if t.displacements_mm]
        self.temperature_sd = []  # relative f sd from an unstated measurement temperature
        for t in data:
            self.temperature_sd.append(0.0 if t.temperature_stated or t.spec.air.speed_of_sound
                                       else 0.5 * TEMPERATURE_SD_C / (t.temperature_c + 273.15))
        n = len(asbuilt.PARAMETERS)
        self.lower = np.array([p.lower_z for p in asbuilt.PARAMETERS] + [-np.inf] * len(self.zeros))
        self.size = n + len(self.zeros)

    def state(self, z) -> asbuilt.State:
        return asbuilt.state_at(z[:len(asbuilt.PARAMETERS)], self.prior)

    def residuals(self, z, explain: bool = False):
        s = self.state(z)
        out: list = []
        n = len(asbuilt.PARAMETERS)
        for i, (t, d) in enumerate(zip(self.data, self.designs)):
            f0 = f0_hz(d, s, self.name) if t.f0_hz is not None or t.forces_n else None
            rel = math.hypot(self.sd_model[i], self.temperature_sd[i])
            if t.f0_hz is not None:
                out.append(Residual(t.name, "f0 [Hz]", t.f0_hz, f0, math.hypot(t.f0_sd_hz, rel * t.f0_hz)))
            if t.forces_n:
                forces = np.asarray(t.forces_n)
                order = np.argsort(forces, kind="stable")
                first = order[0]
                ratios = shift_ratios(d, s, self.curves[i], forces)
                model_f = ratios / ratios[first]
                meas = np.asarray(t.f_hz) / t.f_hz[first]
                if t.f0_hz is None:  # the series' first point carries the level
                    out.append(Residual(t.name, f"f({forces[first]:g} N) [Hz]", t.f_hz[first],
                                        f0 * ratios[first], math.hypot(t.f0_sd_hz, rel * t.f_hz[first])))
                for j in order[1:]:
                    sd = math.hypot(math.sqrt(2) * t.f0_sd_hz / t.f_hz[j], SHIFT_SD * abs(model_f[j] - 1))
                    out.append(Residual(t.name, f"f({forces[j]:g} N)/f({forces[first]:g} N)", meas[j], model_f[j],
                                        sd))
            if t.displacements_mm:
                k = self.zeros.index(i)
                zero = STAGE_ZERO_SD_MM * z[n + k]
                model_force = forces_at(self.curves[i], s, t.displacements_mm, zero)
                for x, fm, fx in zip(t.displacements_mm, t.displacement_forces_n, model_force):
                    sd = math.hypot(FORCE_SD[0] * fm, FORCE_SD[1])
                    out.append(Residual(t.name, f"F({x:g} mm) [N]", fm, float(fx), sd))
            for value, what, modelled, sd in (
                    (t.neck_diameter_mm, "neck diameter [mm]", t.spec.neck.diameter + s.neck_offset_mm,
                     asbuilt.MEASUREMENT_SD["neck_diameter"]),
                    (t.neck_taper_mm, "neck taper [mm]", s.neck_taper_mm, asbuilt.MEASUREMENT_SD["neck_taper"]),
                    (t.sheet_mm, "sheet [mm]", t.spec.neck.length + s.sheet_offset_mm,
                     asbuilt.MEASUREMENT_SD["sheet"])):
                if value is not None:
                    out.append(Residual(t.name, what, value, modelled, sd))
        if explain:
            return out
        return np.concatenate([[r.z for r in out], z])


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

    def samples(self) -> np.ndarray:
        """:data:`SAMPLES` states drawn from the Laplace posterior in standard coordinates (fixed draws, so a
        prediction is reproducible), bounded parameters clipped at their bound."""
        n = len(asbuilt.PARAMETERS)
        draws = np.random.default_rng(SAMPLE_SEED).standard_normal((SAMPLES, n))
        root = np.linalg.cholesky(self.covariance[:n, :n] + 1e-12 * np.eye(n))
        z = self.z[:n] + draws @ root.T
        return np.maximum(z, [p.lower_z for p in asbuilt.PARAMETERS])

    def predict(self, spec) -> PredictedF0:
        """f0 of the single-taxel ``spec`` built by this lab (Hz): the model on the most probable state, the 95 %
        range over the posterior's states (sampled: a state may tip a doublet to its other peak), the model's own
        error (over every benchmark case when the built design fails one of its checks), the air temperature of
        use, part-to-part scatter, and the doublet's other peak when the built design has one."""
        from matcad.acoustics import registry
        from matcad.acoustics.evaluation import Evaluation
        from matcad.acoustics.resonator import elastic_wall_doublet_hz, resonator

        d = design_of(spec)
        f = f0_hz(d, self.state, self.model)
        fs = np.array([f0_hz(d, asbuilt.state_at(z, self.prior), self.model) for z in self.samples()])
        low, high = np.percentile(fs, [2.5, 97.5]) - f
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
    part-to-part scatter (sd), and the other peak of a doublet (None: one peak wins)."""

    f0_hz: float
    state_low_hz: float
    state_high_hz: float
    model: str
    model_sd_hz: float
    temperature_sd_hz: float
    part_sd_hz: float
    failed_checks: tuple[str, ...] = ()
    doublet_hz: float | None = None


_CACHE: dict = {}
"""Inferences by their data: one fit per lab per process (a design search asks for many predictions)."""


def infer(spec) -> Inference:
    """The as-built inference of ``spec``'s measured taxels ([[measured]], [reference]); ValueError without any."""
    data = taxels(spec)
    if not data:
        raise ValueError(f"{spec.name} has no [[measured]] taxel or [reference] to infer an as-built state from")
    key = tuple((t.name, t.spec, t.temperature_c, t.temperature_stated, t.f0_hz, t.f0_sd_hz, t.forces_n, t.f_hz,
                 t.displacements_mm, t.displacement_forces_n, t.neck_diameter_mm, t.neck_taper_mm, t.sheet_mm)
                for t in data)
    if key not in _CACHE:
        _CACHE[key] = _fit(spec, data)
    return _CACHE[key]


def _fit(spec, data: list[Taxel]) -> Inference:
    from scipy.optimize import least_squares

    problem = _Problem(spec, data)
    z0 = np.zeros(problem.size)
    z0[problem.lower > -np.inf] = 0.5  # a bounded parameter starts inside its bound
    result = least_squares(problem.residuals, z0, bounds=(problem.lower, np.full(problem.size, np.inf)),
                           x_scale=1.0, xtol=FIT_TOLERANCE, ftol=FIT_TOLERANCE, gtol=FIT_TOLERANCE, diff_step=1e-4)
    jac = result.jac
    covariance = np.linalg.pinv(jac.T @ jac)
    explained = problem.residuals(result.x, explain=True)
    data_jac = jac[:len(explained)]
    chi2 = float(sum(r.z ** 2 for r in explained))
    return Inference(spec, tuple(data), problem.prior, result.x, covariance, data_jac.T @ data_jac,
                     tuple(explained), problem.name, chi2, len(explained))
