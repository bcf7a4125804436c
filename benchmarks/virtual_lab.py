"""A virtual lab: does measured beat modelled? (issue 19; docs/inference.md)

Each lab has a hidden as-built state (neck cut wider or narrower, taper, sheet, air joined to the cavity, the
silicone's kHz and static moduli), drawn at random, wider than the inference's priors expect. Its taxels are
"built" with the FEM rungs only: unloaded f0 from the coupled elastic-cap + air FEM (matcad.acoustics.fsi) on the
built geometry, f(F) from FElupe run at the hidden static modulus and the rigid acoustic FEM on each deformed
cavity (never the closed-form models the inference uses). The lab measures one taxel of the paper's design (f0 with
20 Hz noise; with --load also f(F) at 4 forces), then predicts DESIGNS, six other taxels; each prediction is set
against its FEM truth, beside the physics-only prediction (the chosen closed-form model on the drawing).

Printed: per lab and overall, |error| of the anchored (as-built) and physics-only predictions (median, 90th
percentile, max), the share of truths inside the anchored 95 % band (coverage), and with --load whether the hidden
neck offset and joined air lie inside their 95 % intervals. --json FILE writes every row.

Run: PYTHONPATH=. python benchmarks/virtual_lab.py --labs 20 --level 4 [--load] [--json out/virtual_lab.json]
A lab takes ~1 min at level 4 (f0 only) and ~2 min with --load on one core.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "templates" / "mat-paper.toml"
DESIGNS = (
    {"neck.diameter": 1.6},
    {"neck.diameter": 2.6},
    {"cavity.diameter": 4.0},
    {"cavity.length": 6.5},
    {"neck.length": 4.5},
    {"cavity.diameter": 2.6, "cavity.length": 3.5},
)
"""The other taxels a lab predicts after measuring one of the paper's design (fields changed from it, mm)."""
LOAD_FORCES_N = (2.0, 5.0, 10.0, 15.0)
"""Forces of the measured f(F) pairs with --load (N)."""
NOISE_HZ = 20.0
"""sd of a measured frequency (Hz)."""
HYBRID_BAND = 0.15
"""A cap mode within this fraction of f makes a doublet (as matcad.acoustics.wall.HYBRID_BAND)."""
HIDDEN = {
    "neck_offset_mm": ("uniform", -0.25, 0.25),
    "neck_taper_mm": ("uniform", -0.2, 0.2),
    "sheet_offset_mm": ("uniform", -0.4, 0.4),
    "side_volume_mm3": ("uniform", 0.0, 60.0),
    "khz_modulus_scale": ("loguniform", 0.6, 1.6),
    "static_modulus_scale": ("loguniform", 0.5, 1.8),
}
"""How a lab's hidden state is drawn (uniform or log-uniform between the two values)."""


def hidden_state(rng):
    from matcad.prediction.asbuilt import State

    values = {}
    for name, (kind, lo, hi) in HIDDEN.items():
        values[name] = float(math.exp(rng.uniform(math.log(lo), math.log(hi))) if kind == "loguniform"
                             else rng.uniform(lo, hi))
    return State(**values)


def variant(spec, fields: dict):
    from matcad.design.solve import with_fields

    return with_fields(spec, fields)


def truth_f0(spec, state, level: int) -> tuple[float, bool]:
    """The built taxel's f0 by the coupled elastic-cap + air FEM (Hz), and whether one of the cap's in-vacuo modes
    (same FEM) lies within the hybridisation band of it (a doublet: two resonances compete)."""
    from matcad.acoustics import fem, fsi
    from matcad.acoustics.design import design, speed_of_sound
    from matcad.prediction.asbuilt import built
    from matcad.prediction.measurements import f0_hz

    b = built(design(spec), state)
    shear, loss = b.wall.dynamic_moduli_pa()[1], b.wall.loss_factors()[1]
    guess = f0_hz(design(spec), state, "elastic_wall")  # where the FEM's search starts
    run = fsi.solve(fem.geometry(b), fsi.cap(b, shear, loss), guess, level, speed_of_sound(b.air))
    return run.f0_hz, any(abs(m / run.f0_hz - 1) <= HYBRID_BAND for m in run.wall_modes_hz)


def truth_load(spec, state, f0: float, forces, level: int) -> list[float]:
    """f at ``forces`` (N): FElupe at the hidden static modulus, the rigid FEM on each deformed cavity (Hz)."""
    from matcad.acoustics.design import design
    from matcad.mechanics.case import cap_case
    from matcad.mechanics.frequency import at_forces, force_curve
    from matcad.mechanics.solver import cap_curve
    from matcad.prediction.asbuilt import built

    case = cap_case(spec)
    case = dataclasses.replace(case, material=case.material.scaled(state.static_modulus_scale),
                               displacement_mm=min(3.0, 0.9 * (case.section.height - case.section.flange_thickness)))
    curve = cap_curve(case)
    fc = force_curve(built(design(spec), state), curve, f0, fem_level=level)
    return [row[1] for row in at_forces(fc, forces)]


def lab(seed: int, level: int, load: bool, designs=DESIGNS) -> dict:
    """One lab: its hidden state, the measured taxel (as its [[measured]] entry), and each of ``designs``' truth
    and predictions."""
    from matcad import spec as spec_mod
    from matcad.prediction import predict
    from matcad.spec.measured import Measured

    rng = np.random.default_rng(seed)
    state = hidden_state(rng)
    base = dataclasses.replace(spec_mod.load(TEMPLATE), calibration=None, reference=None)
    t0 = time.perf_counter()
    f_meas, _ = truth_f0(base, state, level)
    entry = {"name": "built1", "f0_hz": f_meas + rng.normal(0, NOISE_HZ), "f0_tolerance_hz": NOISE_HZ}
    if load:
        fs = truth_load(base, state, f_meas, LOAD_FORCES_N, level)
        entry |= {"force_n": (0.0, *LOAD_FORCES_N),
                  "f_hz": tuple(f + rng.normal(0, NOISE_HZ) for f in (f_meas, *fs))}
    # as a spec file would hold it: the entry's drawing filled from the spec as loaded
    measured = spec_mod.from_dict(spec_mod.to_dict(dataclasses.replace(base, measured=(Measured(**entry),))))
    rows = []
    for fields in designs:
        s = variant(measured, fields)
        truth, hybrid = truth_f0(variant(base, fields), state, level)
        p = predict(s, mechanics=False)
        rows.append({"design": fields, "truth_hz": truth, "hybrid": hybrid, "as_built_hz": p.f0_hz,
                     "band_hz": list(p.band_hz),
                     "physics_hz": p.physics_f0_hz, "model": p.model,
                     "as_built_error": p.f0_hz / truth - 1, "physics_error": p.physics_f0_hz / truth - 1,
                     "inside": bool(p.band_hz[0] <= truth <= p.band_hz[1])})
    from matcad.prediction.inference import infer

    inference = infer(measured)
    recovered = {name: {"hidden": getattr(state, name), "low": lo, "high": hi, "inside": bool(lo <= getattr(state, name) <= hi)}
                 for name, _, lo, hi in inference.intervals()}
    return {"seed": seed, "level": level, "load": load, "hidden": dataclasses.asdict(state),
            "measured_f0_hz": f_meas, "measured": entry, "rows": rows, "recovered": recovered,
            "seconds": time.perf_counter() - t0}


def _errors(rows: list[dict], what: str) -> str:
    if not rows:
        return "none"
    ab = np.array([abs(r["as_built_error"]) for r in rows])
    ph = np.array([abs(r["physics_error"]) for r in rows])
    inside = np.array([r["inside"] for r in rows])
    return (f"{what}: {len(rows)} predictions\n"
            f"    |error| as built (anchored): median {100 * np.median(ab):.2f} %, 90th pct "
            f"{100 * np.percentile(ab, 90):.2f} %, max {100 * ab.max():.2f} %; within 2 %: "
            f"{100 * np.mean(ab <= 0.02):.0f} %\n"
            f"    |error| physics only:        median {100 * np.median(ph):.2f} %, 90th pct "
            f"{100 * np.percentile(ph, 90):.2f} %, max {100 * ph.max():.2f} %\n"
            f"    coverage of the anchored 95 % band: {100 * inside.mean():.1f} % ({inside.sum()}/{len(inside)})")


def summary(labs: list[dict]) -> str:
    rows = [r for lab_ in labs for r in lab_["rows"]]
    lines = [f"{len(labs)} labs x {len(DESIGNS)} designs (FEM level {labs[0]['level']}, "
             f"{'f0 + f(F)' if labs[0]['load'] else 'f0 only'} of one measured taxel)",
             "  " + _errors([r for r in rows if not r["hybrid"]], "clear (no cap mode within 15 % of the FEM's f)"),
             "  " + _errors([r for r in rows if r["hybrid"]], "hybridised (a cap mode within 15 %: a doublet)"),
             "  " + _errors(rows, "all")]
    for name in ("neck_offset_mm", "side_volume_mm3", "static_modulus_scale"):
        hits = [lab_["recovered"][name]["inside"] for lab_ in labs]
        lines.append(f"  hidden {name} inside its 95 % interval: {sum(hits)}/{len(hits)}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--labs", type=int, default=5)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--level", type=int, default=4, help="FEM elements across the neck radius")
    ap.add_argument("--load", action="store_true", help="the measured taxel's f(F) too")
    ap.add_argument("--json", type=Path, help="write every lab's rows here")
    args = ap.parse_args()
    labs = []
    for seed in range(args.first_seed, args.first_seed + args.labs):
        one = lab(seed, args.level, args.load)
        labs.append(one)
        ab = max(abs(r["as_built_error"]) for r in one["rows"])
        ph = max(abs(r["physics_error"]) for r in one["rows"])
        print(f"lab {seed}: hidden neck {one['hidden']['neck_offset_mm']:+.3f} mm, air "
              f"{one['hidden']['side_volume_mm3']:.1f} mm^3, G x{one['hidden']['static_modulus_scale']:.2f}, kHz "
              f"x{one['hidden']['khz_modulus_scale']:.2f}: max |error| as built {100 * ab:.2f} %, physics "
              f"{100 * ph:.2f} %, inside {sum(r['inside'] for r in one['rows'])}/{len(one['rows'])} "
              f"({one['seconds']:.0f} s)", flush=True)
        if args.json:
            args.json.parent.mkdir(parents=True, exist_ok=True)
            args.json.write_text(json.dumps(labs, indent=1))
    print(summary(labs))


if __name__ == "__main__":
    main()
