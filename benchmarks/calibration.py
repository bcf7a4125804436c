"""Calibration intervals by simulation, and the cost of the fit.

1. Coverage: a taxel whose pitch follows Eq. 5 (the paper's b and a, 4.4 kHz unloaded) is calibrated from one or
   three load cycles (11 points each over 0-TOP N, σ_f = 2 Hz; each cycle's taxel offset by a force δ ~ N(0, τ):
   hysteresis between cycles), then read in a NEW cycle (its own δ) at a force drawn uniformly over the range,
   optionally with the air ±3 °C off the calibration's and no --temperature-c. Per case: the share of 95 % force
   intervals that hold the true force, the median half-width, and the half-width an oracle needs (the 95th
   percentile of |error|): "width / needed" above 2 is the "twice as wide as needed" of issue 24.
2. Cost: the fit's peak memory (tracemalloc) and time at 10^3, 10^5 and 10^6 points (several cycles).

Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/calibration.py [--trials N] [--cost-only | --coverage-only]
Prints numbers; asserts nothing.
"""

import argparse
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.acoustics.eq5 import Eq5  # noqa: E402
from matcad.acoustics.eq5fit import fit  # noqa: E402
from matcad.errors import LoopError  # noqa: E402

TRUE = Eq5(37.8, -0.0086, 0.4626, 37.8 * 4400.0 ** 2)
SIGMA_HZ = 2.0
POINTS = 11
T_CAL_C = 20.0


def cycles_data(rng, cycles, tau_n, top):
    forces = np.tile(np.linspace(0.0, top, POINTS), cycles)
    labels = np.repeat(np.arange(cycles), POINTS)
    offsets = rng.normal(0.0, tau_n, cycles)
    freqs = TRUE.frequency_hz(forces + offsets[labels]) + rng.normal(0.0, SIGMA_HZ, len(forces))
    return forces, freqs, labels


def read(law, heard_hz, temperature_c):
    """The force and half-width `matcad sense` reports for a frequency heard (the loop's own reading path)."""
    try:
        from matcad.loop.sense import force_interval
    except ImportError:  # before issue 24: sense read Eq5.force_with_interval directly
        force, half = law.force_with_interval([heard_hz], temperature_c=temperature_c)
        return float(force[0]), float(half[0])
    force, half, _ = force_interval(law, np.array([heard_hz]), temperature_c)
    return float(force[0]), float(half[0])


def coverage(cycles, tau_n, top, shift_c, trials, given, seed0=0):
    hits, halves, errors = 0, [], []
    for trial in range(trials):
        rng = np.random.default_rng(seed0 + trial)
        forces, freqs, labels = cycles_data(rng, cycles, tau_n, top)
        try:
            law = fit(forces, freqs, TRUE.k_mm3_hz2, cycles=labels, temperature_c=T_CAL_C).law
        except LoopError:
            continue
        true_force = rng.uniform(0.03 * top, 0.97 * top)
        delta_t = rng.uniform(-shift_c, shift_c)
        heard = float(TRUE.frequency_hz(true_force + rng.normal(0.0, tau_n))) + rng.normal(0.0, SIGMA_HZ)
        heard *= np.sqrt((T_CAL_C + delta_t + 273.15) / (T_CAL_C + 273.15))  # f follows c ∝ sqrt(T)
        force, half = read(law, heard, T_CAL_C + delta_t if given else None)
        if not np.isfinite(force):
            continue
        hits += abs(force - true_force) <= half
        halves.append(half)
        errors.append(abs(force - true_force))
    n = len(halves)
    needed = float(np.quantile(errors, 0.95))
    return hits / n, float(np.median(halves)), needed, n


def coverage_table(trials):
    print(f"Force-interval coverage by simulation ({trials} trials per row; 11 points per cycle over 0-TOP N, "
          f"sigma_f {SIGMA_HZ:g} Hz; a new cycle read at a uniform force; shift: air temperature uniform within "
          "+-shift of the calibration's; T given: sense knows it (--temperature-c), else not):\n")
    print("| cycles | tau [N] | range [N] | shift [degC] | T given | coverage | median half-width [N] | needed [N] | "
          "width / needed |")
    print("|---:|---:|---:|---:|---|---:|---:|---:|---:|")
    rows = [(*row, True) for row in BASE_ROWS] + [(*row, False) for row in TEMPERATURE_ROWS]
    for cycles, tau, top, shift, given in rows:
        cov, half, needed, n = coverage(cycles, tau, top, shift, trials, given)
        print(f"| {cycles} | {tau:g} | 0-{top:g} | {shift:g} | {'yes' if given else 'no'} | {100 * cov:.1f} % | "
              f"{half:.2f} | {needed:.2f} | {half / needed:.2f} |")


BASE_ROWS = ((1, 0.0, 15.4, 0.0), (1, 0.5, 15.4, 0.0), (1, 0.7, 15.4, 0.0), (1, 1.0, 15.4, 0.0),
             (1, 0.7, 15.4, 3.0), (1, 1.0, 20.0, 0.0), (3, 0.0, 15.4, 0.0), (3, 0.5, 15.4, 0.0),
             (3, 0.7, 15.4, 0.0), (3, 1.0, 15.4, 0.0), (3, 1.5, 15.4, 0.0), (1, 0.0, 2.0, 0.0),
             (1, 0.13, 2.0, 0.0), (3, 0.13, 2.0, 0.0), (1, 0.0, 5.0, 0.0), (1, 0.32, 5.0, 0.0),
             (3, 0.32, 5.0, 0.0))
"""(cycles, τ N, top force N, temperature shift °C) with the temperature given to sense."""
TEMPERATURE_ROWS = ((1, 0.7, 15.4, 0.0), (1, 0.7, 15.4, 3.0), (1, 1.0, 15.4, 3.0), (3, 0.7, 15.4, 3.0),
                    (1, 0.13, 2.0, 3.0))
"""The same, with the temperature not given to sense."""


def cost_table(max_points):
    print("\nThe fit's cost (10 cycles, points spread over 0-20 N; peak memory by tracemalloc, numpy's arrays "
          "included):\n")
    print("| points | time [s] | peak memory [MB] | MB per 10^5 points |")
    print("|---:|---:|---:|---:|")
    for n in (n for n in (10 ** 3, 10 ** 4, 10 ** 5, 10 ** 6) if n <= max_points):
        rng = np.random.default_rng(1)
        forces = rng.uniform(0.0, 20.0, n)
        labels = np.arange(n) % 10
        freqs = TRUE.frequency_hz(forces + rng.normal(0.0, 0.5, 10)[labels]) + rng.normal(0.0, SIGMA_HZ, n)
        tracemalloc.start()
        t0 = time.perf_counter()
        try:
            fit(forces, freqs, TRUE.k_mm3_hz2, cycles=labels)
            status = ""
        except MemoryError:
            status = " (MemoryError)"
        spent = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
        print(f"| {n:.0e} | {spent:.3f}{status} | {peak:.1f} | {peak / n * 1e5:.1f} |")


def cli_table(max_points):
    """`matcad calibrate` end to end (CSV read, fit, residual plot, outputs) on files of 10^3-10^6 rows."""
    import os
    import subprocess
    import tempfile

    print("\n`matcad calibrate` end to end on a CSV (force_n, frequency_hz, cycle; 10 cycles; peak RSS from "
          "/usr/bin/time -v):\n")
    print("| rows | file [MB] | wall time [s] | CPU time [s] | peak RSS [MB] |")
    print("|---:|---:|---:|---:|---:|")
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        for n in (n for n in (10 ** 3, 10 ** 5, 10 ** 6) if n <= max_points):
            rng = np.random.default_rng(2)
            forces = rng.uniform(0.0, 20.0, n)
            labels = np.arange(n) % 10
            freqs = TRUE.frequency_hz(forces) + rng.normal(0.0, SIGMA_HZ, n)
            path = Path(tmp) / f"cal-{n}.csv"
            path.write_text("force_n,frequency_hz,cycle\n" + "".join(
                f"{a:.4f},{b:.3f},c{c}\n" for a, b, c in zip(forces, freqs, labels)))
            cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "matcad", "calibrate", str(path), "--spec",
                   str(root / "templates" / "mat-paper.toml"), "--out", str(Path(tmp) / f"out-{n}")]
            t0 = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, cwd=root,
                                  env={**os.environ, "PYTHONPATH": str(root)})
            wall = time.perf_counter() - t0
            told = dict(ln.strip().rsplit(": ", 1) for ln in proc.stderr.splitlines()
                        if ln.startswith("\t") and ": " in ln)
            peak = float(told.get("Maximum resident set size (kbytes)", "nan")) / 1024
            cpu = float(told.get("User time (seconds)", "nan")) + float(told.get("System time (seconds)", "nan"))
            status = "" if proc.returncode == 0 else f" (exit {proc.returncode})"
            print(f"| {n:.0e} | {path.stat().st_size / 1e6:.1f} | {wall:.1f}{status} | {cpu:.2f} | {peak:.0f} |")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--trials", type=int, default=2000)
    parser.add_argument("--cost-only", action="store_true")
    parser.add_argument("--coverage-only", action="store_true")
    parser.add_argument("--max-points", type=float, default=1e6, help="skip cost rows above this many points")
    args = parser.parse_args()
    if not args.cost_only:
        coverage_table(args.trials)
    if not args.coverage_only:
        cost_table(args.max_points)
        if Path("/usr/bin/time").exists():
            cli_table(args.max_points)


if __name__ == "__main__":
    main()
