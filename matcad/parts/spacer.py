"""Spacers between the neck plate and the needle mount (paper: 1.59 mm tall), one per bolt."""

from matcad.parts.features import bolt_clearance_mm, plate_bolt_positions_mm, sheet_kerf_mm
from matcad.parts.flat import Flat, Hole
from matcad.parts.registry import Kind, Part


def spacer(spec) -> Flat:
    """Square laser-cut spacer, spacer.size wide, sheet thickness = spacer.height, one bolt hole; one per bolt."""
    bolt = bolt_clearance_mm(spec.fasteners.bolt, spec.fasteners.bolt_fit)
    return Flat(name="spacer", thickness=spec.spacer.height, thickness_measured=spec.spacer.thickness_measured,
                thickness_example=spec.spacer.thickness_example, sheet="spacer", kerf=sheet_kerf_mm(spec, "spacer"),
                width=spec.spacer.size, depth=spec.spacer.size,
                holes=(Hole(0.0, 0.0, bolt, "bolt", spec.fasteners.bolt_fit),),
                quantity=len(plate_bolt_positions_mm(spec)), corner_radius=0.5)


def is_laser_cut(spec) -> bool:
    """Whether the spacers are laser-cut parts (else they are standoffs printed on the needle mount)."""
    return spec.spacer.style == "laser"


PARTS = (Part("spacer", Kind.LASER, flag="spacers", make=spacer, order=40, colour="#d8d0f8", sheet="spacer",
              when=is_laser_cut),)
