"""N taxels sharing one microphone: N disjoint bands in [LO, HI], one taxel solved for each, jet-free on the plate.

Bands are placed upward from LO. For taxel k the allocation starts at ``start`` (LO, or the previous loaded band's
top plus the guard, :func:`matcad.prediction.bands.guard_hz`); its f0 is the lowest target whose solved geometry
(:func:`matcad.design.solve.solve`) has a loaded band (:func:`matcad.prediction.bands.taxel_band`: predicted band,
rise to ``mechanics.max_force_n``) starting at or above ``start``, found by bisection on the target. Bands sit side
by side, the guard apart, whether or not another taxel's 2f or 3f lands in them: the board tracker discounts a
predicted harmonic (:func:`matcad.loop.board.discount_harmonics`; issue 24 — the band used to be moved above the
harmonic, which sent the 4th band of 2.5-12 kHz to 11.7 kHz). Every band must end at or below HI; otherwise the
message says how far the N bands reach. The taxels go in two staggered columns of [[taxel]] entries
(:func:`stagger`: every neck downstream of a needle sits between two of its rows) with the pitches that keep the
cap flanges the laser's smallest web apart and every neck out of every jet (:func:`stagger_pitch`, the
``board.jet`` rule's geometry), on a plate grown by the layout's extent; the written array must pass every rule
with no ``board.jet`` finding. A board whose plate would bend (``plate.bending``) is written with support posts under it
(``plate.support_posts``) when the posts fit it (no ``plate.posts`` error: each post 3 mount gaps from every mouth);
when they do not, the rows are spread apart until they do (:func:`post_pitch`) and every taxel is solved again on the
longer plate; a board that has no room for posts either way is written as it was, with its warning. Frequencies Hz,
lengths mm.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

from matcad.design import RulesFailed, Unreachable
from matcad.design.solve import CONTINUOUS, RISER, SHEET, field_text, solve

TARGET_MARGIN = 1e-3
"""Relative precision of each taxel's f0 target (the bisection stops there: 5 Hz at 5 kHz)."""
STEP_UP = 0.03
"""Relative step up of the target while looking for a first band that clears its start."""
LAYOUT_STEPS_PER_MM = 10
"""The layout's pitches are whole tenths of a millimetre: necks at multiples of 0.05 mm, readable in the spec."""
PER_TAXEL = {"neck.diameter": "neck_diameter", "cavity.diameter": "cavity_diameter",
             "cavity.length": "cavity_length", RISER: "neck_riser"}
"""Fields a [[taxel]] entry may set for itself that `design --taxels` varies (the neck length is the plate's sheet,
shared; ``neck.riser`` picks the taxel's one of the board's two neck lengths when there is a [riser]); each entry
also gets the needle flow that matches its pitch (:func:`matched_flow_l_min`)."""


@dataclass(frozen=True)
class Allocation:
    """The written array spec, each taxel's band (:class:`matcad.prediction.bands.TaxelBand`) and solution, the
    guard (Hz), the asked band (Hz), the run time (s) and the design rules' findings on the written array (no
    errors: those refuse it)."""

    spec: object
    bands: tuple
    solutions: tuple
    guard_hz: float
    band_hz: tuple[float, float]
    seconds: float
    findings: tuple = ()
    notes: tuple = ()

    def to_dict(self) -> dict:
        return {"name": self.spec.name, "band_hz": list(self.band_hz), "guard_hz": self.guard_hz,
                "seconds": self.seconds, "room_left_hz": self.band_hz[1] - self.bands[-1].loaded_hz[1],
                "taxels": [b.to_dict() | {"target_hz": s.target_hz, "error": s.error,
                                          "fields": {k: v[1] for k, v in s.fields.items()}}
                           for b, s in zip(self.bands, self.solutions)],
                "findings": [f.to_dict() for f in self.findings], "notes": list(self.notes)}

    def to_text(self) -> str:
        """What `matcad design --taxels` prints: the band shared (Hz), the guard, and each taxel's position (mm),
        f0, unloaded and loaded band (Hz) and solved fields (mm)."""
        lines = [f"{self.spec.name}: {len(self.bands)} taxels in {self.band_hz[0]:g}-{self.band_hz[1]:g} Hz, "
                 f"guard {self.guard_hz:.0f} Hz, {self.seconds:.1f} s"]
        for b, s in zip(self.bands, self.solutions):
            fields = ", ".join(f"{k + ' ' if k != RISER else ''}{field_text(k, v[1], s.spec)}"
                               for k, v in s.fields.items())
            lines.append(f"  {b.name} at ({b.x_mm:g}, {b.y_mm:g}) mm: f0 {b.f0_hz:.0f} Hz, unloaded "
                         f"{b.unloaded_hz[0]:.0f}-{b.unloaded_hz[1]:.0f} Hz, loaded {b.loaded_hz[0]:.0f}-"
                         f"{b.loaded_hz[1]:.0f} Hz; {fields}")
        return "\n".join(lines + [f"  note: {note}" for note in self.notes])


def _one(base, name: str, start: float, stop: float, vary, ratio: float):
    """Solve one taxel so that its loaded band starts at or just above ``start`` (Hz): (solution, band). The
    lowest target f0 whose band clears ``start`` is found by bisection on the target (the band's shape changes
    with the geometry, so its low edge is not a fixed fraction of f0); a target whose solve fails counts as not
    clearing. Raises the last failure when no target up to ``stop`` (Hz) works."""
    from matcad.prediction.bands import taxel_band

    def attempt(target):
        try:
            solution = solve(base, target, vary)
        except (Unreachable, RulesFailed) as exc:
            return exc, None
        return solution, taxel_band(solution.spec, name, mechanics=False)  # the low edge needs no rise

    low, high, found, failure = start, None, None, None
    target = start * ratio * (1 + TARGET_MARGIN)
    while high is None:  # step up from the shape estimate until a band clears the start
        if target > stop:
            raise failure or Unreachable(f"no f0 up to {stop:g} Hz gives a band above {start:.0f} Hz")
        solution, band = attempt(target)
        if band is not None and band.loaded_hz[0] >= start:
            high, found = target, (solution, band)
        else:
            low, failure = target, solution if band is None else failure
            target *= 1 + STEP_UP
    while high / low - 1 > TARGET_MARGIN:
        mid = (low * high) ** 0.5
        solution, band = attempt(mid)
        if band is not None and band.loaded_hz[0] >= start:
            high, found = mid, (solution, band)
        else:
            low = mid
    solution = found[0]
    return solution, taxel_band(solution.spec, name)


def stagger(n: int, pitch_x: float, half_row: float) -> list[tuple[float, float]]:
    """Neck positions (mm) of n taxels in two columns ``pitch_x`` apart, centred on the plate, from the top: taxel
    i (0-based) in the left column when i is even, at y = ((n − 1)/2 − i) · ``half_row`` — the right column sits
    half a row lower, so every neck downstream (+x) of a needle lies between two of its rows, as in
    templates/mat-array-4.toml."""
    return [((i % 2 - 0.5) * pitch_x, ((n - 1) / 2 - i) * half_row) for i in range(n)]


def widest_neck_mm(base, vary) -> float:
    """The widest neck the solver may give a taxel (mm): the top of its ``--vary neck.diameter`` range (the route
    stays inside it), else the base's neck; never past the cap's outside (the neck fits in the cavity, the cavity
    in the cap: :func:`matcad.spec.checks.geometry_invalid`)."""
    from matcad.design.solve import default_range

    top = (vary["neck.diameter"] or default_range(base, "neck.diameter"))[1] if "neck.diameter" in vary \
        else base.neck.diameter
    return min(top, base.end_cap.outer_diameter)


def stagger_pitch(base, neck_mm: float) -> tuple[float, float]:
    """(pitch_x, half_row) in mm of the flattest :func:`stagger` that keeps every cap flange the laser's smallest web
    from its neighbours and every neck out of every needle's jet (``board.jet``: the rule's own
    :func:`matcad.rules.board.jet_clearance_mm` >= 0), for ``base``'s taxel with a ``neck_mm`` neck (the widest it
    may get: a wider neck moves its needle upstream and opens a wider mouth, so it clears less). ``half_row``
    rises from half the pitch (a hexagonal packing: every neighbour at the pitch) in steps of
    1/:data:`LAYOUT_STEPS_PER_MM`, ``pitch_x`` the least such multiple that keeps the two columns' neighbours a
    pitch apart (0 from ``half_row`` = pitch on: one column, where the clearance grows with ``half_row``, so the
    search ends); three taxels hold every relative position to test — pairs further apart in y clear by more."""
    from matcad.rules.board import jet_clearance_mm
    from matcad.spec import cap_flange_diameter_mm, taxels

    pitch = cap_flange_diameter_mm(base) + base.machine.laser_min_feature
    one = taxels(base)[0]
    one = dataclasses.replace(one, neck=dataclasses.replace(one.neck, diameter=neck_mm))
    steps = math.ceil(pitch / 2 * LAYOUT_STEPS_PER_MM)
    while True:
        half_row = steps / LAYOUT_STEPS_PER_MM
        pitch_x = math.ceil(math.sqrt(max(pitch ** 2 - half_row ** 2, 0.0)) * LAYOUT_STEPS_PER_MM)
        pitch_x /= LAYOUT_STEPS_PER_MM
        probe = [dataclasses.replace(one, x=x, y=y) for x, y in stagger(3, pitch_x, half_row)]
        if all(min(jet_clearance_mm(a, b)) >= 0 for a in probe for b in probe if a is not b):
            return pitch_x, half_row
        steps += 1


def board_base(base, n: int, vary, pitch: tuple[float, float] | None = None):
    """(the single-taxel spec every taxel is solved on, the n :func:`stagger` positions, jet-free for the widest
    neck ``vary`` allows, :func:`stagger_pitch`, or at ``pitch`` = (pitch_x, half_row) when given): the varied
    fields leave the cap's footprint alone (its outside is resolved), and the plate grows by the layout's extent —
    before solving, because the mount mouth's end correction depends on the plate (mm)."""
    points = stagger(n, *(pitch or stagger_pitch(base, widest_neck_mm(base, vary))))
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    plate = dataclasses.replace(base.plate, width=round(base.plate.width + max(xs) - min(xs), 6),
                                depth=round(base.plate.depth + max(ys) - min(ys), 6))
    return dataclasses.replace(base, plate=plate), points


def array_spec(base, points, solutions, name: str):
    """An array spec: ``base``'s tables shared, one [[taxel]] per solution at ``points`` (mm) with its varied
    fields."""
    from matcad.design.spec_toml import plain
    from matcad.spec import from_dict, to_dict

    data = plain(to_dict(base))
    data["name"] = name
    data["taxel"] = [{"name": f"t{i}", "x": round(x, 6), "y": round(y, 6)}
                     | {PER_TAXEL[k]: v[1] for k, v in s.fields.items()}
                     | {"needle_flow_l_min": matched_flow_l_min(s.spec, s.f0_hz)}
                     for i, ((x, y), s) in enumerate(zip(points, solutions), 1)]
    return from_dict(data)


def matched_flow_l_min(spec, f0_hz: float) -> float:
    """The needle flow (L/min, to 0.01) that puts a solved single taxel's jet at the paper's operating point at its
    predicted ``f0_hz`` (Hz; ``jet.strouhal``, :func:`matcad.acoustics.edgetone.matched_flow_l_min`); a board's
    taxels span several kHz, and one shared flow leaves the lowest and highest outside the window."""
    from matcad.acoustics.edgetone import matched_flow_l_min as matched

    needle = spec.needle
    return round(matched(f0_hz, spec.neck.diameter, needle.flow_l_min, needle.outer_diameter), 2)


def allocate(spec, n: int, lo_hz: float, hi_hz: float, vary, name: str | None = None,
             progress=None) -> Allocation:
    """Allocate ``n`` disjoint bands in [``lo_hz``, ``hi_hz``] and solve one taxel for each (see the module
    docstring); ``vary`` as for :func:`matcad.design.solve.solve`: per-taxel fields (at least one continuous; and
    ``neck.riser``, each taxel's way through the [riser]), and ``neck.length``, the plate's sheet;
    ``progress(taxels placed, n)`` (:mod:`matcad.progress`) is told as each is placed. Raises
    :class:`Unreachable` when the bands do not fit, :class:`RulesFailed` when the array breaks a design rule."""
    from matcad.listening import guard_hz
    from matcad.rules import check, errors
    from matcad.spec import MAX_TAXELS, taxel_spec, taxels

    start_time = time.perf_counter()
    if not 2 <= n <= MAX_TAXELS:
        raise ValueError(f"--taxels {n} invalid, must be 2-{MAX_TAXELS} (a board of one is --target-hz)")
    if not (math.isfinite(lo_hz) and math.isfinite(hi_hz) and 0 < lo_hz < hi_hz):
        raise ValueError(f"--band {lo_hz:g} {hi_hz:g} invalid, must be 0 < LO < HI (Hz)")
    bad = [k for k in vary if k not in (*CONTINUOUS, SHEET, RISER)]
    if bad or not set(vary) & set(CONTINUOUS):
        raise ValueError(f"--vary {(bad or list(vary))[0]}: with --taxels the per-taxel fields vary "
                         f"({', '.join(CONTINUOUS)}; at least one, each taxel's f0 is bisected onto its band; and "
                         f"{RISER}, each taxel's neck through the [riser] or not), and {SHEET}, the plate's sheet "
                         "shared by every taxel, among the stock sheets")
    if SHEET in vary:
        return _over_sheets(spec, n, lo_hz, hi_hz, {k: r for k, r in vary.items() if k != SHEET}, name, progress,
                            start_time)
    single = taxel_spec(spec, taxels(spec)[0])
    base, points = board_base(single, n, vary)
    guard = guard_hz(spec.microphone.sample_rate_hz)
    name = name or f"{spec.name}-{n}taxels"
    placed, solutions = _place(base, n, lo_hz, hi_hz, vary, guard, progress)
    out = array_spec(base, points, solutions, name)
    findings = check(out)
    if any(f.id == "plate.bending" for f in findings) and not out.plate.support_posts:  # posts hold it flat
        posted = _with_posts(out)
        with_posts = check(posted)
        pitch = post_pitch(single, n, vary, solutions, name) if errors(with_posts) else None
        if pitch is not None:  # no room for posts between the rows: the rows spread until there is, solved again
            spread, points = board_base(single, n, vary, pitch)
            spread_placed, spread_solutions = _place(spread, n, lo_hz, hi_hz, vary, guard, None)
            posted = _with_posts(array_spec(spread, points, spread_solutions, name))
            with_posts = check(posted)
            if not errors(with_posts):
                placed, solutions = spread_placed, spread_solutions
        if not errors(with_posts):  # posts that do not fit leave the board as it was
            out, findings = posted, with_posts
    broken = [f for f in findings if f.level == "error" or f.id == "board.jet"]
    if broken:  # board.jet cannot fire on the stagger (stagger_pitch): checked on the solved necks all the same
        bad = "; ".join(f"{f.id}: {f.message}" for f in broken)
        raise RulesFailed(f"the {n}-taxel array breaks a design rule: {bad}", findings)
    placed = [dataclasses.replace(b, x_mm=t.x, y_mm=t.y) for b, t in zip(placed, taxels(out))]
    return Allocation(out, tuple(placed), tuple(solutions), guard, (lo_hz, hi_hz), time.perf_counter() - start_time,
                      tuple(findings))


def _over_sheets(spec, n: int, lo_hz: float, hi_hz: float, vary, name, progress, start_time: float) -> Allocation:
    """``--vary neck.length`` with ``--taxels``: the plate's sheet among the stock sheets, nearest ``spec``'s first
    (:func:`matcad.design.solve.stock_order`): the first on which the n bands fit and the plate stays flat (no
    ``plate.bending`` finding, support posts allowed); when none stays flat, the first on which they fit, with its
    warning. A note says which sheets were tried and why each was passed over."""
    from matcad.design.solve import stock_order, with_fields

    tried, fitted, failure = [], None, None
    for sheet in stock_order(spec):
        try:
            a = allocate(with_fields(spec, {SHEET: sheet}), n, lo_hz, hi_hz, vary, name, progress)
        except (Unreachable, RulesFailed) as exc:
            failure = failure or exc
            tried.append(f"{sheet:g} mm ({'a design rule' if isinstance(exc, RulesFailed) else 'bands do not fit'})")
            continue
        except ValueError:  # a sheet the spec's own ranges refuse
            continue
        if not any(f.id == "plate.bending" for f in a.findings):
            fitted = a
            break
        tried.append(f"{sheet:g} mm (the plate bends)")
        fitted = fitted or a
    if fitted is None:
        raise failure or Unreachable(f"no stock sheet fits {n} bands in {lo_hz:g}-{hi_hz:g} Hz")
    how = ("the plate stays flat" if not any(f.id == "plate.bending" for f in fitted.findings)
           else "no sheet kept the plate flat")
    note = (f"{SHEET} = {fitted.spec.neck.length:g} mm: the stock sheet nearest {spec.neck.length:g} mm on which the "
            f"{n} bands fit and {how}" + (f"; passed over: {', '.join(tried)}" if tried else ""))
    return dataclasses.replace(fitted, seconds=time.perf_counter() - start_time, notes=(*fitted.notes, note))


def _place(base, n: int, lo_hz: float, hi_hz: float, vary, guard: float, progress) -> tuple[list, list]:
    """The n bands placed upward from ``lo_hz``, the guard (Hz) apart, each taxel solved on ``base`` (see the
    module docstring): (bands, solutions). Raises :class:`Unreachable` / :class:`RulesFailed` with
    :func:`_fit_text`'s account when taxel k cannot be placed below ``hi_hz``."""
    from matcad.prediction.bands import taxel_band

    shape = taxel_band(base)
    ratio = shape.f0_hz / shape.loaded_hz[0]
    start, placed, solutions = lo_hz, [], []
    for k in range(1, n + 1):
        while True:
            try:
                solution, band = _one(base, f"t{k}", start, hi_hz, vary, ratio)
            except (Unreachable, RulesFailed) as exc:
                raise type(exc)(*_fit_text(exc, k, n, lo_hz, hi_hz, placed)) from None
            if band.loaded_hz[0] < start:  # the load lowered f somewhere below max force: start that much higher
                start = 2 * start - band.loaded_hz[0]
                continue
            break
        if band.loaded_hz[1] > hi_hz:
            raise Unreachable(_fit_text(None, k, n, lo_hz, hi_hz, [*placed, band])[0])
        placed.append(band)
        solutions.append(solution)
        if progress is not None:
            progress(k, n)
        ratio = band.f0_hz / band.loaded_hz[0]
        start = band.loaded_hz[1] + guard
    return placed, solutions


def _with_posts(spec):
    """``spec`` with support posts under its plate (plate.support_posts)."""
    return dataclasses.replace(spec, plate=dataclasses.replace(spec.plate, support_posts=True))


def post_pitch(single, n: int, vary, solutions, name: str) -> tuple[float, float] | None:
    """The least spread of :func:`stagger_pitch`'s rows that gives support posts room, for these solved necks:
    (pitch_x, half_row) in mm with ``half_row`` raised in 1/:data:`LAYOUT_STEPS_PER_MM` steps, pitch_x kept, until
    the ``plate.posts`` rule (:func:`matcad.rules.plate.support_posts`) finds nothing on the relaid array; None
    when ``half_row`` reaches pitch_x + the mouths' keepout without that. A post stands midway between two
    consecutive necks of the stagger, half their distance from each: spreading the rows moves it away from both
    mouths and out of both jets, which run along the rows."""
    from matcad.rules.plate import POST_MOUTH_GAPS, support_posts

    pitch_x, half_row = stagger_pitch(single, widest_neck_mm(single, vary))
    top = half_row + pitch_x + 2 * POST_MOUTH_GAPS * single.spacer.height
    steps = round(half_row * LAYOUT_STEPS_PER_MM)
    while steps / LAYOUT_STEPS_PER_MM <= top:
        steps += 1
        pitch = (pitch_x, steps / LAYOUT_STEPS_PER_MM)
        base, points = board_base(single, n, vary, pitch)
        if not support_posts(_with_posts(array_spec(base, points, solutions, name))):
            return pitch
    return None


def _fit_text(exc, k: int, n: int, lo: float, hi: float, placed) -> tuple:
    """Why the n bands do not fit in [lo, hi]: where the bands so far reach, and the exception's own reason."""
    bands = "; ".join(f"{b.name} {b.loaded_hz[0]:.0f}-{b.loaded_hz[1]:.0f} Hz" for b in placed) or "none"
    text = (f"--band {lo:g} {hi:g}: {n} disjoint bands do not fit (guard); taxel {k} of {n} "
            f"{'ends above ' + format(hi, 'g') + ' Hz' if exc is None else 'cannot be solved: ' + str(exc)}. "
            f"Bands so far: {bands}. Widen the band, lower mechanics.max_force_n, or narrow each taxel's band "
            "(plate.thickness_measured, a [reference] taxel)")
    return (text,) if exc is None or not isinstance(exc, RulesFailed) else (text, exc.findings)
