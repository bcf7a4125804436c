"""Cap mechanics: a whole force curve (10 load steps to 2 mm) on the paper template at G = 0.3 MPa, timed, and set
beside the paper's Fig. 8 fits (F = 8.8719 x + 2.876 N; V_eff = 0.5576 x² − 3.2659 x + 30.74 mm³ with A = d²/4)
and its Eq. 5 calibration. Target: < 20 s per curve on the project machine.
Run: OMP_NUM_THREADS=1 PYTHONPATH=. /work/venv/bin/python benchmarks/mechanics.py
"""

import dataclasses
import os
import sys
import time
from pathlib import Path

os.environ["MATCAD_CACHE_DIR"] = ""  # time the solver, not matcad.mechanics.store's disk cache

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad import spec as spec_mod  # noqa: E402
from matcad.acoustics.eq5 import MAT_PAPER_2024  # noqa: E402
from matcad.prediction import predict  # noqa: E402
from matcad.acoustics.design import design  # noqa: E402
from matcad.mechanics.case import cap_case  # noqa: E402
from matcad.mechanics.frequency import force_curve  # noqa: E402
from matcad.mechanics.solver import cap_curve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
G_MPA = 0.3


def paper_spec(material: str):
    spec = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
    return dataclasses.replace(spec, mechanics=dataclasses.replace(spec.mechanics, material=material,
                                                                   shear_modulus_mpa=G_MPA))


def main():
    print(f"paper template (D 3.18, L 4.76, cap Ø8 x 6.76 mm, 2 mm top, flange Ø12 x 1.6), G = {G_MPA} MPa, "
          "sticking plate, 10 steps to 2 mm")
    for material in ("neo_hookean", "yeoh", "ogden"):
        spec = paper_spec(material)
        t0 = time.perf_counter()
        curve = cap_curve(cap_case(spec))
        t_mech = time.perf_counter() - t0
        f0 = predict(spec).f0_hz
        t1 = time.perf_counter()
        fc = force_curve(design(spec), curve, f0)
        t_tl = time.perf_counter() - t1
        print(f"\n{material}: curve {t_mech:.1f} s ({curve.nodes} nodes, {curve.newton_iterations} Newton iterations, "
              f"complete: {curve.complete}), f(F) by transmission line {t_tl:.2f} s, total {t_mech + t_tl:.1f} s "
              f"(target < 20 s)")
        c = spec.air.speed_of_sound or 343.21
        paper = MAT_PAPER_2024.bound(c, spec.neck.diameter, spec.neck.length)
        k_d2 = paper.k_mm3_hz2
        print(f"  {'x mm':>5} {'F N':>7} {'paper F':>8} {'V mm3':>7} {'Veff d2/4':>9} {'paper Veff':>10} "
              f"{'f Hz':>7} {'paper Eq5 f':>11} {'df/dF Hz/N':>10} {'peak eps':>8}")
        for s, d, eps in zip(fc.states, fc.sensitivity_hz_per_n, curve.column("peak_strain")):
            x = s.displacement_mm
            paper_f = float(paper.frequency_hz(s.force_n))
            print(f"  {x:5.2f} {s.force_n:7.2f} {8.8719 * x + 2.876:8.2f} {s.cavity_volume_mm3:7.2f} "
                  f"{k_d2 / s.f_hz ** 2:9.2f} {0.5576 * x * x - 3.2659 * x + 30.74:10.2f} {s.f_hz:7.0f} "
                  f"{paper_f:11.0f} {d:10.1f} {eps:8.3f}")
        force, x = curve.column("force_n"), curve.column("displacement_mm")
        slope, icpt = np.polyfit(x[1:], force[1:], 1)
        print(f"  linear fit F = {slope:.3f} x + {icpt:.3f} N over x 0.2-2 mm (paper: 8.8719 x + 2.876)")
        vol = curve.column("cavity_volume_mm3")
        q = np.polyfit(x, vol, 2)
        print(f"  quadratic fit V = {q[0]:.4f} x² {q[1]:+.4f} x {q[2]:+.3f} mm³ (geometric cavity volume)")
        for cal in (fc.eq5, fc.eq5_paper_convention):
            print(f"  Eq. 5 fit ({cal.area_convention}): V0 = {cal.v0_mm3:.3f} mm³, a = {cal.a:.5f} mm³/N², "
                  f"b = {cal.b:.4f} mm³/N")
        print(f"  paper Eq. 5 (d2/4): V0 = 32.21 mm³, a = -0.0086 mm³/N², b = 0.4626 mm³/N; f stops rising at "
              f"{fc.turn_force_n} (predicted) vs ~25 N (paper, Fig. 7)")
        e = fc.eq5_paper_convention
        print(f"  relative (independent of f0 and of the area convention): b/V0 = {e.b / e.v0_mm3:.5f} /N, "
              f"a/V0 = {e.a / e.v0_mm3:.3e} /N² (paper: {0.4626 / 32.21:.5f}, {-0.0086 / 32.21:.3e}); f(F)/f0 at "
              + ", ".join(f"{F:g} N: {np.interp(F, force, [s.f_hz for s in fc.states]) / fc.states[0].f_hz:.4f} "
                          f"(paper {float(paper.frequency_hz(F) / paper.frequency_hz(0.0)):.4f})"
                          for F in (5.0, 10.0, 15.4, 25.0)))
    spec = paper_spec("ogden")
    curve = cap_curve(cap_case(spec))
    t0 = time.perf_counter()
    fc = force_curve(design(spec), curve, None, fem_level=4)
    print(f"\nFEM on the deformed outlines (level 4, {len(fc.states)} states): {time.perf_counter() - t0:.1f} s; "
          f"{fc.fem_note or 'all states meshed'}")
    for s in fc.states:
        fem_f = f"{s.f_fem_hz:7.0f}" if s.f_fem_hz is not None else "      -"
        print(f"  F {s.force_n:6.2f} N: TL {s.f_tl_hz:7.0f} Hz, FEM {fem_f} Hz")


if __name__ == "__main__":
    main()
