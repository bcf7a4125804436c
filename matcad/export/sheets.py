"""One cut file per acrylic sheet: every laser part cut from that sheet, nested side by side, kerf compensated
(the per-part cut plans moved into place), one reference square. Written as DXF and SVG by
:mod:`matcad.export.dxf_svg` (engraving first, then every inner cut of every part, the outlines last) and drawn at
1:1 on paper by :mod:`matcad.export.pdf`. Lengths in mm.

Nesting is row by row (a shelf packing of the parts' kerf-compensated bounding rectangles, tallest first), each
row at most the laser bed's usable width (:func:`usable_bed_mm`) wide, :data:`PART_GAP_MM` apart: the kit's parts
are rectangles, so this wastes no more than the gaps. The design rule ``laser.bed`` holds each nested sheet
(:func:`kit_sheets`, the plans the build writes) to the usable bed.
"""

from __future__ import annotations

import dataclasses

from matcad.parts.flat import REFERENCE_SQUARE_MM, CutPlan, Flat

BED_MARGIN_MM = 10.0
"""Kept free at every edge of the laser's bed (``machine.laser_bed_x``, ``laser_bed_y``): the sheet's hold-downs and
the head's reach near the rails."""
PART_GAP_MM = 3.0
"""Acrylic left between two parts (and between copies of one part): more than the kerf, enough to not melt."""
SHEET_FILE = "sheet_{sheet}"
"""File stem of a sheet's nested cut file."""


def _moved(plan: CutPlan, dx: float, dy: float) -> tuple[list, list, list]:
    outlines = [(x0 + dx, y0 + dy, x1 + dx, y1 + dy, r) for x0, y0, x1, y1, r in plan.outlines]
    circles = [dataclasses.replace(c, x=c.x + dx, y=c.y + dy) for c in plan.circles]
    texts = [dataclasses.replace(t, x=t.x + dx, y=t.y + dy) for t in plan.texts]
    return outlines, circles, texts


def _outline_box(plan: CutPlan) -> tuple[float, float, float, float]:
    """The box around a part's kerf-compensated outlines, without its reference square (mm)."""
    return (min(o[0] for o in plan.outlines), min(o[1] for o in plan.outlines),
            max(o[2] for o in plan.outlines), max(o[3] for o in plan.outlines))


def usable_bed_mm(spec) -> tuple[float, float]:
    """The laser bed less :data:`BED_MARGIN_MM` at every edge (x, y mm): how wide a nested row may be, and what a
    nested sheet must fit."""
    return spec.machine.laser_bed_x - 2 * BED_MARGIN_MM, spec.machine.laser_bed_y - 2 * BED_MARGIN_MM


def nest(plans: list[CutPlan], sheet: str, reference_square: bool, row_width_mm: float) -> CutPlan:
    """The cut plans of every part cut from ``sheet`` (all of one thickness and kerf) as one plan: each part
    moved into place, rows left to right at most ``row_width_mm`` wide (a part wider stands alone), tallest first,
    the reference square after the last part (mm).

    Raises ValueError if the plans do not share one sheet thickness and kerf."""
    if not plans:
        raise ValueError(f"sheet {sheet!r}: no parts to nest")
    first = plans[0].flat
    if any(p.flat.thickness != first.thickness or p.kerf != plans[0].kerf for p in plans):
        raise ValueError(f"sheet {sheet!r}: parts of different thickness or kerf cannot share one sheet")
    order = sorted(plans, key=lambda p: -(_outline_box(p)[3] - _outline_box(p)[1]))
    outlines, circles, texts, names = [], [], [], []
    x = y = row_h = 0.0
    for plan in order:
        x0, y0, x1, y1 = _outline_box(plan)
        w, h = x1 - x0, y1 - y0
        if x > 0 and x + w > row_width_mm:
            x, y, row_h = 0.0, y - row_h - PART_GAP_MM, 0.0
        o, c, t = _moved(plan, x - x0, y - y1)  # the part's top-left corner at (x, y)
        outlines += o
        circles += c
        texts += t
        names.append(plan.flat.name)
        x += w + PART_GAP_MM
        row_h = max(row_h, h)
    xs = [v for o in outlines for v in (o[0], o[2])]
    ys = [v for o in outlines for v in (o[1], o[3])]
    square = None
    if reference_square:
        square = (max(xs) + PART_GAP_MM, max(ys) - REFERENCE_SQUARE_MM, REFERENCE_SQUARE_MM)
        xs.append(square[0] + REFERENCE_SQUARE_MM)
        ys.append(square[1])  # below parts shorter than the square (the spacers)
    extents = (min(xs), min(ys), max(xs), max(ys))
    flat = Flat(name=SHEET_FILE.format(sheet=sheet), thickness=first.thickness,
                thickness_measured=first.thickness_measured, thickness_example=first.thickness_example,
                sheet=sheet, kerf=plans[0].kerf, width=extents[2] - extents[0], depth=extents[3] - extents[1],
                holes=(), engrave=tuple(texts), quantity=1, corner_radius=0.0)
    return CutPlan(flat, plans[0].kerf, tuple(outlines), tuple(circles), tuple(texts), square, extents,
                   tuple(names))


def sheet_plans(plans: list[CutPlan], reference_square: bool, row_width_mm: float) -> dict[str, CutPlan]:
    """Sheet key → the nested plan of every part ``plans`` cuts from it (:func:`nest`, rows at most
    ``row_width_mm`` wide), sheets in the parts' order; each plan's ``parts`` names the parts on it."""
    by_sheet: dict[str, list[CutPlan]] = {}
    for plan in plans:
        by_sheet.setdefault(plan.flat.sheet, []).append(plan)
    return {sheet: nest(group, sheet, reference_square, row_width_mm) for sheet, group in by_sheet.items()}


def kit_sheets(spec, plans: list[CutPlan] | None = None) -> dict[str, CutPlan]:
    """The nested sheets of ``spec``'s kit as the build writes them: ``plans`` (default: the cut plan of every
    laser part it asks for, :func:`matcad.parts.flat.cut_plan`) nested on the usable laser bed (mm)."""
    if plans is None:
        from matcad.parts.catalogue import laser_parts
        from matcad.parts.flat import cut_plan

        plans = [cut_plan(flat, spec.outputs.reference_square) for flat in laser_parts(spec)]
    return sheet_plans(plans, spec.outputs.reference_square, usable_bed_mm(spec)[0])

