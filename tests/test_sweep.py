"""`matcad sweep`: the vectorised rungs against predict, the grid's input errors, the table and maps read back,
the executors (local processes, a Dask LocalCluster) giving the same table, failures recorded."""

import csv
import dataclasses
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from matcad.acoustics.design import calibration
from matcad.prediction import predict
from matcad.spec import from_dict, read_spec_data
from matcad.sweep import MAX_POINTS, Executor, parse_axes, sweep
from matcad.sweep import fast
from matcad.sweep.arrays import CHUNK
from matcad.sweep.run import LOAD_SENSITIVITY, sensitivity_column
from tests.conftest import MINIMAL, PAPER, ROOT, run_cli

PEAK_PRECISION = 6e-11
"""A silicone wall's searched peak is found to this fraction of f0 (the 99th percentile over random variants,
tests/test_wall_peak.py): `predict`'s central difference of two searched peaks at step h is good to ~2 x this x f0 / 2h
(a sweep's slope of followed peaks is the derivative to 3e-5 of itself, tests/test_wall_peak.py)."""


def _random_specs(n, seed):
    """Random valid variants of the paper taxel across the ranges a sweep explores (mm, deg, °C)."""
    rng = np.random.default_rng(seed)
    data = read_spec_data(PAPER)
    specs = []
    for _ in range(n):
        cavity_d = rng.uniform(1.5, 8.0)
        d = dict(data)
        d["cavity"] = {"diameter": cavity_d, "length": rng.uniform(0.8, 12.0)}
        d["neck"] = {**data["neck"], "diameter": rng.uniform(0.3, 1.0) * cavity_d, "length": rng.uniform(0.5, 10.0),
                     "mouth": str(rng.choice(["mount", "baffled", "unflanged"]))}
        d["mold"] = {"draft_deg": rng.uniform(0.0, 2.0)}
        d["air"] = {"temperature_c": rng.uniform(-10.0, 50.0)} if rng.random() < 0.7 else \
            {"speed_of_sound": rng.uniform(300.0, 400.0)}
        d["spacer"] = {"height": rng.uniform(0.3, 4.0)}
        d["plate"] = {"width": rng.uniform(10.0, 40.0), "depth": rng.uniform(10.0, 40.0),
                      "neck_pilot": bool(rng.random() < 0.3), "thickness_measured": bool(rng.random() < 0.5)}
        d["machine"] = {"printer": str(rng.choice(["fdm", "sla"]))}
        specs.append(from_dict(d))
    return specs


@pytest.mark.parametrize("model", fast.VECTORISED)
def test_vectorised_rungs_equal_predict(model):
    specs = _random_specs(60, seed=fast.VECTORISED.index(model))
    for mouth in ("mount", "baffled", "unflanged"):
        group = [s for s in specs if s.neck.mouth == mouth]
        v = fast.from_specs(group)
        f0 = fast.f0_hz(v, model)
        ok = fast.valid(v, model, f0)
        low, high = fast.band_hz(v, model, f0, ok)
        for i, spec in enumerate(group):
            p = predict(spec, model=model, mechanics=False)
            assert f0[i] == pytest.approx(p.f0_hz, rel=1e-9)
            assert (low[i], high[i]) == pytest.approx(p.band_hz, rel=1e-9)
            assert bool(ok[i]) == p.models[model].valid


def test_vectorised_sensitivity_is_the_slope_of_predict():
    """df0/dfield (central difference at 1e-6) against predict at ±1e-3 mm: an independent route, O(h²)."""
    spec = from_dict(read_spec_data(PAPER))
    v = fast.from_specs([spec])
    for section, name in (("cavity", "length"), ("neck", "diameter"), ("air", "temperature_c")):
        x = getattr(getattr(spec, section), name)
        ends = [from_dict({**read_spec_data(PAPER), section: {**read_spec_data(PAPER).get(section, {}),
                                                                 name: x + s * 1e-3}}) for s in (-1, 1)]
        f = [predict(e, model="transmission_line", mechanics=False).f0_hz for e in ends]
        slope = (f[1] - f[0]) / 2e-3
        assert fast.sensitivity(v, "transmission_line", f"{section}.{name}")[0] == pytest.approx(slope, rel=1e-5)
    assert fast.sensitivity(v, "transmission_line", "guide.thickness")[0] == 0.0


def test_sweep_table_load_sensitivity_is_eq5_slope():
    data = read_spec_data(PAPER)
    result = sweep(data, parse_axes(["neck.diameter=1.8,2.1"]), model="transmission_line", rules=False)
    for row in result.rows:
        spec = from_dict({**data, "neck": {**data["neck"], "diameter": row["neck.diameter"]}})
        cal = calibration(spec)  # tied to this variant's neck and air
        assert cal.k_mm3_hz2 == pytest.approx(predict(spec, mechanics=False).speed_of_sound_m_s ** 2 * 1e6
                                              * spec.neck.diameter ** 2 / 4 / (4 * np.pi ** 2 * spec.neck.length))
        f = cal.frequency_hz(np.array([0.0, 1e-4]))
        assert row[LOAD_SENSITIVITY] == pytest.approx((f[1] - f[0]) / 1e-4, rel=1e-3)


def test_grid_model_and_rules_match_predict_per_variant():
    data = read_spec_data(PAPER)
    result = sweep(data, parse_axes(["cavity.length=3:6:3", "neck.diameter=1.6,3.3"]), model="end_corrected")
    assert len(result.rows) == 6 and result.shape == (3, 2)
    invalid = [r for r in result.rows if r["status"] == "invalid"]
    assert [r["neck.diameter"] for r in invalid] == [3.3] * 3 and "neck.diameter" in invalid[0]["reason"]
    from matcad.rules import check

    for row in (r for r in result.rows if r["status"] == "ok"):
        spec = from_dict({**data, "cavity": {**data["cavity"], "length": row["cavity.length"]},
                          "neck": {**data["neck"], "diameter": row["neck.diameter"]}})
        p = predict(spec, model="end_corrected", mechanics=False)
        assert row["f0_hz"] == pytest.approx(p.f0_hz, rel=1e-12)
        findings = check(spec, p)
        assert row["rule_errors"] == sum(f.level == "error" for f in findings)
        assert row["rule_warnings"] == sum(f.level == "warning" for f in findings)


def _equal_per_variant(result, data, axes, model: str) -> None:
    """Every row of an array sweep equals the per-variant path's (:func:`matcad.sweep.tasks.run_variant`:
    from_dict, predict, check) on the same data: status, reason, f0, band, validity and every rule verdict."""
    from matcad.sweep.grid import grid, variant_data
    from matcad.sweep.tasks import run_variant

    for row, values in zip(result.rows, grid(axes)):
        one = run_variant({"index": row["index"], "data": variant_data(data, axes, values), "model": model,
                           "predict": True, "rules": True})
        for key in ("status", "reason", "f0_hz", "band_low_hz", "band_high_hz", "model_valid", "rule_errors",
                    "rule_warnings", "failing_rules"):
            assert row.get(key) == one.get(key), (key, values, row.get(key), one.get(key))


@pytest.mark.parametrize("riser,wall,vary", [
    ({"thickness": 1.5}, "rigid", ["riser.thickness=1.5,3", "cavity.length=3:5:3"]),  # necks through it
    (None, "silicone", ["riser.thickness=1.5,3", "neck.diameter=1.5,2.1"]),  # an axis adds one: caps in pockets
])
def test_a_sweep_with_a_riser_runs_each_variant_as_predict_does(riser, wall, vary):
    """A riser's sheet is in no array of matcad.sweep.fast: such a grid runs variant by variant, each row what
    `predict` + `check` give (the arrays would keep the plate's one neck length and clamp: fails if the grid
    goes to them). Through the riser the neck grows; in its pockets the silicone wall is clamped higher."""
    data = {**read_spec_data(ROOT / "templates/mat-laser-only.toml"), "wall": {"model": wall}}
    if riser is not None:
        data = {**data, "riser": riser, "neck": {**data["neck"], "riser": True}}
    model = {"rigid": "transmission_line", "silicone": "elastic_wall"}[wall]
    axes = parse_axes(vary)
    result = sweep(data, axes, model=model)
    assert not result.vectorised
    _equal_per_variant(result, data, axes, model)
    half = len(result.rows) // 2  # the riser's thickness (the first axis) moves every pitch
    for one, other in zip(result.rows[:half], result.rows[half:]):
        assert one["riser.thickness"] != other["riser.thickness"] and one["f0_hz"] != other["f0_hz"]


@pytest.mark.parametrize("template,vary,bends", [
    (PAPER, ["cavity.diameter=1.5:9:4", "neck.diameter=1.2,2.1,3.3", "mold.draft_deg=0,8",
             "microphone.sample_rate_hz=9000,48000"], False),
    ("templates/mat-laser-only.toml", ["cavity.length=1:14:4", "neck.diameter=0.4,2.0,3.9", "plate.width=10,30",
                                       "neck.length=0.8,9"], False),
    ("templates/mat-laser-only.toml", ["neck.length=0.8,1.5,3", "mechanics.max_force_n=0.5,2,20",
                                       "spacer.height=0.3,1.5", "plate.width=24,60"], True),
    (PAPER, ["neck.length=0.8,1.5,3", "mechanics.max_force_n=0.5,5,20", "spacer.height=0.3,1.5"], True),
])
def test_array_sweep_equals_the_per_variant_path(template, vary, bends):
    """Validation messages, f0, band and every rule verdict of the array sweep against the per-variant path
    (:func:`matcad.sweep.tasks.run_variant`: from_dict, predict, check) on grids with invalid and rule-breaking
    variants (fails if a memoised rule misses a field it reads, or the array checks miss a refusal). The last two
    grids bend the plate: plate.bending judged on arrays (matcad.rules.plate.bending_warnings) with pitch shifts of
    -1.0 to -4520 Hz either side of its limit, mouths closed by the plate, rigid and silicone walls."""
    data = read_spec_data(ROOT / template)
    axes = parse_axes(vary)
    result = sweep(data, axes, model="transmission_line")
    assert result.vectorised
    _equal_per_variant(result, data, axes, "transmission_line")
    statuses = set()
    for row in result.rows:
        statuses.add((row["status"], bool(row.get("rule_errors"))) if not bends else
                     "plate.bending:warning" in (row.get("failing_rules") or ""))
    assert statuses == {True, False} if bends else {("invalid", False), ("ok", True), ("ok", False)} <= statuses


def test_elastic_wall_sweeps_on_arrays_equal_to_predict():
    """The silicone wall (the paper spec's own physics, its calibration left out) runs on arrays: each row is
    predict's f0 and band exactly, and df0/dfield is the model's own derivative (against predict at +-1e-3 mm,
    O(h^2))."""
    data = {k: v for k, v in read_spec_data(PAPER).items() if k != "calibration"}
    result = sweep(data, parse_axes(["cavity.length=4:5:3"]), rules=False)
    assert result.model == "elastic_wall" and result.vectorised
    col = sensitivity_column(result.axes[0])
    for row, x in zip(result.rows, (4.0, 4.5, 5.0)):
        p = predict(from_dict({**data, "cavity": {**data["cavity"], "length": x}}), mechanics=False)
        assert row["f0_hz"] == p.f0_hz and (row["band_low_hz"], row["band_high_hz"]) == p.band_hz
        f = [predict(from_dict({**data, "cavity": {**data["cavity"], "length": x + s}}), mechanics=False).f0_hz
             for s in (-1e-3, 1e-3)]
        assert row[col] == pytest.approx((f[1] - f[0]) / 2e-3, rel=1e-4)


def test_a_calibrated_spec_sweeps_by_its_calibration():
    """The paper template's calibration anchors every variant of its sweep (the calibrated f(0) times the physics
    ratio to the calibrated drawing), row for row predict's, on arrays."""
    data = read_spec_data(PAPER)
    result = sweep(data, parse_axes(["cavity.length=4:5:3"]), rules=False)
    assert result.model == "calibration" and result.vectorised
    base = from_dict(data)  # the calibrated taxel is the one drawn as loaded, whatever a variant changes
    for row, x in zip(result.rows, (4.0, 4.5, 5.0)):
        p = predict(dataclasses.replace(base, cavity=dataclasses.replace(base.cavity, length=x)), mechanics=False)
        assert p.model == "calibration" and row["f0_hz"] == p.f0_hz
        assert (row["band_low_hz"], row["band_high_hz"]) == p.band_hz
    assert result.rows[0]["f0_hz"] > result.rows[2]["f0_hz"]  # a longer cavity sings lower


@pytest.mark.parametrize("vary", [["cavity.length=3.5,4.76,6", "neck.diameter=1.5,2.1,2.4"],
                                  ["cavity.diameter=3,3.18,6", "spacer.height=0.5,1.5", "neck.length=3,6.35"],
                                  ["end_cap.outer_diameter=10,12", "microphone.sample_rate_hz=9000,48000",
                                   "mold.draft_deg=0,1", "silicone.density_g_cm3=1.0,1.2"]])
def test_calibrated_sweep_on_arrays_equals_the_per_variant_path(vary):
    """The calibration anchor on arrays (matcad.sweep.calibrated) against `predict --model calibration` and `check`
    variant by variant: status, f0, band, validity and every rule verdict equal, on grids that include the
    calibrated drawing itself (ratio 1, no model-ratio line), vary how it is built (the mount gap, the draft) and a
    field the drawing does not fix (the silicone's density: the calibrated drawing's physics moves too), and break
    rules; the slope is the anchored f0's own derivative, to the precision of the peaks predict differences (the
    sweep follows the moved variants' peaks from the variant's own, predict searches for them; see PEAK_PRECISION)."""
    from matcad.prediction.anchor import CalibrationAnchor
    from matcad.spec.drawn import DRAWN, pinned
    from matcad.sweep.grid import variant_data

    data = read_spec_data(PAPER)
    axes = parse_axes(vary)
    result = sweep(data, axes)
    assert result.model == "calibration" and result.vectorised
    pinned_data = pinned(data, from_dict(data))
    f_cal = CalibrationAnchor(from_dict(data)).f_cal
    _equal_per_variant(result, pinned_data, axes, "calibration")
    drawn = {f"{table}.{name}": getattr(from_dict(data).calibration, key) for key, (table, name) in DRAWN.items()}
    for row in result.rows:  # the calibrated drawing sings at f(0) exactly (whatever else varies)
        assert (row["f0_hz"] == f_cal) == all(row[a.field] == drawn.get(a.field, row[a.field]) for a in axes)
    assert any(row["rule_errors"] for row in result.rows) or any(row["rule_warnings"] for row in result.rows)
    col = sensitivity_column(axes[0])
    row = result.rows[1]
    x = row[axes[0].field]
    h = 1e-6 * max(abs(x), 1.0)  # the array's step (matcad.sweep.fast.RELATIVE_STEP): predict's own difference
    f = [predict(from_dict(variant_data(pinned_data, axes, (x + s,) + tuple(row[a.field] for a in axes[1:]))),
                 model="calibration", mechanics=False).f0_hz for s in (-h, h)]
    assert row[col] == pytest.approx((f[1] - f[0]) / (2 * h), rel=1e-6, abs=PEAK_PRECISION * row["f0_hz"] / h)


def test_a_sweeps_bending_reads_the_f0_it_already_has():
    """plate.bending on a sweep's arrays takes the variants' f0 as built from the sweep rather than searching for
    it again: the same pitch changes, bit for bit."""
    from matcad.acoustics.registry import CHOSEN
    from matcad.rules.plate import pitch_shift_hz
    from matcad.sweep import arrays

    data = read_spec_data(PAPER)
    base = from_dict(data)
    chunk = arrays.GridChunk(data, parse_axes(["neck.length=2:8:5", "cavity.length=3:6:4"]), np.arange(20))
    v = arrays.variants(chunk, base)
    built = fast.f0_hz(v, CHOSEN[base.wall.model])
    bent = np.linspace(0.05, 0.5, 20)
    searched = pitch_shift_hz(v.design(), bent, base.wall.model)
    assert pitch_shift_hz(v.design(), bent, base.wall.model, built).tobytes() == searched.tobytes()
    assert np.all(searched < 0)  # a narrower gap lengthens the mouth's end correction: the pitch falls


def test_a_calibration_remembers_the_mount_gap_it_was_measured_with():
    """The calibrated taxel is its drawing as built (matcad.spec.drawn.DRAWN): a sweep of the mount gap on the paper
    template moves the calibrated f0 by the physics ratio to the gap it was measured with (it kept f(0) on every
    row while the drawing was its geometry alone), and the measured gap's own row is f(0)."""
    from matcad.acoustics.registry import CHOSEN, model
    from matcad.acoustics.design import design
    from matcad.acoustics.resonator import resonator
    from matcad.prediction.anchor import CalibrationAnchor

    data = read_spec_data(PAPER)
    base = from_dict(data)
    result = sweep(data, parse_axes(["spacer.height=0.5,1.59,3.0"]), rules=False)
    f0 = [row["f0_hz"] for row in result.rows]
    f_cal = CalibrationAnchor(base).f_cal
    physics = model(CHOSEN["silicone"])

    def f_physics(height):
        d = design(dataclasses.replace(base, spacer=dataclasses.replace(base.spacer, height=height)))
        return physics.f0_hz(resonator(d), d.wall)

    assert f0[1] == f_cal and f0[0] < f0[1] < f0[2]
    assert f0[0] / f_cal == pytest.approx(f_physics(0.5) / f_physics(1.59), rel=1e-12)
    assert f0[0] / f_cal < 0.93  # the 0.5 mm gap: 8.8 % lower


def test_cavity_diameter_slope_moves_the_cap_that_follows_it():
    """Where the spec leaves the cap's size to its default (2.5 x and 0.6 x cavity.diameter), df0/d(cavity.diameter)
    moves the cap with the cavity, as a spec file with that diameter would (the physics: no calibration)."""
    data = {k: v for k, v in read_spec_data(PAPER).items() if k != "calibration"}
    data = {**data, "end_cap": {}}
    result = sweep(data, parse_axes(["cavity.diameter=3.0,3.2"]), rules=False)
    col = sensitivity_column(result.axes[0])
    for row in result.rows:
        f = [predict(from_dict({**data, "cavity": {**data["cavity"], "diameter": row["cavity.diameter"] + s}}),
                     mechanics=False).f0_hz for s in (-1e-3, 1e-3)]
        assert row[col] == pytest.approx((f[1] - f[0]) / 2e-3, rel=1e-4)


def test_per_variant_model_and_grid_slope():
    """A spec with a [reference] runs predict per variant ('relative'); df0/dfield is then numpy.gradient along
    the axis."""
    data = {k: v for k, v in read_spec_data(PAPER).items() if k != "calibration"}  # else the calibration anchors
    data = {**data, "reference": {"f0_hz": 4000.0, "f0_tolerance_hz": 100.0}}
    result = sweep(data, parse_axes(["cavity.length=4:5:3"]), rules=False)
    assert result.model == "relative" and not result.vectorised
    f0 = [r["f0_hz"] for r in result.rows]
    base = from_dict(data)  # the reference is the taxel drawn as loaded, whatever a variant changes
    for row, x in zip(result.rows, (4.0, 4.5, 5.0)):
        p = predict(dataclasses.replace(base, cavity=dataclasses.replace(base.cavity, length=x)), mechanics=False)
        assert row["f0_hz"] == p.f0_hz and (row["band_low_hz"], row["band_high_hz"]) == p.band_hz
    col = sensitivity_column(result.axes[0])
    assert result.rows[1][col] == pytest.approx((f0[2] - f0[0]) / 1.0)
    assert result.rows[0][col] == pytest.approx((f0[1] - f0[0]) / 0.5)
    edge = sweep(data, parse_axes(["neck.diameter=1.8,2.4,3.3"]), rules=False)  # 3.3 mm > the 3.18 mm cavity
    f0 = [r.get("f0_hz") for r in edge.rows]
    assert edge.rows[2]["status"] == "invalid" and f0[2] is None
    col = sensitivity_column(edge.axes[0])
    assert edge.rows[1][col] == pytest.approx((f0[1] - f0[0]) / 0.6) == edge.rows[0][col]
    assert col not in edge.rows[2]


@pytest.mark.parametrize("model", ["transmission_line", "relative"])
def test_failed_variant_is_recorded_not_fatal(monkeypatch, model):
    """A design rule that raises on one variant fails that row only, on arrays and per variant alike."""
    from matcad.rules import laser

    def flaky(spec):
        if spec.cavity.length > 5:
            raise RuntimeError("solver diverged")
        return []

    monkeypatch.setattr(laser, "RULES", laser.RULES + (flaky,))
    data = read_spec_data(PAPER)
    if model == "relative":
        data = {**data, "reference": {"f0_hz": 4000.0, "f0_tolerance_hz": 100.0}}
    result = sweep(data, parse_axes(["cavity.length=4,6"]), model=model)
    assert result.vectorised == (model != "relative")
    assert [r["status"] for r in result.rows] == ["ok", "failed"]
    assert "RuntimeError: solver diverged" in result.rows[1]["reason"]
    assert result.rows[0]["rule_errors"] is not None and "rule_errors" not in result.rows[1]


def _table(result):
    return [{k: v for k, v in r.items()} for r in result.rows]


def test_dask_local_cluster_gives_the_same_table():
    from dask import distributed  # matcad[cluster], installed by the dev extra
    data = read_spec_data(PAPER)
    axes = parse_axes(["cavity.length=3.5:5.5:3", "neck.diameter=1.8,2.4"])
    local = sweep(data, axes)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) \
            as cluster:
        remote = sweep(data, axes, executor=Executor(scheduler=cluster.scheduler_address))
    assert remote.executor.startswith("dask") and local.executor == "this process"
    assert _table(remote) == _table(local)


@pytest.mark.slow
def test_local_processes_give_the_same_table():
    data = read_spec_data(PAPER)
    axes = parse_axes(["cavity.length=3.5:5.5:3", "neck.diameter=1.8,2.4"])
    assert _table(sweep(data, axes, executor=Executor(2))) == _table(sweep(data, axes))


def crash_on_index_3(tasks):
    """A chunk function whose worker process dies on variant 3 (module level: spawned workers import it)."""
    import os

    if any(t["index"] == 3 for t in tasks):
        os._exit(3)
    return [{"index": t["index"], "status": "ok", "reason": ""} for t in tasks]


@pytest.mark.slow
def test_dead_worker_fails_its_variants_not_the_sweep():
    from matcad.sweep.executor import run

    results = run(crash_on_index_3, [{"index": i} for i in range(8)], Executor(2))
    assert [r["index"] for r in results] == list(range(8))
    assert results[3]["status"] == "failed" and "worker lost" in results[3]["reason"]
    # only the dead worker's chunk (one variant here: 8 tasks in 2 x 4 chunks) fails; the others are run again
    assert [r["status"] for r in results] == ["ok"] * 3 + ["failed"] + ["ok"] * 4


def test_a_killed_worker_fails_only_its_own_chunk_at_ci_cost():
    """The property of the two slow tests around this one, on every CI run (~1 s of CPU: the chunk function lives in
    a small module, so a spawned worker imports nothing heavy): a local worker killed mid-sweep (SIGKILL) fails only
    its own chunk ("worker lost"); the chunks its death took down with the pool (still running or queued then) run
    again and come back ok, in task order, from run and stream alike."""
    from matcad.sweep.executor import run, stream
    from tests.dying_worker import killed_on_index_1

    tasks = [{"index": i} for i in range(4)]  # 2 workers x 4 chunks per worker: one task per chunk
    for results in (run(killed_on_index_1, tasks, Executor(2)),
                    [r for chunk in stream(killed_on_index_1, tasks, Executor(2)) for r in chunk]):
        assert [r["index"] for r in results] == [0, 1, 2, 3]
        assert [r["status"] for r in results] == ["ok", "failed", "ok", "ok"], results
        assert "worker lost" in results[1]["reason"]


def test_streams_on_shared_processes_reuse_them_and_outlive_a_killed_worker():
    """A sweep's warm-up and grid stream on the same local processes (matcad.sweep.executor.Processes): the second
    stream runs on the first one's processes, none spawned anew; a worker killed in one stream fails only its own
    task there, and the next stream on the restarted processes runs whole."""
    import os

    from matcad.sweep.executor import Processes, stream
    from tests.dying_worker import killed_on_index_1, process_of

    tasks = [{"index": i} for i in range(4)]
    with Processes(2) as shared:
        pids = {r["pid"] for _ in range(2) for chunk in stream(process_of, tasks, Executor(2), shared)
                for r in chunk}
        killed = [r for chunk in stream(killed_on_index_1, tasks, Executor(2), shared) for r in chunk]
        after = [r for chunk in stream(process_of, tasks, Executor(2), shared) for r in chunk]
    assert 1 <= len(pids) <= 2 and os.getpid() not in pids  # two streams, at most the two processes
    assert [r["status"] for r in killed] == ["ok", "failed", "ok", "ok"] and "worker lost" in killed[1]["reason"]
    assert [r["status"] for r in after] == ["ok"] * 4 and not {r["pid"] for r in after} & pids


@pytest.mark.slow
def test_streamed_chunks_come_in_order_and_a_dead_worker_fails_only_its_own():
    from matcad.sweep.executor import stream

    results = [r for chunk in stream(crash_on_index_3, [{"index": i} for i in range(8)], Executor(2)) for r in chunk]
    assert [r["index"] for r in results] == list(range(8))
    assert [r["status"] for r in results] == ["ok"] * 3 + ["failed"] + ["ok"] * 4
    assert "worker lost" in results[3]["reason"]


@pytest.mark.parametrize("address", ["nonsense", "tcp://host:notaport", "tcp://127.0.0.1:99999", "localhost:8786x",
                                     "http://127.0.0.1:8786", "tcp://:8786"])
def test_malformed_scheduler_is_bad_input_at_once(tmp_path, address):
    with pytest.raises(ValueError, match="host:port"):  # refused when the executor is made, before any connection
        Executor(scheduler=address)                     # (Dask itself would wait 20 s, then raise a traceback)
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3,4", "--scheduler", address,
                           "--out", tmp_path / "s")
    assert code == 2 and f"--scheduler {address}" in err and "host:port" in err and "Traceback" not in err, err
    assert not (tmp_path / "s").exists()


def test_unreachable_scheduler_is_bad_input(tmp_path):
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3,4", "--scheduler", "tcp://127.0.0.1:9",
                           "--out", tmp_path / "s")
    assert code == 2 and "--scheduler tcp://127.0.0.1:9" in err
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("vary,words", [
    ("cavity.lenght=3:6:4", ["cavity.lenght", "did you mean 'cavity.length'"]),
    ("cavity.length=3:6:0", ["cavity.length", "N = 0", f"1 <= N <= {MAX_POINTS}"]),
    (f"cavity.length=3:6:{MAX_POINTS + 1}", ["cavity.length", f"<= {MAX_POINTS}"]),
    ("cavity.length=6:3:4", ["cavity.length", "LO = 6 must be <= HI = 3"]),
    ("cavity.length=-1:3:4", ["cavity.length", "-1", "outside the field's range", "0.001 <= value <= 100000 mm"]),
    ("mold.draft_deg=0,12", ["mold.draft_deg", "12", "<= 10 deg"]),
    ("neck.mouth=1,2", ["neck.mouth", "not a numeric spec field"]),
    ("cavity.length=3:x:4", ["cavity.length", "finite number"]),
    ("mold.count=1.5,2", ["mold.count", "whole numbers"]),
    ("mold.count=0,1", ["mold.count = 0:", "1 <= value <= 50"]),
    ("mechanics.steps=1:200:3", ["mechanics.steps", "not all whole numbers", "(HI - LO) / (N - 1) whole"]),
])
def test_bad_vary_is_exit_2_and_writes_nothing(tmp_path, vary, words):
    out = tmp_path / "sweep"
    code, _, err = run_cli("sweep", PAPER, "--vary", vary, "--out", out)
    assert code == 2, err
    assert "Traceback" not in err and all(w in err for w in words), err
    assert not out.exists() and not list(tmp_path.iterdir())


def test_integer_fields_sweep_as_whole_numbers_from_their_lower_bound(tmp_path):
    """An integer field's bounds are both inclusive, as the spec checks them (mold.count = 1 is valid): `--vary
    mold.count=1,2` and `mechanics.steps=1,200` were refused ("1.0: outside the field's range: a whole number,
    1 <= value <= 50"; the sweep read an open lower bound). Their values are ints: in the axis, the table, the JSON."""
    axes = parse_axes(["mechanics.steps=1,200", "array.columns=1:4:4"])
    assert [a.values for a in axes] == [(1, 200), (1, 2, 3, 4)]
    assert all(type(v) is int for a in axes for v in a.values)
    out = tmp_path / "s"
    code, _, err = run_cli("sweep", ROOT / "templates" / "mat-laser-only.toml", "--vary", "mold.count=1,2",
                           "--no-rules", "--workers", "1", "--out", out)
    assert code == 0, err
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [(r["mold.count"], r["status"]) for r in rows] == [("1", "ok"), ("2", "ok")]
    assert json.loads((out / "sweep.json").read_text())["axes"][0]["values"] == [1, 2]


def test_grid_cap_and_bad_model(tmp_path):
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3:6:200", "--vary", "neck.diameter=1:2:200",
                           "--model", "fem", "--out", tmp_path / "s")  # per variant: at most MAX_VARIANTS
    assert code == 2 and "40000 variants, at most 20000" in err and "model fem" in err and "Traceback" not in err
    code, _, err = run_cli("sweep", PAPER, *[x for f in ("cavity.length", "neck.diameter", "neck.length",
                                                         "mold.draft_deg") for x in ("--vary", f"{f}=0.5:0.9:200")],
                           "--out", tmp_path / "s")  # on arrays: at most MAX_GRID
    assert code == 2 and "1600000000 variants, at most 10000000" in err
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3,4", "--model", "lumpd", "--out", tmp_path / "s")
    assert code == 2 and "'lumpd'" in err and "lumped" in err
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3,4", "--model", "elastic_wall",
                           "--set", "wall.model=rigid", "--out", tmp_path / "s")
    assert code == 2 and "--model 'elastic_wall' invalid" in err and "transmission_line" in err
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3,4", "--fem-level", "99", "--model", "fem",
                           "--out", tmp_path / "s")
    assert code == 2 and "--fem-level 99 invalid" in err
    assert not list(tmp_path.iterdir())


def _png_axes(path):
    from PIL import Image

    with Image.open(path) as im:
        assert im.format == "PNG" and im.size[0] > 300 and im.size[1] > 200
        pixels = np.asarray(im.convert("L"), dtype=float)
        assert pixels.std() > 5  # something is drawn
        return im.text["matcad:x"], im.text["matcad:y"], im.text["matcad:quantity"]


@pytest.mark.parametrize("varies", [["neck.diameter=20,30"],
                                    ["neck.diameter=30,2", "cavity.length=3:6:200", "neck.length=1:8:21"]])
def test_chunks_of_invalid_variants_only_are_rows_with_rules_on(tmp_path, varies):
    """A grid whose variants are all invalid, and one whose first chunk of 4 096 is (a neck wider than the cavity),
    with the rules on: exit 0, every invalid row names its reason and has no f0, slope or verdict, the valid ones
    have all three (it was an internal error: the chunk had no rule columns)."""
    out = tmp_path / "inv"
    code, _, err = run_cli("sweep", PAPER, *[a for v in varies for a in ("--vary", v)], "--model",
                           "transmission_line", "--out", out)
    assert code == 0, err
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == (2 if len(varies) == 1 else 8400) and int(rows[-1]["index"]) == len(rows) - 1
    slope = "df0_d_neck.diameter_hz_per_mm"
    for r in rows:
        if float(r["neck.diameter"]) == 2.0:
            assert r["status"] == "ok" and r["f0_hz"] and r[slope] and r["rule_errors"].isdigit()
        else:
            assert r["status"] == "invalid" and "neck.diameter" in r["reason"]
            assert r["f0_hz"] == r[slope] == r["rule_errors"] == r["failing_rules"] == ""


def test_cli_two_axes_table_and_heat_maps_read_back(tmp_path):
    out = tmp_path / "s2"
    code, stdout, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3:6:4", "--vary", "neck.diameter=1.5,2.1,3.3",
                                "--model", "transmission_line", "--set", "microphone.sample_rate_hz=12000",
                                "--out", out, "--json")
    assert code == 0, err
    summary = json.loads(stdout)
    assert summary["variants"] == 12 and summary["invalid"] == 4 and summary["rule_errors"] >= 1
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 12
    assert [(float(r["cavity.length"]), float(r["neck.diameter"])) for r in rows[:3]] == \
        [(3.0, 1.5), (3.0, 2.1), (3.0, 3.3)]
    ok = [r for r in rows if r["status"] == "ok"]
    assert all(float(r["band_low_hz"]) < float(r["f0_hz"]) < float(r["band_high_hz"]) for r in ok)
    assert any(int(r["rule_errors"]) > 0 and "acoustic.band_high:error" in r["failing_rules"] for r in ok)
    assert all(r["f0_hz"] == "" and r["reason"] for r in rows if r["status"] == "invalid")
    doc = json.loads((out / "sweep.json").read_text())
    assert [a["field"] for a in doc["axes"]] == ["cavity.length", "neck.diameter"] and len(doc["rows"]) == 12
    maps = sorted(p.name for p in (out / "maps").iterdir())
    assert maps == sorted(["f0.png", "band_low.png", "band_high.png", "df0_d_cavity.length.png",
                           "df0_d_neck.diameter.png", "rule_errors.png"])
    assert _png_axes(out / "maps" / "f0.png") == ("neck.diameter [mm]", "cavity.length [mm]", "f0_hz")
    manifest = json.loads((out / ".matcad-manifest.json").read_text())
    assert set(manifest["files"]) == {"sweep.csv", "sweep.json", *(f"maps/{m}" for m in maps)}


def _cell_edges(values) -> list[float]:
    """Midpoints between ascending grid values, half a step beyond the ends (as a heat map's cells span)."""
    v = sorted(values)
    mid = [(a + b) / 2 for a, b in zip(v, v[1:])]
    return [v[0] - (mid[0] - v[0]), *mid, v[-1] + (v[-1] - mid[-1])]


def _assert_heat_map_cells(png, rows, y_field, x_field, quantity="f0_hz") -> set:
    """Read the heat map ``png`` back pixel by pixel against the CSV ``rows`` it shows (``y_field`` up,
    ``x_field`` across): inside each variant's cell (its grid point's midpoints to its neighbours, placed by the
    plot's box) the colour is matplotlib's viridis of its value on the map's range (within 6/255), in white
    diagonal hatching exactly where the variant has rule errors, and an invalid variant's cell is blank. Returns
    the kinds of cells seen (blank, hatched, plain)."""
    from matplotlib import colormaps
    from PIL import Image

    from matcad.sweep.maps import BOX

    ys, xs = sorted({float(r[y_field]) for r in rows}), sorted({float(r[x_field]) for r in rows})
    assert len(rows) == len(ys) * len(xs)
    values = [float(r[quantity]) for r in rows if r["status"] == "ok"]
    lo, hi = min(values), max(values)
    xe, ye = _cell_edges(xs), _cell_edges(ys)
    left, top, right, bottom = BOX
    with Image.open(png) as im:
        pixels = np.asarray(im.convert("RGB")).astype(int)
    white = np.array([255, 255, 255])
    kinds = set()
    for r in rows:
        j, i = xs.index(float(r[x_field])), ys.index(float(r[y_field]))
        x0, x1 = (left + (e - xe[0]) / (xe[-1] - xe[0]) * (right - left) for e in xe[j:j + 2])
        y1, y0 = (bottom - (e - ye[0]) / (ye[-1] - ye[0]) * (bottom - top) for e in ye[i:i + 2])
        cell = pixels[round(y0) + 2:round(y1) - 2, round(x0) + 2:round(x1) - 2].reshape(-1, 3)
        is_white = (cell == white).all(axis=1)
        if r["status"] != "ok":
            assert is_white.all()
            kinds.add("blank")
            continue
        expected = np.array(colormaps["viridis"]((float(r[quantity]) - lo) / (hi - lo))[:3]) * 255
        assert is_white.mean() < 0.5 and np.abs(cell[~is_white] - expected).max() <= 6
        if int(r["rule_errors"] or 0) > 0:
            assert 0.12 < is_white.mean() < 0.22  # one pixel diagonal in six
            kinds.add("hatched")
        else:
            assert not is_white.any()
            kinds.add("plain")
    return kinds


def test_heat_map_cells_read_back(tmp_path):
    """The f0 heat map read back pixel by pixel (:func:`_assert_heat_map_cells`), its axes given out of order:
    blank, hatched and plain cells all where the table puts them."""
    out = tmp_path / "hm"
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3:6:4", "--vary", "neck.diameter=2.1,1.5,3.3",
                           "--model", "transmission_line", "--set", "microphone.sample_rate_hz=12000", "--out", out)
    assert code == 0, err
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert _cell_edges([1.5, 2.1, 3.3]) == pytest.approx([1.2, 1.8, 2.7, 3.9])
    assert _assert_heat_map_cells(out / "maps" / "f0.png", rows, "cavity.length", "neck.diameter") == \
        {"blank", "hatched", "plain"}


def test_a_constant_map_is_mid_scale_in_its_cells_and_on_its_bar(tmp_path):
    """A quantity with one value on every variant (df0/d of a field f0 does not read: exactly 0): every cell is
    viridis's middle colour, and so is the colour bar at the height of that value (the cells were the bottom colour
    while the bar showed the top one above the value)."""
    from matplotlib import colormaps
    from PIL import Image

    from matcad.sweep.maps import BAR, BOX

    out = tmp_path / "c"
    code, _, err = run_cli("sweep", PAPER, "--vary", "neck.length=2,3", "--vary", "mold.count=1,2", "--no-rules",
                           "--model", "transmission_line", "--out", out)
    assert code == 0, err
    with open(out / "sweep.csv", newline="") as f:
        assert {float(r["df0_d_mold.count_hz_per_unit"]) for r in csv.DictReader(f)} == {0.0}
    with Image.open(out / "maps" / "df0_d_mold.count.png") as im:
        pixels = np.asarray(im.convert("RGB")).astype(int)
    middle = np.array(colormaps["viridis"](0.5)[:3]) * 255
    left, top, right, bottom = BOX
    assert np.abs(pixels[top + 3:bottom - 3, left + 3:right - 3] - middle).max() <= 6
    assert np.abs(pixels[(top + bottom) // 2, (BAR[0] + BAR[1]) // 2] - middle).max() <= 6


def test_three_axes_map_every_pair_through_the_middle_of_the_others(tmp_path):
    """Three axes: a folder of maps per pair of axes, each the slice of the grid with the third axis at the median
    of its values (given out of order: 5, 1, 3 holds 3, neither the first nor the lowest), named in the PNG's text
    chunks; each slice's f0 and rule-error maps read back cell by cell against the table's rows at that value."""
    out = tmp_path / "s3"
    code, stdout, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3:6:4", "--vary", "neck.diameter=2.1,1.5,3.3",
                                "--vary", "neck.length=5,1,3", "--model", "transmission_line", "--set",
                                "microphone.sample_rate_hz=12000", "--out", out)
    assert code == 0, err
    assert "18 maps in maps/" in stdout
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    pairs = {"cavity.length-neck.diameter": ("neck.length", 3.0), "cavity.length-neck.length": ("neck.diameter", 2.1),
             "neck.diameter-neck.length": ("cavity.length", 4.0)}
    assert sorted(p.name for p in (out / "maps").iterdir()) == sorted(pairs)
    kinds = set()
    for folder, (held, value) in pairs.items():
        y_field, x_field = folder.split("-")
        assert sorted(p.name for p in (out / "maps" / folder).iterdir()) == sorted(
            ["f0.png", "band_low.png", "band_high.png", f"df0_d_{y_field}.png", f"df0_d_{x_field}.png",
             "rule_errors.png"])
        from PIL import Image

        with Image.open(out / "maps" / folder / "f0.png") as im:
            assert im.text["matcad:held"] == f"{held}={value!r}" and im.text["matcad:quantity"] == "f0_hz"
            assert (im.text["matcad:y"], im.text["matcad:x"]) == (f"{y_field} [mm]", f"{x_field} [mm]")
        plane = [r for r in rows if float(r[held]) == value]
        kinds |= _assert_heat_map_cells(out / "maps" / folder / "f0.png", plane, y_field, x_field)
    assert kinds == {"blank", "hatched", "plain"}
    manifest = json.loads((out / ".matcad-manifest.json").read_text())
    assert sum(name.startswith("maps/") for name in manifest["files"]) == 18


def test_cli_one_axis_line_maps(tmp_path, write_spec):
    out = tmp_path / "s1"
    code, _, err = run_cli("sweep", write_spec(MINIMAL), "--vary", "neck.length=2:8:7", "--out", out, "--workers", "1")
    assert code == 0, err
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 7 and all(r["model"] == "transmission_line" for r in rows)
    f0 = [float(r["f0_hz"]) for r in rows]
    assert all(a > b for a, b in zip(f0, f0[1:]))  # a longer neck sings lower
    assert all(float(r["df0_d_neck.length_hz_per_mm"]) < 0 for r in rows)
    assert _png_axes(out / "maps" / "df0_d_neck.length.png") == \
        ("neck.length [mm]", "df0/d(neck.length) [Hz/mm]", "df0_d_neck.length_hz_per_mm")


def test_fast_sweep_imports_no_cad_kernel_dask_nor_matplotlib(tmp_path):
    """A closed-form sweep with its maps loads neither the CAD kernel, the cluster, the FEMs nor matplotlib."""
    code = ("import sys; from matcad.cli import main; "
            "assert main(['sweep', %r, '--vary', 'cavity.length=3:6:5', '--no-rules', '--model', 'lumped', "
            "'--out', %r]) == 0; "
            "bad = [m for m in ('build123d', 'OCP', 'trimesh', 'dask', 'distributed', 'skfem', 'felupe', "
            "'matplotlib') if m in sys.modules]; assert not bad, bad" % (str(PAPER), str(tmp_path / 's')))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


@pytest.mark.slow
def test_fem_rung_on_local_processes_equals_predict():
    data = read_spec_data(PAPER)
    data = {**data, "wall": {"model": "rigid"}}
    result = sweep(data, parse_axes(["cavity.length=4,5"]), model="fem", fem_level=4, rules=False,
                   executor=Executor(2))
    for row in result.rows:
        spec = from_dict({**data, "cavity": {**data["cavity"], "length": row["cavity.length"]}})
        assert row["f0_hz"] == pytest.approx(predict(spec, model="fem", fem_level=4, mechanics=False).f0_hz,
                                             rel=1e-9)


@pytest.mark.slow
def test_cad_rung_stl_volume_matches_closed_form():
    result = sweep(read_spec_data(PAPER), parse_axes(["cavity.diameter=2.5,3.5"]), model="lumped", rules=False,
                   cad=True)
    for row in result.rows:
        assert row["cad_watertight"] is True
        assert row["cad_stl_volume_mm3"] == pytest.approx(row["cad_closed_form_volume_mm3"], rel=5e-3)


def test_memo_runs_a_rule_once_per_combination_of_the_fields_it_reads():
    """A rule reading one varied field runs once per value of it, one reading none once per grid, one branching
    on a field reads more where it branches; every variant gets its own result (fails if the memo keys on fields
    a rule did not read, or misses one it did)."""
    import numpy as np

    from matcad.sweep.arrays import GridChunk
    from matcad.sweep.memo import Memo

    data = read_spec_data(PAPER)
    axes = parse_axes(["cavity.length=3:6:4", "neck.diameter=1.5:2.4:5", "mold.draft_deg=0,0.5,1"])
    chunk = GridChunk(data, axes, np.arange(60))
    calls = {"neck": 0, "none": 0, "branch": 0}

    def neck(spec):
        calls["neck"] += 1
        return round(spec.neck.diameter, 6)

    def none(spec):
        calls["none"] += 1
        return spec.name

    def branch(spec):
        calls["branch"] += 1
        return spec.neck.diameter if spec.cavity.length > 4.5 else -1.0

    for function, expected in ((neck, 5), (none, 1), (branch, 2 + 2 * 5)):
        memo = Memo(function)
        numbers = memo.apply(chunk)
        assert calls[function.__name__] == expected
        for j in range(60):
            assert memo.outcomes[numbers[j]] == function(chunk.spec(j))


def test_mold_rules_and_the_load_slope_read_only_what_they_depend_on():
    """The mold's rules read the cap (cavity, end cap, whether the neck runs through a riser), not the neck's size,
    and Eq. 5's slope reads the neck and the air, not the cavity: on a grid over cavity.length x neck.diameter x
    neck.length each then runs once per cap or once per neck, not once per variant (fails if a one-taxel spec is
    re-validated through its own taxel, which reads every field, or if the slope builds the whole design)."""
    from matcad.rules import printing
    from matcad.sweep.arrays import GridChunk, slope_memo
    from matcad.sweep.memo import Memo, run

    spec = from_dict(read_spec_data(PAPER))
    neck_size = {"neck.diameter", "neck.length"}
    for rule in (printing.clamp_nut, printing.cavity_appendages, printing.print_bed):
        reads, _ = run(rule, spec)
        assert "cavity.length" in reads and not reads & neck_size, (rule.__name__, sorted(reads))
    reads, slope = run(slope_memo().function, spec)
    assert neck_size <= reads and not any(r.startswith("cavity.") for r in reads), sorted(reads)
    assert slope == pytest.approx(float(calibration(spec).slope_hz_per_n(0.0)), rel=1e-12)

    axes = parse_axes(["cavity.length=3:6:4", "neck.diameter=1.5:2.4:5", "neck.length=2,3,4"])
    chunk = GridChunk(read_spec_data(PAPER), axes, np.arange(60))
    for function, runs in ((printing.clamp_nut, 4), (slope_memo().function, 15)):
        memo = Memo(function)
        memo.apply(chunk)
        assert sum(len(table) for table in memo.tables.values()) == runs


def test_the_column_writer_writes_what_the_csv_module_writes_row_by_row(tmp_path):
    """sweep.csv from columns (run.Block) is, byte for byte, the csv module's row-by-row table of the same rows: a
    blank for a missing value, None and NaN, floats as repr, text with commas, quotes and line breaks quoted, an
    integer axis as integers (fails if the columnar writer formats or quotes a cell differently)."""
    from matcad.sweep.outputs import CsvTable
    from matcad.sweep.run import Block, table_columns

    axes = parse_axes(["cavity.length=3:6:3", "mold.count=1,2"])
    rows = [{"index": 0, "cavity.length": 3.0, "mold.count": 1, "status": "ok", "reason": "", "model": "lumped",
             "f0_hz": 4276.123456789012, "band_low_hz": float("nan"), "band_high_hz": 1e17, "model_valid": True,
             "rule_errors": 2, "rule_warnings": 0, "failing_rules": "a:error b:warning"},
            {"index": 1, "cavity.length": 4.5, "mold.count": 2, "status": "invalid",
             "reason": 'neck.diameter = 5 "too wide", must be < 4\nsee [cavity]', "model": "lumped"},
            {"index": 2, "cavity.length": 6.0, "mold.count": 1, "status": "failed", "reason": "x,y", "model": "lumped",
             "f0_hz": 1e-05, "model_valid": False, "rule_errors": None}]
    writer = CsvTable(tmp_path, axes, True)
    writer(Block.from_rows(rows[:2]))
    writer(rows[2:])
    writer.close()
    expected = tmp_path / "expected.csv"
    with open(expected, "w", newline="", encoding="utf-8") as f:
        out = csv.writer(f)
        columns = table_columns(axes, True, rows)
        out.writerow(columns)
        for row in rows:
            out.writerow(["" if row.get(k) is None or (isinstance(row.get(k), float) and not np.isfinite(row[k]))
                          else row[k] for k in columns])
    assert (tmp_path / "sweep.csv").read_bytes() == expected.read_bytes()
    assert Block.from_rows(rows).rows() == [{k: v for k, v in r.items() if v is not None} for r in rows]


def test_the_parquet_table_holds_what_the_csv_holds_typed(tmp_path):
    """sweep.parquet (`--table parquet`) of a streamed 22 500-variant grid and of a small grid with invalid variants
    and an integer axis: every cell the CSV's (a number equal to the CSV's text read back, null where the CSV is
    blank), the columns typed (counts and integer axes int64, flags bool, text string, the rest float64), one row
    group per streamed chunk, and sweep.json pointing at it."""
    import pyarrow.parquet as pq

    laser = ROOT / "templates" / "mat-laser-only.toml"
    grids = ((laser, ["cavity.length=2:10:30", "neck.diameter=0.8:2.4:30", "neck.length=1:8:25"]),
             (laser, ["neck.diameter=1.5,9.5", "mold.count=1,2"]))
    for spec, vary in grids:
        tables = {}
        for fmt in ("csv", "parquet"):
            out = tmp_path / f"{len(vary)}-{fmt}"
            code, _, err = run_cli("sweep", spec, *[x for v in vary for x in ("--vary", v)], "--workers", "1",
                                   "--table", fmt, "--out", out)
            assert code == 0, err
            tables[fmt] = out
        with open(tables["csv"] / "sweep.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        parquet = pq.ParquetFile(tables["parquet"] / "sweep.parquet")
        columns = parquet.read().to_pydict()
        assert list(columns) == list(rows[0]) and not (tables["parquet"] / "sweep.csv").exists()
        types = {f.name: str(f.type) for f in parquet.schema_arrow}
        assert types["index"] == types["rule_errors"] == "int64" and types["model_valid"] == "bool"
        assert types["status"] == types["failing_rules"] == "string" and types["f0_hz"] == "double"
        for name, values in columns.items():
            for row, value in zip(rows, values):
                text = row[name]
                assert (text == "") if value is None else (
                    text == str(value) if isinstance(value, (bool, str)) else float(text) == value), (name, text)
        doc = json.loads((tables["parquet"] / "sweep.json").read_text())
        if len(rows) > 100:
            assert doc["rows_in"] == "sweep.parquet" and parquet.num_row_groups == math.ceil(len(rows) / CHUNK) > 1
        else:
            assert types["mold.count"] == "int64" and any(r["status"] == "invalid" for r in rows)
            assert [r["f0_hz"] for r in doc["rows"]] == columns["f0_hz"]


def test_parquet_without_pyarrow_says_which_extra_installs_it(monkeypatch):
    """Without pyarrow (the optional extra), `--table parquet` is refused before anything is written, naming the
    extra (the CLI turns the ValueError into exit 2, as for an unknown format below)."""
    import importlib.util

    from matcad.sweep.outputs import ParquetTable, table_format

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pyarrow" else real(name, *a))
    with pytest.raises(ValueError, match=r"--table parquet needs pyarrow: pip install 'matcad\[parquet\]'"):
        table_format("parquet")
    monkeypatch.undo()
    assert table_format("parquet") is ParquetTable


def test_a_table_format_that_does_not_exist_is_exit_2_and_writes_nothing(tmp_path):
    out = tmp_path / "sweep"
    code, _, err = run_cli("sweep", PAPER, "--vary", "cavity.length=3,4", "--table", "xlsx", "--out", out)
    assert code == 2 and "--table 'xlsx' invalid, must be one of csv, parquet" in err and "Traceback" not in err
    assert not list(tmp_path.iterdir())


def test_large_grid_streams_to_the_csv(tmp_path):
    """A three-axis grid beyond MAX_VARIANTS on arrays: the CSV holds every variant in grid order with the rows an
    in-memory sweep gives, the JSON the counts (no rows); the sweep kept no rows, and its maps, drawn from the
    stream, show the table's rows at the middle of the third axis."""
    vary = ["cavity.length=2:10:30", "neck.diameter=0.8:2.4:30", "neck.length=1:8:25"]  # 22 500 variants
    out = tmp_path / "big"
    code, stdout, err = run_cli("sweep", ROOT / "templates" / "mat-laser-only.toml", *[x for v in vary
                                for x in ("--vary", v)], "--workers", "1", "--out", out, "--json")
    assert code == 0, err
    summary = json.loads(stdout)
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert summary["variants"] == len(rows) == 22_500 and [int(r["index"]) for r in rows] == list(range(22_500))
    doc = json.loads((out / "sweep.json").read_text())
    assert "rows" not in doc and doc["rows_in"] == "sweep.csv" and doc["counts"]["ok"] == summary["ok"]
    assert summary["ok"] == sum(r["status"] == "ok" for r in rows)
    plane = [r for r in rows if r["neck.length"] == rows[12]["neck.length"]]  # the 13th of 25 lengths: the median
    _assert_heat_map_cells(out / "maps" / "cavity.length-neck.diameter" / "f0.png", plane, "cavity.length",
                           "neck.diameter")
    assert summary["rule_errors"] == sum(r["rule_errors"] not in ("", "0") for r in rows) > 0
    data = read_spec_data(ROOT / "templates" / "mat-laser-only.toml")
    kept = []
    result = sweep(data, parse_axes(vary), sink=kept.extend)
    assert result.rows == () and result.tally == {k: summary[k] for k in ("ok", "invalid", "failed", "rule_errors")}
    for row, line in zip(kept[::997], rows[::997]):
        assert line["failing_rules"] == (row.get("failing_rules") or "")
        assert float(line["f0_hz"]) == row["f0_hz"] and line["status"] == row["status"]


def test_map_planes_keep_only_the_slices_whatever_the_grid():
    """The maps' sink on an 8·10^6-variant grid (200 x 200 x 199): its arrays hold each pair of axes' values, at
    most 200 x 200 numbers a quantity, allocated once; a streamed block puts each of its rows on the planes it lies
    on (the other axis at its median) at its grid point, and nowhere else (row order does not matter)."""
    from matcad.sweep.maps import Planes
    from matcad.sweep.run import Block

    axes = parse_axes(["cavity.length=3:6:200", "neck.diameter=1:2:200", "neck.length=1:8:199"])
    planes = Planes(axes, rules=True)
    sizes = {id(v): v.shape for _, _, p in planes.planes for v in p.values.values()}
    assert sorted({shape for shape in sizes.values()}) == [(200, 199), (200, 200)]
    assert sum(math.prod(s) for s in sizes.values()) == 6 * (200 * 200 + 2 * 200 * 199)
    rng = np.random.default_rng(3)
    shape = (200, 200, 199)
    middle = (99, 99, 99)  # the lower middle of 200 ascending values, the middle of 199
    on = [np.ravel_multi_index((i, j, middle[2]), shape) for i, j in rng.integers(0, 199, (50, 2))] + \
        [np.ravel_multi_index((middle[0], j, k), shape) for j, k in rng.integers(0, 199, (50, 2))]
    index = rng.permutation(np.unique(np.concatenate([on, rng.integers(0, math.prod(shape), 4000)])))
    f0 = index * 1e-3
    planes(Block({"index": index.tolist(), "f0_hz": f0.tolist(), "rule_errors": [None] * len(index)}))
    by_index = dict(zip(index.tolist(), f0.tolist()))
    for pair, held, plane in planes.planes:
        got = plane.values["f0_hz"]
        expected = np.full(got.shape, np.nan)
        for k in index.tolist():
            at = np.unravel_index(k, shape)
            if all(at[m] == i for m, i in held.items()):
                expected[tuple(at[m] for m in pair)] = by_index[k]
        assert np.array_equal(got, expected, equal_nan=True) and np.isnan(plane.values["rule_errors"]).all()
        assert held == {m: middle[m] for m in range(3) if m not in pair}
    assert {id(v): v.shape for _, _, p in planes.planes for v in p.values.values()} == sizes


def test_a_table_finds_many_codes_at_once_as_its_dict_does():
    """Table.find of an array of codes is, code for code, the dict's get(code, -1), after every growth of the
    table (fails if the sorted arrays go stale after an insert or the binary search misses a code at an end)."""
    from matcad.sweep.memo import Table

    rng = np.random.default_rng(7)
    table, numbers = Table(), {}
    assert table.find(np.array([0, 5], dtype=np.int64)).tolist() == [-1, -1]
    for _ in range(30):
        for code in rng.integers(-50, 1_000, size=rng.integers(1, 20)).tolist():
            numbers[code] = table[code] = int(rng.integers(0, 9))
        codes = rng.integers(-60, 1_010, size=200)
        assert table.find(codes).tolist() == [numbers.get(c, -1) for c in codes.tolist()]
        assert len(table) == len(numbers) and all(c in table for c in numbers)


def test_unique_rows_are_numpys_unique_rows():
    """unique_rows(m) is np.unique(m, axis=0, return_inverse=True), rows and numbers, on small and huge ranges of
    values (fails if the mixed-radix key overflows or does not keep the rows' order)."""
    from matcad.sweep.arrays import unique_rows

    rng = np.random.default_rng(3)
    for k in range(200):
        scale = (3, 100, 2**40, 2**62)[k % 4]
        matrix = rng.integers(-scale, scale, size=(int(rng.integers(0, 60)), int(rng.integers(1, 9))))
        rows, numbers = unique_rows(matrix)
        expected_rows, expected_numbers = np.unique(matrix, axis=0, return_inverse=True)
        assert np.array_equal(rows, expected_rows) and np.array_equal(numbers, expected_numbers.reshape(-1))


def test_memos_of_two_halves_merge_into_the_memo_of_the_whole():
    """Memo.merge: two processes' memos of one function over disjoint halves of a grid, merged, give every variant
    the outcome a memo of the whole grid gives it, and run nothing more (the warm-up's merge, matcad.sweep.warm)."""
    from matcad.sweep.arrays import GridChunk
    from matcad.sweep.memo import Memo

    data = read_spec_data(PAPER)
    axes = parse_axes(["cavity.length=3:6:4", "neck.diameter=1.5:2.4:5", "mold.draft_deg=0,0.5,1"])
    whole = GridChunk(data, axes, np.arange(60))

    def branch(spec):
        return spec.neck.diameter if spec.cavity.length > 4.5 else -1.0

    halves = [Memo(branch), Memo(branch)]
    for memo, rows in zip(halves, (np.arange(0, 60, 2), np.arange(1, 60, 2))):
        memo.apply(GridChunk(data, axes, rows))
    merged = Memo(lambda spec: pytest.fail("a merged memo ran its function"))
    for memo in halves:
        merged.merge(memo.tables, memo.outcomes)
    numbers = merged.apply(whole)
    assert [merged.outcomes[k] for k in numbers] == [branch(whole.spec(j)) for j in range(60)]


def test_the_warm_up_runs_each_memos_own_combinations_and_eq5s_slope():
    """The paper's spec: one memo reads the cavity, others the neck, so together they read the whole grid, where the
    warm-up used to give up. Each memo is warmed on its own combinations (every neck, every cavity; not every
    neck with every cavity), Eq. 5's slope memo first, each exactly as a memo run over the whole grid fills it."""
    from matcad.sweep.arrays import GridChunk, memos
    from matcad.sweep.warm import warmed

    vary = ["cavity.length=3:6:10", "neck.diameter=1.5:2.4:4", "neck.length=1:8:5"]
    data, axes = read_spec_data(PAPER), parse_axes(vary)
    warm = warmed(data, axes, True, Executor(workers=2))
    assert warm is not None
    sizes = [{key: len(table) for key, table in tables.items()} for tables, _ in warm]
    assert sizes[0] == {(1, 2): 20} and {(0,): 10} in sizes and {(1,): 4} in sizes
    assert all(len(key) < 3 for s in sizes for key in s)
    whole = memos(True)
    grid = GridChunk(data, axes, np.arange(200))
    for memo in whole:
        memo.apply(grid)
    for memo, (tables, outcomes) in zip(whole, warm):
        for key, table in tables.items():
            assert {code: outcomes[k] for code, k in table.items()} == \
                {code: memo.outcomes[k] for code, k in memo.tables[key].items()}


def test_warmed_workers_split_the_rules_and_give_the_one_process_table(tmp_path):
    """On 2 processes the rules' distinct inputs are warmed once, split over both (matcad.sweep.warm), not run in
    each: the warm-up covers every neck of a 2-chunk laser grid whose rules read the neck, and the sweep's table
    is byte for byte the one process's."""
    from matcad.sweep.warm import warmed

    laser = ROOT / "templates" / "mat-laser-only.toml"
    vary = ["cavity.length=2:10:25", "neck.diameter=0.8:2.4:20", "neck.length=1:8:10"]
    data = read_spec_data(laser)
    warm = warmed(data, parse_axes(vary), True, Executor(workers=2))
    assert warm is not None
    tables = [table for tables, _ in warm for axes, table in tables.items() if len(axes) == 2]
    assert tables and max(len(t) for t in tables) == 20 * 10  # every neck (diameter x length), once
    assert warmed(data, parse_axes(vary), True, Executor(workers=1)) is None
    outs = []
    for workers in ("1", "2"):
        out = tmp_path / workers
        code, _, err = run_cli("sweep", str(laser), *[x for v in vary for x in ("--vary", v)], "--workers", workers,
                               "--out", str(out))
        assert code == 0, err
        outs.append((out / "sweep.csv").read_bytes())
    assert outs[0] == outs[1] and outs[0].count(b"\n") == 25 * 20 * 10 + 1
