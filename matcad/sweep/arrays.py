"""A sweep of a one-taxel spec by a closed-form model (:data:`matcad.sweep.fast.VECTORISED`), evaluated on arrays
of variants end to end: validation, the model's f0, checks, band and df0/dfield, the design rules and Eq. 5's
slope, chunk by chunk of the grid. Every number is the one `matcad predict` / `matcad check` gives the variant.

- Validation: each spec table that holds a varied field is read once per combination of its varied values (the
  table's own checks); the whole-spec checks that a grid of a one-taxel spec without [reference] can change are
  the taxel's geometry checks, judged on arrays by :func:`matcad.spec.checks.geometry_invalid` (the same test);
  a variant they refuse gets its message from :func:`matcad.spec.from_dict`, once per combination of the
  geometry fields.
- Design rules of the spec (:data:`matcad.rules.registry.SPEC_MODULES`) run through :class:`matcad.sweep.memo.Memo`:
  once per combination of the varied fields each rule reads (exact: see memo.py). The sound rules
  (:mod:`matcad.rules.acoustic`, :mod:`matcad.rules.jet`) are arithmetic on the predicted band and warnings,
  evaluated on the arrays; so is a module's ``ARRAY_RULES`` (plate.bending) from its memoised input.
- A spec of several taxels, with a [reference], or a per-variant model (fem, relative) takes the per-variant path
  of :mod:`matcad.sweep.run`.
"""

from __future__ import annotations

import functools

import numpy as np

from matcad.sweep import calibrated, fast
from matcad.sweep.grid import variant_data
from matcad.sweep.memo import Memo, Table

CHUNK = 4_096
"""Variants per pass of the whole pipeline (the models split it further: :data:`matcad.sweep.fast.CHUNK`)."""
GEOMETRY = ("cavity.diameter", "cavity.length", "neck.diameter", "mold.draft_deg", "end_cap.outer_diameter",
            "end_cap.top_thickness")
"""The fields the whole-spec checks of one taxel read (:func:`matcad.spec.checks.cross_checks`), the cap's
through their defaults."""


def _proportional():
    from matcad.spec.model import PROPORTIONAL_DEFAULTS

    return PROPORTIONAL_DEFAULTS


class GridChunk:
    """Some variants of the grid of ``axes`` over the raw spec ``data`` (``rows``: flat grid indices, the first
    axis varying slowest): each variant's axis values, its spec, and codes of its values on chosen axes."""

    def __init__(self, data: dict, axes, rows):
        self.data, self.axes = data, tuple(axes)
        self.rows = np.asarray(rows, dtype=np.int64)
        self.shape = tuple(len(a.values) for a in self.axes)
        self.index = np.unravel_index(self.rows, self.shape) if self.axes else ()
        self._values = [np.asarray(a.values, dtype=float) for a in self.axes]
        unset = {key for key in _proportional()
                 if (data.get(key.split(".")[0]) or {}).get(key.split(".")[1]) is None}
        self.follows_cavity = {key: factor for key, factor in _proportional().items() if key in unset}
        """The cap fields the spec leaves to their default, which follows cavity.diameter: {field: factor}."""

    def __len__(self) -> int:
        return len(self.rows)

    def subset(self, positions) -> GridChunk:
        return GridChunk(self.data, self.axes, self.rows[positions])

    def axis(self, field: str) -> int | None:
        return next((k for k, a in enumerate(self.axes) if a.field == field), None)

    def value(self, k: int) -> np.ndarray:
        """Axis ``k``'s value of every variant."""
        return self._values[k][self.index[k]]

    def data_of(self, j: int) -> dict:
        values = tuple(a.values[int(self.index[k][j])] for k, a in enumerate(self.axes))
        return variant_data(self.data, self.axes, values)

    def spec(self, j: int):
        """Variant ``j``'s validated spec (made once per variant and chunk, however many rules ask)."""
        from matcad.spec import from_dict

        cache = self.__dict__.setdefault("_specs", {})
        if j not in cache:
            cache[j] = from_dict(self.data_of(j))
        return cache[j]

    def axes_of(self, reads) -> tuple[int, ...]:
        """The axes whose field is among ``reads`` (dotted fields; ``table.*`` for a whole table), the cavity's
        diameter too where a cap field that follows it by default was read."""
        reads = set(reads)
        if any(key in reads or f"{key.split('.')[0]}.*" in reads for key in self.follows_cavity):
            reads.add("cavity.diameter")
        return tuple(k for k, a in enumerate(self.axes) if a.field in reads or f"{a.section}.*" in reads)

    def codes(self, axes: tuple[int, ...], positions) -> np.ndarray:
        """One integer per variant at ``positions`` naming its combination of values on ``axes``."""
        positions = np.asarray(positions)
        if not axes:
            return np.zeros(len(positions), dtype=np.int64)
        return np.ravel_multi_index(tuple(self.index[k][positions] for k in axes), tuple(self.shape[k] for k in axes))

    def field(self, base, key: str) -> np.ndarray:
        """Every variant's resolved value of the dotted ``key`` (float; NaN where unset): the axis's values, the
        cavity-proportional default of a cap field the spec leaves out, else the base spec's value."""
        k = self.axis(key)
        if k is not None:
            return self.value(k)
        if key in self.follows_cavity:
            return self.follows_cavity[key] * self.field(base, "cavity.diameter")
        return np.full(len(self), fast.field_value(base, key), dtype=float)


def eligible(base, model: str, axes=()) -> bool:
    """Whether a sweep of ``base`` by ``model`` over ``axes`` runs on arrays: one taxel, no [reference] and no
    [riser] (whose two sheets the arrays do not carry), and a closed-form model or the calibration anchor
    (:func:`matcad.sweep.calibrated.eligible`)."""
    from matcad.spec import taxels

    if base.reference is not None or not one_sheet(base, axes) or base.taxel or len(taxels(base)) != 1:
        return False
    return calibrated.eligible(base, axes) if model == calibrated.MODEL else model in fast.VECTORISED


def one_sheet(base, axes=()) -> bool:
    """Whether every variant of ``base`` over ``axes`` has its neck in the plate's one sheet and its cap on it: no
    [riser] in ``base`` and no axis in one (the arrays of :mod:`matcad.sweep.fast` carry neither the riser's length
    of a neck nor its height of a pocketed cap's clamp)."""
    return base.riser is None and not any(a.section == "riser" for a in axes)


def _by_combination(chunk: GridChunk, axes: tuple[int, ...], positions, function, seen: dict) -> np.ndarray:
    """``function(j)`` once per combination of the values on ``axes`` among ``positions`` (j: the first variant
    with it), given to every variant with that combination: an object array. ``seen`` keeps the results across the
    grid's chunks (its codes are the whole grid's), by ``axes``: (a :class:`matcad.sweep.memo.Table` {combination:
    result number}, the results): a combination met in an earlier chunk is not asked again."""
    positions = np.asarray(positions, dtype=np.int64)
    table, results = seen.setdefault(axes, (Table(), []))
    codes = chunk.codes(axes, positions)
    numbers = table.find(codes)
    new = np.flatnonzero(numbers < 0)
    if len(new):
        uniq, first = np.unique(codes[new], return_index=True)
        for code, f in zip(uniq.tolist(), first.tolist()):
            table[code] = len(results)
            results.append(function(int(positions[new[f]])))
        numbers[new] = table.find(codes[new])
    out = np.empty(len(results), dtype=object)
    out[:] = results
    return out[numbers]


def validate(chunk: GridChunk, base, seen: dict | None = None) -> np.ndarray:
    """Each variant's validation message ('' where it validates), exactly as :func:`matcad.spec.from_dict`;
    ``seen``: the messages of the grid's earlier chunks (:func:`_by_combination`), filled in."""
    from matcad.spec import SECTIONS, SpecError
    from matcad.spec.checks import geometry_invalid
    from matcad.spec.fields import read_section

    n = len(chunk)
    seen = {} if seen is None else seen
    reason = np.full(n, "", dtype=object)
    everyone = np.arange(n)
    for section, cls in SECTIONS.items():  # the first failing table in from_dict's order names the error
        axes = tuple(k for k, a in enumerate(chunk.axes) if a.section == section)
        if not axes:
            continue

        def read(j, section=section, cls=cls):
            try:
                read_section(cls, section, chunk.data_of(j)[section])
            except SpecError as exc:
                return str(exc)
            return ""

        found = _by_combination(chunk, axes, everyone, read, seen.setdefault(section, {}))
        reason = np.where(reason == "", found, reason)
    g = {key: chunk.field(base, key) for key in GEOMETRY}
    tolerances = {key: (_schema_range(key)) for key in chunk.follows_cavity}
    suspect = geometry_invalid(g["cavity.diameter"], g["cavity.length"], g["neck.diameter"], g["mold.draft_deg"],
                               g["end_cap.outer_diameter"])
    for key, (lo, hi) in tolerances.items():  # a default out of its field's range: from_dict decides
        suspect = suspect | (g[key] < lo) | (g[key] > hi)
    ask = np.flatnonzero(suspect & (reason == ""))
    if len(ask):
        geometry = tuple(k for k, a in enumerate(chunk.axes) if a.field in GEOMETRY)

        def whole(j):
            try:
                chunk.spec(j)
            except SpecError as exc:
                return str(exc)
            return ""

        reason[ask] = _by_combination(chunk, geometry, ask, whole, seen.setdefault("", {}))
    return reason


@functools.cache
def _schema_range(key: str) -> tuple[float, float]:
    """The allowed (lo, hi) of a spec field (read from the schema once per field, not once per chunk)."""
    from matcad.spec import schema

    row = next(r for r in schema() if r["key"] == key)
    return row["lo"], row["hi"]


def variants(chunk: GridChunk, base) -> fast.Variants:
    """The arrays of the model fields (:data:`matcad.sweep.fast.FIELDS`) of the chunk's (valid) variants."""
    from matcad.acoustics.design import Making, design

    one = design(base)
    n = len(chunk)
    making = Making(np.full(n, one.making.neck_drilled), np.full(n, one.making.sheet_measured),
                    np.full(n, one.making.printer))
    return fast.Variants({key: chunk.field(base, key) for key in fast.FIELDS}, base.neck.mouth, one.wall, making)


def _summary(findings) -> tuple:
    return tuple((f.id, f.level) for f in findings if f.level in ("error", "warning"))


def spec_rules():
    """Every rule of the spec modules that can give an error or a warning, in :func:`matcad.rules.check`'s order
    (those a module lists in ``INFO_RULES`` only inform: they never change a verdict column)."""
    from matcad.rules.registry import SPEC_MODULES

    return [rule for module in SPEC_MODULES for rule in module.RULES if rule not in getattr(module, "INFO_RULES", ())]


def _array_rules() -> dict:
    """The spec rules judged on arrays (each module's ``ARRAY_RULES``): {rule: its
    :class:`matcad.rules.finding.ArrayRule`}."""
    from matcad.rules.registry import SPEC_MODULES

    return {rule: entry for module in SPEC_MODULES for rule, entry in getattr(module, "ARRAY_RULES", {}).items()}


def _array_column(chunk: GridChunk, base, memo: Memo, v: fast.Variants, entry, physics_hz=None) -> np.ndarray:
    """An array rule's count of findings per variant (``entry``: its ArrayRule, ``memo``: its memoised inputs), or
    -(k + 1) where its input failed with the memo's outcome k. ``physics_hz``: the variants' f0 by the chosen
    physics (:func:`rule_columns`), or None."""
    numbers = memo.apply(chunk)
    outcomes = memo.outcomes
    failed = np.array([isinstance(o, tuple) for o in outcomes], dtype=bool)[numbers]
    inputs = np.array([0.0 if isinstance(o, tuple) else o for o in outcomes], dtype=float)[numbers]
    column = entry.column(inputs, lambda key: chunk.field(base, key), v.design(), lambda rows: v.take(rows).design(),
                          base.wall.model, lambda rows: None if physics_hz is None else physics_hz[rows])
    return np.where(failed, -(numbers + 1), column)


def rule_columns(chunk: GridChunk, base, memos: list[Memo], v: fast.Variants, f0, low, high,
                 model_warnings, known: dict | None = None, physics_hz=None) -> dict:
    """rule_errors, rule_warnings, failing_rules (and status/reason where a rule raised) of the chunk's valid
    variants, as :func:`matcad.sweep.tasks.rule_verdicts` gives them one by one (``memos``: :func:`rule_memos`;
    ``model_warnings``: each variant's count of its prediction's warnings from its own model; ``known``: the
    verdicts of the grid's earlier chunks by row of outcome numbers and counts (:func:`_verdict`), filled in;
    ``physics_hz``: the variants' f0 by the model `predict` chooses for their wall
    (:data:`matcad.acoustics.registry.CHOSEN`) when the sweep has computed it, which a rule then reads rather than
    computing it again)."""
    from matcad.acoustics.design import speed_of_sound
    from matcad.rules import acoustic, jet

    n = len(chunk)
    groups, on_arrays = rule_groups(), _array_rules()
    numbers = [_array_column(chunk, base, memo, v, on_arrays[group[0]], physics_hz) if group[0] in on_arrays
               else memo.apply(chunk) for group, memo in zip(groups, memos)]
    d = v.design()
    sound = acoustic.array_counts(chunk.field(base, "microphone.sample_rate_hz"),
                                  chunk.field(base, "microphone.floor_hz"), low, high,
                                  model_warnings)
    sound |= jet.array_counts(f0, chunk.field(base, "neck.diameter"), chunk.field(base, "needle.flow_l_min"),
                              chunk.field(base, "needle.outer_diameter"), speed_of_sound(d.air))
    matrix = np.stack(numbers + [np.asarray(c, dtype=np.int64) for c in sound.values()], axis=1) if n else \
        np.zeros((0, len(memos) + len(sound)), dtype=np.int64)
    uniq, inverse = unique_rows(matrix)
    known = {} if known is None else known
    combos = list(map(tuple, uniq.tolist()))
    for combo in combos:
        if combo not in known:
            known[combo] = _verdict(combo, groups, memos, on_arrays, tuple(sound))
    verdicts = [known[combo] for combo in combos]

    def column(k: int, dtype) -> np.ndarray:
        return np.array([v[k] for v in verdicts], dtype=dtype)[inverse]

    return {"rule_errors": column(0, np.int64), "rule_warnings": column(1, np.int64),
            "failing_rules": column(2, object), "failed": column(3, object)}


def _verdict(combo: tuple, groups, memos: list[Memo], on_arrays: dict, sound: tuple) -> tuple[int, int, str, str]:
    """(rule_errors, rule_warnings, failing_rules, the message of the first rule that raised or '') of the variants
    whose row of :func:`rule_columns`' matrix is ``combo``: each memo's outcome number (an array rule's count, or
    -(k + 1) for its failed input k), then each sound rule's count (``sound``: their (id, level))."""
    items, broken = [], ""
    for group, memo, number in zip(groups, memos, combo[:len(memos)]):
        if group[0] in on_arrays:
            if number >= 0:
                items += [(on_arrays[group[0]].id, on_arrays[group[0]].level)] * int(number)
                continue
            outcomes = (memo.outcomes[-number - 1],)
        else:
            outcomes = memo.outcomes[number]
        for outcome in outcomes:
            if isinstance(outcome, tuple) and outcome[:1] == ("failed",):
                broken = broken or outcome[1]
                continue
            items += list(outcome)
    for (rule_id, level), count in zip(sound, combo[len(memos):]):
        items += [(rule_id, level)] * int(count)
    ordered = [x for x in items if x[1] == "error"] + [x for x in items if x[1] == "warning"]
    return (sum(x[1] == "error" for x in items), sum(x[1] == "warning" for x in items),
            " ".join(dict.fromkeys(f"{i}:{lvl}" for i, lvl in ordered)), broken)


def unique_rows(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the distinct rows of the 2-D integer ``matrix`` in ascending order, each row's number among them): what
    ``np.unique(matrix, axis=0, return_inverse=True)`` gives, from one int64 key per row, its columns as the digits
    of a mixed radix (key and column renumbered densely first where the next digit could overflow), so one sort of
    integers instead of a sort of rows."""
    key = np.zeros(len(matrix), dtype=np.int64)
    for column in matrix.T if len(matrix) else ():
        low = column.min()
        radix = int(column.max() - low) + 1
        if (int(key.max()) + 1) * radix > 2**62:
            key = np.unique(key, return_inverse=True)[1].reshape(-1)
            column, low = np.unique(column, return_inverse=True)[1].reshape(-1), 0
            radix = int(column.max()) + 1
        key = key * radix + (column - low)
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    return matrix[first], inverse.reshape(-1)


def rule_groups() -> list[tuple]:
    """The spec rules as the sweep memoises them, in :func:`spec_rules`' order: each rule judged on arrays alone,
    and the other rules of one module together (they read the same tables and build the same parts: the laser
    rules' five kit sheets are one build per variant, :func:`matcad.parts.catalogue.laser_parts`)."""
    on_arrays = _array_rules()
    groups: list[tuple] = []
    for rule in spec_rules():
        if rule in on_arrays:
            groups.append((rule,))
        elif groups and groups[-1][0] not in on_arrays and groups[-1][0].__module__ == rule.__module__:
            groups[-1] += (rule,)
        else:
            groups.append((rule,))
    return groups


def _verdicts(rules, spec) -> tuple:
    """Each rule's summary of its findings on ``spec`` (:func:`_summary`), or ("failed", "Type: message") where it
    raised (as :func:`matcad.sweep.memo.run` records a failure)."""
    out = []
    for rule in rules:
        try:
            out.append(_summary(rule(spec)))
        except Exception as exc:  # noqa: BLE001 - a variant's failure is a row of the table, never fatal
            out.append(("failed", f"{exc.__class__.__name__}: {exc}"))
    return tuple(out)


def rule_memos() -> list[Memo]:
    """One :class:`Memo` per group of :func:`rule_groups`: a module's rules keep the tuple of their summaries of
    findings (id, level) at error and warning; a rule judged on arrays, its inputs (:func:`_array_rules`)."""
    on_arrays = _array_rules()
    return [Memo(on_arrays[group[0]].inputs) if group[0] in on_arrays
            else Memo(functools.partial(_verdicts, group)) for group in rule_groups()]


def slope_memo() -> Memo:
    """Eq. 5's df0/dF at 0 N (Hz/N) from the spec's [calibration], None without one, once per combination."""
    from matcad.acoustics.design import calibration

    def slope(spec):
        cal = calibration(spec)
        return None if cal is None else float(cal.slope_hz_per_n(0.0))

    return Memo(slope)


def memos(rules: bool) -> list[Memo]:
    """One sweep process's memos: :func:`slope_memo`'s, then :func:`rule_memos` when ``rules``."""
    return [slope_memo(), *(rule_memos() if rules else ())]


def evaluate(chunk: GridChunk, base, model: str, rules: bool, memos, slope: Memo, seen: dict | None = None,
             known: dict | None = None) -> dict:
    """Every column of the chunk's variants: status, reason, f0_hz, band_low_hz, band_high_hz, model_valid,
    df0/dfield per axis (keyed by field), the load slope, and the rule columns when ``rules``; arrays. ``seen``:
    the grid's validation messages so far (:func:`validate`); ``known``: its rule verdicts so far
    (:func:`rule_columns`)."""
    n = len(chunk)
    reason = validate(chunk, base, seen)
    ok = np.flatnonzero(reason == "")
    out = {"status": np.where(reason == "", "ok", "invalid").astype(object), "reason": reason,
           "f0_hz": np.full(n, np.nan), "band_low_hz": np.full(n, np.nan), "band_high_hz": np.full(n, np.nan),
           "model_valid": np.full(n, None, dtype=object), "load_slope": np.full(n, None, dtype=object),
           **{("slope", a.field): np.full(n, np.nan) for a in chunk.axes}}
    if rules:  # -1/None where not judged (a chunk may hold no valid variant at all)
        out |= {"rule_errors": np.full(n, -1, dtype=np.int64), "rule_warnings": np.full(n, -1, dtype=np.int64),
                "failing_rules": np.full(n, None, dtype=object)}
    if not len(ok):
        return out
    good = chunk.subset(ok)
    v = variants(good, base)
    if model == calibrated.MODEL:
        anchor = calibrated.CalibratedSweep(good, base, v)
        f0, low, high = anchor.columns()
        valid, warned = np.ones(len(f0), dtype=bool), np.zeros(len(f0), dtype=np.int64)
        physics = anchor.physics_hz[0]

        def slope_of(field, follows):
            return anchor.sensitivity(field, follows)
    else:
        from matcad.acoustics.predict import warning_count
        from matcad.acoustics.registry import CHOSEN

        near = fast.branch(v, model)
        f0 = near.f0_hz
        physics = f0 if model == CHOSEN[base.wall.model] else None
        failed = fast.failed_checks(v, model, f0)
        valid, warned = failed == 0, warning_count(v.design(), f0, failed)
        low, high = fast.band_hz(v, model, f0, valid)

        def slope_of(field, follows):
            return fast.sensitivity(v, model, field, follows, near=near)
    out["f0_hz"][ok], out["band_low_hz"][ok], out["band_high_hz"][ok] = f0, low, high
    out["model_valid"][ok] = valid
    for a in chunk.axes:
        follows = good.follows_cavity if a.field == "cavity.diameter" else None
        out[("slope", a.field)][ok] = slope_of(a.field, follows)
    numbers = slope.apply(good)
    outcomes = np.empty(len(slope.outcomes), dtype=object)
    outcomes[:] = slope.outcomes
    out["load_slope"][ok] = outcomes[numbers]
    if rules:
        verdicts = rule_columns(good, base, memos, v, f0, low, high, warned, known, physics)
        for key in ("rule_errors", "rule_warnings", "failing_rules"):
            out[key][ok] = verdicts[key]
        broken = ok[verdicts["failed"] != ""]
        out["status"][broken] = "failed"
        out["reason"][broken] = verdicts["failed"][verdicts["failed"] != ""]
    return out
