"""Laser-cut guides (paper: 1.5 mm acrylic) that hold the end cap concentric with the neck.

The locator surrounds the cap's base flange; the clamp lies over the flange with a hole for the cap body, and
the bolts press it down so the flange (guide thickness + squeeze) seals against the plate.
"""

import functools

from matcad.parts.features import cap_flange_diameter_mm, laser_stack_holes, sheet_kerf_mm
from matcad.parts.flat import Flat, Hole, edge_label
from matcad.parts.registry import Kind, Part

BODY_CLEARANCE_MM = 0.2
"""Diametral clearance of the clamp's hole around the silicone body, so clamping does not pinch the cavity."""
ROLES = ("locator", "clamp")


def guide(spec, role: str) -> Flat:
    """Guide layer ``role`` ('locator' or 'clamp'): same outline and stack holes as the neck plate (mm)."""
    if role == "locator":
        cap_hole = Hole(0.0, 0.0, cap_flange_diameter_mm(spec), "cap")
    elif role == "clamp":
        cap_hole = Hole(0.0, 0.0, spec.end_cap.outer_diameter + BODY_CLEARANCE_MM, "cap")
    else:
        raise ValueError(f"role {role!r} invalid, must be one of {ROLES}")
    holes = (cap_hole, *laser_stack_holes(spec))
    return Flat(name=f"guide_{role}", thickness=spec.guide.thickness,
                thickness_measured=spec.guide.thickness_measured, kerf=sheet_kerf_mm(spec, "guide"),
                width=spec.plate.width,
                depth=spec.plate.depth, holes=holes,
                engrave=edge_label(f"{role.upper()} {spec.guide.thickness:g}", spec.plate.width, spec.plate.depth,
                                   holes))


PARTS = (Part("guide_locator", Kind.LASER, flag="guides", make=functools.partial(guide, role="locator"), order=20,
              colour="#c4e0fa", sheet="guide", label="locator guide"),
         Part("guide_clamp", Kind.LASER, flag="guides", make=functools.partial(guide, role="clamp"), order=30,
              colour="#c4e0fa", sheet="guide", label="clamp guide"))
