"""Design-sweep throughput: the vectorised closed-form rungs (designs/s; target >= 2e6/s for f0), the FEM rung on
1 and 2 local processes (variants/s), and a Dask LocalCluster's start-up and per-task overhead.

Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/sweep.py [--quick] [--closed-form]   (prints numbers, asserts
nothing; --closed-form: the vectorised rungs and the elastic wall's peak search only)
"""

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.spec import read_spec_data  # noqa: E402
from matcad.sweep import Executor, parse_axes, sweep  # noqa: E402
from matcad.acoustics.design import Making, WallMaterial  # noqa: E402
from matcad.sweep import fast  # noqa: E402

PAPER = Path(__file__).resolve().parents[1] / "templates" / "mat-paper.toml"


def random_variants(n: int, seed: int = 0) -> fast.Variants:
    """n random designs around the paper taxel as the arrays a sweep evaluates (mm, deg, °C)."""
    rng = np.random.default_rng(seed)
    cavity_d = rng.uniform(2.0, 8.0, n)
    values = {"cavity.diameter": cavity_d, "cavity.length": rng.uniform(1.0, 12.0, n),
              "neck.diameter": cavity_d * rng.uniform(0.2, 0.9, n), "neck.length": rng.uniform(1.0, 10.0, n),
              "mold.draft_deg": rng.uniform(0.0, 1.0, n), "air.temperature_c": rng.uniform(10.0, 30.0, n),
              "air.speed_of_sound": np.full(n, np.nan), "spacer.height": rng.uniform(0.5, 3.0, n),
              "plate.width": np.full(n, 24.0), "plate.depth": np.full(n, 24.0),
              "end_cap.outer_diameter": 2.5 * cavity_d, "end_cap.top_thickness": 0.6 * cavity_d,
              "guide.thickness": np.full(n, 1.5), "end_cap.flange_squeeze": np.full(n, 0.1),
              "silicone.density_g_cm3": np.full(n, 1.08)}
    return fast.Variants(values, "mount", WallMaterial("rigid", (0.2, 0.6), (1.0, 1.6), (0.1, 0.2), 1080.0),
                         Making(np.zeros(n, bool), np.zeros(n, bool), np.full(n, "fdm")))


def best_time(fn, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


ELASTIC_DESIGNS = 2048
"""The elastic wall is ~10^3 times dearer per design (a driven response searched for its peak): timed on fewer."""


def vectorised(n_all: int, repeats: int) -> None:
    print(f"vectorised closed-form rungs, {n_all:.0e} designs from geometry arrays ({ELASTIC_DESIGNS} for "
          f"elastic_wall; best of {repeats}):")
    for model in fast.VECTORISED:
        n = ELASTIC_DESIGNS if model == "elastic_wall" else n_all
        v = random_variants(n)
        t = best_time(lambda: fast.f0_hz(v, model), repeats)
        f0 = fast.f0_hz(v, model)

        def full():
            ok = fast.valid(v, model, f0)
            fast.band_hz(v, model, f0, ok)
            fast.sensitivity(v, model, "cavity.length")

        t_full = best_time(full, max(1, repeats // 2)) + t
        print(f"  {model:<18} f0: {n / t:10.3g} designs/s ({t * 1e3:6.0f} ms)   f0 + checks + band + one "
              f"df0/dfield: {n / t_full:10.3g} designs/s")


def wall_peaks(n: int, repeats: int) -> None:
    """The elastic wall's peak search (matcad.acoustics.peaks) against the 601-point scan it replaced, on the same
    n random designs at random moduli and loss factors: rows/s and the largest difference in f0."""
    from dataclasses import replace

    from matcad.acoustics import wall
    from matcad.acoustics.evaluation import Evaluation
    from matcad.acoustics.resonator import _step_neck_length_mm, transmission_line_hz, wall_modes

    rng = np.random.default_rng(1)
    v = replace(random_variants(n), wall=WallMaterial("silicone", (0.2, 0.6), (1.0, 1.6), (0.1, 0.2), 1080.0))
    res = Evaluation(v.design()).res
    args = (transmission_line_hz(res), res.c_m_s, res.neck_area, res.cavity_area, _step_neck_length_mm(res),
            res.cavity_length, wall_modes(res, np.exp(rng.uniform(np.log(2e5), np.log(1e6), n))),
            rng.uniform(0.1, 0.2, n), res.side_volume)
    found, scanned = wall.peak_ratio(*args), wall.peak_ratio(*args, scan=True)
    t_root = best_time(lambda: wall.peak_ratio(*args), repeats)
    t_scan = best_time(lambda: wall.peak_ratio(*args, scan=True), repeats)
    print(f"elastic wall peak, {n} designs (G 0.2-1 MPa, eta 0.1-0.2; best of {repeats}): root find "
          f"{n / t_root:.3g}/s, 601-point scan {n / t_scan:.3g}/s ({t_scan / t_root:.1f}x); largest |f0 difference| "
          f"{np.max(np.abs(found / scanned - 1)):.1e}")


def fem(n: int) -> None:
    data = {**read_spec_data(PAPER), "wall": {"model": "rigid"}}
    axes = parse_axes([f"cavity.length=3.5:6.0:{n}"])
    print(f"FEM rung (rigid wall, default level), {n} variants, no rules:")
    for workers in (1, 2):
        t0 = time.perf_counter()
        result = sweep(data, axes, model="fem", rules=False, executor=Executor(workers))
        t = time.perf_counter() - t0
        ok = sum(r["status"] == "ok" for r in result.rows)
        print(f"  {workers} local worker(s): {n / t:.3g} variants/s ({t:.1f} s, {ok}/{n} ok; busy "
              f"{result.worker_seconds:.1f} s in workers)")


def _noop(x):
    return x


def dask_overhead(tasks: int) -> None:
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("dask.distributed not installed (pip install 'matcad[cluster]'): LocalCluster not measured")
        return
    for processes in (False, True):
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=processes, dashboard_address=None)
        client = Client(cluster)
        start = time.perf_counter() - t0
        client.gather(client.map(_noop, range(20), pure=False))  # warm
        t0 = time.perf_counter()
        client.gather(client.map(_noop, range(tasks), pure=False))
        per_task = (time.perf_counter() - t0) / tasks
        data = read_spec_data(PAPER)
        axes = parse_axes(["cavity.length=3.5:6.0:8"])
        t0 = time.perf_counter()
        sweep(data, axes, model="transmission_line", executor=Executor(scheduler=cluster.scheduler_address))
        t_dask = time.perf_counter() - t0
        client.close()
        cluster.close()
        t0 = time.perf_counter()
        sweep(data, axes, model="transmission_line")
        t_local = time.perf_counter() - t0
        print(f"LocalCluster(2 workers, processes={processes}): start-up {start:.2f} s, {per_task * 1e3:.2f} ms "
              f"per no-op task ({tasks} tasks); an 8-variant rules sweep {t_dask:.2f} s on it vs {t_local:.2f} s "
              "in-process")


def main() -> None:
    quick = "--quick" in sys.argv
    vectorised(100_000 if quick else 1_000_000, 3 if quick else 5)
    wall_peaks(2048, 3)
    if "--closed-form" in sys.argv:
        return
    fem(2 if quick else 16)
    dask_overhead(200 if quick else 1000)


if __name__ == "__main__":
    main()
