"""The closed-form rungs on arrays of variants: f0, validity checks, the uncertainty band and df0/dfield, each in a
few numpy calls. These are the registered models (:mod:`matcad.acoustics.registry`), their checks
(:mod:`matcad.acoustics.checks`) and the uncertainty budget (:mod:`matcad.acoustics.uncertainty`) evaluated on a
:class:`~matcad.acoustics.design.Design` whose fields are arrays: the same code `matcad predict` runs on one
variant, each entry the same arithmetic, so the numbers are the same (tested equal on random variants).

Inputs are a dict of arrays keyed by dotted spec field (:data:`FIELDS`; lengths mm, angles deg, temperature °C,
speed of sound m/s — NaN where the spec leaves it to the temperature —, density g/cm³) and what the variants
share (the neck's mouth, the wall material, how they are made).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from matcad.acoustics import checks, registry, uncertainty
from matcad.acoustics.design import Air, Design, Making, WallMaterial, gap_radius_mm
from matcad.acoustics.evaluation import Evaluation
from matcad.acoustics.resonator import Branch

VECTORISED = tuple(m.name for m in registry.MODELS if m.cheap)
"""The registered rungs that are closed forms of the design (no FEM): lumped, end_corrected, transmission_line and
the silicone wall models soft_wall and elastic_wall."""
FIELDS = ("cavity.diameter", "cavity.length", "neck.diameter", "neck.length", "mold.draft_deg", "air.temperature_c",
          "air.speed_of_sound", "spacer.height", "plate.width", "plate.depth", "end_cap.outer_diameter",
          "end_cap.top_thickness", "guide.thickness", "end_cap.flange_squeeze", "silicone.density_g_cm3")
"""The spec fields the closed-form rungs read (the cap's and the silicone's only through the wall models);
df0/dfield of any other field is exactly 0."""
CHUNK = 16_384
"""Variants per numpy pass of the rigid rungs: arrays that stay in cache (measured ~2x faster than one 1e6 pass)."""
RELATIVE_STEP = 1e-6
"""Central-difference step of :func:`sensitivity`, relative to the field's value (at least 1e-6 of its unit)."""


@dataclass(frozen=True)
class Variants:
    """Arrays of the :data:`FIELDS` (one entry per variant), how each variant is made (a :class:`Making` of
    arrays) and what every variant shares: the neck's mouth and the wall material (its density per variant)."""

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

    def take(self, rows) -> Variants:
        """The variants at index ``rows``."""
        m = self.making
        making = Making(m.neck_drilled[rows], m.sheet_measured[rows], m.printer[rows])
        return Variants({k: x[rows] for k, x in self.values.items()}, self.mouth, self.wall, making)

    def with_value(self, field: str, array) -> Variants:
        return Variants({**self.values, field: np.asarray(array, dtype=float)}, self.mouth, self.wall, self.making)

    def design(self) -> Design:
        """The variants as one :class:`Design` of arrays."""
        x = self.values
        return Design(cavity_diameter=x["cavity.diameter"], cavity_length=x["cavity.length"],
                      draft_deg=x["mold.draft_deg"], neck_diameter=x["neck.diameter"], neck_length=x["neck.length"],
                      mouth=self.mouth, gap_mm=x["spacer.height"],
                      gap_radius_mm=gap_radius_mm(x["plate.width"], x["plate.depth"]),
                      cap_outer_diameter=x["end_cap.outer_diameter"], cap_top_thickness=x["end_cap.top_thickness"],
                      cap_clamp_height=x["guide.thickness"] + x["end_cap.flange_squeeze"],
                      air=Air(x["air.temperature_c"], x["air.speed_of_sound"]),
                      wall=replace(self.wall, density_kg_m3=x["silicone.density_g_cm3"] * 1000.0), making=self.making)


def field_value(spec, key: str) -> float:
    """A resolved spec's value of one of the :data:`FIELDS` (NaN where the spec leaves it unset)."""
    section, name = key.split(".")
    value = getattr(getattr(spec, section), name)
    return np.nan if value is None else value


def from_specs(specs) -> Variants:
    """The arrays of validated specs that share one ``neck.mouth`` and one wall material."""
    from matcad.acoustics.design import design

    mouths = {s.neck.mouth for s in specs}
    if len(mouths) != 1:
        raise ValueError(f"variants must share one neck.mouth, got {sorted(mouths)}")
    values = {key: np.array([field_value(s, key) for s in specs], dtype=float) for key in FIELDS}
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


def f0_hz(v: Variants, model: str, near: Branch | None = None) -> np.ndarray:
    """f0 (Hz) of every variant by one of :data:`VECTORISED` (paper Eq. 1; Rayleigh/Ingard; Selamet 1997; the
    silicone wall at the middle of its modulus and loss ranges). ``near`` (per variant: the peaks of the variants
    these were moved a little from, :func:`branch`) lets a model that searches for its peak follow it from there."""
    m = _model(model)

    def chunk(part, *peaks):
        d = part.design()
        return np.asarray(m.f0_hz(Evaluation(d).res, d.wall, near=Branch(*peaks) if peaks else None), dtype=float)

    follow = near is not None and m.follows
    return _chunked(chunk, v, *((np.asarray(near.f0_hz, dtype=float), np.asarray(near.rigid_hz, dtype=float))
                                if follow else ()))


def branch(v: Variants, model: str) -> Branch:
    """The f0 (Hz) of every variant by ``model`` with, for a model that follows its peak, the peaks it was found
    from (:meth:`matcad.acoustics.registry.AcousticModel.branch_of`; else ``rigid_hz`` None): what moved variants
    follow. The same f0 as :func:`f0_hz`."""
    m = _model(model)
    if not m.follows:
        return Branch(f0_hz(v, model), None)

    def chunk(part):
        d = part.design()
        b = m.branch_of(Evaluation(d).res, d.wall)
        return np.asarray(b.f0_hz, dtype=float), np.asarray(b.rigid_hz, dtype=float)

    return Branch(*_chunked(chunk, v))


def failed_checks(v: Variants, model: str, f0) -> np.ndarray:
    """How many of the model's validity checks (:mod:`matcad.acoustics.checks`) fail, per variant (each failed
    check is one warning of `matcad predict`)."""
    m = _model(model)

    def chunk(part, f):
        results = checks.evaluate(m.checks, Evaluation(part.design()), np.asarray(f))
        return np.sum([~np.broadcast_to(np.asarray(r, dtype=bool), np.shape(f)) for r in results.values()], axis=0,
                      dtype=np.int64) if results else np.zeros(np.shape(f), dtype=np.int64)

    return _chunked(chunk, v, np.asarray(f0, dtype=float))


def valid(v: Variants, model: str, f0) -> np.ndarray:
    """The model's validity checks per variant: True where all pass."""
    return failed_checks(v, model, f0) == 0


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


def sensitivity(v: Variants, model: str, field: str, follows: dict | None = None, f0=None,
                near: Branch | None = None) -> np.ndarray:
    """df0/dfield per variant (Hz per the field's unit: Hz/mm for lengths) by a central difference of the
    vectorised model, step :data:`RELATIVE_STEP` × the value; exactly 0 for a field the model does not read.
    ``follows`` ({field: factor}) moves the fields whose default follows this one with it (the cap's size follows
    the cavity diameter); ``f0`` (variants → Hz), when given, is differentiated instead of the model's f0. A model
    that searches for its peak follows it (and the rigid network's peak its ratio divides by) from the variants' own
    (``near``, :func:`branch`; found when not given) to the moved variants' rather than searching again: the
    derivative of the branch the variant sings on."""
    if field not in v.values:
        return np.zeros(len(v))
    x = v.values[field]
    h = RELATIVE_STEP * np.maximum(np.abs(x), 1.0)

    def moved(value):
        out = v.with_value(field, value)
        for other, factor in (follows or {}).items():
            out = out.with_value(other, factor * value)
        return out

    if f0 is None:
        near = branch(v, model) if near is None else near

        def f0(moved_v):
            return f0_hz(moved_v, model, near=near)

    return (f0(moved(x + h)) - f0(moved(x - h))) / (2 * h)
