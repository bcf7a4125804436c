"""The closed-form rungs on arrays of variants: f0, validity checks, the uncertainty band and df0/dfield in one
numpy call each, the same numbers as :func:`matcad.acoustics.predict.predict` one variant at a time (tested to
1e-9 relative on random variants).

Inputs are a dict of arrays keyed by dotted spec field (:data:`FIELDS`; lengths mm, angles deg, temperature °C,
speed of sound m/s, NaN where the spec leaves it to the temperature). The band is
:mod:`matcad.acoustics.uncertainty`'s budget evaluated line by line on the arrays: model error (model_errors.json),
neck diameter, sheet, cavity diameter, draft and temperature tolerances, boundary layers; root-sum-square in ln f.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matcad.acoustics import models, registry, uncertainty
from matcad.acoustics.air import boundary_layer_shift, speed_of_sound_m_s
from matcad.acoustics.predict import (LUMPED_END_CORRECTION_RATIO, LUMPED_NECK_AIR_RATIO, PANCAKE_L_OVER_D,
                                      PLANE_WAVE_CUTOFF_KA)
from matcad.acoustics.resonator import as_built, evaluate

VECTORISED = tuple(m.name for m in registry.MODELS if m.cheap and "rigid" in m.walls)
"""The registered rungs that are closed forms of the geometry alone (no wall, no reference, no FEM): lumped,
end_corrected, transmission_line."""
FIELDS = ("cavity.diameter", "cavity.length", "neck.diameter", "neck.length", "mold.draft_deg", "air.temperature_c",
          "air.speed_of_sound", "spacer.height", "plate.width", "plate.depth")
"""The spec fields the closed-form rungs read; df0/dfield of any other field is exactly 0 for them."""
CHUNK = 16_384
"""Variants per numpy pass in :func:`f0_hz`: arrays that stay in cache (measured ~2x faster than one 1e6 pass)."""
RELATIVE_STEP = 1e-6
"""Central-difference step of :func:`sensitivity`, relative to the field's value (at least 1e-6 of its unit)."""


@dataclass(frozen=True)
class Variants:
    """Arrays of the :data:`FIELDS` (one entry per variant), the per-variant tolerances of the budget (mm) and
    the neck mouth they share."""

    values: dict[str, np.ndarray]
    neck_diameter_tol: np.ndarray
    sheet_tol: np.ndarray
    cavity_diameter_tol: np.ndarray
    mouth: str

    def __len__(self) -> int:
        return len(self.values["cavity.diameter"])

    def part(self, start: int, stop: int) -> "Variants":
        """Variants ``start:stop``."""
        return Variants({k: x[start:stop] for k, x in self.values.items()}, self.neck_diameter_tol[start:stop],
                        self.sheet_tol[start:stop], self.cavity_diameter_tol[start:stop], self.mouth)

    def with_value(self, field: str, array) -> "Variants":
        return Variants({**self.values, field: np.asarray(array, dtype=float)}, self.neck_diameter_tol,
                        self.sheet_tol, self.cavity_diameter_tol, self.mouth)


def from_specs(specs) -> Variants:
    """The arrays of validated specs that share one ``neck.mouth`` (a sweep varies numbers only)."""
    mouths = {s.neck.mouth for s in specs}
    if len(mouths) != 1:
        raise ValueError(f"variants must share one neck.mouth, got {sorted(mouths)}")

    def get(spec, key):
        section, name = key.split(".")
        value = getattr(getattr(spec, section), name)
        return np.nan if value is None else value

    values = {key: np.array([get(s, key) for s in specs], dtype=float) for key in FIELDS}
    d_tol = np.array([uncertainty.NECK_DIAMETER_TOL_MM["drilled" if s.plate.neck_pilot else "laser"] for s in specs])
    sheet = np.array([uncertainty.sheet_tolerance_mm(s.neck.length, s.plate.thickness_measured) for s in specs])
    cav_tol = np.array([uncertainty.CAVITY_DIAMETER_TOL_MM[s.machine.printer] for s in specs])
    return Variants(values, d_tol, sheet, cav_tol, mouths.pop())


def speed_of_sound(v: Variants) -> np.ndarray:
    """c per variant (m/s): air.speed_of_sound where given, else from air.temperature_c."""
    given = v.values["air.speed_of_sound"]
    return np.where(np.isnan(given), speed_of_sound_m_s(v.values["air.temperature_c"]), given)


def resonators(v: Variants):
    """:func:`matcad.acoustics.resonator.as_built` on the arrays (a Resonator of arrays)."""
    x = v.values
    return as_built(speed_of_sound(v), x["cavity.diameter"], x["cavity.length"], x["neck.diameter"], x["neck.length"],
                    x["mold.draft_deg"], v.mouth, x["spacer.height"], np.minimum(x["plate.width"], x["plate.depth"]) / 2)


def f0_hz(v: Variants, model: str) -> np.ndarray:
    """f0 (Hz) of every variant by one of :data:`VECTORISED` (paper Eq. 1; Rayleigh/Ingard; Selamet 1997)."""
    if model not in VECTORISED:
        raise ValueError(f"model {model!r} is not vectorised, must be one of {list(VECTORISED)}")
    if len(v) > CHUNK:
        return np.concatenate([f0_hz(v.part(i, i + CHUNK), model) for i in range(0, len(v), CHUNK)])
    return np.asarray(evaluate(resonators(v), model), dtype=float)


def valid(v: Variants, model: str, f0) -> np.ndarray:
    """predict's validity checks of ``model`` per variant (True where all pass): lumped neck (A·l/V), end
    corrections ≪ l, Ingard's ξ < 0.4, plane waves in the cavity (k·D/2 < 1.8412) and L/D ≥ 0.3."""
    res = resonators(v)
    air_ratio = res.neck_area * res.neck_length / res.volume
    if model == "lumped":
        return (air_ratio < LUMPED_NECK_AIR_RATIO) & \
            ((res.outer_correction + res.inner_step) / res.neck_length < LUMPED_END_CORRECTION_RATIO)
    if model == "end_corrected":
        return (air_ratio < LUMPED_NECK_AIR_RATIO) & (np.sqrt(res.neck_area / res.cavity_area) < models.INGARD_XI_LIMIT)
    k = 2 * np.pi * np.asarray(f0) / (res.c_m_s * models.MM_PER_M)
    return (k * res.cavity_diameter / 2 < PLANE_WAVE_CUTOFF_KA) & (res.cavity_length / res.cavity_diameter
                                                                    >= PANCAKE_L_OVER_D)


def band_hz(v: Variants, model: str, f0, ok) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) band edges (Hz): :func:`matcad.acoustics.uncertainty.budget` line by line on the arrays: the
    model's measured error (``ok`` is :func:`valid`), each tolerance moved to both of its
    :func:`~matcad.acoustics.uncertainty.tolerance_ends`, boundary layers; combined root-sum-square in ln f by
    :func:`~matcad.acoustics.uncertainty.combine`."""
    f0 = np.asarray(f0, dtype=float)
    x = v.values
    lows, highs = [], []
    error = uncertainty.model_errors().get(model)
    if error is not None:
        worst = uncertainty.model_error_share(error, ok)
        lows.append(-worst * f0)
        highs.append(worst * f0)
    ends = uncertainty.tolerance_ends(x["neck.diameter"], x["neck.length"], x["cavity.diameter"], x["cavity.length"],
                                      x["mold.draft_deg"], x["air.temperature_c"], v.neck_diameter_tol, v.sheet_tol,
                                      v.cavity_diameter_tol)
    by_temperature = np.isnan(x["air.speed_of_sound"])  # an explicit speed of sound has no temperature line
    for field, (low_end, high_end) in ends.items():
        fs = [f0_hz(v.with_value(field, end), model) - f0 for end in (low_end, high_end)]
        applies = by_temperature if field == "air.temperature_c" else True
        lows.append(np.where(applies, np.minimum(np.minimum(*fs), 0.0), 0.0))
        highs.append(np.where(applies, np.maximum(np.maximum(*fs), 0.0), 0.0))
    eps = boundary_layer_shift(f0, x["neck.diameter"] / 2)
    lows.append(-eps / (1.0 + eps) * f0)
    low, high = uncertainty.combine(lows, highs, f0)
    return f0 + low, f0 + high


def sensitivity(v: Variants, model: str, field: str) -> np.ndarray:
    """df0/dfield per variant (Hz per the field's unit: Hz/mm for lengths) by a central difference of the
    vectorised model, step :data:`RELATIVE_STEP` × the value; exactly 0 for a field the model does not read."""
    if field not in v.values:
        return np.zeros(len(v))
    x = v.values[field]
    h = RELATIVE_STEP * np.maximum(np.abs(x), 1.0)
    return (f0_hz(v.with_value(field, x + h), model) - f0_hz(v.with_value(field, x - h), model)) / (2 * h)
