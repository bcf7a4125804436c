"""Cap mechanics against the paper, measured: whole force curves (10 load steps to 2 mm) on the paper template at
G = 0.3 MPa, timed, and set beside the paper's own numbers without fitting anything to ours:
- f(F): our Δf/f0 at equal force against paper Eq. 5, f/f0 = sqrt(V0/(V0 − bF − aF²)) (V0 = 32.21 mm³,
  a = −0.0086 mm³/N², b = 0.4626 mm³/N; the ratio is free of K, hence of f0 and of the area convention);
- F(x): our plate force against the paper's Fig. 8 fit F = 8.8719 x + 2.876 N of its measurements at
  x = 0.87 … 2.87 mm (§IV-B), slope over the shared range and F at equal x;
- V(x): our cavity volume and the paper's V_eff = 0.5576 x² − 3.2659 x + 30.74 mm³ (Fig. 8, A = d²/4).
Target: < 20 s per curve on the project machine.

``--caps`` adds how the cap's outer diameter, top thickness, modulus and plate contact move stiffness and
sensitivity (Ogden);
``--convergence [H ...]`` adds F and V at x = 0.2 … 1 mm on a mesh sequence (default h = 0.4, 0.2, 0.1,
0.05 mm, ~1–1.5 min; neo-Hookean, sticking; 0.025 mm adds 3–5 min), successive differences, observed orders,
a Richardson estimate and the default mesh (h = 0.2 mm) against it.
``--steps`` adds the paper template's own cap asked in 1/2/3/4/10 load steps and to 3 mm: the curve's end must not
depend on the step count.
Run: OMP_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python benchmarks/mechanics.py [--caps] [--convergence [H ...]]
[--steps] [--skip-materials]
"""

import argparse
import dataclasses
import math
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
from matcad.mechanics.section import section_from_spec  # noqa: E402
from matcad.mechanics.solver import cap_curve, compress  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
G_MPA = 0.3
FORCES_N = (1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 25.0)
PAPER_F_OF_X = (8.8719, 2.8760)
"""Paper Fig. 8: F = slope · x + intercept (N/mm, N), a line through its measurements at x = 0.87 … 2.87 mm."""
PAPER_X_MM = (0.87, 1.37, 1.87, 2.37, 2.87)
"""Paper §IV-B: the displacements it measured (besides 0.05 and 0.17 mm 'to approximate initial contact')."""
CAPS = ((8.0, 2.0, G_MPA, "sticking"), (10.0, 2.0, G_MPA, "sticking"), (12.0, 2.0, G_MPA, "sticking"),
        (8.0, 1.5, G_MPA, "sticking"), (8.0, 3.0, G_MPA, "sticking"), (8.0, 2.0, 0.2, "sticking"),
        (8.0, 2.0, 0.46, "sticking"), (8.0, 2.0, G_MPA, "frictionless"))
"""(end_cap.outer_diameter mm, end_cap.top_thickness mm, shear modulus MPa, plate contact) for ``--caps``; the
first is the template's."""
MESHES_MM = (0.4, 0.2, 0.1, 0.05)


def paper_shift(forces_n) -> np.ndarray:
    """Relative shift Δf/f0 of paper Eq. 5 at these forces (N): sqrt(V0/V_eff(F)) − 1, free of K."""
    f = np.asarray(forces_n, dtype=float)
    return np.sqrt(MAT_PAPER_2024.volume_mm3(0.0) / MAT_PAPER_2024.volume_mm3(f)) - 1.0


def curve_shift(force_n, f_hz, forces_n) -> np.ndarray:
    """Relative shift Δf/f0 of a computed f(F) (unloaded state first) at these forces, interpolated linearly
    between load states as ``matcad predict --load`` does; NaN beyond the curve."""
    force_n, f_hz = np.asarray(force_n, dtype=float), np.asarray(f_hz, dtype=float)
    f = np.asarray(forces_n, dtype=float)
    out = np.interp(f, force_n, f_hz) / f_hz[0] - 1.0
    return np.where(f <= force_n[-1], out, np.nan)


def paper_force_n(x_mm) -> np.ndarray:
    """The paper's Fig. 8 line F(x) (N) at plate travel x (mm); its 2.876 N at x = 0 is the line's intercept."""
    return PAPER_F_OF_X[0] * np.asarray(x_mm, dtype=float) + PAPER_F_OF_X[1]


def paper_veff_mm3(x_mm) -> np.ndarray:
    """The paper's Fig. 8 fit V_eff(x) (mm³, its A = d²/4 convention) at plate travel x (mm)."""
    x = np.asarray(x_mm, dtype=float)
    return 0.5576 * x * x - 3.2659 * x + 30.74


def observed_orders(values, ratio: float = 2.0) -> np.ndarray:
    """Observed convergence order of each successive triple of values on meshes refined by ``ratio``:
    log(|q1 − q2| / |q2 − q3|) / log(ratio). Meaningful only once the differences shrink by a steady factor."""
    d = np.abs(np.diff(np.asarray(values, dtype=float)))
    return np.log(d[:-1] / d[1:]) / math.log(ratio)


def richardson(coarse: float, fine: float, order: float, ratio: float = 2.0) -> float:
    """Richardson estimate of the mesh-converged value from two meshes refined by ``ratio`` and an order."""
    return fine + (fine - coarse) / (ratio ** order - 1.0)


def steady(values, ratio: float = 2.0, spread: float = 0.25) -> bool:
    """Whether a mesh sequence is in its asymptotic range: successive differences of one sign, shrinking, and
    observed orders within ``spread`` of each other (a stress singularity or a contact event breaks this)."""
    d = np.diff(np.asarray(values, dtype=float))
    if len(d) < 2 or not (np.all(d > 0) or np.all(d < 0)) or np.any(np.abs(d[1:]) >= np.abs(d[:-1])):
        return False
    p = observed_orders(values, ratio)
    return bool(np.ptp(p) <= spread)


def paper_spec(material: str, *overrides: str, g_mpa: float = G_MPA, contact: str | None = None):
    """The paper template with ``material`` at shear modulus ``g_mpa`` (and ``contact`` when given), after
    ``key=value`` overrides."""
    spec = spec_mod.load_spec(ROOT / "templates" / "mat-paper.toml", list(overrides))[0]
    mech = dataclasses.replace(spec.mechanics, material=material, shear_modulus_mpa=g_mpa,
                               contact=contact or spec.mechanics.contact)
    return dataclasses.replace(spec, mechanics=mech)


def compare_with_paper(fc, curve):
    """Print the fit-free f(F) comparison and the F(x) comparison of one computed curve."""
    force, x = curve.column("force_n"), curve.column("displacement_mm")
    f = np.array([s.f_hz for s in fc.states])
    ours, paper = curve_shift(force, f, FORCES_N), paper_shift(FORCES_N)
    print(f"  f(F), fit-free (paper Eq. 5 at equal force):\n  {'F N':>5} {'ours df/f0':>10} {'paper df/f0':>11} "
          f"{'ratio':>6} {'our x mm':>8}")
    for F, o, p in zip(FORCES_N, ours, paper):
        print(f"  {F:5.1f} {100 * o:9.2f}% {100 * p:10.2f}% {o / p:6.2f} {np.interp(F, force, x):8.3f}")
    shared = [xp for xp in PAPER_X_MM if xp <= x[-1] + 1e-9]
    print(f"  F(x) against the paper's Fig. 8 line ({PAPER_F_OF_X[0]} x + {PAPER_F_OF_X[1]} N; measured over "
          f"x {PAPER_X_MM[0]}-{PAPER_X_MM[-1]} mm):")
    for hi in (1.6, x[-1]):
        lo = PAPER_X_MM[0]
        secant = (np.interp(hi, x, force) - np.interp(lo, x, force)) / (hi - lo)
        print(f"    our secant slope over x {lo:g}-{hi:g} mm: {secant:.2f} N/mm, {secant / PAPER_F_OF_X[0]:.2f} x the "
              f"paper's {PAPER_F_OF_X[0]} N/mm")
    print(f"    {'x mm':>5} {'ours F N':>8} {'paper F N':>9} {'ratio':>6} {'paper F - 2.876':>15} {'ratio':>6}")
    for xp in sorted(set(shared) | {p for p in (0.2, 0.4, 1.0, 2.0) if p <= x[-1] + 1e-9}):
        fo, fp = np.interp(xp, x, force), float(paper_force_n(xp))
        print(f"    {xp:5.2f} {fo:8.2f} {fp:9.2f} {fo / fp:6.2f} {fp - PAPER_F_OF_X[1]:15.2f} "
              f"{fo / (fp - PAPER_F_OF_X[1]):6.2f}")
    vol = curve.column("cavity_volume_mm3")
    veff = paper_veff_mm3(x)
    print("  f(x) at equal travel: " + ", ".join(
        f"x {xp:g} mm: ours {100 * (np.interp(xp, x, f) / f[0] - 1):.1f} %, paper Fig. 8 V_eff "
        f"{100 * (math.sqrt(paper_veff_mm3(0.0) / paper_veff_mm3(xp)) - 1):.1f} %"
        for xp in (0.4, 1.0, 2.0) if xp <= x[-1] + 1e-9))
    print(f"  V over the curve: ours {100 * (vol[-1] / vol[0] - 1):.1f} % (geometric), "
          f"{100 * ((f[0] / f[-1]) ** 2 - 1):.1f} % (the V_eff our f implies, V ∝ 1/f²); paper V_eff "
          f"{100 * (veff[-1] / veff[0] - 1):.1f} % at x = {x[-1]:g} mm")


def materials():
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
            print(f"  {x:5.2f} {s.force_n:7.2f} {float(paper_force_n(x)):8.2f} {s.cavity_volume_mm3:7.2f} "
                  f"{k_d2 / s.f_hz ** 2:9.2f} {float(paper_veff_mm3(x)):10.2f} {s.f_hz:7.0f} "
                  f"{paper_f:11.0f} {d:10.1f} {eps:8.3f}")
        x, vol = curve.column("displacement_mm"), curve.column("cavity_volume_mm3")
        q = np.polyfit(x, vol, 2)
        print(f"  quadratic fit V = {q[0]:.4f} x² {q[1]:+.4f} x {q[2]:+.3f} mm³ (geometric cavity volume)")
        for cal in (fc.eq5, fc.eq5_paper_convention):
            print(f"  Eq. 5 fit ({cal.area_convention}): V0 = {cal.v0_mm3:.3f} mm³, a = {cal.a:.5f} mm³/N², "
                  f"b = {cal.b:.4f} mm³/N")
        e = fc.eq5_paper_convention
        print(f"  paper Eq. 5 (d2/4): V0 = 32.21 mm³, a = -0.0086 mm³/N², b = 0.4626 mm³/N; f stops rising at "
              f"{fc.turn_force_n} (predicted) vs ~25 N (paper, Fig. 7); fitted ratios (shape-dependent, not a "
              f"comparison): b/V0 = {e.b / e.v0_mm3:.5f} /N, a/V0 = {e.a / e.v0_mm3:.3e} /N² (paper "
              f"{0.4626 / 32.21:.5f}, {-0.0086 / 32.21:.3e})")
        slope0 = 100 * fc.sensitivity_hz_per_n[0] / fc.states[0].f_hz
        print(f"  initial slope of f/f0: the curve's df/dF(0)/f0 {slope0:.3f} %/N, the Eq. 5 fit's b/(2 V0) "
              f"{100 * e.b / (2 * e.v0_mm3):.3f} %/N, the paper's "
              f"{100 * 0.4626 / (2 * 32.21):.3f} %/N")
        compare_with_paper(fc, curve)
    spec = paper_spec("ogden")
    curve = cap_curve(cap_case(spec))
    t0 = time.perf_counter()
    fc = force_curve(design(spec), curve, None, fem_level=4)
    print(f"\nFEM on the deformed outlines (level 4, {len(fc.states)} states): {time.perf_counter() - t0:.1f} s; "
          f"{fc.fem_note or 'all states meshed'}")
    for s in fc.states:
        fem_f = f"{s.f_fem_hz:7.0f}" if s.f_fem_hz is not None else "      -"
        print(f"  F {s.force_n:6.2f} N: TL {s.f_tl_hz:7.0f} Hz, FEM {fem_f} Hz")


def caps():
    """Stiffness and sensitivity against the cap's outer diameter, top thickness, modulus and plate contact (Ogden):
    F at x = 0.2, 1, 2 mm, the initial slope of f, our Δf/f0 at 1, 10, 20 N over paper Eq. 5's, and f at 1 mm."""
    forces = (1.0, 10.0, 20.0)
    paper = paper_shift(forces)
    print("\ncap variants (Ogden, 10 steps to 2 mm; f shift by transmission line; ratio = our df/f0 over paper "
          "Eq. 5's at equal force):")
    print(f"  {'cap Ø mm':>8} {'top mm':>6} {'G MPa':>5} {'contact':>12} {'F(0.2) N':>8} {'F(1) N':>7} {'F(2) N':>7} "
          f"{'df/dF(0) %/N':>12} {'df/f0 @10 N':>11} {'ratio @1/10/20 N':>16} {'df/f0 @1 mm':>11} {'complete':>8}")
    for diameter, top, g, contact in CAPS:
        spec = paper_spec("ogden", f"end_cap.outer_diameter={diameter}", f"end_cap.top_thickness={top}", g_mpa=g,
                          contact=contact)
        curve = cap_curve(cap_case(spec))
        fc = force_curve(design(spec), curve)
        force, x = curve.column("force_n"), curve.column("displacement_mm")
        f = np.array([s.f_hz for s in fc.states])
        at = [np.interp(xp, x, force) if xp <= x[-1] + 1e-9 else float("nan") for xp in (0.2, 1.0, 2.0)]
        ours = curve_shift(force, f, forces)
        print(f"  {diameter:8.1f} {top:6.1f} {g:5.2f} {contact:>12} {at[0]:8.2f} {at[1]:7.2f} {at[2]:7.2f} "
              f"{100 * fc.sensitivity_hz_per_n[0] / f[0]:12.3f} {100 * ours[1]:10.2f}% "
              f"{' / '.join(f'{r:.2f}' for r in ours / paper):>16} "
              f"{100 * (np.interp(1.0, x, f) / f[0] - 1):10.2f}% {str(curve.complete):>8}")
        if not curve.complete:
            print(f"    {curve.message}")


def convergence(meshes_mm):
    """F and V at x = 0.2 … 1 mm on a mesh sequence (neo-Hookean, G_MPA, sticking, 5 steps to 1 mm): values,
    successive differences, observed orders, a Richardson estimate where the sequence is steady, and the default
    mesh (h = 0.2 mm) against it."""
    from matcad.mechanics.material import preset

    spec = paper_spec("neo_hookean")
    sec, law = section_from_spec(spec), preset("neo_hookean", spec.silicone.grade, G_MPA)
    print(f"\nmesh convergence (neo-Hookean, G = {G_MPA} MPa, sticking, 5 steps to 1 mm; h = asked element size, "
          f"block divisions rounded up, so refinement by ~2):")
    rows = []
    for h in meshes_mm:
        t0 = time.perf_counter()
        rows.append(compress(sec, law, "sticking", 1.0, 5, h))
        print(f"  h {h:6.4g} mm: {rows[-1].cells:6d} cells, {time.perf_counter() - t0:6.1f} s, "
              f"complete: {rows[-1].complete}")
    if not all(c.complete for c in rows):
        print("  a mesh did not reach 1 mm: no convergence table")
        return
    halving = len(meshes_mm) >= 3 and np.allclose(np.array(meshes_mm[:-1]) / np.array(meshes_mm[1:]), 2.0)
    default = list(meshes_mm).index(0.2) if 0.2 in meshes_mm else None
    summary = []
    for name, unit in (("force_n", "N"), ("cavity_volume_mm3", "mm³")):
        table = [(rows[0].steps[i].displacement_mm, np.array([getattr(c.steps[i], name) for c in rows]))
                 for i in range(5)]
        # the corners' singularities set one order for every x; take it from the first steady sequence and use it
        # where contact events (the bulging side meeting the plate or the guide) jitter the differences
        p_ref = next((float(observed_orders(q)[-1]) for _, q in table if halving and steady(q)), None)
        print(f"  {name} ({unit}) on h = " + ", ".join(f"{h:g}" for h in meshes_mm) + " mm"
              + (f" (reference order {p_ref:.2f}, from the first steady x)" if p_ref else "") + ":")
        for x, q in table:
            line = (f"    x {x:.1f}: " + " ".join(f"{v:.4f}" for v in q) + "; differences "
                    + " ".join(f"{d:+.4f}" for d in np.diff(q)))
            target, label = q[-1], "finest"
            if halving:
                line += "; orders " + " ".join(f"{o:.2f}" for o in observed_orders(q))
                if steady(q):
                    target, label = richardson(q[-2], q[-1], float(observed_orders(q)[-1])), "Richardson"
                elif p_ref is not None:
                    target, label = richardson(q[-2], q[-1], p_ref), f"Richardson at p {p_ref:.2f}"
                    line += " (not steady)"
                else:
                    line += " (not steady)"
                if label != "finest":
                    line += f"; {label} {target:.4f}"
            if default is not None:
                err = 100 * (q[default] / target - 1)
                line += f"; h 0.2 vs {label} {err:+.2f} %" + (
                    f", vs finest {100 * (q[default] / q[-1] - 1):+.2f} %" if label != "finest" else "")
                summary.append((name, x, err))
            print(line)
    for name in ("force_n", "cavity_volume_mm3"):
        errs = [(x, e) for n, x, e in summary if n == name]
        if errs:
            print(f"  default mesh (h 0.2 mm) {name} against the converged estimate: "
                  + ", ".join(f"x {x:.1f} {e:+.2f} %" for x, e in errs))


def steps_table():
    """The paper template's own cap asked in 1/2/3/4/10 load steps and to 3 mm in 10: where each curve ends, its
    force there, its Newton iterations and df/dF at 0 N (the curve's tangent); the end must not depend on the step
    count."""
    print("paper template as shipped: steps, travel asked, where the curve ends, F there, Newton iterations, "
          "df/dF at 0 N, time")
    base = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
    for steps, travel in ((1, 2.0), (2, 2.0), (3, 2.0), (4, 2.0), (10, 2.0), (10, 3.0)):
        spec = dataclasses.replace(base, mechanics=dataclasses.replace(base.mechanics, steps=steps,
                                                                       displacement_mm=travel))
        t0 = time.perf_counter()
        curve = cap_curve(cap_case(spec))
        seconds = time.perf_counter() - t0
        end = curve.column("displacement_mm")[-1] if curve.steps else 0.0
        force = curve.column("force_n")[-1] if curve.steps else 0.0
        slope = force_curve(design(spec), curve).sensitivity_hz_per_n[0] if curve.steps else float("nan")
        print(f"  {steps:>2} steps to {travel:g} mm: ends at {end:.3g} mm, F {force:.2f} N, "
              f"{curve.newton_iterations} iterations, df/dF(0) {slope:.1f} Hz/N, {seconds:.1f} s"
              + ("" if curve.complete else f" ({curve.message[:90]})"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--caps", action="store_true", help="add the cap, modulus and contact variants (8 curves, 2-4 min)")
    ap.add_argument("--convergence", nargs="*", type=float, metavar="H",
                    help=f"add the mesh sequence (element sizes in mm, default {' '.join(map(str, MESHES_MM))})")
    ap.add_argument("--skip-materials", action="store_true", help="skip the default three-material run")
    ap.add_argument("--steps", action="store_true", help="add the step-count table of the paper template's cap")
    args = ap.parse_args(argv)
    if not args.skip_materials:
        materials()
    if args.caps:
        caps()
    if args.convergence is not None:
        convergence(tuple(args.convergence) or MESHES_MM)
    if args.steps:
        steps_table()


if __name__ == "__main__":
    main()
