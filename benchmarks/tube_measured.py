"""The tube's air column against measured tubes (issue 26; docs/tube.md, "Against published measurements"): a
closed-open cylinder, and two fipple whistles (:data:`WHISTLES`, their window against measurement).

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
    :data:`LENGTH_MM` (bore + the cap's cavity of one diameter), 20 °C. Its wall is not stated: the template's
    1.2 mm is kept (no wall to 2 mm moves f1 by 0.06 %)."""
    from matcad.spec import load, to_dict

    data = to_dict(load(TEMPLATE))
    bore = 2 * radius_mm
    data["tube"].update(bore_diameter=bore, length=LENGTH_MM - bore, cap_depth=bore, mouth="unflanged")
    data["wall"] = {"model": "rigid"}
    data["air"] = {"temperature_c": TEMPERATURE_C}
    data["end_cap"]["outer_diameter"] = 2 * bore
    return data


def transfer_matrix_peak_hz(radius_mm: float, near_hz: float, delta_mm: float) -> float:
    """The |Z| maximum (Hz) at the closed end of the lossy line near ``near_hz``: Z_in = Z_c (Z_r cos kL + i Z_c sin
    kL) / (Z_c cos kL + i Z_r sin kL), k and Z_c from Zwikker & Kosten's ρ_eff = ρ / (1 − F_v) and
    C_eff = (1 + (γ − 1) F_t) / ρc², the radiation Z_r = Z_c0 (i k₀ δ + (k₀a)²/4) (the end's mass, ``delta_mm``, and
    Levine & Schwinger's resistance)."""
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
        zr = 1j * k0 * delta_mm / 1e3 + (k0 * a) ** 2 / 4
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
                    "matrix": transfer_matrix_peak_hz(radius_mm, f, tube.mouth_correction_mm(td))})
    return out


WHISTLES = {
    "Feadog Mk 1": {"bore": 12.0, "length": 265.5, "window": (5.2, 8.2, 2.9, 1.8), "flange": 12.0,
                    "holes": ((117.5, 5.0, 0.35), (138.0, 6.6, 0.35), (161.0, 5.6, 0.35), (183.5, 5.7, 0.35),
                              (201.0, 7.7, 0.35), (226.5, 6.9, 0.35)), "measured": (560.0, 600.0)},
    "BP8": {"bore": 11.9, "length": 269.0, "window": (5.9, 7.4, 4.0, 1.8), "flange": 15.9,
            "holes": ((123.0, 4.76, 2.0), (144.0, 5.56, 2.0), (162.5, 5.56, 2.0), (188.0, 4.76, 2.0),
                      (205.0, 6.35, 2.0), (229.0, 6.35, 2.0)), "measured": (568.0, 585.0)},
}
"""Two fipple whistles measured with every hole closed (WWIDesigner v2.6.0, github.com/edwardkort/WWIDesigner,
GPL-3.0: ``releases/2/WhistleStudy/instruments/FeadogMk1.xml`` with ``tunings/FeadogMk1-tuning.xml``, "untweaked",
a brass tube; ``src/test/com/wwidesigner/optimization/example/BP8-partial.xml`` with ``BP8-partial-tuning.xml``, a PVC
whistle under construction). mm: a cylindrical bore, the column from the window's edge to the open foot, the
window (its length W along the bore, width B, depth = the wall, the windway's height), the foot's outer diameter,
each closed hole (position from the edge, diameter, chimney height); measured (Hz): the softest and hardest
speaking pitch, the hardest WWIDesigner's resonance. No temperature is stated: 20 °C taken (+0.17 %/°C)."""


def whistle_design(w: dict):
    """A whistle as a fipple tube's design (matcad.acoustics.tube.TubeDesign: its window, bore and air), 20 °C."""
    from matcad.acoustics import tube
    from matcad.spec import from_dict, load, to_dict

    data = to_dict(load(TEMPLATE))
    length_w, width, depth, windway = w["window"]
    data["tube"].update(bore_diameter=w["bore"], length=w["length"], edge_distance=length_w, windway_width=width,
                        wall=depth, windway_height=windway, cap_depth=0.5, mouth="fipple")
    data["wall"], data["air"] = {"model": "rigid"}, {"temperature_c": TEMPERATURE_C}
    data["end_cap"]["outer_diameter"] = 2 * w["bore"]
    return tube.tube_design(from_dict(data))


def whistle_hz(w: dict, window_factor: float = 1.0) -> float:
    """The whistle's first resonance (Hz) with matcad's fipple window (Rayleigh's aperture, × ``window_factor``),
    its foot's end (matcad's unflanged end of the tube's wall, (flange − bore)/2) and the bore's boundary layers: the
    lossless open-open line with each closed hole's chimney as a side branch (i tan(k h) S_h/S, admittance per the
    bore's), the window's mass in series at the edge, written here; then matcad's boundary layers."""
    from scipy.optimize import brentq

    from matcad.acoustics import tube

    td = whistle_design(w)
    a = w["bore"] / 2
    window = window_factor * tube.mouth_correction_mm(td)
    foot = tube.wall_end_correction((w["flange"] - w["bore"]) / 2 / a) * a
    c = tube.speed_of_sound(td.air) * 1e3

    def reactance(f):  # Z/(i Z_c) at the edge, looking to the foot, plus the window's mass: zero at resonance
        k = 2 * math.pi * f / c
        z, x = 1j * k * foot, w["length"]
        for pos, diameter, height in sorted(w["holes"], reverse=True) + [(0.0, 0.0, 0.0)]:
            cs, sn = math.cos(k * (x - pos)), math.sin(k * (x - pos))
            z, x = (z * cs + 1j * sn) / (1j * z * sn + cs), pos
            if diameter:
                z = 1 / (1 / z + 1j * math.tan(k * height) * diameter**2 / w["bore"] ** 2)
        return (z + 1j * k * window).imag

    guess = c / (2 * (w["length"] + window + foot))
    return tube.boundary_layer_hz(td, brentq(reactance, 0.8 * guess, 1.2 * guess))


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
    print("\nFipple whistles, every hole closed, open foot, 20 °C (WWIDesigner's measured tunings)")
    print("| whistle | measured (Hz) | matcad (Hz) | error vs the top | window's δ × 0.8 | × 1.45 |")
    print("|---|---|---|---|---|---|")
    for name, w in WHISTLES.items():
        top = w["measured"][1]
        f, low, high = (whistle_hz(w, factor) for factor in (1.0, 0.8, 1.45))
        print(f"| {name} | {w['measured'][0]:g}-{top:g} | {f:.1f} | {f / top - 1:+.2%} | {low / top - 1:+.2%} | "
              f"{high / top - 1:+.2%} |")


if __name__ == "__main__":
    main()
