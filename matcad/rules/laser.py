"""Rules for laser-cut acrylic parts: features and webs, taper in thick sheet, stock thickness, fits."""

from __future__ import annotations

import math

from matcad.acoustics.uncertainty import sheet_tolerance_mm
from matcad.export.sheets import BED_MARGIN_MM, kit_sheet_sizes, usable_bed_mm
from matcad.parts.catalogue import laser_parts
from matcad.parts.features import is_stock_sheet, sheet_row_key
from matcad.parts.flat import DrawnSizeError, Flat, drawn_holes
from matcad.rules.finding import Finding, fits_bed

TAPER_RATIO = 0.7
"""CO₂-laser holes smaller than ~0.7 × sheet thickness come out visibly tapered (docs/physics.md)."""


def _webs(flat: Flat) -> list[tuple[float, str]]:
    """Narrowest material between holes, and between each hole and the outline (mm, what)."""
    webs = []
    for i, a in enumerate(flat.holes):
        edge = min(flat.width / 2 - abs(a.x), flat.depth / 2 - abs(a.y)) - a.diameter / 2
        webs.append((edge, f"{a.purpose} hole to edge"))
        for b in flat.holes[i + 1:]:
            gap = math.hypot(a.x - b.x, a.y - b.y) - (a.diameter + b.diameter) / 2
            webs.append((gap, f"{a.purpose} to {b.purpose} hole"))
    return webs


def feature_and_web(spec) -> list[Finding]:
    out = []
    limit = spec.machine.laser_min_feature
    for flat in laser_parts(spec):
        web, what = min(_webs(flat))
        if web < limit:
            level = "error" if web <= 0 else "warning"
            out.append(Finding("laser.web", level, round(web, 4), limit,
                               f"{flat.name}: {what} leaves {web:.2f} mm of acrylic (< {limit:g} mm)",
                               "enlarge plate.width/depth or plate.bolt_inset, or use smaller fasteners"))
    return out


SHEET_THICKNESS_FIELDS = {"plate": "neck.length", "riser": "riser.thickness", "guide": "guide.thickness",
                          "spacer": "spacer.height"}
"""The spec field that holds each sheet's thickness."""
HOLE_FIELDS = {"neck": "neck.diameter", "neck_pilot": "plate.pilot_undersize", "dowel": "fasteners.dowel_diameter",
               "bolt": "fasteners.bolt", "cap": "end_cap.outer_diameter"}
"""The spec field that sets each hole purpose's size (what the user changes to fix a drawn size)."""


def drawn_size(spec) -> list[Finding]:
    """Holes as drawn, after kerf (the numbers written into the DXF/SVG, from the same function the exporter
    uses): ≤ 0 cannot be drawn at all (``laser.drawn_size``, not overridable by --force); below
    machine.laser_min_feature the beam cannot cut it cleanly (``laser.feature``)."""
    out = []
    limit = spec.machine.laser_min_feature
    for flat in laser_parts(spec):
        kerf = flat.kerf
        seen = set()
        for hole, drawn in drawn_holes(flat, kerf):
            if hole.purpose in seen or drawn >= limit:
                continue
            seen.add(hole.purpose)
            field = HOLE_FIELDS.get(hole.purpose, "machine.laser_kerf")
            where = (f"{flat.name}: {hole.purpose} hole ({field}) finished {hole.diameter:g} mm is drawn at "
                     f"{drawn:.3g} mm after the {kerf:g} mm kerf")
            if drawn <= 0:
                out.append(Finding("laser.drawn_size", "error", round(drawn, 4), "> 0",
                                   f"{where}: nothing to cut", f"enlarge {field} or lower the sheet's laser_kerf"))
            else:
                out.append(Finding("laser.feature", "error", round(drawn, 4), limit,
                                   f"{where}, below the laser's smallest feature {limit:g} mm "
                                   "(machine.laser_min_feature)", f"enlarge {field}, or drill it instead"))
    return out


def hole_taper(spec) -> list[Finding]:
    out = []
    fixes = {"neck": ("warning", "set plate.neck_pilot = true and drill to size, or measure the cut neck"),
             "neck_pilot": ("info", f"drill the pilot to {spec.neck.diameter:g} mm"),
             "dowel": ("warning", "ream the dowel holes after cutting"),
             "bolt": ("info", "clearance holes tolerate taper")}
    for flat in laser_parts(spec):
        for purpose in dict.fromkeys(h.purpose for h in flat.holes):
            hole = min((h for h in flat.holes if h.purpose == purpose), key=lambda h: h.diameter)
            ratio = hole.diameter / flat.thickness
            if ratio >= TAPER_RATIO or purpose not in fixes:
                continue
            level, fix = fixes[purpose]
            out.append(Finding("laser.taper", level, round(ratio, 3), TAPER_RATIO,
                               f"{flat.name}: {purpose} hole {hole.diameter:g} mm in {flat.thickness:g} mm sheet "
                               f"is {ratio:.2f} x thickness: the laser cuts it tapered", fix))
    return out


def stock_thickness(spec) -> list[Finding]:
    out = []
    seen = set()
    for flat in laser_parts(spec):
        if sheet_row_key(flat) in seen:
            continue
        seen.add(sheet_row_key(flat))
        if flat.thickness_status == "example":
            tol = sheet_tolerance_mm(flat.thickness, False)
            field = SHEET_THICKNESS_FIELDS[flat.sheet]
            out.append(Finding("laser.stock", "warning", flat.thickness, "measured",
                               f"{flat.name}: unverified: {field} = {flat.thickness:g} mm is the template's example of "
                               f"a calipered sheet, not yours; every number built on it assumes your sheet is "
                               f"{flat.thickness:g} mm (nominal stock may be off by +-{tol:.2f} mm, ISO 7823-1)",
                               f"caliper the sheet, enter {field}, set {flat.sheet}.thickness_example = false"))
        elif flat.thickness_measured:
            out.append(Finding("laser.stock", "info", flat.thickness, "measured",
                               f"{flat.name}: {flat.thickness:g} mm sheet taken as measured", ""))
        elif not is_stock_sheet(flat.thickness):
            out.append(Finding("laser.stock", "warning", flat.thickness, "stock sizes",
                               f"{flat.name}: {flat.thickness:g} mm is not a stock acrylic thickness",
                               "use a stock sheet, or measure yours and mark it *_measured = true"))
        else:
            tol = sheet_tolerance_mm(flat.thickness, False)
            # the plate's thickness is the neck length l, which sets f: nominal is not good enough there (nor in the
            # riser: the necks run on through it)
            level = "warning" if flat.sheet in ("plate", "riser") else "info"
            out.append(Finding("laser.stock", level, flat.thickness, round(tol, 3),
                               f"{flat.name}: nominal {flat.thickness:g} mm cast acrylic may be off by "
                               f"+-{tol:.2f} mm (ISO 7823-1); measure it and mark it measured",
                               "caliper the sheet, enter the value, set thickness_measured = true"))
    return out


def dowel_fit(spec) -> list[Finding]:
    if spec.fasteners.dowel_fit_laser == "press":
        return [Finding("fit.dowel_laser", "error", "press", "clearance | slip",
                        "press fits are not achievable in laser-cut acrylic (+-0.1 mm); the plate would crack "
                        "or the pin fall out", "set fasteners.dowel_fit_laser = 'slip'")]
    return []


def laser_bed(spec) -> list[Finding]:
    """Every acrylic sheet's nested cut file (:func:`matcad.export.sheets.kit_sheet_sizes`: the layout the build
    writes, kerf and reference square included) must fit the laser's bed less its margins
    (``machine.laser_bed_x/y``), either way round: a part off the bed cannot be cut. A hole that cannot be drawn is
    ``laser.drawn_size``'s."""
    try:
        sheets = kit_sheet_sizes(spec)
    except DrawnSizeError:
        return []
    usable = usable_bed_mm(spec)
    out = []
    for sheet, (name, parts, (x0, y0, x1, y1)) in sheets.items():
        size = (x1 - x0, y1 - y0)
        if fits_bed(size, usable):
            continue
        alone = [f.name for f in laser_parts(spec)
                 if f.sheet == sheet and not fits_bed((f.width + f.kerf, f.depth + f.kerf), usable)]
        fix = (f"{', '.join(alone)} alone does not fit: enter a laser with a larger bed (machine.laser_bed_x/y), "
               "or make the plate smaller (fewer taxels, plate.width/depth)" if alone else
               "every part fits alone: cut the sheet in several runs (split the cut file), or enter a larger bed")
        out.append(Finding("laser.bed", "error", [round(v, 3) for v in size], [round(v, 3) for v in usable],
                           f"{name}: the nested sheet ({', '.join(dict.fromkeys(parts))}) is "
                           f"{size[0]:.1f} x {size[1]:.1f} mm; the laser bed machine.laser_bed_x/y = "
                           f"{spec.machine.laser_bed_x:g} x {spec.machine.laser_bed_y:g} mm less {BED_MARGIN_MM:g} mm "
                           f"margins holds {usable[0]:g} x {usable[1]:g} mm (either way round)", fix))
    return out


RULES = (feature_and_web, drawn_size, hole_taper, stock_thickness, dowel_fit, laser_bed)
