"""The acoustic model registry: every rung of the prediction ladder as an object, cheapest first, in one place.

An :class:`AcousticModel` carries everything the rest of matcad asks of a model: its name and rung (cost order,
measured by benchmarks/error_vs_runtime.py), the wall models it serves, whether it solves a mesh (scikit-fem,
seconds: evaluated only when asked for), its source, its f0 function (named ``"module:function"`` and imported only
when called, so reading the registry imports neither scikit-fem nor numpy), the validity checks it depends on
(:mod:`matcad.acoustics.checks`, each with its warning text) and its error measured against the converged FEM
(model_errors.json). :func:`matcad.acoustics.predict.predict`, the uncertainty budget, `matcad predict --model`,
sweeps (the closed forms on arrays of variants) and the error benchmark all loop over :data:`MODELS`; adding a rung
is one entry here plus its f0 function and its measured error (a test asks every model for one).
"""

from __future__ import annotations

import functools
import importlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable


@dataclass(frozen=True)
class ModelResult:
    """One rung evaluated: f0 (Hz), its validity checks (name → passed) and its source."""

    f0_hz: float
    checks: dict[str, bool]
    source: str

    @property
    def valid(self) -> bool:
        return all(self.checks.values())


@dataclass(frozen=True)
class AcousticModel:
    """One rung (see the module docstring). ``wall`` says which silicone modulus its f0 takes: '' none (rigid
    walls), 'static' the static shear modulus, 'dynamic' the kHz storage modulus and the loss factor, each at the
    middle of the spec's range. ``describe`` (``"module:function"`` of (evaluation, f0) → text) words the source
    with the numbers of one evaluation; without it the source is ``source``. ``branch`` (``"module:function"`` of the
    same arguments as ``evaluate`` → :class:`matcad.acoustics.resonator.Branch`): its f0 is a peak, and these are the
    peaks it was found from, which a nearby design follows rather than searching again (``near`` of
    :meth:`f0_hz`)."""

    name: str
    rung: int
    walls: tuple[str, ...]
    needs_skfem: bool
    evaluate: str
    source: str
    checks: tuple[str, ...] = ()
    wall: str = ""
    describe: str | None = None
    branch: str | None = None

    @property
    def follows(self) -> bool:
        """Whether its f0 is a peak that a nearby design can follow (it declares its ``branch``)."""
        return self.branch is not None

    @property
    def cheap(self) -> bool:
        """A closed form on the resonator (µs-ms, vectorised): evaluated on every prediction."""
        return not self.needs_skfem

    def function(self) -> Callable:
        """The evaluation function (imported now)."""
        return _load(self.evaluate)

    def wall_arguments(self, material) -> tuple:
        """The (shear modulus Pa, loss factor) this model's f0 takes from a
        :class:`matcad.acoustics.design.WallMaterial`: the middle of its static or kHz range, or none."""
        if self.wall == "dynamic":
            return material.dynamic_moduli_pa()[1], material.loss_factors()[1]
        if self.wall == "static":
            return material.static_moduli_pa()[1], 0.0
        return None, 0.0

    def f0_hz(self, res, material=None, shear_modulus_pa=None, loss_factor=None, near=None):
        """f0 (Hz) of a closed-form rung on a resonator (floats, or arrays of variants; the wall rungs also at arrays
        of moduli and loss factors), at the middle of ``material``'s ranges unless a modulus (Pa) and loss factor
        are given. ``near`` (:class:`matcad.acoustics.resonator.Branch`: the peaks of designs these were moved a
        little from) is followed by a rung that ``follows``; a closed form has nothing to follow."""
        if not self.cheap:
            raise ValueError(f"model {self.name!r} solves a mesh: evaluate it through its result()")
        if shear_modulus_pa is None and material is not None:
            shear_modulus_pa, loss_factor = self.wall_arguments(material)
        follow = {"near": near} if self.follows and near is not None else {}
        return self.function()(res, shear_modulus_pa, 0.0 if loss_factor is None else loss_factor, **follow)

    def branch_of(self, res, material=None):
        """The :class:`matcad.acoustics.resonator.Branch` of a rung that ``follows``, as :meth:`f0_hz` takes its
        arguments (its f0 with the peaks it was found from, one search of each)."""
        shear_modulus_pa, loss_factor = self.wall_arguments(material) if material is not None else (None, 0.0)
        return _load(self.branch)(res, shear_modulus_pa, loss_factor)

    def result(self, ev, f_guess_hz: float | None = None, level: int | None = None) -> ModelResult:
        """This rung on one :class:`matcad.acoustics.evaluation.Evaluation`: f0 (Hz), checks, source. A mesh rung
        starts its search at ``f_guess_hz`` with ``level`` elements across the neck radius."""
        if self.needs_skfem:
            return self.function()(ev.design, ev.res.c_m_s, f_guess_hz, level)
        from matcad.acoustics import checks

        f0 = float(self.f0_hz(ev.res, ev.design.wall))
        source = _load(self.describe)(ev, f0) if self.describe else self.source
        return ModelResult(f0, checks.evaluate(self.checks, ev, f0), source)

    @property
    def error(self) -> dict | None:
        """Its relative error against the converged FEM (benchmarks/error_vs_runtime.py), None before measured."""
        return model_errors().get(self.name)


def _load(path: str) -> Callable:
    module, name = path.split(":")
    return getattr(importlib.import_module(module), name)


PLANE = ("plane_waves_in_cavity", "not_pancake")
MODELS: tuple[AcousticModel, ...] = (
    AcousticModel("lumped", 1, ("rigid", "silicone"), False, "matcad.acoustics.resonator:lumped_hz",
                  "paper Eq. 1 with c_f = 0 (Helmholtz/Rayleigh)", ("neck_air_ratio_small", "end_corrections_small")),
    AcousticModel("end_corrected", 2, ("rigid", "silicone"), False, "matcad.acoustics.resonator:end_corrected_hz",
                  "Eq. 1 with l + the mouth's outer correction + Ingard 1953 inner correction",
                  ("neck_air_ratio_small", "ingard_xi_below_0.4"),
                  describe="matcad.acoustics.evaluation:describe_end_corrected"),
    AcousticModel("transmission_line", 3, ("rigid", "silicone"), False,
                  "matcad.acoustics.resonator:transmission_line_hz",
                  "Selamet et al. 1997 transmission line, Kergomard & Garcia 1987 step correction", PLANE),
    AcousticModel("soft_wall", 4, ("silicone",), False, "matcad.acoustics.resonator:soft_wall_hz",
                  "transmission line with a quasi-static (massless) silicone wall (Lame cylinder + half-space end)",
                  PLANE + ("quasi_static_wall",), "static", "matcad.acoustics.evaluation:describe_soft_wall"),
    AcousticModel("elastic_wall", 5, ("silicone",), False, "matcad.acoustics.resonator:elastic_wall_hz",
                  "transmission line coupled to the cap's wall modes (from the coupled FEM's elastic operator, "
                  "wall_modes.json)", PLANE + ("wall_shape_in_table", "no_wall_mode_near_f"), "dynamic",
                  "matcad.acoustics.evaluation:describe_elastic_wall",
                  "matcad.acoustics.resonator:elastic_wall_branch"),
    AcousticModel("fem", 6, ("rigid", "silicone"), True, "matcad.acoustics.fem_model:fem_result",
                  "axisymmetric P2 FEM (scikit-fem); with silicone the elastic cap coupled to the air"),
)
"""Every acoustic model, in rung order."""
CHOSEN = {"rigid": "transmission_line", "silicone": "elastic_wall"}
"""The model `predict` chooses for each ``wall.model`` (the cheapest whose measured error is small for that wall)."""
DERIVED = {"relative": "the [reference] taxel's measured f0 times the chosen model's ratio (this design / "
                       "reference)",
           "calibration": "the taxel's own [calibration]: Eq. 5 f(0) at the air's temperature",
           "as_built": "the lab state inferred from the [[measured]] taxels (`matcad infer`), this design built in it"}
"""Choices of ``predict --model`` that are not models of their own: anchors to measurements (the last two are made
in :mod:`matcad.prediction.anchor`)."""


def model(name: str) -> AcousticModel:
    """The registered model called ``name``."""
    for m in MODELS:
        if m.name == name:
            return m
    raise ValueError(f"model {name!r} invalid, must be one of {model_names()}")


def serving(wall: str) -> list[AcousticModel]:
    """The models that serve ``wall`` ('rigid' or 'silicone'), cheapest first."""
    return [m for m in sorted(MODELS, key=lambda m: m.rung) if wall in m.walls]


def model_names() -> list[str]:
    """Every model's name, cheapest first."""
    return [m.name for m in sorted(MODELS, key=lambda m: m.rung)]


def cheap_models() -> tuple[str, ...]:
    """The closed-form models, cheapest first."""
    return tuple(m.name for m in sorted(MODELS, key=lambda m: m.rung) if m.cheap)


def model_choices() -> list[str]:
    """What ``predict --model`` accepts: every model and the derived choices."""
    return model_names() + list(DERIVED)


@functools.cache
def model_errors() -> dict:
    """Relative model errors against the converged FEM, as measured by benchmarks/error_vs_runtime.py."""
    return json.loads((Path(__file__).parent / "model_errors.json").read_text(encoding="utf-8"))
