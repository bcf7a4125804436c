"""Inverse design: accuracy by `predict` and time per solve; the band allocation of a 4-taxel array.

Prints numbers, asserts nothing. Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/design.py
"""

import dataclasses
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad import spec as spec_mod  # noqa: E402
from matcad.prediction import predict  # noqa: E402
from matcad.design import RulesFailed, Unreachable  # noqa: E402
from matcad.design.solve import parse_vary, solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TARGETS = np.arange(4000.0, 6001.0, 250.0)
VARY = (["neck.diameter"], ["cavity.length"], ["cavity.diameter", "neck.diameter"], ["neck.length", "neck.diameter"])


def inverse_design():
    for template in ("mat-laser-only", "mat-paper"):
        s = spec_mod.load(ROOT / "templates" / f"{template}.toml")
        for vary in VARY:
            errors, times, refused = [], [], []
            for target in TARGETS:
                t0 = time.perf_counter()
                try:
                    r = solve(s, float(target), parse_vary(s, vary))
                except (Unreachable, RulesFailed) as exc:
                    refused.append(f"{target:.0f} Hz ({type(exc).__name__})")
                    continue
                times.append(time.perf_counter() - t0)
                errors.append(abs(predict(r.spec).f0_hz / target - 1))
            print(f"{template:<15} {'+'.join(vary):<28} {len(errors)}/{len(TARGETS)} solved, max |error| by predict "
                  f"{max(errors):.1e}, time per solve median {1e3 * statistics.median(times):.0f} ms, max "
                  f"{1e3 * max(times):.0f} ms" + (f"; refused {', '.join(refused)}" if refused else ""))


def allocation():
    from matcad.listening import guard_hz
    from matcad.prediction.bands import conflicts, taxel_bands
    from matcad.design.allocate import allocate

    s = spec_mod.load(ROOT / "templates" / "mat-laser-only.toml")
    s = dataclasses.replace(s, plate=dataclasses.replace(s.plate, thickness_measured=True),
                            mechanics=dataclasses.replace(s.mechanics, max_force_n=5.0))
    t0 = time.perf_counter()
    a = allocate(s, 4, 3500.0, 7000.0, parse_vary(s, ["neck.diameter"]), "laser-4taxels")
    print(f"\nallocate 4 taxels in 3500-7000 Hz (mat-laser-only, calipered sheet, max force 5 N, cap mechanics): "
          f"{time.perf_counter() - t0:.1f} s, guard {a.guard_hz:.1f} Hz")
    bands = taxel_bands(a.spec)
    for b, sol in zip(bands, a.solutions):
        print(f"  {b.name} ({b.x_mm:+.3f}, {b.y_mm:+.3f}) mm  neck {sol.spec.neck.diameter:.4f} mm  f0 {b.f0_hz:7.1f} Hz  "
              f"unloaded {b.unloaded_hz[0]:7.1f}-{b.unloaded_hz[1]:7.1f}  loaded {b.loaded_hz[0]:7.1f}-"
              f"{b.loaded_hz[1]:7.1f} Hz  rise {100 * (b.rise - 1):+.2f} %")
    gaps = [b2.loaded_hz[0] - b1.loaded_hz[1] for b1, b2 in zip(bands, bands[1:])]
    print(f"  gaps {', '.join(f'{g:.1f}' for g in gaps)} Hz; conflicts "
          f"{len(conflicts(bands, guard_hz(a.spec.microphone.sample_rate_hz)))}; "
          f"room left {7000 - bands[-1].loaded_hz[1]:.0f} Hz")


if __name__ == "__main__":
    inverse_design()
    allocation()
