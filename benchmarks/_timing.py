"""Shared benchmark helpers: median wall time of a command, interleaved with its baseline."""

import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def wall_time_s(argv, cwd=ROOT) -> float:
    t0 = time.perf_counter()
    subprocess.run(argv, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def median_ratio(argv, baseline, runs=31, warmup=3):
    """Median wall time of ``argv`` and of ``baseline`` (alternating runs), and their ratio."""
    for _ in range(warmup):
        wall_time_s(argv), wall_time_s(baseline)
    times, base = [], []
    for _ in range(runs):
        times.append(wall_time_s(argv))
        base.append(wall_time_s(baseline))
    t, b = statistics.median(times), statistics.median(base)
    return t, b, t / b


def matcad(*args):
    """argv running matcad's console entry point in this interpreter."""
    return [sys.executable, "-c", "from matcad.cli import run; run()", *args]
