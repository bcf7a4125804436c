"""The acoustic model registry: every rung of the prediction ladder, cheapest first, in one place.

Each :class:`AcousticModel` names its evaluation function as ``"module:function"`` and it is imported only when
called, so reading the registry imports neither scikit-fem nor a CAD kernel. The cheap models' functions take
the as-built :class:`matcad.acoustics.resonator.Resonator` and return f0 (Hz); the FEM's takes the spec and
returns a :class:`matcad.acoustics.predict.ModelResult`. ``predict``, the uncertainty budget, the CLI's
``--model`` choices and benchmarks/error_vs_runtime.py all read this list; adding a rung is one entry here plus
its function (and its measured error in model_errors.json, which a test asks for).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class AcousticModel:
    """One rung: ``rung`` orders the ladder by cost (cheapest first; benchmarks/error_vs_runtime.py measures the
    run times), ``walls`` the ``wall.model`` values it is evaluated for, ``needs_skfem`` whether it solves a
    mesh (scikit-fem, seconds; only on ``--model``), ``source`` the equation or paper it implements."""

    name: str
    rung: int
    walls: tuple[str, ...]
    needs_skfem: bool
    evaluate: str
    source: str

    @property
    def cheap(self) -> bool:
        """A closed form on the resonator (µs-ms, vectorised): evaluated on every prediction."""
        return not self.needs_skfem

    def function(self) -> Callable:
        """The evaluation function (imported now)."""
        module, name = self.evaluate.split(":")
        return getattr(importlib.import_module(module), name)


MODELS: tuple[AcousticModel, ...] = (
    AcousticModel("lumped", 1, ("rigid", "silicone"), False, "matcad.acoustics.resonator:lumped_hz",
                  "paper Eq. 1 with c_f = 0 (Helmholtz/Rayleigh)"),
    AcousticModel("end_corrected", 2, ("rigid", "silicone"), False, "matcad.acoustics.resonator:end_corrected_hz",
                  "Eq. 1 with l + the mouth's outer correction + Ingard 1953 inner correction"),
    AcousticModel("transmission_line", 3, ("rigid", "silicone"), False,
                  "matcad.acoustics.resonator:transmission_line_hz",
                  "Selamet et al. 1997 transmission line, Kergomard & Garcia 1987 step correction"),
    AcousticModel("soft_wall", 4, ("silicone",), False, "matcad.acoustics.resonator:soft_wall_hz",
                  "transmission line with a quasi-static (massless) silicone wall (Lame cylinder + half-space end)"),
    AcousticModel("elastic_wall", 5, ("silicone",), False, "matcad.acoustics.resonator:elastic_wall_hz",
                  "transmission line coupled to the cap's wall modes (from the coupled FEM's elastic operator, "
                  "wall_modes.json)"),
    AcousticModel("fem", 6, ("rigid", "silicone"), True, "matcad.acoustics.predict:fem_result",
                  "axisymmetric P2 FEM (scikit-fem); with silicone the elastic cap coupled to the air"),
)
"""Every acoustic model, in rung order."""
DERIVED = {"relative": "the [reference] taxel's measured f0 times the chosen model's ratio (this design / "
                       "reference)"}
"""Choices of ``predict --model`` that are not models of their own."""


def model(name: str) -> AcousticModel:
    """The registered model called ``name``."""
    for m in MODELS:
        if m.name == name:
            return m
    raise ValueError(f"model {name!r} invalid, must be one of {model_names()}")


def model_names() -> list[str]:
    """Every model's name, cheapest first."""
    return [m.name for m in sorted(MODELS, key=lambda m: m.rung)]


def cheap_models() -> tuple[str, ...]:
    """The closed-form models, cheapest first."""
    return tuple(m.name for m in sorted(MODELS, key=lambda m: m.rung) if m.cheap)


def model_choices() -> list[str]:
    """What ``predict --model`` accepts: every model and the derived choices."""
    return model_names() + list(DERIVED)
