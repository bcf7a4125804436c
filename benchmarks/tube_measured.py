"""The tube's air column against a measured tube (issue 26; docs/tube.md, "Against published measurements").

The measurement: the input impedance of a 436 mm cylinder of 1.95 mm inner radius (2 mm in another of the
authors' scripts), measured at 20 °C at one end with its far end open and unflanged (Ernoult, Chabassier,
Rodriguez & Humeau, "Full waveform inversion for bore reconstruction of woodwind-like instruments", Acta Acustica
5 (2021) 47, hal-03231946; two measurements, shipped with INRIA's openwind as
``examples/Ernoult-Chabassier-Rodriguez_Humeau_2021/Impedances/Impedance_20degC_Measure_Cyl_436mm.txt`` and
``examples/inversion/Impedance_20degC_MeasureCyl_L436mm_R2mm.txt``). An impedance maximum at the measured end is a
resonance of the tube closed there and open at the far end: a closed-open column with an unflanged mouth, a
rigid cap, exactly `kind = "tube"` with ``mouth = "unflanged"``. :data:`MEASURED_HZ` are its first four maxima read
from the two files: the quadratic fit of |Z| around each maximum and the Im Z = 0 crossing there (±12 Hz fits of
the 1 Hz grid), the lowest and highest of the four readings per mode.

Printed per mode: the measured range, the line without and with the bore's boundary layers (matcad's tube, spec in
:func:`spec_data`), and a second route with the layers: the peak of |Z| at the closed end of the lossy transfer
matrix (Zwikker & Kosten's effective density and compressibility, the unflanged end's mass and radiation
resistance (ka)²/4), written here apart from the package. A narrow, long tube: the layers are ~6 % of f1 here
against ~1 % on the tube template, and the end correction ~0.3 %.

Run: PYTHONPATH=. python benchmarks/tube_measured.py
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "templates" / "acoustac-tube.toml"
LENGTH_MM = 436.0
RADII_MM = (1.95, 2.0)
"""The cylinder's inner radius: 1.95 mm in the authors' comparison script, 2 mm in their inversion example."""
TEMPERATURE_C = 20.0
MEASURED_HZ = ((184.8, 186.3), (569.7, 571.2), (956.4, 959.8), (1344.9, 1348.7))
"""(lowest, highest) of the four readings of modes 1-4 (Hz): |Z| maximum and Im Z = 0, two measurements."""


def spec_data(radius_mm: float) -> dict:
    """The measured cylinder as a tube spec: the template with a rigid cap, an unflanged mouth, the column of
    :data:`LENGTH_MM` (bore + the cap's cavity of one diameter), 20 °C."""
    from matcad.spec import load, to_dict

    data = to_dict(load(TEMPLATE))
    bore = 2 * radius_mm
    data["tube"].update(bore_diameter=bore, length=LENGTH_MM - bore, cap_depth=bore, mouth="unflanged")
    data["wall"] = {"model": "rigid"}
    data["air"] = {"temperature_c": TEMPERATURE_C}
    data["end_cap"]["outer_diameter"] = 2 * bore
    return data


def transfer_matrix_peak_hz(radius_mm: float, near_hz: float) -> float:
    """The |Z| maximum (Hz) at the closed end of the lossy line near ``near_hz``: Z_in = Z_c (Z_r cos kL + i Z_c sin
    kL) / (Z_c cos kL + i Z_r sin kL), k and Z_c from Zwikker & Kosten's ρ_eff = ρ / (1 − F_v) and
    C_eff = (1 + (γ − 1) F_t) / ρc², the radiation Z_r = Z_c0 (i k₀ 0.6133 a + (k₀a)²/4) (Levine & Schwinger)."""
    from scipy.optimize import minimize_scalar
    from scipy.special import jve

    from matcad.acoustics.air import GAMMA, KINEMATIC_VISCOSITY_M2_S, PRANDTL, speed_of_sound_m_s

    a, length, c = radius_mm / 1e3, LENGTH_MM / 1e3, float(speed_of_sound_m_s(TEMPERATURE_C))

    def bessel_ratio(r):
        z = r * np.sqrt(-1j)
        return 2 * jve(1, z) / (z * jve(0, z))

    def minus_abs_z(f):
        w = 2 * math.pi * f
        r_v = a * math.sqrt(w / KINEMATIC_VISCOSITY_M2_S)
        density = 1 / (1 - bessel_ratio(r_v))  # ρ_eff / ρ
        compressibility = 1 + (GAMMA - 1) * bessel_ratio(r_v * math.sqrt(PRANDTL))  # C_eff ρc²
        k0 = w / c
        k, zc = k0 * np.sqrt(density * compressibility), np.sqrt(density / compressibility)
        zr = 1j * k0 * 0.6133 * a + (k0 * a) ** 2 / 4
        return -abs(zc * (zr * np.cos(k * length) + 1j * zc * np.sin(k * length))
                    / (zc * np.cos(k * length) + 1j * zr * np.sin(k * length)))

    return float(minimize_scalar(minus_abs_z, bounds=(0.97 * near_hz, 1.03 * near_hz), method="bounded",
                                 options={"xatol": 1e-6}).x)


def rows(radius_mm: float) -> list[dict]:
    """Per mode: measured (lo, hi), the lossless and the lossy line, the lossy transfer matrix's peak (Hz)."""
    import dataclasses

    from matcad.acoustics import tube
    from matcad.spec import from_dict

    td = tube.tube_design(from_dict(spec_data(radius_mm)))
    lossless = dataclasses.replace(td, boundary_layers=False)
    out = []
    for mode, measured in enumerate(MEASURED_HZ, start=1):
        f = tube.line_hz(td, mode=mode)
        out.append({"mode": mode, "measured": measured, "lossless": tube.line_hz(lossless, mode=mode), "line": f,
                    "matrix": transfer_matrix_peak_hz(radius_mm, f)})
    return out


def main() -> None:
    print(f"A {LENGTH_MM:g} mm cylinder closed at one end, open and unflanged at the other, {TEMPERATURE_C:g} °C; "
          "measured by Ernoult et al. 2021 (Acta Acustica 5:47)")
    for radius in RADII_MM:
        print(f"\ninner radius {radius} mm")
        print("| mode | measured (Hz) | line, lossless | error | line + boundary layers | error | lossy transfer "
              "matrix, |Z| max | line - matrix |")
        print("|---|---|---|---|---|---|---|---|")
        for r in rows(radius):
            mid = sum(r["measured"]) / 2
            print(f"| {r['mode']} | {r['measured'][0]:.1f}-{r['measured'][1]:.1f} | {r['lossless']:.1f} | "
                  f"{r['lossless'] / mid - 1:+.2%} | {r['line']:.1f} | {r['line'] / mid - 1:+.2%} | "
                  f"{r['matrix']:.1f} | {r['line'] / r['matrix'] - 1:+.2%} |")


if __name__ == "__main__":
    main()
