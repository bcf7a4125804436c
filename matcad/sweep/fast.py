"""The closed-form rungs on arrays of variants: f0, validity checks, the uncertainty band and df0/dfield, each in a
few numpy calls. These are the registered models (:mod:`matcad.acoustics.registry`), their checks
(:mod:`matcad.acoustics.checks`) and the uncertainty budget (:mod:`matcad.acoustics.uncertainty`) evaluated on a
:class:`~matcad.acoustics.design.Design` whose fields are arrays: the same code `matcad predict` runs on one
variant, so the numbers are the same (tested to 1e-9 relative on random variants).

Inputs are a dict of arrays keyed by dotted spec field (:data:`FIELDS`; lengths mm, angles deg, temperature °C,
speed of sound m/s, NaN where the spec leaves it to the temperature) and what the variants share (the neck's mouth,
the wall material, how they are made). The closed forms read no cap: its fields are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matcad.acoustics import checks, registry, uncertainty
from matcad.acoustics.design import Air, Design, Making, WallMaterial, gap_radius_mm
from matcad.acoustics.evaluation import Evaluation

VECTORISED = tuple(m.name for m in registry.MODELS if m.cheap and "rigid" in m.walls)
"""The registered rungs that are closed forms of the geometry alone (no wall, no reference, no FEM): lumped,
end_corrected, transmission_line."""
FIELDS = ("cavity.diameter", "cavity.length", "neck.diameter", "neck.length", "mold.draft_deg", "air.temperature_c",
          "air.speed_of_sound", "spacer.height", "plate.width", "plate.depth")
"""The spec fields the closed-form rungs read; df0/dfield of any other field is exactly 0 for them."""
CHUNK = 16_384
"""Variants per numpy pass: arrays that stay in cache (measured ~2x faster than one 1e6 pass)."""
RELATIVE_STEP = 1e-6
"""Central-difference step of :func:`sensitivity`, relative to the field's value (at least 1e-6 of its unit)."""
NO_CAP = float("nan")


@dataclass(frozen=True)
class Variants:
    """Arrays of the :data:`FIELDS` (one entry per variant), how each variant is made (a :class:`Making` of
    arrays) and what every variant shares: the neck's mouth and the wall material (the closed forms ignore it)."""

    values: dict[str, np.ndarray]
    mouth: str
    wall: WallMaterial
    making: Making

    def __len__(self) -> int:
        return len(self.values["cavity.diameter"])

    def part(self, start: int, stop: int) -> Variants:
        """Variants ``start:stop``."""
        m = self.making
        making = Making(m.neck_drilled[start:stop], m.sheet_measured[start:stop], m.printer[start:stop])
        return Variants({k: x[start:stop] for k, x in self.values.items()}, self.mouth, self.wall, making)

    def with_value(self, field: str, array) -> Variants:
        return Variants({**self.values, field: np.asarray(array, dtype=float)}, self.mouth, self.wall, self.making)

    def design(self) -> Design:
        """The variants as one :class:`Design` of arrays."""
        x = self.values
        return Design(cavity_diameter=x["cavity.diameter"], cavity_length=x["cavity.length"],
                      draft_deg=x["mold.draft_deg"], neck_diameter=x["neck.diameter"], neck_length=x["neck.length"],
                      mouth=self.mouth, gap_mm=x["spacer.height"],
                      gap_radius_mm=gap_radius_mm(x["plate.width"], x["plate.depth"]), cap_outer_diameter=NO_CAP,
                      cap_top_thickness=NO_CAP, cap_clamp_height=NO_CAP,
                      air=Air(x["air.temperature_c"], x["air.speed_of_sound"]), wall=self.wall, making=self.making)


def from_specs(specs) -> Variants:
    """The arrays of validated specs that share one ``neck.mouth``."""
    from matcad.acoustics.design import design

    mouths = {s.neck.mouth for s in specs}
    if len(mouths) != 1:
        raise ValueError(f"variants must share one neck.mouth, got {sorted(mouths)}")

    def get(spec, key):
        section, name = key.split(".")
        value = getattr(getattr(spec, section), name)
        return np.nan if value is None else value

    values = {key: np.array([get(s, key) for s in specs], dtype=float) for key in FIELDS}
    made = [design(s).making for s in specs]
    making = Making(np.array([m.neck_drilled for m in made]), np.array([m.sheet_measured for m in made]),
                    np.array([m.printer for m in made]))
    return Variants(values, mouths.pop(), design(specs[0]).wall, making)


def _chunked(function, v: Variants, *columns):
    """``function(variants, *columns)`` chunk by chunk of :data:`CHUNK` variants (columns: per-variant arrays),
    its array results joined."""
    if len(v) <= CHUNK:
        return function(v, *columns)
    parts = [function(v.part(i, i + CHUNK), *(c[i:i + CHUNK] for c in columns)) for i in range(0, len(v), CHUNK)]
    if isinstance(parts[0], tuple):
        return tuple(np.concatenate(p) for p in zip(*parts))
    return np.concatenate(parts)


def _model(model: str):
    if model not in VECTORISED:
        raise ValueError(f"model {model!r} is not vectorised, must be one of {list(VECTORISED)}")
    return registry.model(model)


def f0_hz(v: Variants, model: str) -> np.ndarray:
    """f0 (Hz) of every variant by one of :data:`VECTORISED` (paper Eq. 1; Rayleigh/Ingard; Selamet 1997)."""
    m = _model(model)
    return _chunked(lambda part: np.asarray(m.f0_hz(Evaluation(part.design()).res), dtype=float), v)


def valid(v: Variants, model: str, f0) -> np.ndarray:
    """The model's validity checks (:mod:`matcad.acoustics.checks`) per variant: True where all pass."""
    m = _model(model)

    def chunk(part, f):
        results = checks.evaluate(m.checks, Evaluation(part.design()), np.asarray(f))
        return np.logical_and.reduce([np.asarray(r, dtype=bool) for r in results.values()])

    return _chunked(chunk, v, np.asarray(f0, dtype=float))


def band_hz(v: Variants, model: str, f0, ok) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) band edges (Hz): the uncertainty budget of ``model`` (:func:`matcad.acoustics.uncertainty.budget`)
    on the arrays, ``ok`` the variants whose checks pass (:func:`valid`), combined root-sum-square in ln f."""
    _model(model)

    def chunk(part, f, good):
        d = part.design()
        lines = uncertainty.budget(d, Evaluation(d).res, model, f, good)
        low, high = uncertainty.combine([x.low_hz for x in lines], [x.high_hz for x in lines], f)
        return f + low, f + high

    return _chunked(chunk, v, np.asarray(f0, dtype=float), np.asarray(ok))


def sensitivity(v: Variants, model: str, field: str) -> np.ndarray:
    """df0/dfield per variant (Hz per the field's unit: Hz/mm for lengths) by a central difference of the
    vectorised model, step :data:`RELATIVE_STEP` × the value; exactly 0 for a field the model does not read."""
    if field not in v.values:
        return np.zeros(len(v))
    x = v.values[field]
    h = RELATIVE_STEP * np.maximum(np.abs(x), 1.0)
    return (f0_hz(v.with_value(field, x + h), model) - f0_hz(v.with_value(field, x - h), model)) / (2 * h)
