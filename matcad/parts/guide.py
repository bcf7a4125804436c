"""Laser-cut guides (paper: 1.5 mm acrylic) that hold the end cap concentric with the neck.

The locator surrounds the cap's base flange; the clamp lies over the flange with a hole for the cap body, and
the bolts press it down so the flange (guide thickness + squeeze) seals against the plate.
"""

import functools

from matcad.parts.features import laser_stack_holes, sheet_kerf_mm
from matcad.parts.flat import Flat, Hole, edge_label
from matcad.parts.labels import place_labels
from matcad.parts.neck_plate import taxel_keepout
from matcad.parts.registry import Kind, Part
from matcad.spec import cap_flange_diameter_mm

BODY_CLEARANCE_MM = 0.2
"""Diametral clearance of the clamp's hole around the silicone body, so clamping does not pinch the cavity."""
ROLES = ("locator", "clamp")


def cap_holes(board, role: str) -> tuple[Hole, ...]:
    """Guide layer ``role``'s hole for every taxel's cap, at the taxel's position: the locator around its flange
    (:func:`cap_flange_diameter_mm`), the clamp around its body (outer diameter +
    :data:`BODY_CLEARANCE_MM`) (mm)."""
    if role == "locator":
        return tuple(Hole(t.x, t.y, cap_flange_diameter_mm(t), "cap", taxel=t.name) for t in board)
    if role == "clamp":
        return tuple(Hole(t.x, t.y, t.end_cap.outer_diameter + BODY_CLEARANCE_MM, "cap", taxel=t.name)
                     for t in board)
    raise ValueError(f"role {role!r} invalid, must be one of {ROLES}")


def guide(spec, role: str) -> Flat:
    """Guide layer ``role`` ('locator' or 'clamp'): same outline and stack holes as the neck plate, one cap hole
    per taxel, its edge label and, on a board, each cap hole's taxel name beside it, outside the flange (mm)."""
    from matcad.spec import taxels

    board = taxels(spec)
    holes = (*cap_holes(board, role), *laser_stack_holes(spec))
    label = edge_label(f"{role.upper()} {spec.guide.thickness:g}", spec.plate.width, spec.plate.depth, holes)
    if len(board) > 1:
        label += place_labels([(t.name, t.x, t.y) for t in board], taxel_keepout(board, holes), spec.plate.width,
                              spec.plate.depth, taken=label)
    return Flat(name=f"guide_{role}", thickness=spec.guide.thickness,
                thickness_measured=spec.guide.thickness_measured, thickness_example=spec.guide.thickness_example,
                sheet="guide", kerf=sheet_kerf_mm(spec, "guide"), width=spec.plate.width,
                depth=spec.plate.depth, holes=holes, engrave=label)

PARTS = (Part("guide_locator", Kind.LASER, flag="guides", make=functools.partial(guide, role="locator"), order=20,
              colour="#c4e0fa", sheet="guide", label="locator guide"),
         Part("guide_clamp", Kind.LASER, flag="guides", make=functools.partial(guide, role="clamp"), order=30,
              colour="#c4e0fa", sheet="guide", label="clamp guide"))
