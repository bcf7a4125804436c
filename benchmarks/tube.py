"""The fipple tube's routes: error against run time and refinement, and the template against the AcousTac range.

Prints: the 1-D FEM's error against the transmission line's root (P1, P2) with its run time and observed order; the
closed form's error; the column length that sings at 3 and 5.5 kHz (the AcousTac range the MAT paper cites) and what
a 100 mm column sings at. Run: .venv/bin/python benchmarks/tube.py
"""

import dataclasses
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.acoustics import tube as T  # noqa: E402
from matcad.spec import load  # noqa: E402

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "acoustac-tube.toml"


def timed(fn, *args, **kw):
    t0 = time.perf_counter()
    value = fn(*args, **kw)
    return value, time.perf_counter() - t0


def main():
    td = T.tube_design(load(TEMPLATE))
    kappa = T.with_wall_hz(td, td.wall.dynamic_moduli_pa()[1])[1]
    exact, t_line = timed(T.line_hz, td, kappa)
    closed, t_closed = timed(T.closed_form_hz, td, kappa)
    print(f"template, cap wall kappa = {kappa:.3f} mm: line {exact:.4f} Hz ({t_line * 1e3:.2f} ms), closed form "
          f"{closed:.1f} Hz ({closed / exact - 1:+.2%}, {t_closed * 1e6:.1f} us)")
    print("FEM order elements  f (Hz)         error (Hz)   order  time (ms)")
    for order in (1, 2):
        prev = None
        for n in (8, 16, 32, 64, 128, 256):
            f, t = timed(T.fem_hz, td, kappa, n, order)
            err = abs(f - exact)
            rate = "" if prev is None or err == 0 else f"{math.log2(prev / err):5.2f}"
            print(f"    P{order}  {n:6d}  {f:12.6f}  {err:12.3e}  {rate:>5}  {t * 1e3:8.1f}")
            prev = err
    for target in (3000.0, 5500.0):  # the column (mouth to cap wall) for a pitch, by bisection on the line
        lo, hi = 1.0, 500.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            f = T.line_hz(dataclasses.replace(td, length=mid - td.cap_depth), kappa)
            lo, hi = (mid, hi) if f > target else (lo, mid)
        print(f"column for {target:.0f} Hz with this mouth and cap: {lo:.1f} mm (+ mouth correction "
              f"{T.mouth_correction_mm(td):.2f} mm)")
    long = dataclasses.replace(td, length=100.0 - td.cap_depth)
    print("100 mm column: modes " + ", ".join(f"{T.line_hz(long, kappa, mode=m):.0f}" for m in (1, 2, 3, 4))
          + " Hz")


if __name__ == "__main__":
    main()
