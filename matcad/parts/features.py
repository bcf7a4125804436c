"""Shared features: fit classes per process, bolt and dowel holes, stock sheets. Lengths in mm.

One table each, used by every part, so a plate hole and the mount hole under it can never disagree.
"""

from __future__ import annotations

ISO_273_CLEARANCE_MM = {
    "M2": {"close": 2.2, "normal": 2.4, "loose": 2.6},
    "M2.5": {"close": 2.7, "normal": 2.9, "loose": 3.1},
    "M3": {"close": 3.2, "normal": 3.4, "loose": 3.6},
}
"""ISO 273 bolt clearance hole diameters (mm)."""

SELF_TAP_PILOT_MM = {"M2": 1.6, "M2.5": 2.05, "M3": 2.5}
"""Pilot hole for a machine screw cutting its own thread in a printed part (ISO tap-drill size, mm)."""

PIN_FIT_ALLOWANCE_MM = {
    "laser": {"clearance": 0.15, "slip": 0.05, "press": 0.0},
    "fdm": {"clearance": 0.4, "slip": 0.2, "press": 0.0},
    "sla": {"clearance": 0.2, "slip": 0.1, "press": -0.05},
}
"""Finished hole diameter minus pin diameter (mm) by process and fit. FDM holes print ~0.1-0.2 mm undersize,
so its nominal-size hole is already a press fit. A laser "press" hole is drawn at pin size, but laser-cut
acrylic holds only ±0.1 mm (docs/physics.md): the design rules reject it. Laser values are for the hole as cut after
kerf compensation."""

STOCK_ACRYLIC_MM = (1.0, 1.5, 1.59, 2.0, 2.5, 3.0, 3.18, 4.0, 4.76, 5.0, 6.0, 6.35, 8.0, 9.53, 10.0, 12.0,
                    12.7)
"""Common cast/extruded acrylic sheet thicknesses: metric and 1/16-inch steps (mm)."""


SHEETS = {"plate": "neck plate (thickness neck.length)", "riser": "riser (riser.thickness)",
          "guide": "guides (guide.thickness)", "spacer": "spacers (spacer.height)"}
"""Spec sections that are each one acrylic sheet, with its own kerf (``<section>.laser_kerf``)."""


def sheet_row_key(flat) -> tuple[float, bool]:
    """Under which row a laser part ``flat`` (:class:`matcad.parts.flat.Flat`) is listed where each sheet is named
    once (what to caliper, ``laser.stock``): its thickness, parts of one thickness sharing a sheet; the riser's row
    apart, its thickness being a neck's length and a flange's of its own (mm)."""
    return flat.thickness, flat.sheet == "riser"


def sheet_kerf_mm(spec, sheet: str) -> float:
    """Full laser kerf in ``sheet`` (a key of :data:`SHEETS`): its own ``laser_kerf`` when given, else
    ``machine.laser_kerf`` (mm). Kerf widens with thickness (the beam's waist is short), so a 6 mm plate and a
    1.5 mm guide rarely share one value."""
    own = getattr(spec, sheet).laser_kerf
    return spec.machine.laser_kerf if own is None else own


def sheet_thickness_mm(spec, sheet: str) -> tuple[float, bool]:
    """(thickness mm, measured) of ``sheet``: an example value counts as measured (:func:`sheet_status`)."""
    if sheet == "riser":  # only a spec with a [riser] cuts one
        return spec.riser.thickness, spec.riser.thickness_measured
    return {"plate": (spec.neck.length, spec.plate.thickness_measured),
            "guide": (spec.guide.thickness, spec.guide.thickness_measured),
            "spacer": (spec.spacer.height, spec.spacer.thickness_measured)}[sheet]


SHEET_STATUSES = ("measured", "example", "nominal")
"""What a sheet's thickness is: calipered by the user; a template's example of a calipered value (predictions
use it as measured, the rules report it unverified); or the nominal stock size (ISO 7823-1 tolerance)."""


def sheet_status(spec, sheet: str) -> str:
    """``sheet``'s thickness status, one of :data:`SHEET_STATUSES`: ``<section>.thickness_measured`` and
    ``<section>.thickness_example``."""
    section = getattr(spec, sheet)
    if not section.thickness_measured:
        return "nominal"
    return "example" if section.thickness_example else "measured"


NEEDLE_GAUGE_OD_MM = {14: 2.108, 15: 1.829, 16: 1.651, 17: 1.473, 18: 1.270, 19: 1.067, 20: 0.908, 21: 0.819,
                      22: 0.718, 23: 0.641, 25: 0.514}
"""Nominal outer diameter of hypodermic / dispensing needle tubing by gauge (ISO 9626 normal wall, mm)."""


def nearest_needle_gauge(outer_diameter_mm: float) -> tuple[int, float]:
    """The standard gauge whose nominal outer diameter is nearest (gauge, OD mm)."""
    return min(NEEDLE_GAUGE_OD_MM.items(), key=lambda kv: abs(kv[1] - outer_diameter_mm))


def pin_hole_diameter_mm(pin_diameter_mm: float, process: str, fit: str) -> float:
    """Finished hole diameter (mm) for a pin (dowel, needle) of the given diameter, process and fit."""
    return pin_diameter_mm + PIN_FIT_ALLOWANCE_MM[process][fit]


def bolt_clearance_mm(bolt: str, fit: str) -> float:
    """ISO 273 clearance hole diameter (mm)."""
    return ISO_273_CLEARANCE_MM[bolt][fit]


ISO_4762_LENGTHS_MM = (3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0,
                       60.0)
"""Preferred stock lengths of socket head cap screws, ISO 4762 (mm): what a shop or kit box holds."""
ISO_8734_LENGTHS_MM = (3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 22.0, 24.0, 26.0, 28.0, 30.0,
                       32.0, 35.0, 40.0, 45.0, 50.0)
"""Stock lengths of hardened dowel pins, ISO 8734 (mm)."""
NEEDLE_LENGTHS_MM = (6.35, 12.7, 25.4, 38.1)
"""Stock lengths of blunt dispensing needles: 1/4, 1/2, 1 and 1 1/2 in (mm)."""


def stock_length_mm(needed_mm: float, series) -> float | None:
    """The shortest stock length of ``series`` at least ``needed_mm`` long; None when none is (mm)."""
    return next((length for length in series if length >= needed_mm - 1e-9), None)


def bolt_nominal_mm(bolt: str) -> float:
    """Nominal major diameter of a metric bolt, e.g. 'M2.5' → 2.5 (mm)."""
    return float(bolt[1:])


def is_stock_sheet(thickness_mm: float, tol_mm: float = 0.005) -> bool:
    """Whether a sheet thickness is a common stock acrylic size (mm)."""
    return any(abs(thickness_mm - t) <= tol_mm for t in STOCK_ACRYLIC_MM)


def laser_stack_holes(spec) -> tuple:
    """Dowel and bolt holes shared by every laser-cut layer of the stack (plate, riser, guides)."""
    from matcad.parts.flat import Hole

    fit = spec.fasteners.dowel_fit_laser
    dowel = pin_hole_diameter_mm(spec.fasteners.dowel_diameter, "laser", fit)
    bolt = bolt_clearance_mm(spec.fasteners.bolt, spec.fasteners.bolt_fit)
    return (tuple(Hole(x, y, dowel, "dowel", fit) for x, y in plate_dowel_positions_mm(spec))
            + tuple(Hole(x, y, bolt, "bolt", spec.fasteners.bolt_fit) for x, y in plate_bolt_positions_mm(spec)))


def plate_bolt_positions_mm(spec) -> list[tuple[float, float]]:
    """Bolt centres (x, y) at the four plate corners, inset ``plate.bolt_inset`` + bolt radius (mm)."""
    inset = spec.plate.bolt_inset + bolt_nominal_mm(spec.fasteners.bolt) / 2
    x, y = spec.plate.width / 2 - inset, spec.plate.depth / 2 - inset
    return [(-x, -y), (x, -y), (x, y), (-x, y)]


def plate_post_positions_mm(spec) -> list[tuple[float, float]]:
    """Support post centres (x, y) under the neck plate, when ``plate.support_posts`` (else none; mm): on the centre
    line between each two neighbouring columns of necks (taxels sharing an x; :func:`matcad.design.allocate.stagger`
    makes two), one midway in y between each two necks of those columns that follow each other in y. On the
    stagger that puts a post between a left-column row and the right-column row half a row below it: the right
    neck's own needle runs along its row toward +x and the left needle's jet along the left row, so the post stands
    between them, and the necks' mouths either side of it are equally far. A board of one column (or one taxel)
    has no such line and no posts. Every part, rule and drawing takes the posts from here; the ``plate.posts`` rule
    (:mod:`matcad.rules.plate`) checks each against the jets, needles, mouths, bolts and dowels."""
    from matcad.spec import taxels

    if not spec.plate.support_posts:
        return []
    board = taxels(spec)
    columns = sorted({t.x for t in board})
    out = []
    for left, right in zip(columns, columns[1:]):
        ys = sorted({t.y for t in board if t.x in (left, right)}, reverse=True)
        out += [((left + right) / 2, (a + b) / 2) for a, b in zip(ys, ys[1:])]
    return out


def plate_dowel_positions_mm(spec) -> list[tuple[float, float]]:
    """Dowel centres (x, y): mid-edge on ±y, offset in x so the stack only assembles one way (mm)."""
    inset = spec.plate.bolt_inset + spec.fasteners.dowel_diameter / 2
    y = spec.plate.depth / 2 - inset
    return [(spec.plate.width * 0.1, y), (-spec.plate.width * 0.1, -y)]




def cap_volume_mm3(spec) -> float:
    """Cast silicone volume of one end cap: flange + body − drafted cavity (mm³)."""
    import math

    from matcad.acoustics.geometry import drafted_cavity_volume_mm3
    from matcad.spec import cap_flange_diameter_mm, cap_flange_thickness_mm, cap_height_mm

    flange_d, tf = cap_flange_diameter_mm(spec), cap_flange_thickness_mm(spec)
    envelope = math.pi / 4 * (flange_d**2 * tf + spec.end_cap.outer_diameter**2 * (cap_height_mm(spec) - tf))
    return envelope - float(drafted_cavity_volume_mm3(spec.cavity.diameter, spec.cavity.length,
                                                      spec.mold.draft_deg))



def needle_axis_mm(spec) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """The needle's axis in the assembly frame (plate underside z = 0, neck axis = z axis, mm).

    The axis lies in the XZ plane at ``needle.theta_deg`` to the plate surface, pointing up toward +x. It meets
    the plane of the plate's underside (the neck's mouth) at (−d/2 − y, 0, 0): ``needle.y`` is the distance,
    measured in that plane, from that point to the nearest edge of the neck opening (−d/2, 0, 0) — the
    paper's "distance between air supply and nearest edge of cavity opening" (Fig. 2).
    Returns (point on the mouth plane, unit direction). ``spec`` may be a Spec or a
    :class:`matcad.spec.Taxel`: a taxel's axis is moved to its neck at (taxel.x, taxel.y).
    """
    import math

    t = math.radians(spec.needle.theta_deg)
    x0, y0 = getattr(spec, "x", 0.0), getattr(spec, "y", 0.0)
    return (x0 - spec.neck.diameter / 2 - spec.needle.y, y0, 0.0), (math.cos(t), 0.0, math.sin(t))


def needle_tip_mm(spec) -> tuple[float, float, float]:
    """Centre of the needle's end face: back along the axis until the face's highest point sits
    ``needle.tip_clearance`` below the plate underside (mm). ``spec``: a Spec or a Taxel (at its position)."""
    import math

    (px, py, pz), (ux, uy, uz) = needle_axis_mm(spec)
    t = math.radians(spec.needle.theta_deg)
    drop = spec.needle.tip_clearance + spec.needle.outer_diameter / 2 * math.cos(t)
    s = drop / max(math.sin(t), 1e-12)
    return (px - s * ux, py - s * uy, pz - s * uz)


EAR_WIDTH_MM = 9.0
EAR_THICKNESS_MM = 3.0
FIXING_BOLT = "M3"
"""Two ears on ±y, flush with the mount's underside (they print on the bed, no support), each with two M3
clearance holes: screw the mount to a bench bracket or a robot plate on standoffs tall enough for the needle's
hub, which hangs below the mount."""


def ear_holes_mm(spec) -> list[tuple[float, float]]:
    """Centres (x, y) of the fixing holes in the ears, assembly frame (mm)."""
    y = spec.plate.depth / 2 + EAR_WIDTH_MM / 2
    return [(sx * spec.plate.width / 4, sy * y) for sy in (-1, 1) for sx in (-1, 1)]


def needle_protrusion_mm(spec) -> float:
    """How far the needle's tip stands out of the mount's top face, along the needle (mm): set it with a depth
    gauge or calipers before tightening (the tip then sits needle.tip_clearance below the plate)."""
    import math

    tip_z = needle_tip_mm(spec)[2]
    return (tip_z + spec.spacer.height) / math.sin(math.radians(spec.needle.theta_deg))
