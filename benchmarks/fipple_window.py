"""The fipple window's end correction by the 3-D potential-flow FEM (matcad.acoustics.mouth3d): verified on two
mouths with known answers, refined on the template's window, and against Rayleigh's aperture (the model's δ) over
ten windows.

Prints, per level (cells across the bore's radius), nodes, δ, its error and CPU time for:
1. a pipe in an infinite baffle against Norris & Sheng's 0.8216 a (a closed form), with the observed order;
2. a pipe with the template's 1.2 mm wall (0.6 a) ending in free space against the axisymmetric exterior FEM
   (matcad.acoustics.fem, level 16, 60 mm of bore: ka = 0.048), a second, independent route;
3. the template's printed window: δ, δ over Rayleigh's thin aperture, the rigid line's f1 with it; and two other
   windows at levels 8 and 12 (the range's level against a finer one);
4. ten windows (wall, window width B and height W, labium bevel) at level 8: δ over Rayleigh's, the range that
   :data:`matcad.prediction.tube.MOUTH_RANGE` must hold.
Run: .venv/bin/python benchmarks/fipple_window.py [--fine]   (--fine adds level 16: ~5 min and ~8 GB for the window)
"""

import dataclasses
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.acoustics import mouth3d as M  # noqa: E402
from matcad.acoustics import tube as T  # noqa: E402
from matcad.prediction.tube import MOUTH_RANGE, MOUTH_STUDY, MOUTH_STUDY_BORE_MM  # noqa: E402
from matcad.spec import load  # noqa: E402

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "acoustac-tube.toml"


def timed(mouth, level):
    t0 = time.process_time()
    result = M.end_correction(mouth, level)
    return result, time.process_time() - t0


def study(name, mouth, levels, reference=None):
    a, previous = mouth.a, None
    print(f"{name}" + (f": reference {reference / a:.4f} a" if reference else ""))
    for level in levels:
        r, cpu = timed(mouth, level)
        line = f"  level {level:2d} {r.nodes:8d} nodes  delta {r.delta_mm:.4f} mm = {r.delta_mm / a:.4f} a"
        if reference:
            error = r.delta_mm / reference - 1
            line += f"  error {error:+.2%}"
            if previous:
                line += f"  order {math.log(abs(previous[1] / error)) / math.log(level / previous[0]):.2f}"
            previous = (level, error)
        print(f"{line}  {cpu:.0f} s CPU", flush=True)
    return r


def main(fine: bool):
    spec = load(TEMPLATE)
    td = T.tube_design(spec)
    a = td.bore_diameter / 2
    extra = (16,) if fine else ()
    study("1. pipe in an infinite baffle (Norris & Sheng)", M.Mouth("baffled", a), (4, 6, 8, 12) + extra, 0.8216 * a)
    long = dataclasses.replace(td, mouth="unflanged", length=60.0)
    axisymmetric = T.phase_correction_mm(long, T.exterior_fem(long, 16).f0_hz)
    study(f"2. pipe with a {td.tube_wall} mm wall in free space (axisymmetric exterior FEM, level 16)",
          M.Mouth("unflanged", a, td.tube_wall), (4, 6, 8, 12), axisymmetric)
    rayleigh = T.mouth_correction_mm(td)
    print(f"3. the template's window: Rayleigh's thin aperture {rayleigh:.4f} mm, line f1 {T.line_hz(td):.0f} Hz")
    for level in (6, 8, 12) + extra:
        r, cpu = timed(M.from_tube(td), level)
        f1 = T.line_hz(td, correction_factor=r.delta_mm / rayleigh)
        print(f"  level {level:2d} {r.nodes:8d} nodes  delta {r.delta_mm:.4f} mm = {r.delta_mm / rayleigh:.4f} x "
              f"Rayleigh's  line f1 {f1:.0f} Hz ({f1 / T.line_hz(td) - 1:+.2%})  {cpu:.0f} s CPU", flush=True)
    for wall, b, w, angle in MOUTH_STUDY[1:9:7]:
        one = dataclasses.replace(td, tube_wall=wall, windway_width=b, edge_distance=w, edge_angle=angle)
        d8, d12 = (M.end_correction(M.from_tube(one), level).delta_mm for level in (8, 12))
        print(f"  wall {wall} B {b} W {w}: level 8 {d8:.4f} mm, level 12 {d12:.4f} mm ({d8 / d12 - 1:+.2%})",
              flush=True)
    print(f"4. ten windows (MOUTH_STUDY) on a {MOUTH_STUDY_BORE_MM} mm bore, level 8: delta / Rayleigh's "
          f"(MOUTH_RANGE {MOUTH_RANGE})")
    ratios = []
    for wall, b, w, angle in MOUTH_STUDY:
        one = dataclasses.replace(td, bore_diameter=MOUTH_STUDY_BORE_MM, tube_wall=wall, windway_width=b,
                                  edge_distance=w, edge_angle=angle)
        r, cpu = timed(M.from_tube(one), 8)
        ratios.append(r.delta_mm / T.mouth_correction_mm(one))
        print(f"  wall {wall} B {b} W {w} bevel {angle:2.0f} deg: delta {r.delta_mm:.3f} mm, Rayleigh's "
              f"{T.mouth_correction_mm(one):.3f} mm, ratio {ratios[-1]:.3f}  {cpu:.0f} s CPU", flush=True)
    print(f"  ratio range {min(ratios):.3f}-{max(ratios):.3f}; inside MOUTH_RANGE: "
          f"{MOUTH_RANGE[0] <= min(ratios) and max(ratios) <= MOUTH_RANGE[1]}")


if __name__ == "__main__":
    main("--fine" in sys.argv[1:])
