"""Printed air-supply mount: holds the needle at θ and y under the neck (paper Fig. 2), below a spacer gap.

Assembly frame (shared with every part): plate underside z = 0, neck axis = z axis. The mount's top face is
at z = −spacer.height and it is ``mount.thickness`` thick. Bolts from the stack thread into self-tapping
pilots; dowels press into it; with ``spacer.style = "standoff"`` the spacers are printed on it, and with
``plate.support_posts`` the support posts under the plate (:func:`matcad.parts.features.plate_post_positions_mm`),
exactly the gap tall: the press only ever pushes the plate down onto them, so they carry compression and need no
fastening.
"""

import math

from matcad.parts.features import (EAR_THICKNESS_MM, EAR_WIDTH_MM, FIXING_BOLT, SELF_TAP_PILOT_MM, bolt_clearance_mm,
                                   ear_holes_mm, needle_axis_mm, needle_tip_mm, pin_hole_diameter_mm,
                                   plate_bolt_positions_mm, plate_dowel_positions_mm, plate_post_positions_mm)
from matcad.parts.registry import Kind, Part, PrintPose


def needle_bore_diameter_mm(spec) -> float:
    """Bore diameter for the needle: outer diameter plus the printer's allowance for needle.fit (mm)."""
    return pin_hole_diameter_mm(spec.needle.outer_diameter, spec.machine.printer, spec.needle.fit)


def _on_needle_axis(taxel, start, radius: float, length: float):
    """Cylinder of ``radius`` on ``taxel``'s needle axis, from point ``start`` on it back ``length`` mm (mm)."""
    from matcad.parts.solid import tilted_cylinder

    return tilted_cylinder(radius, length, start, taxel.needle.theta_deg)


def taxel_needle(taxel):
    """One taxel's needle, ``needle.length`` long, ending at its tip under the taxel's neck (mm)."""
    return _on_needle_axis(taxel, needle_tip_mm(taxel), taxel.needle.outer_diameter / 2, taxel.needle.length)


def needle(spec):
    """The needle of a single-taxel spec (for collision checks and assembly), at the plate centre (mm)."""
    return taxel_needle(spec)


def needle_bore(taxel, bore_diameter: float, reach: float):
    """The bore for ``taxel``'s needle: ``bore_diameter`` wide, along its axis from the plate-underside plane back
    ``reach`` mm, so wherever the tip stands the jet's path to its neck is open (mm)."""
    mouth_point, _ = needle_axis_mm(taxel)
    return _on_needle_axis(taxel, mouth_point, bore_diameter / 2, reach)


def dowel_hole_radius_mm(spec) -> float:
    """Radius (mm) of the dowel holes printed in the mount: the dowel's press-fit hole on this printer."""
    return pin_hole_diameter_mm(spec.fasteners.dowel_diameter, spec.machine.printer,
                                spec.fasteners.dowel_fit_printed) / 2


def mount_extent_mm(spec) -> tuple[float, float, float]:
    """The mount's bounding box in its print pose (x, y, z mm): the block plate.width wide, its ears
    :data:`~matcad.parts.features.EAR_WIDTH_MM` beyond the plate's depth on ±y, ``mount.thickness`` tall plus the
    standoffs or support posts (spacer.height) when they are printed on it."""
    standoffs = spec.spacer.height if spec.spacer.style == "standoff" or plate_post_positions_mm(spec) else 0.0
    return spec.plate.width, spec.plate.depth + 2 * EAR_WIDTH_MM, spec.mount.thickness + standoffs


def needle_mount(spec):
    """The mount solid in the assembly frame (mm): block, fixing ears, standoffs (if printed), support posts (if
    any), bolt pilots, dowel holes, one needle bore per taxel (at its θ and y, aimed at its own neck), and on a
    board each bore's taxel name recessed beside its mouth on the top face. No manifold: each needle takes its own
    air line."""
    from build123d import Box, Pos

    from matcad.parts.labels import PRINTED_LABEL_DEPTH_MM
    from matcad.parts.solid import BOTTOM, TOP, cylinder_up, engraved
    from matcad.spec import taxels

    gap, thick = spec.spacer.height, spec.mount.thickness
    top = -gap
    width, span, _ = mount_extent_mm(spec)
    body = Pos(0, 0, top) * Box(width, spec.plate.depth, thick, align=TOP)
    ears = Pos(0, 0, top - thick) * Box(width, span, EAR_THICKNESS_MM, align=BOTTOM)
    body = body + ears
    if spec.spacer.style == "standoff":
        for x, y in plate_bolt_positions_mm(spec):
            body += cylinder_up(spec.spacer.size / 2, gap, x, y, top)
    for x, y in plate_post_positions_mm(spec):
        body += cylinder_up(spec.plate.post_diameter / 2, gap, x, y, top)
    pilot = SELF_TAP_PILOT_MM[spec.fasteners.bolt] / 2
    dowel = dowel_hole_radius_mm(spec)
    bores = []
    for t in taxels(spec):
        reach = (thick + gap + spec.plate.width + spec.plate.depth) / max(math.sin(math.radians(
            t.needle.theta_deg)), 1e-3)
        bore = pin_hole_diameter_mm(t.needle.outer_diameter, spec.machine.printer, t.needle.fit)
        bores.append(needle_bore(t, bore, reach))
    holes = ([cylinder_up(pilot, thick + gap, x, y, top - thick) for x, y in plate_bolt_positions_mm(spec)]
             + [cylinder_up(dowel, thick, x, y, top - thick) for x, y in plate_dowel_positions_mm(spec)]
             + bores
             + [cylinder_up(bolt_clearance_mm(FIXING_BOLT, "normal") / 2, EAR_THICKNESS_MM, x, y, top - thick)
                for x, y in ear_holes_mm(spec)])
    return body.cut(*holes, *engraved(mount_labels(spec), top, PRINTED_LABEL_DEPTH_MM))


def bore_mouth_mm(spec, taxel) -> tuple[float, float, float]:
    """Where ``taxel``'s needle bore opens in the mount's top face: (x, y, radius of a circle holding the bore's
    elliptical mouth, r / sin θ) (mm)."""
    (px, py, _), _ = needle_axis_mm(taxel)
    theta = math.radians(taxel.needle.theta_deg)
    r = pin_hole_diameter_mm(taxel.needle.outer_diameter, spec.machine.printer, taxel.needle.fit) / 2
    return px - spec.spacer.height / max(math.tan(theta), 1e-3), py, r / max(math.sin(theta), 1e-3)


def mount_labels(spec) -> tuple:
    """A board's taxel names recessed in the mount's top face, each beside its needle bore's mouth, clear of the
    other mouths, the bolt pilots (or standoffs), the dowel holes and the support posts; () for a single taxel
    (mm)."""
    from matcad.parts.labels import PRINTED_LABEL_HEIGHTS_MM, place_labels
    from matcad.spec import taxels

    board = taxels(spec)
    if len(board) < 2:
        return ()
    mouths = [bore_mouth_mm(spec, t) for t in board]
    post = (spec.spacer.size if spec.spacer.style == "standoff" else SELF_TAP_PILOT_MM[spec.fasteners.bolt]) / 2
    dowel = dowel_hole_radius_mm(spec)
    keepout = (mouths + [(x, y, post) for x, y in plate_bolt_positions_mm(spec)]
               + [(x, y, dowel) for x, y in plate_dowel_positions_mm(spec)]
               + [(x, y, spec.plate.post_diameter / 2) for x, y in plate_post_positions_mm(spec)])
    return place_labels([(t.name, x, y) for t, (x, y, _) in zip(board, mouths)], keepout, spec.plate.width,
                        spec.plate.depth, heights=PRINTED_LABEL_HEIGHTS_MM)

PARTS = (Part("needle_mount", Kind.PRINTED, flag="needle_mount", make=needle_mount, order=80, colour="#b4b4b4",
              pose=PrintPose(0.0, "flat underside; standoffs and the needle bore's mouth face up"),
              view=("section through a needle's plane: its bore at θ", 0.0, -90.0), label="needle mount (printed)",
              section="bore", extent=mount_extent_mm),)
