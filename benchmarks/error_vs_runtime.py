"""Every model's signed error against the converged FEM, and its run time, over a geometry set; the FEM itself
at several mesh levels; STL tessellation tolerance against volume error and export time.

Writes docs/error_vs_runtime.md and the README's copy of it, docs/error_vs_runtime.png (log-log error vs time)
and matcad/acoustics/model_errors.json (each model's max |error| where its validity checks pass, which the
uncertainty budget uses). Run: .venv/bin/python benchmarks/error_vs_runtime.py
"""

from __future__ import annotations

import dataclasses
import json
import math
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from matcad import spec as spec_mod  # noqa: E402
from matcad.acoustics import fem, fsi  # noqa: E402
from matcad.prediction import predict  # noqa: E402
from matcad.acoustics import wall as wall_model  # noqa: E402
from matcad.acoustics.design import design  # noqa: E402
from matcad.acoustics.registry import cheap_models, model as registered  # noqa: E402
from matcad.acoustics.resonator import resonator, wall_modes  # noqa: E402


def model_f(spec, name):
    """f0 (Hz) of closed-form model ``name`` on ``spec`` at the middle of its wall ranges."""
    d = design(spec)
    return float(registered(name).f0_hz(resonator(d), d.wall))


def elastic_cap(spec):
    """The coupled FEM's cap of ``spec`` at the middle of its kHz modulus and loss ranges."""
    d = design(spec)
    return fsi.cap(d, *registered("elastic_wall").wall_arguments(d.wall))

LEVELS = (2, 4, 8, 16)
WALL_SWEEP_G_MPA = (0.1, 0.2, 0.35, 0.6, 1.0, 2.0, 4.0, 10.0)
WALL_SWEEP_ETA = (0.1, 0.2)
CLOSING_G_MPA = (0.2, 0.35, 0.6)
"""The paper template's cap over G (kHz storage modulus) and η, both mouths: the elastic-wall model against the
coupled FEM (level 8), the quasi-static model beside them, all relative to the rigid FEM."""
CASES = {
    # name: (cavity D, L, neck d, l, mouth, wall)
    "paper taxel (mount)": (3.18, 4.76, 2.10, 6.35, "mount", "rigid"),
    "paper taxel (baffled)": (3.18, 4.76, 2.10, 6.35, "baffled", "rigid"),
    "paper taxel, silicone (mount)": (3.18, 4.76, 2.10, 6.35, "mount", "silicone"),
    "neck almost cavity-wide (d = 0.95 D)": (3.18, 4.76, 3.02, 6.35, "baffled", "rigid"),
    "1 mm neck": (3.18, 4.76, 2.10, 1.0, "baffled", "rigid"),
    "20 mm neck": (3.18, 4.76, 2.10, 20.0, "baffled", "rigid"),
    "pancake cavity (L/D = 0.2)": (10.0, 2.0, 2.0, 3.0, "baffled", "rigid"),
    "classic 10 x 10 mm cavity": (10.0, 10.0, 2.5, 3.0, "baffled", "rigid"),
    "sub-mm ultrasonic taxel (x0.1)": (0.318, 0.476, 0.21, 0.635, "baffled", "rigid"),
    "bottle (70 x 150 mm, 20 mm neck)": (70.0, 150.0, 20.0, 50.0, "baffled", "rigid"),
    "classic 10 x 10 mm cavity, silicone": (10.0, 10.0, 2.5, 3.0, "baffled", "silicone"),
    "1 mm neck, silicone": (3.18, 4.76, 2.10, 1.0, "baffled", "silicone"),
}
README_MARKERS = ("<!-- error-table -->", "<!-- /error-table -->")
STL_TOLERANCES = ((0.1, 0.5), (0.05, 0.3), (0.01, 0.1), (0.005, 0.05), (0.001, 0.02))


def case_spec(dims):
    big_d, big_l, d, l, mouth, wall = dims
    scale = big_d / 3.18
    return spec_mod.from_dict({
        "name": "bench", "cavity": {"diameter": big_d, "length": big_l}, "neck": {"diameter": d, "length": l,
                                                                             "mouth": mouth},
        "plate": {"width": 24 * scale, "depth": 24 * scale}, "spacer": {"height": 1.59 * scale},
        "wall": {"model": wall, "shear_modulus_mpa": [0.2, 0.6]}})


def _timed(fn, repeats):
    t0 = time.perf_counter()
    for _ in range(repeats):
        value = fn()
    return value, (time.perf_counter() - t0) / repeats


def reference(levels_f):
    """Richardson extrapolation from the last three levels with the observed rate."""
    f2, f4, f8 = levels_f[-3:]
    ratio = (f2 - f4) / (f4 - f8) if f4 != f8 else math.inf
    if not math.isfinite(ratio) or ratio <= 1.05:
        return f8
    return f8 + (f8 - f4) / (ratio - 1)


def run_case(name, dims):
    spec = case_spec(dims)
    p = predict(spec)
    geom = fem.geometry(design(spec))
    c = p.speed_of_sound_m_s
    if spec.wall.model == "silicone":  # the coupled elastic cap + air FEM at the spec's middle kHz modulus and loss
        cap = elastic_cap(spec)
        runs = [fsi.solve(geom, cap, p.f0_hz, level, c) for level in LEVELS]
    else:
        k0 = 2 * math.pi * p.f0_hz / (c * 1e3)
        runs = [fem.solve(geom, k0, level, c) for level in LEVELS]
    f_ref = reference([r.f0_hz for r in runs])
    rows = []
    # rigid-wall models are scored against the rigid FEM only; a silicone case scores the two wall models
    models = ["soft_wall", "elastic_wall"] if spec.wall.model == "silicone" else [
        m for m in cheap_models() if m in p.models and m not in ("soft_wall", "elastic_wall")]
    for model in models:
        f, seconds = _timed(lambda: model_f(spec, model), 20)
        rows.append({"case": name, "model": model, "f_hz": f, "error": f / f_ref - 1, "seconds": seconds,
                     "valid": p.models[model].valid})
    for r in runs:
        rows.append({"case": name, "model": f"fem level {r.level}", "f_hz": r.f0_hz, "error": r.f0_hz / f_ref - 1,
                     "seconds": r.seconds, "valid": True, "dofs": r.dofs})
    return f_ref, rows


def wall_sweep():
    """The paper template's cap over G and η, both mouths: coupled FEM (level 8), elastic_wall, soft_wall."""
    rows = []
    for mouth in ("mount", "baffled"):
        spec = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
        spec = dataclasses.replace(spec, neck=dataclasses.replace(spec.neck, mouth=mouth))
        d = design(spec)
        res = resonator(d)
        geom = fem.geometry(d)
        c = res.c_m_s
        rigid = fsi.solve(geom, None, float(registered("transmission_line").f0_hz(res)), fem.DEFAULT_LEVEL, c)
        for g_mpa in WALL_SWEEP_G_MPA:
            for eta in WALL_SWEEP_ETA:
                fast, seconds = _timed(lambda: float(registered("elastic_wall").f0_hz(res, shear_modulus_pa=g_mpa * 1e6,
                                                                                      loss_factor=eta)), 5)
                near = wall_model.mode_near(wall_modes(res, g_mpa * 1e6), fast)
                run = fsi.solve(geom, fsi.cap(d, g_mpa * 1e6, eta), fast, fem.DEFAULT_LEVEL, c)
                rows.append({"mouth": mouth, "g_mpa": g_mpa, "eta": eta, "fem_hz": run.f0_hz, "q": run.q,
                             "fem_seconds": run.seconds, "wall_modes_hz": run.wall_modes_hz, "rigid_hz": rigid.f0_hz,
                             "elastic_hz": fast, "elastic_seconds": seconds,
                             "soft_hz": float(registered("soft_wall").f0_hz(res, shear_modulus_pa=g_mpa * 1e6)),
                             "near_mode_hz": near})
                print(f"  {mouth} G {g_mpa} eta {eta}: FEM {run.f0_hz:.0f} Hz ({run.seconds:.1f} s), elastic_wall "
                      f"{fast:.0f} Hz ({fast / run.f0_hz - 1:+.2%})", flush=True)
    return rows


RATIO_VARIANTS = {
    # name: changes to the paper template (relative to it as the measured reference)
    "cavity L x0.75": {"cavity": {"length": 3.57}}, "cavity L x1.25": {"cavity": {"length": 5.95}},
    "cavity D x0.85": {"cavity": {"diameter": 2.70}}, "cavity D x1.15": {"cavity": {"diameter": 3.66}},
    "neck d x0.8": {"neck": {"diameter": 1.68}}, "neck d x1.2": {"neck": {"diameter": 2.52}},
    "sheet 3 mm": {"neck": {"length": 3.0}}, "sheet 10 mm": {"neck": {"length": 10.0}},
    "cap 10 mm, 3 mm top": {"end_cap": {"outer_diameter": 10.0, "top_thickness": 3.0}},
    "cap 6 mm, 1 mm top": {"end_cap": {"outer_diameter": 6.0, "top_thickness": 1.0}},
}


def _variant(spec, changes):
    return dataclasses.replace(spec, **{sec: dataclasses.replace(getattr(spec, sec), **vals)
                                        for sec, vals in changes.items()})


def ratio_sweep():
    """Designs near the paper template predicted relative to it (as a measured reference) against absolutely:
    each model's ratio error (new/reference vs the FEM's ratio) beside its absolute error, rigid and silicone."""
    rows = []
    for wall in ("rigid", "silicone"):
        base = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
        base = dataclasses.replace(base, wall=dataclasses.replace(base.wall, model=wall))
        models = ["transmission_line"] if wall == "rigid" else ["elastic_wall", "soft_wall"]

        def fem_f(spec):
            d = design(spec)
            res = resonator(d)
            guess = float(registered("transmission_line").f0_hz(res))
            if wall == "silicone":
                return fsi.solve(fem.geometry(d), elastic_cap(spec), guess, fem.DEFAULT_LEVEL, res.c_m_s,
                                 wall_modes=0).f0_hz
            return fem.solve(fem.geometry(d), 2 * math.pi * guess / (res.c_m_s * 1e3),
                             fem.DEFAULT_LEVEL, res.c_m_s).f0_hz

        f_ref = fem_f(base)
        for name, changes in RATIO_VARIANTS.items():
            if wall == "rigid" and name.startswith("cap"):
                continue
            spec = _variant(base, changes)
            f_fem = fem_f(spec)
            p_new, p_base = predict(spec), predict(base)
            for model in models:
                f_new, f_base = model_f(spec, model), model_f(base, model)
                rows.append({"wall": wall, "variant": name, "model": model, "fem_hz": f_fem,
                             "absolute": f_new / f_fem - 1, "ratio": (f_new / f_base) / (f_fem / f_ref) - 1,
                             "valid": p_new.models[model].valid and p_base.models[model].valid})
            print(f"  ratio {wall} {name}: FEM {f_fem:.0f} Hz", flush=True)
    return rows


def ratio_table(rows) -> list[str]:
    lines = ["", "Prediction relative to a measured reference (`[reference]`): designs near the paper template, each "
             "model's error in the ratio new/reference against the FEM's ratio (level "
             f"{fem.DEFAULT_LEVEL}; silicone: the coupled FEM), beside its absolute error:", "",
             "| wall | design (reference: paper template) | FEM [Hz] | model | absolute error | ratio error |",
             "|---|---|---:|---|---:|---:|"]
    lines += [f"| {r['wall']} | {r['variant']} | {r['fem_hz']:.0f} | {r['model']} | {100 * r['absolute']:+.2f} % | "
              f"{100 * r['ratio']:+.2f} %{'' if r['valid'] else '†'} |" for r in rows]
    lines.append("\n† the model's checks fail on this design or the reference (for elastic_wall: a wall mode near f).")
    for model in dict.fromkeys(r["model"] for r in rows):
        picked = [r for r in rows if r["model"] == model]
        lines.append(f"\n{model}: max |absolute error| {100 * max(abs(r['absolute']) for r in picked):.2f} %, max "
                     f"|ratio error| {100 * max(abs(r['ratio']) for r in picked):.2f} % over {len(picked)} designs.")
    return lines


def wall_table(rows) -> list[str]:
    lines = ["", "The paper template's Dragon Skin cap (Ø8 mm, 2 mm top, flange clamped), coupled FEM (level "
             f"{fem.DEFAULT_LEVEL}, peak of the driven response) against the fast `elastic_wall` and the quasi-static "
             "`soft_wall`, over the kHz shear modulus G and loss factor η, both mouths (shifts relative to the "
             "rigid-wall FEM peak):", "",
             "| mouth | G [MPa] | η | coupled FEM [Hz] | vs rigid | Q | first wall modes [Hz] | FEM time | elastic_wall "
             "[Hz] | error | soft_wall [Hz] | error | hybrid |",
             "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        modes = ", ".join(f"{f:.0f}" for f in r["wall_modes_hz"])
        lines.append(f"| {r['mouth']} | {r['g_mpa']:g} | {r['eta']:g} | {r['fem_hz']:.0f} | "
                     f"{100 * (r['fem_hz'] / r['rigid_hz'] - 1):+.1f} % | {r['q']:.1f} | {modes} | "
                     f"{r['fem_seconds']:.1f} s | {r['elastic_hz']:.0f} | {100 * (r['elastic_hz'] / r['fem_hz'] - 1):+.2f} % | "
                     f"{r['soft_hz']:.0f} | {100 * (r['soft_hz'] / r['fem_hz'] - 1):+.1f} % |"
                     + ("" if r["near_mode_hz"] is None else f" wall mode at {r['near_mode_hz']:.0f} Hz † |"))
    worst = max(rows, key=lambda r: abs(r["elastic_hz"] / r["fem_hz"] - 1))
    clear = [r for r in rows if r["near_mode_hz"] is None]
    worst_clear = max(clear, key=lambda r: abs(r["elastic_hz"] / r["fem_hz"] - 1))
    lines += ["", "† a coupled wall mode lies within 15 % of f: cavity and wall hybridise (matcad flags it).", "",
              f"Worst elastic_wall error: {100 * (worst['elastic_hz'] / worst['fem_hz'] - 1):+.2f} % "
              f"({worst['mouth']}, G = {worst['g_mpa']:g} MPa, η = {worst['eta']:g}); without a wall mode near f "
              f"{100 * (worst_clear['elastic_hz'] / worst_clear['fem_hz'] - 1):+.2f} % ({worst_clear['mouth']}, "
              f"G = {worst_clear['g_mpa']:g} MPa, η = {worst_clear['eta']:g}). Both include the transmission "
              "line's own rigid-wall error for that mouth."]
    return lines


def stl_rows():
    from matcad.export.mesh import mesh_checks, write_stl
    from matcad.parts.end_cap import end_cap
    from matcad.parts.features import cap_volume_mm3

    spec = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
    cap, exact = end_cap(spec), cap_volume_mm3(spec)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for tol, ang in STL_TOLERANCES:
            path = Path(tmp) / f"cap-{tol}.stl"
            _, seconds = _timed(lambda: write_stl(cap, path, tol, ang), 3)
            checks = mesh_checks(path)
            rows.append({"tolerance_mm": tol, "angular_rad": ang, "triangles": checks["triangles"],
                         "volume_error": checks["volume_mm3"] / exact - 1, "seconds": seconds,
                         "bytes": path.stat().st_size})
    return rows


def write_outputs(results, stls, sweep, ratios):
    docs = ROOT / "docs"
    docs.mkdir(exist_ok=True)
    lines = ["| geometry | f_ref (FEM, extrapolated) [Hz] | " + " | ".join(
        ["lumped", "end_corrected", "transmission_line", "soft_wall", "elastic_wall"]
        + [f"FEM L{lv}" for lv in LEVELS]) + " |",
        "|---|---:|" + "---:|" * (5 + len(LEVELS))]
    for name, (f_ref, rows) in results.items():
        by = {r["model"]: r for r in rows}
        cells = []
        for key in (["lumped", "end_corrected", "transmission_line", "soft_wall", "elastic_wall"]
                    + [f"fem level {lv}" for lv in LEVELS]):
            r = by.get(key)
            cells.append("–" if r is None else f"{100 * r['error']:+.2f} %{'' if r['valid'] else '†'}")
        lines.append(f"| {name} | {f_ref:.1f} | " + " | ".join(cells) + " |")
    timing = {}
    for _, rows in results.values():
        for r in rows:
            timing.setdefault(r["model"], []).append(r["seconds"])
    lines += ["", "† the model's own validity checks fail for that geometry (matcad warns). Silicone rows: the "
              "reference is the coupled elastic cap + air FEM at the spec's middle kHz modulus and loss.", "",
              "Median run time per evaluation: " + ", ".join(
                  f"{m} {sorted(ts)[len(ts) // 2] * 1e6:.0f} µs" if sorted(ts)[len(ts) // 2] < 0.01 else
                  f"{m} {sorted(ts)[len(ts) // 2]:.2f} s" for m, ts in timing.items()) + ".", "",
              *wall_table(sweep), *ratio_table(ratios), "",
              "STL tessellation of the paper's end cap (volume against the closed form):", "",
              "| chordal tol [mm] | angular tol [rad] | triangles | volume error | export time | size |",
              "|---:|---:|---:|---:|---:|---:|"]
    lines += [f"| {s['tolerance_mm']:g} | {s['angular_rad']:g} | {s['triangles']} | {100 * s['volume_error']:+.3f} % | "
              f"{s['seconds'] * 1e3:.0f} ms | {s['bytes'] / 1024:.0f} KiB |" for s in stls]
    table = "\n".join(lines) + "\n"
    (docs / "error_vs_runtime.md").write_text(table, encoding="utf-8")
    readme = ROOT / "README.md"
    text = readme.read_text(encoding="utf-8")
    start, end = text.index(README_MARKERS[0]), text.index(README_MARKERS[1])
    readme.write_text(text[:start + len(README_MARKERS[0])] + "\n" + table + text[end:], encoding="utf-8")

    errors = {}
    sweep_rows = [{"model": "elastic_wall", "error": r["elastic_hz"] / r["fem_hz"] - 1,
                   "valid": r["near_mode_hz"] is None} for r in sweep]
    for model in list(cheap_models()) + ["fem"]:
        key = f"fem level {fem.DEFAULT_LEVEL}" if model == "fem" else model
        picked = [r for _, rows in results.values() for r in rows if r["model"] == key]
        picked += [r for r in sweep_rows if r["model"] == key]
        valid = [r for r in picked if r["valid"]] or picked
        errors[model] = {"max_abs": max(abs(r["error"]) for r in valid), "cases": len(valid),
                         "of": len(picked), "max_abs_all": max(abs(r["error"]) for r in picked),
                         "measured_by": "benchmarks/error_vs_runtime.py"}
        in_ratio = [r for r in ratios if r["model"] == model]
        if in_ratio:
            valid_ratio = [r for r in in_ratio if r["valid"]] or in_ratio
            errors[model]["ratio_max_abs"] = max(abs(r["ratio"]) for r in valid_ratio)
            errors[model]["ratio_cases"] = len(valid_ratio)
            errors[model]["ratio_max_abs_all"] = max(abs(r["ratio"]) for r in in_ratio)
    (ROOT / "matcad" / "acoustics" / "model_errors.json").write_text(json.dumps(errors, indent=1) + "\n")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for model, marker in (("lumped", "v"), ("end_corrected", "s"), ("transmission_line", "o"), ("soft_wall", "D"),
                          ("elastic_wall", "^")):
        pts = [(r["seconds"], abs(r["error"])) for _, rows in results.values() for r in rows if r["model"] == model]
        if pts:
            ax.scatter(*zip(*pts), marker=marker, label=model)
    for name, (_, rows) in results.items():
        pts = [(r["seconds"], max(abs(r["error"]), 1e-6)) for r in rows if r["model"].startswith("fem")]
        ax.plot(*zip(*pts), color="grey", alpha=0.5, marker=".")
    ax.plot([], [], color="grey", marker=".", label="FEM levels 2-16 (one line per geometry)")
    ax.set(xscale="log", yscale="log", xlabel="run time per evaluation [s]", ylabel="|error| vs converged FEM",
           title="matcad model ladder: error against run time")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(docs / "error_vs_runtime.png", dpi=120)


def main():
    results = {}
    for name, dims in CASES.items():
        t0 = time.perf_counter()
        results[name] = run_case(name, dims)
        print(f"{name}: f_ref {results[name][0]:.1f} Hz ({time.perf_counter() - t0:.1f} s)", flush=True)
    sweep = wall_sweep()
    ratios = ratio_sweep()
    stls = stl_rows()
    write_outputs(results, stls, sweep, ratios)
    print((ROOT / "docs" / "error_vs_runtime.md").read_text())
    print(json.dumps(json.loads((ROOT / "matcad" / "acoustics" / "model_errors.json").read_text()), indent=1))


if __name__ == "__main__":
    main()
