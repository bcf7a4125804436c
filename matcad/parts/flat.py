"""Flat (laser-cut) parts as data, and the one place where kerf is applied. Lengths in mm.

A :class:`Flat` holds design intent: the finished outline and finished hole diameters. :func:`cut_plan`
turns it into what the laser must follow — outlines grow and holes shrink by kerf/2 — and records the
compensation per feature, so exporters draw it and the report declares it.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path

REFERENCE_SQUARE_MM = 10.0


@dataclass(frozen=True)
class Hole:
    """A round hole: centre (x, y), diameter as cut (after kerf compensation), what it is for and what it must fit;
    the taxel it belongs to on a board, and the size it is drilled to after cutting (a neck pilot) (mm)."""

    x: float
    y: float
    diameter: float
    purpose: str  # neck | neck_pilot | dowel | bolt | cap
    fit: str = ""
    taxel: str = ""
    drill_to: float | None = None

    @property
    def finished_mm(self) -> float:
        """The hole's finished diameter: drilled to, or as cut (mm)."""
        return self.diameter if self.drill_to is None else self.drill_to


@dataclass(frozen=True)
class Engraving:
    """Text to engrave: baseline start (x, y) and cap height (mm)."""

    x: float
    y: float
    height: float
    text: str


EM_PER_CAP = 0.62 / 0.729
"""Mean advance of a DejaVu Sans character per capital height (for placing labels; the exporter draws them)."""


CAP_HEIGHT_PER_SIZE = 0.729
"""DejaVu Sans capital height / font size: an Engraving's height is its capital height."""


GLYPH_TABLE_MAX_MM = 4.0
"""Tallest engraving drawn from glyphs.json: matplotlib flattens a glyph's curves into more points once it is larger
(from ~6 mm capitals), so taller text goes to matplotlib; up to here the table gives matplotlib's points exactly
(tests/test_fast_pictures.py)."""


def engraving_outlines(t) -> list[list[tuple[float, float]]]:
    """An :class:`~matcad.parts.flat.Engraving` as closed glyph outlines (mm): the text converted to polygons
    with DejaVu Sans (shipped with matplotlib, so every machine draws the same shapes), baseline at (t.x, t.y),
    capitals t.height tall. Lasers engrave or score the outlines, printed parts recess them
    (:func:`matcad.parts.solid.engraved`); no font is needed on the laser's or printer's computer. Printable ASCII
    comes from glyphs.json (matplotlib's outlines and spacing, tabulated by benchmarks/glyph_table.py: no
    matplotlib import on a laser-only build) up to :data:`GLYPH_TABLE_MAX_MM` tall; any other text is laid out
    by matplotlib itself."""
    size = t.height / CAP_HEIGHT_PER_SIZE
    table = glyph_table()
    glyphs, pairs = table["glyphs"], table["pairs"]
    if (t.height <= GLYPH_TABLE_MAX_MM and all(c in glyphs for c in t.text)
            and not any(j in t.text for j in table["joined"])):
        out, x = [], 0.0
        for k, c in enumerate(t.text):
            if k:
                prev = t.text[k - 1]
                x += pairs.get(prev + c, glyphs[prev]["advance"])
            out += [[(t.x + (gx + x) * size, t.y + gy * size) for gx, gy in poly] for poly in glyphs[c]["polygons"]]
        return out
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    path = TextPath((0.0, 0.0), t.text, size=size, prop=FontProperties(family="DejaVu Sans"))
    return [[(t.x + float(x), t.y + float(y)) for x, y in poly[:-1]]
            for poly in path.to_polygons(closed_only=True) if len(poly) > 3]


@functools.cache
def glyph_table() -> dict:
    """glyphs.json: per printable ASCII character its outlines at font size 1 and its advance; kerned pairs'
    spacing; pairs the shaper joins (those texts go to matplotlib)."""
    import json

    return json.loads((Path(__file__).parent / "glyphs.json").read_text(encoding="utf-8"))


def _inside(point, poly) -> bool:
    """Even-odd ray test: is ``point`` inside polygon ``poly`` (mm)."""
    x, y = point
    inside = False
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def even_odd_faces(outlines) -> list[tuple[list, list[list]]]:
    """Glyph outlines grouped as filled regions under the even-odd rule: (outer loop, its inner loops) per
    region. A loop inside an even number of others is an outer boundary; one inside an odd number is a hole
    (the counter of 0, 6, 8, 9) of the smallest outer loop around it (mm; PostScript/SVG even-odd fill)."""
    def containers(i):
        return [j for j, other in enumerate(outlines) if j != i and _inside(outlines[i][0], other)]

    depth = {i: containers(i) for i in range(len(outlines))}
    outers = [i for i, c in depth.items() if len(c) % 2 == 0]
    return [(outlines[i], [outlines[k] for k, c in depth.items()
                           if len(c) == len(depth[i]) + 1 and i in c]) for i in outers]


def edge_label(text: str, width: float, depth: float, holes, height: float = 1.0, margin: float = 0.6):
    """A part label engraved along the bottom (else top) edge of a width x depth part, clear of every hole by
    ``margin``; () when it fits nowhere (mm)."""
    length = len(text) * EM_PER_CAP * height
    if length + 2 * margin > width:
        return ()
    for y0 in (-depth / 2 + margin, depth / 2 - margin - height):
        box = (-length / 2 - margin, y0 - margin, length / 2 + margin, y0 + height + margin)
        if all(h.x + h.diameter / 2 < box[0] or h.x - h.diameter / 2 > box[2] or h.y + h.diameter / 2 < box[1]
               or h.y - h.diameter / 2 > box[3] for h in holes):
            return (Engraving(-length / 2, y0, height, text),)
    return ()


@dataclass(frozen=True)
class Flat:
    """A laser-cut part: rectangular outline centred on the origin, holes, engraved text (mm)."""

    name: str
    thickness: float
    thickness_measured: bool  # calipered, or a template's example of a calipered value (thickness_example)
    kerf: float  # full kerf of this part's sheet (see features.sheet_kerf_mm)
    width: float
    depth: float
    holes: tuple[Hole, ...]
    engrave: tuple[Engraving, ...] = ()
    quantity: int = 1
    corner_radius: float = 0.5
    thickness_example: bool = False  # the measured thickness is a template's example, not the user's sheet
    sheet: str = ""  # the acrylic sheet it is cut from (a key of features.SHEETS)

    @property
    def area_mm2(self) -> float:
        return self.width * self.depth

    @property
    def thickness_status(self) -> str:
        """'measured', 'example' or 'nominal' (:data:`matcad.parts.features.SHEET_STATUSES`)."""
        if not self.thickness_measured:
            return "nominal"
        return "example" if self.thickness_example else "measured"


@dataclass(frozen=True)
class CutCircle:
    x: float
    y: float
    diameter: float
    finished_diameter: float
    compensation: float
    purpose: str


@dataclass(frozen=True)
class CutPlan:
    """What the laser follows: outline(s), inner circles, engraving, reference, with compensation declared."""

    flat: Flat
    kerf: float
    outlines: tuple[tuple[float, float, float, float, float], ...]  # x0, y0, x1, y1, corner radius
    circles: tuple[CutCircle, ...]
    texts: tuple[Engraving, ...] = ()
    reference_square: tuple[float, float, float] | None = None  # x0, y0, side
    extents: tuple[float, float, float, float] = field(default=(0, 0, 0, 0))
    parts: tuple[str, ...] = ()  # a nested sheet's parts (matcad.export.sheets); () for one part's plan


class DrawnSizeError(ValueError):
    """A feature whose drawn (kerf-compensated) size is not a real size: nothing can be drawn or cut."""


def drawn_diameter_mm(finished_mm: float, kerf_mm: float) -> float:
    """Diameter the laser must follow for a hole of ``finished_mm``: the finished size minus the full kerf
    (the beam removes kerf/2 on each side of the line), mm."""
    return finished_mm - kerf_mm


def drawn_holes(flat: Flat, kerf: float) -> list[tuple[Hole, float]]:
    """Every hole of ``flat`` with the diameter it is drawn at (mm), smallest first."""
    return sorted(((h, drawn_diameter_mm(h.diameter, kerf)) for h in flat.holes), key=lambda hd: hd[1])


def check_drawable(flat: Flat) -> None:
    """Raises :class:`DrawnSizeError` when a hole of ``flat`` would be drawn at a diameter ≤ 0 (a hole smaller than
    the kerf): the design rule ``laser.drawn_size`` reports the same thing, naming the spec field, before any
    build."""
    for hole, drawn in drawn_holes(flat, flat.kerf):
        if drawn <= 0:
            raise DrawnSizeError(f"{flat.name}: {hole.purpose} hole of {hole.diameter:g} mm would be drawn at "
                                 f"{drawn:g} mm after the {flat.kerf:g} mm kerf; it must be drawn > 0 mm")


def _copies_x(flat: Flat, spacing: float) -> list[float]:
    """x offset of each of the ``quantity`` copies of ``flat`` laid side by side ``spacing`` apart (mm)."""
    return [i * (flat.width + flat.kerf + spacing) for i in range(flat.quantity)]


def cut_outlines(flat: Flat, spacing: float = 3.0) -> tuple[tuple[float, float, float, float, float], ...]:
    """The outline of each copy of ``flat`` as the laser follows it, grown by kerf/2 (x0, y0, x1, y1, corner radius;
    mm), copies side by side ``spacing`` apart: :func:`cut_plan`'s outlines."""
    half = flat.kerf / 2
    return tuple((dx - flat.width / 2 - half, -flat.depth / 2 - half, dx + flat.width / 2 + half,
                  flat.depth / 2 + half, flat.corner_radius + half) for dx in _copies_x(flat, spacing))


def cut_plan(flat: Flat, reference_square: bool, spacing: float = 3.0) -> CutPlan:
    """Apply the sheet's kerf compensation (outline +kerf/2, holes −kerf/2) and lay out ``quantity`` copies.

    Raises :class:`DrawnSizeError` when a hole would be drawn at a diameter ≤ 0 (:func:`check_drawable`).
    """
    check_drawable(flat)
    kerf = flat.kerf
    half = kerf / 2
    outlines = cut_outlines(flat, spacing)
    circles = [CutCircle(dx + h.x, h.y, drawn_diameter_mm(h.diameter, kerf), h.diameter, -kerf, h.purpose)
               for dx in _copies_x(flat, spacing) for h in flat.holes]
    x_max = outlines[-1][2]
    square = None
    if reference_square:
        square = (x_max + spacing, -flat.depth / 2, REFERENCE_SQUARE_MM)
        x_max = square[0] + REFERENCE_SQUARE_MM
    y_max = max(flat.depth / 2 + half, -flat.depth / 2 + REFERENCE_SQUARE_MM if square else 0)
    extents = (outlines[0][0], -flat.depth / 2 - half, x_max, y_max)
    return CutPlan(flat, kerf, outlines, tuple(circles), flat.engrave, square, extents)
