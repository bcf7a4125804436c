"""Heights in the assembled stack, and the flange squeeze the clamp can produce: arithmetic of the spec (mm).

Assembly frame: plate underside z = 0, neck axis = z. Bottom to top: the needle mount (its top face at
z = −spacer.height, ``mount.thickness`` thick), the spacers, the neck plate (0 … l), the locator guide around the
cap's flange, and the clamp guide resting on the flange (:func:`matcad.spec.cap_flange_thickness_mm`:
guide thickness + squeeze) until the bolts press it down onto the locator. The parts, the design rules, the bill
of materials and the fabrication plan all read these heights from here.
"""

from __future__ import annotations

from matcad.acoustics.uncertainty import sheet_tolerance_mm
from matcad.spec import cap_flange_thickness_mm


def clamp_seat_z_mm(spec) -> float:
    """Height of the clamp guide's underside, resting on the unclamped flange: l + flange thickness (mm)."""
    return spec.neck.length + cap_flange_thickness_mm(spec)


def bolt_span_mm(spec) -> float:
    """Stack the bolts and dowels must span, from the mount's top face to the clamp guide's top face, the flange
    unclamped: l + flange thickness + guide thickness + spacer height (mm)."""
    return clamp_seat_z_mm(spec) + spec.guide.thickness + spec.spacer.height


def mount_depth_mm(spec) -> float:
    """Depth of the needle mount's underside below the plate's underside: spacer height + mount thickness (mm)."""
    return spec.spacer.height + spec.mount.thickness


def squeeze_range_mm(spec, nominal: bool = False) -> tuple[float, float, float]:
    """Flange squeeze the clamp can produce over the guide sheet's tolerance: (low, high, tolerance) in mm.

    The flange is cast guide.thickness + squeeze thick; the clamp bottoms out on the locator, cut from the same
    sheet, so the real squeeze is the flange minus the real sheet (nominal ±
    :func:`matcad.acoustics.uncertainty.sheet_tolerance_mm`). A measured sheet (or a template's example of one)
    takes the calipering tolerance unless ``nominal``: what the sheet on the bench may really be until calipered."""
    tol = sheet_tolerance_mm(spec.guide.thickness, spec.guide.thickness_measured and not nominal)
    s = spec.end_cap.flange_squeeze
    return s - tol, s + tol, tol
