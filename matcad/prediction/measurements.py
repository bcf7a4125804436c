"""The data a lab measured on the taxels it built, and the forward models that predict each datum from a lab state
(:mod:`matcad.prediction.asbuilt`). Frequencies Hz, forces N, lengths mm, volumes mm³.

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
docs/inference.md gives the sources.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from matcad.prediction import asbuilt
from matcad.prediction.curves import cap_curve

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
    checks pass, or all of them) over :data:`~matcad.prediction.asbuilt.MODEL_ERROR_SIGMAS`."""
    from matcad.acoustics.registry import model_errors
    from matcad.acoustics.uncertainty import model_error_share

    return float(model_error_share(model_errors()[name], valid)) / asbuilt.MODEL_ERROR_SIGMAS


def drawing(spec) -> tuple:
    """The drawn geometry of a single-taxel spec (mm; :data:`matcad.spec.drawn.DRAWN`): two taxels of one drawing
    share the model's error exactly."""
    from matcad.spec.drawn import DRAWN

    return tuple(getattr(getattr(spec, table), name) for table, name in DRAWN.values())


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
    return extended_interp(np.asarray(forces_n, dtype=float), forces, f) / f[0]


def forces_at(curve, state: asbuilt.State, displacements_mm, zero_mm: float) -> np.ndarray:
    """The plate force (N) at plate travel ``displacements_mm`` read from a stage whose zero lies ``zero_mm``
    before first contact: the grade's ``curve`` scaled to the state's static modulus, 0 before contact."""
    scaled = asbuilt.built_curve(curve, state)
    x = np.asarray(displacements_mm, dtype=float) + zero_mm
    return np.where(x > 0, extended_interp(x, scaled.column("displacement_mm"), scaled.column("force_n")), 0.0)


def extended_interp(x, xp, fp) -> np.ndarray:
    """Linear interpolation on increasing ``xp``, extended linearly past both ends."""
    x = np.asarray(x, dtype=float)
    y = np.interp(x, xp, fp)
    if len(xp) > 1:
        hi = x > xp[-1]
        y = np.where(hi, fp[-1] + (x - xp[-1]) * (fp[-1] - fp[-2]) / (xp[-1] - xp[-2]), y)
    return y


def measured_curve(taxel: Taxel):
    """The grade's cap curve of a measured taxel, its travel extended to cover its data (computed once per case)."""
    import dataclasses

    from matcad.mechanics.case import cap_case

    case = cap_case(taxel.spec)
    need = max(taxel.displacements_mm, default=0.0) * 1.2 + 0.5
    if need > case.displacement_mm:
        free = case.section.height - case.section.flange_thickness
        case = dataclasses.replace(case, displacement_mm=min(need, 0.9 * free))
    return cap_curve(case)


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


class Problem:
    """The data of a lab and the residual vector of a standard-coordinate state (the state's z, then one stage
    zero per force–displacement series)."""

    def __init__(self, spec, data: list[Taxel]):
        from matcad.acoustics.design import design

        self.spec = spec
        self.data = data
        self.prior = asbuilt.priors(data[0].spec)  # the lab's, whatever design is predicted from it
        from matcad.acoustics import registry
        from matcad.acoustics.evaluation import Evaluation

        self.name = model_name(data[0].spec)
        self.designs = [design(t.spec) for t in data]
        # each taxel's model error: over every benchmark case where its drawing fails one of the model's checks
        self.sd_model = [model_sd(self.name, registry.model(self.name).result(Evaluation(d)).valid)
                         for d in self.designs]
        self.curves = [measured_curve(t) if t.mechanics else None for t in data]
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
