"""A lab's as-built state: what the drawing cannot know of the taxels one lab builds, as named parameters with
priors, and how a state turns a drawn design into the built one. Lengths mm, volumes mm³, moduli as factors.

The parameters are shared by every taxel a lab builds the same way (one laser, one sheet stock, one stack, one
silicone batch): the neck cut wider or narrower than drawn, its taper, the sheet thicker or thinner than its
nominal, air joined to the cavity that the cavity's walls do not hold (gaps in the stack, the guide's clearance),
the silicone's modulus at kHz over the grade's and its static modulus over the grade's. Each has a prior from the
shop tolerances of docs/physics.md (the sources are in :data:`PARAMETERS`); the data of measured taxels move them
(:mod:`matcad.prediction.inference`). A state applies to a :class:`~matcad.acoustics.design.Design` for the
acoustics (:func:`built`) and to a cap curve for the mechanics (:func:`built_curve`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

NECK_OFFSET_SD_MM = {"laser": 0.15, "drilled": 0.03}
"""Prior sd of the neck's diameter as cut minus as drawn: a CO₂ laser's kerf is 0.15–0.25 mm full width and a
hole cut on its drawn line comes out that much wider unless compensated (DIGEST: 2.1 → ~2.3 mm); a drilled pilot
holds a few hundredths."""
NECK_TAPER_SD_MM = {"laser": 0.1, "drilled": 0.02}
"""Prior sd of the neck's taper (mouth minus cavity-side diameter): a laser beam diverges through a thick sheet."""
SIDE_VOLUME_PER_CAVITY = 1.0
"""Prior scale of the air joined to the cavity, in units of the cavity's own volume (half-normal): the paper's
taxel needs 0.7–1.3 cavities of it to explain its f0 (docs/paper.md); no lab should need more than ~2."""
KHZ_FACTOR_SD = 0.25
"""Prior sd of ln(kHz modulus factor / the grade's geometric-mean factor): the grade's range is ±2 sd."""
STATIC_MODULUS_SD = math.log(2.0) / 2
"""Prior sd of ln(static modulus / the grade's): a silicone's G is uncertain by ~2× (DIGEST, Dragon Skin 30)."""
MODEL_ERROR_SIGMAS = 2.0
"""A model's max |error| against the FEM (model_errors.json) is taken as this many sd of its error."""
MEASUREMENT_SD = {"neck_diameter": 0.02, "neck_taper": 0.03, "sheet": 0.02}
"""sd (mm) of a neck measured with pin gauges (both faces), of its taper, and of a calipered sheet."""


@dataclass(frozen=True)
class Parameter:
    """One as-built unknown: its name and unit, what it is, and its prior: a ``normal`` (centre + sd·z), a
    ``lognormal`` (centre·exp(sd·z)) or a ``halfnormal`` (sd·z, z ≥ 0) in the standard coordinate z."""

    name: str
    unit: str
    doc: str
    kind: str
    prior: Callable  # (spec) -> (centre, sd)

    def value(self, z, centre: float, sd: float):
        """The parameter at standard coordinate ``z`` (scalar or array)."""
        if self.kind == "lognormal":
            return centre * np.exp(sd * np.asarray(z))
        if self.kind == "halfnormal":
            return sd * np.asarray(z)
        return centre + sd * np.asarray(z)

    @property
    def lower_z(self) -> float:
        """The smallest standard coordinate the parameter allows."""
        return 0.0 if self.kind == "halfnormal" else -np.inf


def _making(spec) -> str:
    return "drilled" if spec.plate.neck_pilot else "laser"


def _cavity_volume(spec) -> float:
    from matcad.acoustics.geometry import drafted_cavity_volume_mm3

    return float(drafted_cavity_volume_mm3(spec.cavity.diameter, spec.cavity.length, spec.mold.draft_deg))


def _sheet_sd(spec) -> float:
    from matcad.acoustics.design import design
    from matcad.acoustics.uncertainty import fabrication_tolerances

    d = design(spec)
    return fabrication_tolerances(d.making, d.neck_length)[1] / 2


PARAMETERS = (
    Parameter("neck_offset_mm", "mm", "neck diameter as cut minus as drawn (kerf, an undersize drill)", "normal",
              lambda spec: (0.0, NECK_OFFSET_SD_MM[_making(spec)])),
    Parameter("neck_taper_mm", "mm", "neck diameter at the mouth minus at the cavity (a laser's taper)", "normal",
              lambda spec: (0.0, NECK_TAPER_SD_MM[_making(spec)])),
    Parameter("sheet_offset_mm", "mm", "neck sheet as built minus its nominal thickness (half the ISO 7823-1 "
              "tolerance, or of a calipered sheet's)", "normal", lambda spec: (0.0, _sheet_sd(spec))),
    Parameter("side_volume_mm3", "mm^3", "air joined to the cavity that its walls do not hold (gaps in the stack, "
              "the guide's clearance around the cap)", "halfnormal",
              lambda spec: (0.0, SIDE_VOLUME_PER_CAVITY * _cavity_volume(spec))),
    Parameter("khz_modulus_scale", "", "silicone's modulus at kHz over the grade's (geometric-mean kHz factor)",
              "lognormal", lambda spec: (1.0, KHZ_FACTOR_SD)),
    Parameter("static_modulus_scale", "", "silicone's static modulus over the grade's (the cap mechanics' and "
              "the wall's)", "lognormal", lambda spec: (1.0, STATIC_MODULUS_SD)),
)
"""Every as-built unknown, in the order of a state's vector."""
NAMES = tuple(p.name for p in PARAMETERS)


@dataclass(frozen=True)
class State:
    """One as-built state: each parameter of :data:`PARAMETERS` by name (their units)."""

    neck_offset_mm: float = 0.0
    neck_taper_mm: float = 0.0
    sheet_offset_mm: float = 0.0
    side_volume_mm3: float = 0.0
    khz_modulus_scale: float = 1.0
    static_modulus_scale: float = 1.0

    def vector(self) -> np.ndarray:
        return np.array([getattr(self, n) for n in NAMES])


def priors(spec) -> np.ndarray:
    """(centre, sd) of every parameter's prior for the lab that builds ``spec`` (rows in :data:`NAMES` order)."""
    return np.array([p.prior(spec) for p in PARAMETERS], dtype=float)


def state_at(z, prior: np.ndarray) -> State:
    """The :class:`State` at standard coordinates ``z`` under ``prior`` (:func:`priors`)."""
    return State(*(float(p.value(zi, c, s)) for p, zi, (c, s) in zip(PARAMETERS, z, prior)))


NECK_MIN_FRACTION = 0.2
"""A built neck keeps at least this fraction of its drawn diameter, however far a state moves it."""


def built(d, state: State):
    """The :class:`~matcad.acoustics.design.Design` ``d`` as built in ``state``: neck diameter and taper, sheet,
    joined air, and the silicone's moduli (the wall's static range times the static scale, its kHz factor times the
    kHz scale)."""
    wall = d.wall
    wall = dataclasses.replace(
        wall, shear_modulus_mpa=tuple(g * state.static_modulus_scale for g in wall.shear_modulus_mpa),
        khz_modulus_factor=tuple(k * state.khz_modulus_scale for k in wall.khz_modulus_factor))
    return d.replace(neck_diameter=max(d.neck_diameter + state.neck_offset_mm, NECK_MIN_FRACTION * d.neck_diameter),
                     neck_taper_mm=state.neck_taper_mm,
                     neck_length=max(d.neck_length + state.sheet_offset_mm, NECK_MIN_FRACTION * d.neck_length),
                     side_volume_mm3=state.side_volume_mm3, wall=wall)


def built_curve(curve, state: State):
    """A cap curve (:class:`~matcad.mechanics.solver.CapCurve`) of the grade's silicone for the state's: forces
    times the static scale (:meth:`~matcad.mechanics.solver.CapCurve.scaled`)."""
    return curve.scaled(state.static_modulus_scale)
