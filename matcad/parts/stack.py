"""Heights in the assembled stack, the flange squeeze the clamp can produce, and how far a pressed taxel bends the
neck plate toward the mount: arithmetic of the spec (mm).

Assembly frame: plate underside z = 0, neck axis = z. Bottom to top: the needle mount (its top face at
z = −spacer.height, ``mount.thickness`` thick), the spacers, the neck plate (0 … l), the [riser] bonded on it when
there is one (l … l + r), the locator guide around the caps' flanges, and the clamp guide resting on the flanges
(:func:`matcad.spec.cap_flange_thickness_mm`: guide thickness + squeeze) until the bolts press it down onto the
locator. A cap whose neck runs on through the riser sits on the riser; every other cap sits on the plate in a
pocket of the riser, its flange r thicker, so every flange's top meets the clamp at one height. The parts, the
design rules, the bill of materials and the fabrication plan all read these heights from here.
"""

from __future__ import annotations

import numpy as np

from matcad.acoustics.uncertainty import sheet_tolerance_mm
from matcad.materials import ACRYLIC_MODULUS_MPA
from matcad.mechanics.plate import cantilever_deflection_mm, deflection_mm
from matcad.parts.features import plate_bolt_positions_mm, plate_post_positions_mm
from matcad.spec import cap_flange_diameter_mm, cap_flange_thickness_mm, in_pocket, neck_length_mm


def riser_thickness_mm(spec) -> float:
    """Thickness r of the [riser] bonded on the plate; 0 without one (mm)."""
    return spec.riser.thickness if spec.riser is not None else 0.0


def locator_z_mm(spec) -> float:
    """Height of the locator guide's underside: on the plate, or on the riser bonded on it: l + r (mm)."""
    return spec.neck.length + riser_thickness_mm(spec)


def cap_seat_z_mm(spec, t=None) -> float:
    """Height of the face the cap of ``t`` (a :class:`matcad.spec.Taxel`; default ``spec``'s own) sits on: the
    riser's top where its neck runs on through the riser, else the plate's top (in a pocket of a riser, or with no
    riser) — the top of its neck either way (:func:`matcad.spec.neck_length_mm`; mm)."""
    return neck_length_mm(spec, t)


def clamp_seat_z_mm(spec) -> float:
    """Height of the clamp guide's underside, resting on the unclamped flanges: the cap's seat + its flange
    thickness, l + r + guide + squeeze, the same for every cap of a board (mm)."""
    return cap_seat_z_mm(spec) + cap_flange_thickness_mm(spec)


def bolt_span_mm(spec) -> float:
    """Stack the bolts and dowels must span, from the mount's top face to the clamp guide's top face, the flange
    unclamped: the clamp's seat (l + r + guide + squeeze, :func:`clamp_seat_z_mm`) + guide thickness + spacer
    height (mm)."""
    return clamp_seat_z_mm(spec) + spec.guide.thickness + spec.spacer.height


def mount_depth_mm(spec) -> float:
    """Depth of the needle mount's underside below the plate's underside: spacer height + mount thickness (mm)."""
    return spec.spacer.height + spec.mount.thickness


def squeeze_range_mm(spec, nominal: bool = False) -> tuple[float, float, float]:
    """Flange squeeze the clamp can produce over the sheets' tolerance: (low, high, tolerance) in mm, for the cap of
    ``spec`` (a single-taxel spec: :func:`matcad.spec.taxel_spec` for a board's taxel).

    The flange is cast guide.thickness + squeeze thick; the clamp bottoms out on the locator, cut from the same
    sheet, so the real squeeze is the flange minus the real sheet (nominal ±
    :func:`matcad.acoustics.uncertainty.sheet_tolerance_mm`). A cap in a pocket of a [riser]
    (:func:`matcad.spec.in_pocket`) sits on the plate under the riser and the locator: its flange is cast
    riser.thickness thicker, and the real squeeze is that flange minus both real sheets, so the tolerance is both
    sheets' added (sheets of one batch may err the same way). A measured sheet (or a template's example of one)
    takes the calipering tolerance unless ``nominal``: what the sheet on the bench may really be until calipered."""
    tol = sheet_tolerance_mm(spec.guide.thickness, spec.guide.thickness_measured and not nominal)
    if in_pocket(spec):
        tol += sheet_tolerance_mm(spec.riser.thickness, spec.riser.thickness_measured and not nominal)
    s = spec.end_cap.flange_squeeze
    return s - tol, s + tol, tol


def plate_beam(spec) -> tuple[str, float, float]:
    """The neck plate as the beam :mod:`matcad.mechanics.plate` bends: the axis along its longer side ('x' or 'y';
    'y' for a square plate), the span between the bolt rows across that axis, and the plate's width across it
    (mm). The bolts (:func:`matcad.parts.features.plate_bolt_positions_mm`) at the four corners, over the spacers,
    are its only supports."""
    xs, ys = zip(*plate_bolt_positions_mm(spec))
    if spec.plate.depth >= spec.plate.width:
        return "y", max(ys) - min(ys), spec.plate.width
    return "x", max(xs) - min(xs), spec.plate.depth


def post_bay_mm(spec, pressed) -> tuple[float, float, float, float]:
    """Where the support posts (:func:`matcad.parts.features.plate_post_positions_mm`, at least one) hold the plate
    around the taxel ``pressed`` (anything with x, y and a cap): (the support line below it in y and the one above,
    each a row of posts or a bolt row, whichever is nearer; the arm from the nearest post line, in x, to its neck;
    the strip's width, its cap flange's diameter) in mm."""
    posts = plate_post_positions_mm(spec)
    lines = {y for _, y in posts} | {y for _, y in plate_bolt_positions_mm(spec)}
    below = max(y for y in lines if y <= pressed.y)
    above = min(y for y in lines if y >= pressed.y)
    arm = min(abs(pressed.x - x) for x, _ in posts)
    return below, above, arm, cap_flange_diameter_mm(pressed)


def plate_deflection_mm(spec, force_n: float, pressed, taxels):
    """How far the neck plate (cast acrylic, :data:`matcad.materials.ACRYLIC_MODULUS_MPA`, neck.length thick) bends
    down toward the mount under each of ``taxels`` when ``force_n`` presses on the taxel ``pressed`` (a
    :class:`matcad.spec.Taxel`, or anything with x, y and a cap; mm, an array in the order of ``taxels``).

    Without support posts: :func:`matcad.mechanics.plate.deflection_mm` on :func:`plate_beam`. With them
    (:func:`post_bay_mm`), two parts added: the strip of the plate under the pressed cap, its flange's diameter
    wide, as a beam along y simply supported on the two support lines either side of the load (a post row or a bolt
    row; Roark Table 8.1 case 1e), and the same strip across, a cantilever from the post line out to the pressed neck
    (case 1a), the post line taken as its fixed root. Assumptions, each on the soft side but the last: the rest of
    the plate's width, which only adds stiffness to the strip that carries the load, is left out; a taxel beyond
    either support line bends 0 (a continuous plate lifts there, which opens its gap); a neighbour takes the
    strip's bending along y only, not the cantilever, which is the pressed taxel's own; the post line is a clamp,
    though the plate may turn about it where no neck across the line holds it — a point post does not hold a line,
    so this is an estimate, the reason the strip is taken no wider than the cap that loads it."""
    if not plate_post_positions_mm(spec):
        axis, span, width = plate_beam(spec)

        def along(t) -> float:
            return getattr(t, axis) + span / 2

        return deflection_mm(force_n, along(pressed), [along(t) for t in taxels], span, width, spec.neck.length,
                             ACRYLIC_MODULUS_MPA)
    below, above, arm, width = post_bay_mm(spec, pressed)
    bay = deflection_mm(force_n, pressed.y - below, [t.y - below for t in taxels], above - below, width,
                        spec.neck.length, ACRYLIC_MODULUS_MPA)
    own = cantilever_deflection_mm(force_n, arm, width, spec.neck.length, ACRYLIC_MODULUS_MPA)
    return bay + np.array([own if t is pressed else 0.0 for t in taxels])
