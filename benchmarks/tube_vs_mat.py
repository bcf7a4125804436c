"""A MAT taxel and a fipple tube for the same pitch: length, air volume, f(F) sensitivity, fabrication steps.

The MAT taxel is templates/mat-paper.toml as predicted; the tube is templates/acoustac-tube.toml with its length
solved onto the MAT's f0 (`matcad design --target-hz`). f(F) of both from the cap mechanics (FElupe, ~1 min each on
a loaded machine) at 0 and 1 N. Run: .venv/bin/python benchmarks/tube_vs_mat.py
"""

import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from matcad.design.tube import solve_tube  # noqa: E402
from matcad.parts.tube import heights_mm  # noqa: E402
from matcad.prediction import predict  # noqa: E402
from matcad.prediction.tube import predict_tube  # noqa: E402
from matcad.spec import cap_height_mm, load  # noqa: E402
from matcad.tube_build import STEPS  # noqa: E402

FORCES = (0.0, 1.0)


def main():
    t0 = time.perf_counter()
    mat = load(ROOT / "templates" / "mat-paper.toml")
    p_mat = predict(mat, forces_n=FORCES)
    f_mat = [pt.f_hz for pt in p_mat.load_curve if pt.source.startswith("cap mechanics")]
    eq5 = [pt.f_hz for pt in p_mat.load_curve if "Eq. 5" in pt.source]
    tube = solve_tube(load(ROOT / "templates" / "acoustac-tube.toml"), p_mat.f0_hz, "tube-at-mat-pitch").spec
    p_tube = predict_tube(tube, FORCES)
    f_tube = [x.f_hz for x in p_tube.loads]
    a = tube.tube.bore_diameter / 2
    mat_len = mat.spacer.height + mat.neck.length + cap_height_mm(mat)
    tube_len = heights_mm(tube)["top"] + tube.end_cap.top_thickness
    rows = [("pitch f0 (Hz)", f"{p_mat.f0_hz:.0f}", f"{p_tube.f0_hz:.0f}"),
            ("resonator length (mm)", f"{mat.cavity.length + mat.neck.length:.2f} (cavity + neck)",
             f"{p_tube.column_mm:.2f} (column) + {p_tube.mouth_correction_mm:.2f} (mouth)"),
            ("taxel length (mm)", f"{mat_len:.2f} (spacer + plate + cap)", f"{tube_len:.2f} (block to cap top)"),
            ("air volume (mm3)", f"{math.pi * mat.cavity.diameter ** 2 / 4 * mat.cavity.length:.1f}",
             f"{math.pi * a * a * p_tube.column_mm:.1f}"),
            ("f(1 N) - f(0) (Hz)", f"{f_mat[1] - f_mat[0]:.1f} (cap mechanics; paper Eq. 5: {eq5[1] - eq5[0]:.1f})",
             f"{f_tube[1] - f_tube[0]:.1f} (cap mechanics)"),
            ("fabrication steps", "see the MAT report (laser, print, cast, assemble)", f"{len(STEPS)}")]
    for row in rows:
        print(f"{row[0]:<24} | {row[1]:<40} | {row[2]}")
    print(f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
