"""Specs made from a validated spec: the reference taxel's spec and unvalidated model variants. Lengths in mm.

Both take and return a :class:`matcad.spec.model.Spec` (duck-typed: the Spec's own checks call
:func:`reference_spec`, so this module cannot import it).
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any

from matcad.spec.drawn import drawn_spec


def reference_spec(spec):
    """The reference taxel of ``spec``'s [reference] as a whole spec: this design with the reference's geometry."""
    return drawn_spec(spec, spec.reference, reference=None)


def calibrated_spec(spec):
    """The taxel ``spec``'s [calibration] was measured on, as a whole spec: this design with the calibration's
    drawn geometry (filled at load from the spec as loaded, :func:`matcad.spec.drawn.filled`)."""
    return drawn_spec(spec, spec.calibration)


def variant(spec, section: str, **values: Any):
    """A model variant of a validated spec (uncertainty budgets, sweeps): ``values`` set in ``section`` without
    input validation, because a perturbation may step past what a user may write (a 1 µm neck less its sheet
    tolerance, 10.5° of draft). Never use it for user input; ``dataclasses.replace`` validates."""
    part = getattr(spec, section)
    names = {f.name for f in dataclasses.fields(part)}
    unknown = set(values) - names
    if unknown:
        raise TypeError(f"{section} has no field {', '.join(sorted(unknown))}")
    part = copy.copy(part)
    for name, value in values.items():
        object.__setattr__(part, name, value)
    out = copy.copy(spec)
    object.__setattr__(out, section, part)
    return out
