"""Build matcad/acoustics/wall_modes.json: the silicone cap's in-vacuo wall modes over a grid of cap shapes,
from the coupled FEM's elastic operator (matcad.acoustics.fsi.unit_cap_modes), for the fast elastic-wall model.

Shapes are scaled by the cavity radius a: outer radius b/a, top thickness T/a, cavity length L/a and the
clamped fraction of the cavity height; each entry holds, at a = 1 mm, G = 1 MPa, ρ = 1000 kg/m³, the first
modes' frequencies (Hz), their volume compliances (mm³/Pa) and the static volume compliance (mm³/Pa).
Run: .venv/bin/python benchmarks/wall_modes_table.py (1 200 shapes, about 6.5 minutes on one core).
"""

from __future__ import annotations

import itertools
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from matcad.acoustics import fsi  # noqa: E402
from matcad.acoustics.wall import TABLE_AXES, TABLE_PATH  # noqa: E402


def main():
    t0 = time.perf_counter()
    axes = [TABLE_AXES[name] for name in ("outer", "top", "length", "clamp_fraction")]
    freqs, comps, static = [], [], []
    for outer, top, length, clamp in itertools.product(*axes):
        modes = fsi.unit_cap_modes(outer, top, length, clamp)
        freqs.append([float(f"{f:.5g}") for f in modes.frequencies_hz])
        comps.append([float(f"{c:.5g}") for c in modes.compliances_mm3_pa])
        static.append(float(f"{modes.static_mm3_pa:.6g}"))
    data = {"about": "cap wall modes at a = 1 mm, G = 1 MPa, rho = 1000 kg/m3; built by "
                     "benchmarks/wall_modes_table.py", "fem_level": fsi.TABLE_LEVEL,
            "axes": {k: list(v) for k, v in TABLE_AXES.items()},
            "frequencies_hz": freqs, "compliances_mm3_pa": comps, "static_mm3_pa": static}
    TABLE_PATH.write_text(json.dumps(data, separators=(",", ":")) + "\n", encoding="utf-8")
    print(f"{len(static)} shapes in {time.perf_counter() - t0:.0f} s -> {TABLE_PATH}")


if __name__ == "__main__":
    main()
