"""One cap mechanics run as a typed value, and the adapter that builds it from a spec. Lengths mm, moduli MPa.

The solver (:mod:`matcad.mechanics.solver`) and the f(F) route (:mod:`matcad.mechanics.frequency`) take a
:class:`CapCase`, never the spec; equal cases give equal curves, so a case is also the key under which a curve is
computed once and shared (a board's taxels with the same cap).
"""

from __future__ import annotations

from dataclasses import dataclass

from matcad.mechanics.material import Hyperelastic
from matcad.mechanics.section import CapSection


@dataclass(frozen=True)
class CapCase:
    """The cap's section, its hyperelastic law, the contact with the plate ('sticking' or 'frictionless'), the
    plate's travel (mm) in ``steps`` equal steps, and the mesh element size (mm; None: from the cap's thinnest
    part)."""

    section: CapSection
    material: Hyperelastic
    contact: str
    displacement_mm: float
    steps: int
    element_size_mm: float | None = None


def cap_case(spec) -> CapCase:
    """The cap mechanics run of a single-taxel ``spec`` with its [mechanics] choices and [silicone] grade. Raises
    SpecError when the plate travel does not fit above the clamp guide."""
    from matcad.mechanics.material import preset
    from matcad.mechanics.section import section_from_spec
    from matcad.spec import SpecError

    mech = spec.mechanics
    sec = section_from_spec(spec)
    free = sec.height - sec.flange_thickness
    if mech.displacement_mm >= free:
        raise SpecError("mechanics.displacement_mm", mech.displacement_mm,
                        f"must be < {free:.4g} mm, the cap's height above the clamp guide")
    return CapCase(sec, preset(mech.material, spec.silicone.grade, mech.shear_modulus_mpa), mech.contact,
                   mech.displacement_mm, mech.steps, mech.element_size_mm)
