"""A MAT taxel and a fipple tube for the same pitch: length, air volume, f(F) sensitivity, fabrication steps.

Prints the table the tube's report carries (:mod:`matcad.design.tube_vs_mat`) for templates/acoustac-tube.toml:
the MAT paper's taxel with its neck diameter solved onto the tube's f1, f(F) of both from the cap mechanics
(FElupe, ~1 min per cap on a cold cache and a loaded machine). Run: .venv/bin/python benchmarks/tube_vs_mat.py
"""

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from matcad.design.tube_vs_mat import compare  # noqa: E402
from matcad.prediction.tube import predict_tube  # noqa: E402
from matcad.spec import load  # noqa: E402
from matcad.tube_build import STEPS  # noqa: E402


def main():
    t0, cpu0 = time.perf_counter(), time.process_time()
    tube = load(ROOT / "templates" / "acoustac-tube.toml")
    print("\n".join(compare(tube, predict_tube(tube).f0_hz, STEPS).to_markdown()))
    print(f"({time.perf_counter() - t0:.0f} s, {time.process_time() - cpu0:.0f} s CPU)")


if __name__ == "__main__":
    main()
