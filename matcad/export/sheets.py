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
from typing import NamedTuple

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


def _box(outlines) -> tuple[float, float, float, float]:
    """The box around kerf-compensated outlines (x0, y0, x1, y1, r), without a reference square (mm)."""
    return (min(o[0] for o in outlines), min(o[1] for o in outlines),
            max(o[2] for o in outlines), max(o[3] for o in outlines))


def usable_bed_mm(spec) -> tuple[float, float]:
    """The laser bed less :data:`BED_MARGIN_MM` at every edge (x, y mm): how wide a nested row may be, and what a
    nested sheet must fit."""
    return spec.machine.laser_bed_x - 2 * BED_MARGIN_MM, spec.machine.laser_bed_y - 2 * BED_MARGIN_MM


def _same_sheet(sheet: str, flats) -> None:
    """Raises ValueError unless ``flats`` (parts nested on ``sheet``) are some and share one thickness and kerf."""
    if not flats:
        raise ValueError(f"sheet {sheet!r}: no parts to nest")
    if any(f.thickness != flats[0].thickness or f.kerf != flats[0].kerf for f in flats):
        raise ValueError(f"sheet {sheet!r}: parts of different thickness or kerf cannot share one sheet")


def _layout(boxes: list, row_width_mm: float) -> list[tuple[int, float, float]]:
    """Where nesting puts each part, from the boxes around their outlines (x0, y0, x1, y1 mm): (its index, dx, dy
    it is moved by), in nesting order. Rows left to right at most ``row_width_mm`` wide (a part wider stands
    alone), tallest first, :data:`PART_GAP_MM` apart, the first part's top-left corner at the origin."""
    placed = []
    x = y = row_h = 0.0
    for k in sorted(range(len(boxes)), key=lambda k: -(boxes[k][3] - boxes[k][1])):
        x0, y0, x1, y1 = boxes[k]
        w, h = x1 - x0, y1 - y0
        if x > 0 and x + w > row_width_mm:
            x, y, row_h = 0.0, y - row_h - PART_GAP_MM, 0.0
        placed.append((k, x - x0, y - y1))  # the part's top-left corner at (x, y)
        x += w + PART_GAP_MM
        row_h = max(row_h, h)
    return placed


def _extents(boxes: list, placed: list, reference_square: bool) -> tuple[tuple, tuple | None]:
    """(the nested sheet's extents x0, y0, x1, y1, its reference square x0, y0, side or None) from the parts'
    boxes as :func:`_layout` placed them (mm): the square after the last part, level with the top."""
    moved = [(boxes[k][0] + dx, boxes[k][1] + dy, boxes[k][2] + dx, boxes[k][3] + dy) for k, dx, dy in placed]
    xs = [v for b in moved for v in (b[0], b[2])]
    ys = [v for b in moved for v in (b[1], b[3])]
    square = None
    if reference_square:
        square = (max(xs) + PART_GAP_MM, max(ys) - REFERENCE_SQUARE_MM, REFERENCE_SQUARE_MM)
        xs.append(square[0] + REFERENCE_SQUARE_MM)
        ys.append(square[1])  # below parts shorter than the square (the spacers)
    return (min(xs), min(ys), max(xs), max(ys)), square


def nest(plans: list[CutPlan], sheet: str, reference_square: bool, row_width_mm: float) -> CutPlan:
    """The cut plans of every part cut from ``sheet`` (all of one thickness and kerf) as one plan: each part
    moved into place (:func:`_layout`), the reference square after the last part (mm).

    Raises ValueError if the plans do not share one sheet thickness and kerf."""
    _same_sheet(sheet, [p.flat for p in plans])
    first = plans[0].flat
    boxes = [_box(p.outlines) for p in plans]
    placed = _layout(boxes, row_width_mm)
    outlines, circles, texts = [], [], []
    for k, dx, dy in placed:
        o, c, t = _moved(plans[k], dx, dy)
        outlines += o
        circles += c
        texts += t
    extents, square = _extents(boxes, placed, reference_square)
    flat = Flat(name=SHEET_FILE.format(sheet=sheet), thickness=first.thickness,
                thickness_measured=first.thickness_measured, thickness_example=first.thickness_example,
                sheet=sheet, kerf=plans[0].kerf, width=extents[2] - extents[0], depth=extents[3] - extents[1],
                holes=(), engrave=tuple(texts), quantity=1, corner_radius=0.0)
    return CutPlan(flat, plans[0].kerf, tuple(outlines), tuple(circles), tuple(texts), square, extents,
                   tuple(plans[k].flat.name for k, _, _ in placed))


def sheet_plans(plans: list[CutPlan], reference_square: bool, row_width_mm: float) -> dict[str, CutPlan]:
    """Sheet key → the nested plan of every part ``plans`` cuts from it (:func:`nest`, rows at most
    ``row_width_mm`` wide), sheets in the parts' order; each plan's ``parts`` names the parts on it."""
    return {sheet: nest(group, sheet, reference_square, row_width_mm)
            for sheet, group in _by_sheet(plans, lambda plan: plan.flat.sheet).items()}


def _by_sheet(items, sheet_of) -> dict[str, list]:
    """``items`` grouped by the sheet each is cut from (``sheet_of(item)``), sheets in the items' order."""
    groups: dict[str, list] = {}
    for item in items:
        groups.setdefault(sheet_of(item), []).append(item)
    return groups


def kit_sheets(spec, plans: list[CutPlan] | None = None) -> dict[str, CutPlan]:
    """The nested sheets of ``spec``'s kit as the build writes them: ``plans`` (default: the cut plan of every
    laser part it asks for, :func:`matcad.parts.flat.cut_plan`) nested on the usable laser bed (mm)."""
    if plans is None:
        from matcad.parts.catalogue import laser_parts
        from matcad.parts.flat import cut_plan

        plans = [cut_plan(flat, spec.outputs.reference_square) for flat in laser_parts(spec)]
    return sheet_plans(plans, spec.outputs.reference_square, usable_bed_mm(spec)[0])


class SheetSize(NamedTuple):
    """A nested sheet's file stem, its parts (in nesting order) and its extents x0, y0, x1, y1 (mm)."""

    name: str
    parts: tuple[str, ...]
    extents: tuple[float, float, float, float]


def kit_sheet_sizes(spec) -> dict[str, SheetSize]:
    """Each of :func:`kit_sheets`' sheets, its name, parts and extents, without drawing it: the same layout
    (:func:`_layout`) of the same outlines (:func:`matcad.parts.flat.cut_outlines`), so the same numbers, with no
    hole or engraving moved into place (the parts made, 33 µs against 117 µs: the design rule ``laser.bed`` runs on
    every combination of a sweep's plate dimensions). Raises as :func:`kit_sheets` does (DrawnSizeError,
    ValueError)."""
    from matcad.parts.catalogue import laser_parts
    from matcad.parts.flat import check_drawable, cut_outlines

    flats = laser_parts(spec)
    for flat in flats:
        check_drawable(flat)
    row_width = usable_bed_mm(spec)[0]
    out = {}
    for sheet, flats in _by_sheet(flats, lambda flat: flat.sheet).items():
        _same_sheet(sheet, flats)
        boxes = [_box(cut_outlines(f)) for f in flats]
        placed = _layout(boxes, row_width)
        out[sheet] = SheetSize(SHEET_FILE.format(sheet=sheet), tuple(flats[k].name for k, _, _ in placed),
                               _extents(boxes, placed, spec.outputs.reference_square)[0])
    return out
