"""`matcad predict` start-up against `import numpy`, and vectorised transmission-line throughput.

Targets: predict / import-numpy ratio ≤ 1.5; ≥ 1e6 designs/s. Run: .venv/bin/python benchmarks/predict.py
"""

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks._timing import matcad, median_ratio  # noqa: E402
from matcad.acoustics import models  # noqa: E402


def throughput(n=1_000_000, repeats=5):
    rng = np.random.default_rng(0)
    d = rng.uniform(0.5, 3.0, n)
    big_d = d / rng.uniform(0.05, 1.0, n)
    a, s = np.pi * d * d / 4, np.pi * big_d * big_d / 4
    l_eff = rng.uniform(0.5, 20.0, n)
    length = rng.uniform(0.5, 20.0, n)
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        f = models.transmission_line_hz(343.0, a, s, l_eff, length)
        best = min(best, time.perf_counter() - t0)
    assert np.all(np.isfinite(f))
    return n / best, best


def main():
    t, b, ratio = median_ratio(matcad("predict", "templates/mat-paper.toml"), [sys.executable, "-c", "import numpy"])
    print(f"matcad predict templates/mat-paper.toml: median {t * 1e3:.1f} ms")
    print(f"python -c 'import numpy':                median {b * 1e3:.1f} ms")
    print(f"ratio {ratio:.2f} (target <= 1.5)")
    rate, seconds = throughput()
    print(f"transmission_line_hz, 1e6 designs vectorised: {seconds * 1e3:.0f} ms -> {rate:.3g} designs/s "
          f"(target >= 1e6)")


if __name__ == "__main__":
    main()
