"""The fipple tube's routes: error against run time and refinement, and the template against the AcousTac range.

Prints: the 1-D FEM's error against the transmission line's root (P1, P2) with its run time and observed order; the
closed form's error; the axisymmetric exterior FEM of the template made flanged against the quarter wave with
Norris & Sheng's frequency-dependent correction (error, the correction it implies, CPU time); the exterior FEM of a
thin-walled unflanged tube against Levine & Schwinger's 0.6133 a (the correction it implies per level, CPU time); the
column length that sings at 3 and 5.5 kHz (the AcousTac range the MAT paper cites) and what
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


def exterior_fem(td):
    """The flanged template, rigid cap, lossless (as the FEM): the exterior FEM's f1 per level against the quarter
    wave whose correction is Norris & Sheng's at its own frequency (a fixed point), with CPU time (the machine is
    shared)."""
    flanged = dataclasses.replace(td, mouth="flanged", boundary_layers=False)  # the FEM is lossless
    a, c_mm_s = td.bore_diameter / 2, T.speed_of_sound(td.air) * 1e3
    f_ns = T.line_hz(flanged)
    for _ in range(50):
        f_ns = c_mm_s / (4 * (flanged.column_mm + T.flanged_phase_correction_mm(flanged, f_ns)))
    line = T.line_hz(flanged)
    delta = T.flanged_phase_correction_mm(flanged, f_ns) / a
    print(f"flanged, rigid cap: quarter wave + Norris & Sheng {f_ns:.2f} Hz (delta {delta:.4f} a); line with "
          f"0.8216 a {line:.2f} Hz ({line / f_ns - 1:+.2e})")
    print("exterior FEM level   dofs   f (Hz)      error     delta/a   CPU (s)")
    for level in (1, 2, 4, 8, 16):
        t0 = time.process_time()
        run = T.exterior_fem(flanged, level)
        cpu = time.process_time() - t0
        print(f"             {level:5d} {run.dofs:6d} {run.f0_hz:10.3f} {run.f0_hz / f_ns - 1:+.2e} "
              f"{T.phase_correction_mm(flanged, run.f0_hz) / a:9.5f} {cpu:8.2f}")


def unflanged_exterior_fem(td, wall_per_a=0.02, levels=(2, 4, 8, 16)):
    """A thin-walled unflanged tube (wall 0.02 a, 60 mm bore: ka = 0.048), rigid cap: the correction the exterior
    FEM's f1 implies per level against Levine & Schwinger's zero-thickness 0.6133 a and against the Aitken limit of
    the last three levels (the wall's own share), with CPU time (the machine is shared)."""
    a = td.bore_diameter / 2
    thin = dataclasses.replace(td, mouth="unflanged", length=60.0, tube_wall=wall_per_a * a)
    rows = []
    for level in levels:
        t0 = time.process_time()
        run = T.exterior_fem(thin, level)
        rows.append((level, run.dofs, T.phase_correction_mm(thin, run.f0_hz) / a, time.process_time() - t0))
    d = [row[2] for row in rows[-3:]]
    limit = d[2] + (d[2] - d[1]) ** 2 / ((d[1] - d[0]) - (d[2] - d[1]))
    print(f"unflanged, wall {wall_per_a:g} a, rigid cap, ka = {2 * math.pi * run.f0_hz / (T.speed_of_sound(td.air) * 1e3) * a:.3f}: "
          f"Aitken limit {limit:.4f} a (Levine & Schwinger, zero wall: {T.UNFLANGED} a)")
    print("exterior FEM level   dofs  delta/a   - 0.6133   - limit   CPU (s)")
    for level, dofs, delta, cpu in rows:
        print(f"             {level:5d} {dofs:6d} {delta:8.5f} {delta - T.UNFLANGED:+9.5f} {delta - limit:+9.5f} "
              f"{cpu:8.2f}")


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
    exterior_fem(td)
    unflanged_exterior_fem(td)
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
