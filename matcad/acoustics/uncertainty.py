"""Uncertainty budget of a prediction: one line per source, combined root-sum-square into the band (Hz).

Sources: the chosen model's own error (measured against the converged FEM by
benchmarks/error_vs_runtime.py, stored in model_errors.json), fabrication (neck diameter as cut or drilled,
sheet thickness per ISO 7823-1 unless measured, printed cavity diameter, core-pin draft), air temperature,
viscous/thermal boundary layers (one-sided: every model here is lossless) and the silicone's kHz modulus
(static range × kHz factor) and loss factor. Each line re-evaluates the chosen model (or, for the FEM, the cheap
model it refines) with that one input moved to the ends of its tolerance; the silicone line samples the whole
modulus × loss rectangle, because f is not monotonic in G when wall modes cross f. Lines are independent, so
lows and highs add in quadrature separately, in ln f (relative shifts), which keeps a wide band above zero.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from matcad.acoustics.air import boundary_layer_drop
import numpy as np

from matcad.acoustics.resonator import (CHEAP_MODELS, dynamic_moduli_pa, evaluate, loss_factors, resonator,
                                        shear_moduli_pa, wall_arguments)

NECK_DIAMETER_TOL_MM = {"laser": 0.1, "drilled": 0.02}
"""Laser-cut acrylic holds ±0.1 mm (docs/physics.md); a pilot drilled to size ±0.02 mm."""
MEASURED_SHEET_TOL_MM = 0.05
"""A calipered sheet."""
CAVITY_DIAMETER_TOL_MM = {"fdm": 0.1, "sla": 0.05}
DRAFT_TOL_DEG = 0.25
TEMPERATURE_TOL_C = 3.0
"""A lab's day-to-day swing; an explicit speed of sound is taken as exact."""
MODULUS_SAMPLES = 13
"""Log-spaced moduli across the silicone's range (each at the low and the high loss factor)."""


@dataclass(frozen=True)
class BudgetLine:
    """One source: what varies, by how much, and the f shift at each end (Hz, low ≤ 0 ≤ high)."""

    source: str
    tolerance: str
    low_hz: float
    high_hz: float


def sheet_tolerance_mm(thickness_mm: float, measured: bool) -> float:
    """± thickness tolerance of an acrylic sheet (mm): a calipered sheet :data:`MEASURED_SHEET_TOL_MM`, else cast
    sheet per ISO 7823-1, ±(0.4 + 0.1 t)."""
    return MEASURED_SHEET_TOL_MM if measured else 0.4 + 0.1 * thickness_mm


def model_errors() -> dict:
    """Relative model errors against the converged FEM, as measured by benchmarks/error_vs_runtime.py."""
    return json.loads((Path(__file__).parent / "model_errors.json").read_text(encoding="utf-8"))


def _replace(spec, section: str, **values):
    from matcad.spec import variant

    return variant(spec, section, **values)  # a perturbation may leave the user's ranges; it is not input


def tolerance_ends(neck_diameter, neck_length, cavity_diameter, cavity_length, draft_deg, temperature_c,
                   neck_diameter_tol, sheet_tol, cavity_diameter_tol) -> dict[str, tuple]:
    """The two ends of each fabrication and air tolerance, clamped to stay physical (mm, deg, °C; scalars or
    arrays of variants): {dotted field: (low end, high end)}. A neck smaller than its tolerance is a
    design-rule matter, so here it may at most halve; a sheet keeps 5 % of its thickness; the cavity stays at
    least the neck; draft stays within [0, 99 % of what closes the cavity]; air stays above -273 °C."""
    d, t, big_d = neck_diameter, neck_length, cavity_diameter
    max_draft = np.degrees(np.arctan(big_d / (2 * cavity_length))) * 0.99
    return {
        "neck.diameter": (np.maximum(d - neck_diameter_tol, d / 2), np.minimum(d + neck_diameter_tol, big_d)),
        "neck.length": (np.maximum(t - sheet_tol, 0.05 * t), t + sheet_tol),
        "cavity.diameter": (np.maximum(big_d - cavity_diameter_tol, d), big_d + cavity_diameter_tol),
        "mold.draft_deg": (np.maximum(draft_deg - DRAFT_TOL_DEG, 0.0), np.minimum(draft_deg + DRAFT_TOL_DEG,
                                                                                  max_draft)),
        "air.temperature_c": (np.maximum(temperature_c - TEMPERATURE_TOL_C, -273.0),
                              temperature_c + TEMPERATURE_TOL_C),
    }


def model_error_share(error: dict, valid):
    """The model's relative error for the band: its max |error| over the benchmark geometries where its checks
    pass, or over all of them where ``valid`` (bool or array) is False."""
    return np.where(valid, error["max_abs"], error.get("max_abs_all", error["max_abs"]))


def budget(spec, res, model: str, f0_hz: float, valid: bool = True) -> list[BudgetLine]:
    """Every source's contribution for ``model`` at ``f0_hz``; ``res`` is ``resonator(spec)``; ``valid`` False
    (the model's own checks fail) takes its error over every benchmark case, not only the valid ones."""
    cheap = model if model in CHEAP_MODELS else ("elastic_wall" if spec.wall.model == "silicone" else
                                                 "transmission_line")
    relative = model == "relative"
    wall = wall_arguments(spec, cheap)
    base = float(evaluate(res, cheap, *wall))
    scale = f0_hz / base  # sensitivities of the cheap model, applied to the chosen f0

    def shifts(variants):
        fs = [float(evaluate(resonator(v), cheap, *wall)) * scale - f0_hz for v in variants]
        return min(fs + [0.0]), max(fs + [0.0])

    lines = []
    error = model_errors().get(cheap if relative else model)
    if relative:
        ref = spec.reference
        share = error["ratio_max_abs"] if valid else error.get("ratio_max_abs_all", error["ratio_max_abs"])
        lines.append(BudgetLine("model ratio", f"{cheap}: max |error| of new/reference {100 * share:.2f} % vs FEM "
                                               f"over designs near the paper taxel"
                                               f"{'' if valid else ', checks failing included'}",
                                -share * f0_hz, share * f0_hz))
        lines.append(BudgetLine("reference measurement", f"{ref.f0_hz:g} +-{ref.f0_tolerance_hz:g} Hz",
                                -ref.f0_tolerance_hz / ref.f0_hz * f0_hz, ref.f0_tolerance_hz / ref.f0_hz * f0_hz))
    elif error is None:  # only before benchmarks/error_vs_runtime.py has measured a new rung
        lines.append(BudgetLine("model", f"{model}: error not measured yet (run benchmarks/error_vs_runtime.py)",
                                0.0, 0.0))
    else:
        worst, cases, where = float(model_error_share(error, valid)), error["cases"], "geometries where its checks pass"
        if not valid and "max_abs_all" in error:
            cases, where = error["of"], "geometries, checks failing included"
        lines.append(BudgetLine("model", f"{model}: max |error| {100 * worst:.2f} % vs FEM over {cases} {where}",
                                -worst * f0_hz, worst * f0_hz))
    drilled = spec.plate.neck_pilot
    d_tol = NECK_DIAMETER_TOL_MM["drilled" if drilled else "laser"]
    sheet_tol = sheet_tolerance_mm(spec.neck.length, spec.plate.thickness_measured)
    cav_tol = CAVITY_DIAMETER_TOL_MM[spec.machine.printer]
    ends = tolerance_ends(spec.neck.diameter, spec.neck.length, spec.cavity.diameter, spec.cavity.length,
                          spec.mold.draft_deg, spec.air.temperature_c, d_tol, sheet_tol, cav_tol)

    def moved(field):
        section, name = field.split(".")
        return shifts([_replace(spec, section, **{name: float(x)}) for x in ends[field]])

    what = "measured" if spec.plate.thickness_measured else "ISO 7823-1 cast sheet"
    lines += [BudgetLine("neck diameter", f"+-{d_tol:g} mm ({'drilled' if drilled else 'laser cut'})",
                         *moved("neck.diameter")),
              BudgetLine("neck length (sheet)", f"+-{sheet_tol:.3g} mm ({what})", *moved("neck.length")),
              BudgetLine("cavity diameter (core pin)", f"+-{cav_tol:g} mm ({spec.machine.printer})",
                         *moved("cavity.diameter")),
              BudgetLine("core-pin draft", f"{spec.mold.draft_deg:g} +-{DRAFT_TOL_DEG:g} deg", *moved("mold.draft_deg"))]
    if spec.air.speed_of_sound is None:
        lines.append(BudgetLine("air temperature", f"{spec.air.temperature_c:g} +-{TEMPERATURE_TOL_C:g} C",
                                *moved("air.temperature_c")))
    drop = boundary_layer_drop(f0_hz, spec.neck.diameter / 2)
    lines.append(BudgetLine("boundary layers", f"viscous + thermal, not in the lossless models: -{100 * drop:.1f} %",
                            -drop * f0_hz, 0.0))
    if cheap == "soft_wall":
        g_lo, _, g_hi = shear_moduli_pa(spec)
        fs = [float(evaluate(res, cheap, g)) * scale - f0_hz for g in (g_lo, g_hi)]
        lines.append(BudgetLine("silicone shear modulus", f"{g_lo / 1e6:g}-{g_hi / 1e6:g} MPa static",
                                min(fs + [0.0]), max(fs + [0.0])))
    elif cheap == "elastic_wall":
        g_lo, _, g_hi = dynamic_moduli_pa(spec)
        eta_lo, _, eta_hi = loss_factors(spec)
        fs = [float(evaluate(res, cheap, g, eta)) * scale - f0_hz
              for g in np.geomspace(g_lo, g_hi, MODULUS_SAMPLES) for eta in (eta_lo, eta_hi)]
        lines.append(BudgetLine("silicone modulus and loss",
                                f"G {g_lo / 1e6:.3g}-{g_hi / 1e6:.3g} MPa at kHz (static "
                                f"{spec.wall.shear_modulus_mpa[0]:g}-{spec.wall.shear_modulus_mpa[1]:g} x "
                                f"{spec.wall.khz_modulus_factor[0]:g}-{spec.wall.khz_modulus_factor[1]:g}), "
                                f"eta {eta_lo:g}-{eta_hi:g}", min(fs + [0.0]), max(fs + [0.0])))
    return lines


def total(lines: list[BudgetLine], f0_hz: float) -> tuple[float, float]:
    """Lows and highs combined root-sum-square in ln f, as offsets from ``f0_hz`` (Hz): the same as a plain
    root-sum-square of small shifts, and never below zero frequency when shifts are large."""
    low, high = combine([x.low_hz for x in lines], [x.high_hz for x in lines], f0_hz)
    return float(low), float(high)


def combine(lows, highs, f0_hz):
    """:func:`total` on shifts that may be arrays of variants (Hz): (low, high) offsets from ``f0_hz``."""
    def rss(shifts):
        return np.sqrt(sum(np.log1p(np.asarray(x) / f0_hz) ** 2 for x in shifts))

    return f0_hz * np.expm1(-rss(lows)), f0_hz * np.expm1(rss(highs))
