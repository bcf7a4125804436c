"""Every model's signed error against the converged FEM, and its run time, over a geometry set; the FEM itself
at several mesh levels; STL tessellation tolerance against volume error and export time.

Writes docs/error_vs_runtime.md and the README's copy of it, docs/error_vs_runtime.png (log-log error vs time)
and matcad/acoustics/model_errors.json (each model's max |error| where its validity checks pass, which the
uncertainty budget uses). Run: .venv/bin/python benchmarks/error_vs_runtime.py
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from matcad import spec as spec_mod  # noqa: E402
from matcad.acoustics import fem  # noqa: E402
from matcad.acoustics.predict import predict  # noqa: E402
from matcad.acoustics.resonator import CHEAP_MODELS, evaluate, resonator, shear_moduli_pa  # noqa: E402

LEVELS = (2, 4, 8, 16)
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
    shear = shear_moduli_pa(spec)[1] if spec.wall.model == "silicone" else None
    geom = fem.geometry_from_spec(spec, shear)
    k0 = 2 * math.pi * p.f0_hz / (p.speed_of_sound_m_s * 1e3)
    runs = [fem.solve(geom, k0, level, p.speed_of_sound_m_s) for level in LEVELS]
    f_ref = reference([r.f0_hz for r in runs])
    rows = []
    # rigid-wall models are scored against the rigid FEM only; a silicone case scores the soft-wall model
    models = ["soft_wall"] if spec.wall.model == "silicone" else [m for m in CHEAP_MODELS if m in p.models]
    for model in models:
        f, seconds = _timed(lambda: float(evaluate(resonator(spec), model, shear)), 200)
        rows.append({"case": name, "model": model, "f_hz": f, "error": f / f_ref - 1, "seconds": seconds,
                     "valid": p.models[model].valid})
    for r in runs:
        rows.append({"case": name, "model": f"fem level {r.level}", "f_hz": r.f0_hz, "error": r.f0_hz / f_ref - 1,
                     "seconds": r.seconds, "valid": True, "dofs": r.dofs})
    return f_ref, rows


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


def write_outputs(results, stls):
    docs = ROOT / "docs"
    docs.mkdir(exist_ok=True)
    lines = ["| geometry | f_ref (FEM, extrapolated) [Hz] | " + " | ".join(
        ["lumped", "end_corrected", "transmission_line", "soft_wall"] + [f"FEM L{lv}" for lv in LEVELS]) + " |",
        "|---|---:|" + "---:|" * (4 + len(LEVELS))]
    for name, (f_ref, rows) in results.items():
        by = {r["model"]: r for r in rows}
        cells = []
        for key in ["lumped", "end_corrected", "transmission_line", "soft_wall"] + [f"fem level {lv}" for lv in LEVELS]:
            r = by.get(key)
            cells.append("–" if r is None else f"{100 * r['error']:+.2f} %{'' if r['valid'] else '†'}")
        lines.append(f"| {name} | {f_ref:.1f} | " + " | ".join(cells) + " |")
    timing = {}
    for _, rows in results.values():
        for r in rows:
            timing.setdefault(r["model"], []).append(r["seconds"])
    lines += ["", "† the model's own validity checks fail for that geometry (matcad warns).", "",
              "Median run time per evaluation: " + ", ".join(
                  f"{m} {sorted(ts)[len(ts) // 2] * 1e6:.0f} µs" if sorted(ts)[len(ts) // 2] < 0.01 else
                  f"{m} {sorted(ts)[len(ts) // 2]:.2f} s" for m, ts in timing.items()) + ".", "",
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
    for model in list(CHEAP_MODELS) + ["fem"]:
        key = f"fem level {fem.DEFAULT_LEVEL}" if model == "fem" else model
        picked = [r for _, rows in results.values() for r in rows if r["model"] == key]
        valid = [r for r in picked if r["valid"]] or picked
        errors[model] = {"max_abs": max(abs(r["error"]) for r in valid), "cases": len(valid),
                         "of": len(picked), "measured_by": "benchmarks/error_vs_runtime.py"}
    (ROOT / "matcad" / "acoustics" / "model_errors.json").write_text(json.dumps(errors, indent=1) + "\n")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for model, marker in (("lumped", "v"), ("end_corrected", "s"), ("transmission_line", "o"), ("soft_wall", "D")):
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
    stls = stl_rows()
    write_outputs(results, stls)
    print((ROOT / "docs" / "error_vs_runtime.md").read_text())
    print(json.dumps(json.loads((ROOT / "matcad" / "acoustics" / "model_errors.json").read_text()), indent=1))


if __name__ == "__main__":
    main()
