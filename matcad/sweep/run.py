"""A design sweep: every variant of the grid → f0, band, sensitivities and rule verdicts, one row each.

Frequencies Hz; sensitivities in Hz per the varied field's unit (Hz/mm for lengths) and Hz/N.

- The closed-form rungs (:data:`matcad.sweep.fast.VECTORISED`, the silicone wall's included) of a one-taxel spec
  without [reference] are evaluated on arrays end to end, validation and design rules included
  (:mod:`matcad.sweep.arrays`), in chunks of the grid on the executor; their df0/dfield is the model's own
  derivative (central difference at each variant).
- Any other sweep (fem, relative, a board of taxels, ``cad``) runs :func:`matcad.prediction.predict` per
  variant on the executor; df0/dfield is then the slope of f0 along that axis of the grid (``numpy.gradient``:
  central differences inside, one-sided at the ends and next to a failed variant; blank for an axis of one value).
- df0/dF (Hz/N) is paper Eq. 5's slope at 0 N, f(0)·b/(2·V0) (:meth:`matcad.acoustics.eq5.Eq5.slope_hz_per_n`), from
  the spec's [calibration] (blank without one):
  it follows the neck and the air, not the cavity, because V0 is the calibrated taxel's. The cap mechanics
  (FElupe, seconds per variant) is not run in a sweep.
- The design rules run per variant on the executor (on the sweep model's prediction) unless ``rules=False``.
Variants that fail validation or a solver are rows with ``status`` invalid or failed and the reason.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from matcad.sweep import arrays, fast, heap
from matcad.sweep.executor import Executor, processes, run as run_tasks, stream
from matcad.sweep.grid import MAX_VARIANTS, Axis, grid, variant_data
from matcad.sweep.tasks import run_chunk

RESULT_KEYS = ("status", "reason", "f0_hz", "band_low_hz", "band_high_hz", "model_valid", "rule_errors",
               "rule_warnings", "failing_rules", "cad_stl_volume_mm3", "cad_closed_form_volume_mm3",
               "cad_watertight", "cad_triangles")
"""What a worker's result may set in a row (its timing is summed, not tabulated, so tables compare equal)."""


def sensitivity_column(axis: Axis) -> str:
    """Column name of df0/d(field), e.g. ``df0_d_cavity.length_hz_per_mm``."""
    unit = axis.unit.replace("/", "_").replace("^", "") or "unit"
    return f"df0_d_{axis.field}_hz_per_{unit}"


LOAD_SENSITIVITY = "df0_dF_hz_per_n"


def table_columns(axes, rules: bool, rows=()) -> list[str]:
    """The table's columns: index, the varied fields, status ... and the ``cad_`` columns ``rows`` carry."""
    names = ["index", *(a.field for a in axes), "status", "reason", "model", "f0_hz", "band_low_hz",
             "band_high_hz", "model_valid", *(sensitivity_column(a) for a in axes), LOAD_SENSITIVITY]
    if rules:
        names += ["rule_errors", "rule_warnings", "failing_rules"]
    return names + sorted({k for r in rows for k in r if k.startswith("cad_")})


def tally(rows, into: dict | None = None) -> dict:
    """Variants by status (ok, invalid, failed) and how many break a design rule, added to ``into``; ``rows``: row
    dicts or a :class:`Block`."""
    out = into if into is not None else {"ok": 0, "invalid": 0, "failed": 0, "rule_errors": 0}
    columns = Block.of(rows).columns
    for status in ("ok", "invalid", "failed"):
        out[status] += columns.get("status", []).count(status)
    out["rule_errors"] += sum(map(bool, filter(None, columns.get("rule_errors", ()))))
    return out


@dataclass(frozen=True)
class Block:
    """Consecutive rows of the table as columns, {column: list}, each as long as the block; None where a variant
    has no value (a row dict leaves that key out). How the array path's chunks travel and are written: a worker
    sends lists of numbers, not a dict per variant."""

    columns: dict[str, list]

    @classmethod
    def of(cls, rows) -> Block:
        """``rows`` as a block: a :class:`Block` as it is, row dicts by :meth:`from_rows` (what a sink is given)."""
        return rows if isinstance(rows, Block) else cls.from_rows(rows)

    @classmethod
    def from_rows(cls, rows) -> Block:
        """The block of row dicts (a column for every key any row has, in order of first appearance)."""
        names = dict.fromkeys(k for r in rows for k in r)
        return cls({k: [r.get(k) for r in rows] for k in names})

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()), ()))

    def rows(self) -> list[dict]:
        """The row dicts (keys in column order, those without a value left out)."""
        names = list(self.columns)
        return [{k: v for k, v in zip(names, values) if v is not None} for values in zip(*self.columns.values())]

    def __iter__(self):
        """The row dicts, one by one (a sink that wants rows reads a block as it read a list of them)."""
        return iter(self.rows())


@dataclass(frozen=True)
class SweepResult:
    """The table (one dict per variant, grid order: the first axis varies slowest) and how it was made. A sweep
    streamed to a sink keeps no rows when it has three or more axes and more than :data:`MAX_VARIANTS` variants
    (its maps are drawn from the stream, :class:`matcad.sweep.maps.Planes`): ``tally`` then holds its counts."""

    name: str
    model: str
    axes: tuple[Axis, ...]
    rows: tuple[dict, ...]
    vectorised: bool
    executor: str
    rules: bool
    seconds: float
    worker_seconds: float
    tally: dict | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.axes)

    @property
    def variants(self) -> int:
        return math.prod(self.shape)

    def columns(self) -> list[str]:
        return table_columns(self.axes, self.rules, self.rows)

    def counts(self) -> dict:
        """Variants by status (ok, invalid, failed) and how many break a design rule."""
        return dict(self.tally) if self.tally is not None else tally(self.rows)

    def summary_dict(self, folder, files) -> dict:
        """`matcad sweep --json`: where the table went, the model, the counts and the run time (s)."""
        return {"out_dir": str(folder), "written": files, "model": self.model, "variants": self.variants,
                **self.counts(), "seconds": round(self.seconds, 3)}

    def summary_text(self, folder, files) -> str:
        """What `matcad sweep` prints: the counts, the model and executor, the run time and the files."""
        c = self.counts()
        plural = "" if self.variants == 1 else "s"
        maps = sum(name.startswith("maps/") for name in files)
        shown = [name for name in files if not name.startswith("maps/")]
        shown += [f"{maps} maps in maps/"] if maps else []
        return (f"{self.name}: {self.variants} variant{plural} ({c['ok']} ok, {c['invalid']} invalid, "
                f"{c['failed']} failed; "
                f"{c['rule_errors']} with design-rule errors) by {self.model} on {self.executor} in "
                f"{self.seconds:.1f} s\n  {', '.join(shown)} in {folder}/")

    def column(self, name: str) -> np.ndarray:
        """A numeric column as a float array in grid shape (NaN where a variant has no value)."""
        values = [r.get(name) for r in self.rows]
        return np.array([np.nan if v is None or v == "" else float(v) for v in values]).reshape(self.shape)


def allowed_models(spec) -> list[str]:
    """Model names a sweep of ``spec`` accepts: the registered models evaluated for its wall
    (:mod:`matcad.acoustics.registry`), the anchors it has measurements for (:mod:`matcad.prediction.anchor`) and
    ``relative`` when it has a [reference]."""
    from matcad.acoustics.registry import MODELS
    from matcad.prediction.anchor import available

    return ([m.name for m in MODELS if spec.wall.model in m.walls] + available(spec)
            + (["relative"] if spec.reference else []))


def sweep(data: dict, axes: tuple[Axis, ...], model: str | None = None, executor: Executor = Executor(),
          rules: bool = True, cad: bool = False, fem_level: int | None = None, sink=None,
          progress=None) -> SweepResult:
    """Sweep the spec ``data`` (raw TOML-like data; each variant is it with the axes' values set, validated like a
    file, so defaults such as the cap's 2.5 × D follow the varied cavity) over the full grid of ``axes``.
    ``model`` defaults to the spec's own choice (:func:`predict`); ``cad`` also builds each variant's end cap.
    ``sink`` (a callable) is given the rows chunk by chunk (a :class:`Block`, or a list of row dicts), in grid
    order, as they are made; ``progress`` (a callable, :mod:`matcad.progress`) is told (variants done, variants)
    as chunks come back."""
    from matcad.acoustics.design import calibration
    from matcad.prediction import predict
    from matcad.spec import SpecError, from_dict
    from matcad.spec.drawn import pinned

    start = time.perf_counter()
    base = from_dict(data)
    data = pinned(data, base)  # every variant keeps the measured taxels on the drawing they were measured on
    if model is None:
        model = predict(base, mechanics=False).model
    elif model not in allowed_models(base):
        raise ValueError(f"--model {model!r} invalid, must be one of {', '.join(allowed_models(base))}")
    size = math.prod(len(a.values) for a in axes)
    if not cad and arrays.eligible(base, model, axes):
        keep = sink is None or len(axes) <= 2 or size <= MAX_VARIANTS
        rows, counted, worker_seconds = _array_rows(data, axes, model, rules, executor, sink, keep, progress)
        return SweepResult(base.name, model, tuple(axes), tuple(rows), True, executor.describe(), rules,
                           time.perf_counter() - start, worker_seconds, None if keep else counted)
    if size > MAX_VARIANTS:
        raise SpecError(" ".join(a.field for a in axes), size,
                        f"the grid has {size} variants, at most {MAX_VARIANTS} for a sweep that runs each variant "
                        f"on its own (model {model}{', --cad' if cad else ''}; a one-taxel spec without "
                        f"[reference] by a closed-form model sweeps up to 10^7 on arrays)")
    rows: list[dict] = []
    datas, specs = {}, {}
    for i, values in enumerate(grid(axes)):
        rows.append({"index": i, **{a.field: v for a, v in zip(axes, values)}, "status": "ok", "reason": "",
                     "model": model})
        datas[i] = variant_data(data, axes, values)
        try:
            specs[i] = from_dict(datas[i])
        except SpecError as exc:
            rows[i].update(status="invalid", reason=str(exc))
    ok = sorted(specs)
    vectorised = model in fast.VECTORISED and arrays.one_sheet(base, axes)  # a riser: each variant on its own
    if vectorised and ok:
        v = fast.from_specs([specs[i] for i in ok])
        near = fast.branch(v, model)
        f0 = near.f0_hz
        valid = fast.valid(v, model, f0)
        low, high = fast.band_hz(v, model, f0, valid)
        slopes = {sensitivity_column(a): fast.sensitivity(v, model, a.field, near=near) for a in axes}
        for j, i in enumerate(ok):
            rows[i].update(f0_hz=float(f0[j]), band_low_hz=float(low[j]), band_high_hz=float(high[j]),
                           model_valid=bool(valid[j]), **{k: float(s[j]) for k, s in slopes.items()})
    for i in ok:
        cal = calibration(specs[i])
        if cal is not None:
            rows[i][LOAD_SENSITIVITY] = float(cal.slope_hz_per_n(0.0))
    worker_seconds = 0.0
    if not vectorised or rules or cad:
        tasks = [{"index": i, "data": datas[i], "model": model, "fem_level": fem_level, "predict": not vectorised,
                  "rules": rules, "cad": cad} for i in ok]
        for result in run_tasks(run_chunk, tasks, executor, progress):
            worker_seconds += result.get("seconds", 0.0)
            rows[result["index"]].update({k: v for k, v in result.items() if k in RESULT_KEYS or k.startswith("cad_")})
    result = SweepResult(base.name, model, tuple(axes), tuple(rows), vectorised, executor.describe(), rules,
                         0.0, worker_seconds)
    if not vectorised:
        _grid_slopes(result)
    if sink is not None:
        sink(result.rows)
    return SweepResult(**{**result.__dict__, "seconds": time.perf_counter() - start})


def _array_rows(data: dict, axes, model: str, rules: bool, executor: Executor, sink, keep: bool, progress=None):
    """(rows if ``keep``, counts, worker seconds) of every variant by :func:`array_chunk` over chunks of
    :data:`matcad.sweep.arrays.CHUNK` variants streamed from the executor (each chunk's rows go to ``sink`` as
    they come); a chunk whose worker was lost is a row ``failed`` per variant."""
    import uuid

    from matcad.sweep.warm import warmed

    size = math.prod(len(a.values) for a in axes)
    key = uuid.uuid4().hex  # the workers' memos are kept per sweep
    tasks = [{"index": k, "key": key, "data": data, "axes": tuple(axes), "start": lo,
              "stop": min(lo + arrays.CHUNK, size), "model": model, "rules": rules}
             for k, lo in enumerate(range(0, size, arrays.CHUNK))]
    kept, counted, seconds = [], tally(()), 0.0
    with processes(executor, len(tasks), heap.keep_freed_memory) as shared:  # the warm-up and the grid share them
        if shared is None and not executor.scheduler:  # the chunks run in this process
            heap.keep_freed_memory()
        warm = warmed(data, axes, rules, executor, shared) if len(tasks) > 1 else None
        for task in tasks:
            task["warm"] = warm  # installed by each process with the first task of the sweep it runs
        for task, results in zip(tasks, stream(array_chunks, tasks, executor, shared)):
            result = results[0]
            if "block" in result:
                block = result["block"]
                seconds += result["seconds"]
            else:
                block = Block.from_rows(
                    [{"index": i, **{a.field: v for a, v in zip(axes, values)}, "status": "failed",
                      "reason": result["reason"], "model": model}
                     for i, values in zip(range(task["start"], task["stop"]), grid(axes, task["start"], task["stop"]))])
            tally(block, counted)
            if progress is not None:
                progress(task["stop"], size)
            if sink is not None:
                sink(block)
            if keep:
                kept += block.rows()
    return kept, counted, seconds


_MEMOS: dict = {}
"""This process's memos of the sweep it is working on: {sweep key: (rule memos, slope memo, validation messages,
rule verdicts)}."""


def install_memos(key: str, rules: bool, warm: list | None) -> None:
    """This process's memos of sweep ``key`` (the only ones it keeps; :func:`matcad.sweep.arrays.memos`), started
    from ``warm`` (:func:`matcad.sweep.warm.warmed`) where given."""
    memos = arrays.memos(rules)
    for memo, (tables, outcomes) in zip(memos, warm or ()):
        memo.merge(tables, outcomes)
    _MEMOS.clear()
    _MEMOS[key] = memos[1:], memos[0], {}, {}


def array_chunks(tasks: list[dict]) -> list[dict]:
    """Executor function: each task (a chunk of the grid) → {"index", "rows", "seconds"}. The chunks of one sweep
    that reach one process share its memos (keyed on the whole grid's values, so valid across chunks), started
    from the warm-up's (a task's ``warm``)."""
    out = []
    for task in tasks:
        if task["key"] not in _MEMOS:
            install_memos(task["key"], task["rules"], task.get("warm"))
        out.append(array_chunk(task, *_MEMOS[task["key"]]))
    return out


def array_chunk(task: dict, rule_memos=None, slope_memo=None, seen=None, known=None) -> dict:
    """The rows of variants ``start:stop`` of the grid by :func:`matcad.sweep.arrays.evaluate`, as a
    :class:`Block`."""
    from matcad.spec import from_dict

    t0 = time.perf_counter()
    data, axes, model = task["data"], task["axes"], task["model"]
    chunk = arrays.GridChunk(data, axes, np.arange(task["start"], task["stop"]))
    out = arrays.evaluate(chunk, from_dict(data), model, task["rules"], rule_memos or arrays.rule_memos(),
                          slope_memo or arrays.slope_memo(), seen, known)
    n, status = len(chunk), out["status"]
    valued = status != "invalid"

    def where(mask, values) -> list:
        return np.where(mask, np.asarray(values, dtype=object), None).tolist()

    load = out["load_slope"]
    has_load = np.array([v is not None and not isinstance(v, tuple) for v in load], dtype=bool) & valued
    columns = {"index": chunk.rows.tolist(),
               **{a.field: np.asarray(a.values, dtype=object)[chunk.index[k]].tolist() for k, a in enumerate(axes)},
               "status": status.tolist(), "reason": out["reason"].tolist(), "model": [model] * n,
               **{key: where(valued, out[key].astype(float).tolist()) for key in ("f0_hz", "band_low_hz",
                                                                                 "band_high_hz")},
               "model_valid": where(valued, [bool(v) for v in out["model_valid"]]),
               **{sensitivity_column(a): where(valued, out[("slope", a.field)].tolist()) for a in axes},
               LOAD_SENSITIVITY: where(has_load, load)}
    if task["rules"]:
        judged = status == "ok"
        columns.update(rule_errors=where(judged, out["rule_errors"].tolist()),
                       rule_warnings=where(judged, out["rule_warnings"].tolist()),
                       failing_rules=where(judged, out["failing_rules"]))
    return {"index": task["index"], "block": Block(columns), "seconds": time.perf_counter() - t0}


def _grid_slopes(result: SweepResult) -> None:
    """df0/dfield along each axis of the grid for the per-variant models: numpy.gradient on the axis values
    (second-order central inside, one-sided at the ends), one-sided next to an invalid or failed variant."""
    f0 = result.column("f0_hz")
    for k, axis in enumerate(result.axes):
        if len(axis.values) < 2:
            continue
        x = np.array(axis.values)
        f = np.moveaxis(f0, k, -1)
        step = np.diff(f, axis=-1) / np.diff(x)
        pad = np.full(f.shape[:-1] + (1,), np.nan)
        forward, backward = np.concatenate([step, pad], axis=-1), np.concatenate([pad, step], axis=-1)
        slope = np.gradient(f, x, axis=-1)
        slope = np.where(np.isnan(slope), np.where(np.isnan(forward), backward, forward), slope)
        name = sensitivity_column(axis)
        for row, s in zip(result.rows, np.moveaxis(slope, -1, k).ravel()):
            if np.isfinite(s):
                row[name] = float(s)
