"""One taxel's unloaded f0 onto a target: stock sheet first, then the continuous fields by root finding.

The model is the one `matcad predict` chooses for the spec (transmission line, elastic wall, the spec's measured
anchor — its calibration or its lab's as-built state — or the measured reference times its ratio), evaluated on its
own (milliseconds); the answer is then confirmed by
:func:`matcad.prediction.predict` and held to the design rules (:func:`matcad.rules.check`).

With several continuous fields there are many solutions; the solver moves them together along the steepest
route in log space, x_i(t) = x_i0 · exp(t · g_i) with g_i = ∂ln f/∂ln x_i at the start (the least relative change
to first order), restricted to every field's range, scans f along it and refines the root nearest the start with
Brent's method (scipy.optimize.brentq). ``neck.length`` is a sheet: it is chosen among the stock thicknesses
(:data:`matcad.parts.features.STOCK_ACRYLIC_MM`) nearest the start first, and the continuous fields solved for each
until one passes the rules. ``neck.riser`` (a spec with a [riser]) is the taxel's own choice between its two neck
lengths: on each sheet the continuous fields are solved with the neck through the riser and with the cap in a
pocket of it, and the way whose passing root lies nearest the start (least |t|: the least change of the continuous
fields) is kept; a way whose cap the cap mechanics cannot press as [mechanics] asks (:func:`unpressable`: a pocket
of a thick riser leaves little cap above the clamp) is passed over when the spec's loaded band needs them. Without
continuous fields the discrete choice whose f0 is nearest the target is kept. Frequencies Hz, lengths mm.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from matcad.design import RulesFailed, Unreachable
from matcad.prediction.anchor import ANCHORS, anchor, available

CONTINUOUS = ("neck.diameter", "cavity.diameter", "cavity.length")
SHEET = "neck.length"
RISER = "neck.riser"
"""The taxel's neck through the spec's [riser] (neck.length + riser.thickness long) or its cap in a pocket of it."""
DISCRETE = (SHEET, RISER)
FIELDS = CONTINUOUS + DISCRETE
SCAN_POINTS = 33
"""Points scanned along the route for sign changes of f − target (f may not be monotonic near a wall mode)."""
XTOL = 1e-10
"""Brent's tolerance on the route parameter t (ln units): far below the 0.5 % the design must hit."""
DEFAULT_LENGTH_SPAN = 3.0
"""Default cavity.length range: [PANCAKE_L_OVER_D · D, this × the starting length] (give FIELD=LO:HI for another)."""


@dataclass(frozen=True)
class Solution:
    """A solved spec: the target and the f0 ``predict`` gives it (Hz), the relative error, each varied field
    (start, solved) in mm, the model used, the run time (s) and model evaluations, the rule findings and notes."""

    spec: object
    target_hz: float
    f0_hz: float
    model: str
    fields: dict
    seconds: float
    evaluations: int
    findings: tuple
    notes: tuple = ()

    @property
    def error(self) -> float:
        return self.f0_hz / self.target_hz - 1

    def to_dict(self) -> dict:
        return {"name": self.spec.name, "target_hz": self.target_hz, "f0_hz": self.f0_hz, "error": self.error,
                "model": self.model, "fields": {k: {"start": a, "solved": b} for k, (a, b) in self.fields.items()},
                "seconds": self.seconds, "evaluations": self.evaluations, "notes": list(self.notes),
                "findings": [f.to_dict() for f in self.findings]}

    def to_text(self) -> str:
        """What `matcad design --target-hz` prints: f0 by predict against the target (Hz), the error, each varied
        field's start and solution (mm), the run time and the notes."""
        fields = ", ".join(f"{k} {field_text(k, a) if k == RISER else format(a, 'g')} -> "
                           f"{field_text(k, b, self.spec)}" for k, (a, b) in self.fields.items())
        lines = [f"{self.spec.name}: f0 = {self.f0_hz:.1f} Hz by predict ({self.model}) for target "
                 f"{self.target_hz:g} Hz, error {100 * self.error:+.3f} %; {fields}; {self.seconds:.2f} s, "
                 f"{self.evaluations} model evaluations"]
        return "\n".join(lines + [f"  note: {n}" for n in self.notes])


def field_text(path: str, value, spec=None) -> str:
    """One varied field's value as `design` prints it: a length (mm), or for :data:`RISER` the taxel's way, with
    its neck's length when the solved ``spec`` is given (its plate sheet, plus its [riser] through it; mm)."""
    if path != RISER:
        return f"{value:.4g} mm"
    from matcad.spec import neck_length_mm

    way = "neck through the riser" if value else "cap in a riser pocket"
    return way if spec is None else f"{way}, neck {neck_length_mm(spec):.4g} mm"


def get_field(spec, path: str) -> float:
    section, name = path.split(".")
    return getattr(getattr(spec, section), name)


def with_fields(spec, values: dict):
    """``spec`` with dotted fields set (lengths mm, :data:`RISER` a bool), validated (SpecError on an impossible
    geometry, e.g. neck > cavity)."""
    sections: dict[str, dict] = {}
    for path, value in values.items():
        section, name = path.split(".")
        sections.setdefault(section, {})[name] = value if isinstance(value, bool) else float(value)
    return dataclasses.replace(spec, **{s: dataclasses.replace(getattr(spec, s), **v) for s, v in sections.items()})


def default_range(spec, path: str) -> tuple[float, float]:
    """The search range of one field (mm) when the user gives none: the neck between the laser's smallest feature
    and the cavity; the cavity between the neck and the cap's outside less the thinnest silicone wall that demolds
    (:data:`matcad.rules.printing.MIN_SILICONE_WALL_MM` each side: issue 24's 12-taxel design had caps with 0.09 mm
    walls); its length from the flat-cavity limit of the 1-D models (L/D = 0.3) to :data:`DEFAULT_LENGTH_SPAN` × the
    start."""
    from matcad.acoustics.checks import PANCAKE_L_OVER_D
    from matcad.rules.printing import MIN_SILICONE_WALL_MM

    if path == "neck.diameter":
        return spec.machine.laser_min_feature, spec.cavity.diameter
    if path == "cavity.diameter":
        return spec.neck.diameter, spec.end_cap.outer_diameter - 2 * MIN_SILICONE_WALL_MM
    if path == "cavity.length":
        return PANCAKE_L_OVER_D * spec.cavity.diameter, DEFAULT_LENGTH_SPAN * spec.cavity.length
    raise AssertionError(path)


def parse_vary(spec, items, allowed=FIELDS) -> dict[str, tuple[float, float] | None]:
    """``--vary`` items, FIELD or FIELD=LO:HI (mm), as {field: range or None (default)}; ValueError naming the
    item and what is allowed."""
    out: dict[str, tuple[float, float] | None] = {}
    for item in items:
        path, _, rng = item.partition("=")
        if path not in allowed:
            why = f" ({SHEET} is the plate's sheet, shared by every taxel of a board)" if path == SHEET else ""
            raise ValueError(f"--vary {item}: field must be one of {', '.join(allowed)}{why}")
        if path in out:
            raise ValueError(f"--vary {path} given twice")
        if path == RISER and spec.riser is None:
            raise ValueError(f"--vary {item}: {RISER} chooses whether a taxel's neck runs on through a riser sheet, "
                             "and this spec has none; add a [riser] table: [riser] thickness = T (mm, a stock acrylic "
                             "sheet stacked on the plate under the caps)")
        if not rng:
            out[path] = None
            continue
        if path in DISCRETE:
            what = ("a sheet, chosen among the stock thicknesses" if path == SHEET
                    else "a choice, the neck through the riser or the cap in a pocket of it")
            raise ValueError(f"--vary {item}: {path} is {what}; give it without a range")
        try:
            lo, hi = (float(v) for v in rng.split(":"))
        except ValueError:
            lo = hi = math.nan
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ValueError(f"--vary {item}: range must be LO:HI in mm with 0 < LO < HI")
        out[path] = (lo, hi)
    if not out:
        raise ValueError(f"--vary needs at least one field: {', '.join(allowed)}")
    return out


def model_f0(spec, model: str, base: str) -> float:
    """f0 (Hz) of ``spec`` by ``model`` as :func:`matcad.prediction.predict` computes it: one of the cheap models,
    an anchor of :mod:`matcad.prediction.anchor` ('calibration', 'as_built': the measured taxel's f0 carried by the
    physics), or 'relative' (the measured reference f0 times ``base``'s ratio, this design / reference)."""
    from matcad.acoustics import registry
    from matcad.acoustics.design import design
    from matcad.acoustics.resonator import resonator
    from matcad.spec import reference_spec

    def f(s, name):
        d = design(s)
        return float(registry.model(name).f0_hz(resonator(d), d.wall))

    if model in ANCHORS:
        return anchor(spec, model).f0_hz(spec)
    if model == "relative":
        return spec.reference.f0_hz * f(spec, base) / f(reference_spec(spec), base)
    return f(spec, model)


def chosen_model(spec) -> tuple[str, str]:
    """(model, base): the model `predict` picks for ``spec`` (an anchor where it has measurements) and the physics
    model that carries a measurement to a new design."""
    from matcad.acoustics.registry import CHOSEN

    base = CHOSEN[spec.wall.model]
    anchors = available(spec)
    return (anchors[0] if anchors else "relative" if spec.reference is not None else base), base


class _Route:
    """f along x(t) = x0 · exp(t · g) for the continuous fields (NaN where the geometry is impossible)."""

    def __init__(self, spec, ranges: dict[str, tuple[float, float]], model: str, base: str):
        self.spec, self.model, self.base = spec, model, base
        self.x0 = {p: get_field(spec, p) for p in ranges}
        self.evaluations = 0
        grad = {}
        for p in ranges:  # ∂ln f/∂ln x by central differences (1e-4 in ln x)
            h = 1e-4
            up = self.f(with_fields(spec, {p: self.x0[p] * math.exp(h)}))
            down = self.f(with_fields(spec, {p: self.x0[p] * math.exp(-h)}))
            grad[p] = (math.log(up) - math.log(down)) / (2 * h)
        norm = math.sqrt(sum(g * g for g in grad.values())) or 1.0
        self.g = {p: g / norm for p, g in grad.items()}
        lo, hi = -math.inf, math.inf
        for p, (a, b) in ranges.items():  # every field stays inside its range
            g = self.g[p]
            if abs(g) < 1e-12:
                continue
            ends = sorted((math.log(a / self.x0[p]) / g, math.log(b / self.x0[p]) / g))
            lo, hi = max(lo, ends[0]), min(hi, ends[1])
        self.t_range = (lo, hi)

    def _point(self, t: float, g: dict):
        return with_fields(self.spec, {p: self.x0[p] * math.exp(t * g[p]) for p in self.x0})

    def f(self, spec) -> float:
        self.evaluations += 1
        return model_f0(spec, self.model, self.base)

    def at(self, t: float):
        from matcad.spec import SpecError

        try:
            s = self._point(t, self.g)
        except SpecError:
            return None, math.nan
        return s, self.f(s)


def _roots(route: _Route, target_hz: float) -> tuple[list[float], tuple[float, float]]:
    """Every root of f(t) = target along the route, nearest the start first, and the range of f seen (Hz)."""
    from scipy.optimize import brentq

    lo, hi = route.t_range
    ts = np.linspace(lo, hi, SCAN_POINTS)
    fs = np.array([route.at(t)[1] for t in ts])
    seen = (float(np.nanmin(fs)), float(np.nanmax(fs))) if np.isfinite(fs).any() else (math.nan, math.nan)
    roots = []
    for a, b, fa, fb in zip(ts[:-1], ts[1:], fs[:-1], fs[1:]):
        if np.isfinite(fa) and np.isfinite(fb) and (fa - target_hz) * (fb - target_hz) <= 0:
            roots.append(brentq(lambda t: route.at(t)[1] - target_hz, a, b, xtol=XTOL, rtol=4 * np.finfo(float).eps))
    return sorted(roots, key=abs), seen


def stock_order(spec) -> list[float]:
    """Stock sheets (mm), nearest the start's neck.length first (in ratio)."""
    from matcad.parts.features import STOCK_ACRYLIC_MM

    return sorted(STOCK_ACRYLIC_MM, key=lambda t: (abs(math.log(t / spec.neck.length)), t))


def discrete_choices(spec, vary) -> list[list[dict]]:
    """The discrete fields' values :func:`solve` tries, one group per plate sheet (:func:`stock_order` when
    ``vary`` has :data:`SHEET`, else the spec's; mm), each group the taxel's ways through the [riser] (both, the
    start's first, when ``vary`` has :data:`RISER`; else the start's) — as {field: value} to set on the spec."""
    sheets = stock_order(spec) if SHEET in vary else [spec.neck.length]
    ways = [spec.neck.riser, not spec.neck.riser] if RISER in vary else [spec.neck.riser]
    return [[{SHEET: sheet, RISER: way} for way in ways] for sheet in sheets]


def unpressable(spec) -> str | None:
    """Why the cap mechanics cannot press ``spec``'s cap over its [mechanics] travel (mm), when its loaded band needs
    them (no [calibration]): a cap in a thick riser's pocket has that much less of it above the clamp
    (:func:`matcad.mechanics.case.cap_case`). None when it can, or when a calibration gives the rise."""
    from matcad.acoustics.design import calibration
    from matcad.mechanics.case import cap_case
    from matcad.spec import SpecError

    if calibration(spec) is not None:
        return None
    try:
        cap_case(spec)
    except SpecError as exc:
        return str(exc)
    return None


def solve(spec, target_hz: float, vary: dict[str, tuple[float, float] | None]) -> Solution:
    """Solve ``spec``'s f0 = ``target_hz`` (Hz) varying the fields of ``vary`` ({field: (lo, hi) mm or None for
    :func:`default_range`}); see the module docstring. Raises :class:`Unreachable` (no geometry in range reaches
    the target) or :class:`RulesFailed` (every solution breaks a design rule)."""
    from matcad.prediction import predict
    from matcad.rules import check, errors

    from matcad.spec import is_array

    start = time.perf_counter()
    if not (math.isfinite(target_hz) and target_hz > 0):
        raise ValueError(f"--target-hz {target_hz:g} invalid, must be a finite frequency > 0 Hz")
    if is_array(spec):
        raise ValueError("--target-hz solves one taxel: give a single-taxel spec (--taxels N --band LO HI designs a "
                         "board)")
    model, base = chosen_model(spec)
    continuous = {p: (r or default_range(spec, p)) for p, r in vary.items() if p not in DISCRETE}
    candidates, reached, evaluations, failed, unpressed = [], [], 0, None, None
    for group in discrete_choices(spec, vary):
        for choice in group:
            changed = {k: v for k, v in choice.items() if v != get_field(spec, k)}
            try:
                s = with_fields(spec, changed) if changed else spec
            except ValueError:
                continue
            if continuous:  # (|t|, spec) of each root along the route, nearest the start first
                route = _Route(s, continuous, model, base)
                roots, seen = _roots(route, target_hz)
                evaluations += route.evaluations
                reached.append((choice, seen))
                solved = [(abs(t), route.at(t)[0]) for t in roots]
            else:
                f0 = model_f0(s, model, base)
                evaluations += 1
                reached.append((choice, (f0, f0)))
                solved = [(abs(math.log(f0 / target_hz)), s)]
            for distance, candidate in solved:
                findings = check(candidate)
                if errors(findings):
                    failed = failed or (candidate, findings)
                    continue
                why = unpressable(candidate) if RISER in vary else None
                if why:
                    unpressed = unpressed or why
                    continue
                candidates.append((distance, candidate, findings))
                break
        if candidates and continuous:
            break  # the stock sheet nearest the start that works
    if not candidates:
        if failed:
            bad = "; ".join(f"{f.id}: {f.message}" for f in errors(failed[1]))
            raise RulesFailed(f"every solution for {target_hz:g} Hz breaks a design rule (first: {bad})", failed[1])
        if unpressed:
            raise Unreachable(f"--target-hz {target_hz:g}: every solution's cap is too short for its press: {unpressed}")
        raise Unreachable(_unreachable_text(spec, target_hz, vary, continuous, reached, model))
    # the least change of the continuous fields (|t|), or, discrete fields alone, the f0 nearest the target (ln)
    _, best, findings = min(candidates, key=lambda c: c[0])
    p = predict(best, mechanics=False)
    fields = {k: (get_field(spec, k), get_field(best, k)) for k in vary}
    takes = {SHEET: "stock values", RISER: "the neck's two lengths (through the riser or not)"}
    alone = [k for k in DISCRETE if k in vary]
    notes = () if continuous else (f"{' and '.join(alone)} alone take{'s' * (len(alone) == 1)} "
                                   f"{' and '.join(takes[k] for k in alone)} only: the nearest gives {p.f0_hz:.0f} "
                                   "Hz; add a continuous field to --vary to hit the target",)
    return Solution(best, target_hz, p.f0_hz, p.model, fields, time.perf_counter() - start, evaluations,
                    tuple(findings), notes)


def _unreachable_text(spec, target_hz, vary, continuous, reached, model) -> str:
    finite = [r for _, r in reached if np.isfinite(r[0])]
    span = (f"{min(r[0] for r in finite):.0f}-{max(r[1] for r in finite):.0f} Hz" if finite else "no valid geometry")
    ranges = ", ".join(f"{p} {a:g}-{b:g} mm" for p, (a, b) in continuous.items())
    sheets = f"{SHEET} among the stock sheets" if SHEET in vary else f"{SHEET} = {spec.neck.length:g} mm"
    if RISER in vary:
        sheets += f", the neck through the {spec.riser.thickness:g} mm riser or the cap in a pocket of it"
    elif spec.riser is not None and spec.neck.riser:
        sheets += f" + the {spec.riser.thickness:g} mm riser the neck runs through"
    return (f"--target-hz {target_hz:g} unreachable: varying {ranges or ''}{', ' if ranges else ''}{sheets} "
            f"({model}) reaches {span}; widen a range (--vary FIELD=LO:HI) or vary another field")
