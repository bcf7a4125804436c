"""The kit's sheets on paper at 1:1 (sheets_1to1.pdf): one page per nested sheet (:mod:`matcad.export.sheets`),
every cut and engraving at its real size, with a 10 mm reference square and a 50 mm scale bar, to check on paper
that a printer, a PDF viewer or the laser's software keeps the scale, and to lay real parts on the drawing before
cutting. Units mm; written directly as PDF operators (pt = mm · 72 / 25.4), no plotting library.
"""

from __future__ import annotations

import math
from pathlib import Path

from matcad.export.dxf_svg import LAYERS
from matcad.parts.flat import CutPlan, engraving_outlines

MM_PER_INCH = 25.4
PAGES_MM = {"A4": (210.0, 297.0), "A3": (297.0, 420.0)}
"""Paper sizes tried, smallest first, upright or turned (mm); a sheet larger than A3 gets a page of its own size."""
MARGIN_MM = 15.0
HEADER_MM = 26.0
"""Room above the drawing for the title, the instruction and the scale bar (mm)."""
SCALE_BAR_MM = 50.0
LINE_PT = 0.3
INSTRUCTION = ("Print at 100 % (actual size, no 'fit to page'): the square must measure 10.0 mm and the bar "
               "50.0 mm.\nLay the parts you cut on their outlines.")


def page_size_mm(plan: CutPlan) -> tuple[float, float, str]:
    """(width, height, name) of the smallest page of :data:`PAGES_MM`, upright or turned, that holds the sheet with
    its margins and header; else a page of the sheet's own size (mm)."""
    x0, y0, x1, y1 = plan.extents
    need_w = x1 - x0 + 2 * MARGIN_MM
    need_h = y1 - y0 + 2 * MARGIN_MM + HEADER_MM
    for name, (w, h) in PAGES_MM.items():
        for pw, ph in ((w, h), (h, w)):
            if need_w <= pw and need_h <= ph:
                return pw, ph, name
    return math.ceil(need_w), math.ceil(need_h), "custom"


def _rounded_outline(x0, y0, x1, y1, r, steps: int = 12) -> list[tuple[float, float]]:
    """A rounded rectangle's outline as points, counter-clockwise (mm)."""
    r = max(0.0, min(r, (x1 - x0) / 2, (y1 - y0) / 2))
    corners = ((x1 - r, y0 + r, -90.0), (x1 - r, y1 - r, 0.0), (x0 + r, y1 - r, 90.0), (x0 + r, y0 + r, 180.0))
    pts = []
    for cx, cy, a0 in corners:
        for k in range(steps + 1):
            a = math.radians(a0 + 90.0 * k / steps)
            pts.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    return pts


class _Page:
    """One page's content stream in PDF operators; coordinates in mm from the page's bottom left (drawn in pt)."""

    K = 72.0 / MM_PER_INCH

    def __init__(self):
        self.ops: list[str] = []

    def _xy(self, x: float, y: float) -> str:
        return f"{x * self.K:.3f} {y * self.K:.3f}"

    def colour(self, hexcolour: str, fill: bool = False) -> None:
        r, g, b = (int(hexcolour[k:k + 2], 16) / 255 for k in (1, 3, 5))
        self.ops.append(f"{r:.4g} {g:.4g} {b:.4g} {'rg' if fill else 'RG'}")

    def width(self, pt: float) -> None:
        self.ops.append(f"{pt:g} w")

    def path(self, points, close: bool = True) -> None:
        self.ops.append(f"{self._xy(*points[0])} m " + " ".join(f"{self._xy(*p)} l" for p in points[1:])
                        + (" h" if close else ""))

    def circle(self, cx: float, cy: float, r: float) -> None:
        """Four Bézier quarters (the usual 0.5523 handle: within 0.03 % of the radius)."""
        k = 0.5522847498 * r
        quarters = (((cx + r, cy + k), (cx + k, cy + r), (cx, cy + r)), ((cx - k, cy + r), (cx - r, cy + k), (cx - r, cy)),
                    ((cx - r, cy - k), (cx - k, cy - r), (cx, cy - r)), ((cx + k, cy - r), (cx + r, cy - k), (cx + r, cy)))
        self.ops.append(f"{self._xy(cx + r, cy)} m " + " ".join(" ".join(self._xy(*p) for p in q) + " c"
                                                                 for q in quarters) + " h")

    def stroke(self) -> None:
        self.ops.append("S")

    def fill_even_odd(self) -> None:
        self.ops.append("f*")

    def text(self, x: float, y: float, s: str, size_pt: float, hexcolour: str = "#000000", align: str = "left",
             top: bool = True) -> None:
        """``s`` in Helvetica at ``size_pt``; (x, y) its left (centre, with ``align='center'``) and its top (else
        its middle) in mm; one line per newline."""
        self.colour(hexcolour, fill=True)
        lead = 1.2 * size_pt / self.K
        lines = s.split("\n")
        y0 = y - 0.8 * size_pt / self.K if top else y - 0.35 * size_pt / self.K + (len(lines) - 1) * lead / 2
        for k, line in enumerate(lines):
            x0 = x - (0.5 * size_pt * 0.55 * len(line) / self.K if align == "center" else 0.0)
            data = line.encode("cp1252", "replace").replace(b"\\", b"\\\\").replace(b"(", b"\\(").replace(b")", b"\\)")
            self.ops.append(f"BT /F1 {size_pt:g} Tf {self._xy(x0, y0 - k * lead)} Td (" + data.decode("latin-1")
                            + ") Tj ET")

    def stream(self) -> bytes:
        return ("\n".join(self.ops) + "\n").encode("latin-1")


def _draw_page(plan: CutPlan, page: tuple[float, float, str]) -> bytes:
    """One sheet's page: outlines, holes, engravings, reference square, title, instruction and scale bar."""
    pw, ph, name = page
    pg = _Page()
    x0, y0, x1, y1 = plan.extents
    dx, dy = MARGIN_MM - x0, ph - MARGIN_MM - HEADER_MM - y1  # the sheet's top left under the header
    colour = {layer: stroke for layer, (_, stroke, _) in LAYERS.items()}
    pg.width(LINE_PT)
    pg.colour(colour["CUT_OUTER"])
    for ox0, oy0, ox1, oy1, r in plan.outlines:
        pg.path([(x + dx, y + dy) for x, y in _rounded_outline(ox0, oy0, ox1, oy1, r)])
        pg.stroke()
    pg.colour(colour["CUT_INNER"])
    for c in plan.circles:
        pg.circle(c.x + dx, c.y + dy, c.diameter / 2)
        pg.stroke()
    if plan.texts:
        pg.colour(colour["ENGRAVE"], fill=True)
        for t in plan.texts:
            for loop in engraving_outlines(t):
                pg.path([(x + dx, y + dy) for x, y in loop])
            pg.fill_even_odd()
    if plan.reference_square:
        sx, sy, side = plan.reference_square
        pg.colour(colour["REFERENCE"])
        pg.path([(sx + dx, sy + dy), (sx + dx + side, sy + dy), (sx + dx + side, sy + dy + side),
                 (sx + dx, sy + dy + side)])
        pg.stroke()
        pg.text(sx + dx + side / 2, sy + dy - 1.5, f"{side:g} mm", 6, colour["REFERENCE"], align="center")
    top = ph - MARGIN_MM
    pg.text(MARGIN_MM, top, f"{plan.flat.name}: {plan.flat.thickness:g} mm acrylic ({plan.flat.thickness_status}), "
            f"kerf {plan.kerf:g} mm compensated ({name} page)", 8)
    pg.text(MARGIN_MM, top - 4.5, f"parts: {', '.join(plan.parts) or plan.flat.name}", 7)
    pg.text(MARGIN_MM, top - 8.5, INSTRUCTION, 6.5)
    bar_y = top - 17
    pg.colour("#000000")
    pg.width(1.0)
    pg.path([(MARGIN_MM, bar_y), (MARGIN_MM + SCALE_BAR_MM, bar_y)], close=False)
    pg.stroke()
    pg.width(LINE_PT)
    for k in range(int(SCALE_BAR_MM / 10) + 1):
        x = MARGIN_MM + 10 * k
        pg.path([(x, bar_y), (x, bar_y + 2)], close=False)
        pg.stroke()
    pg.text(MARGIN_MM + SCALE_BAR_MM + 2, bar_y, f"{SCALE_BAR_MM:g} mm", 7, top=False)
    return pg.stream()


def write_scale_pdf(plans: list[CutPlan], path: Path) -> list[dict]:
    """One page per sheet plan at 1:1, byte-for-byte reproducible (no dates, no producer); returns each page's
    sheet, page size (mm) and name. Written directly (PDF 1.4: vector paths, Helvetica in WinAnsi encoding, each
    page's content deflated): no plotting library on the laser path."""
    import zlib

    pages, objects = [], [b"", b"", b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica /Encoding /WinAnsiEncoding >>"]
    kids = []
    for plan in plans:
        page = page_size_mm(plan)
        content = zlib.compress(_draw_page(plan, page), 6)
        objects.append(b"<< /Length %d /Filter /FlateDecode >>\nstream\n" % len(content) + content + b"\nendstream")
        w, h = page[0] * _Page.K, page[1] * _Page.K
        objects.append(f"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {w:.3f} {h:.3f}] /Resources << /Font << /F1 3 0 R "
                       f">> >> /Contents {len(objects)} 0 R >>".encode())
        kids.append(f"{len(objects)} 0 R")
        pages.append({"sheet": plan.flat.name, "width_mm": page[0], "height_mm": page[1], "page": page[2]})
    objects[0] = b"<< /Type /Catalog /Pages 2 0 R >>"
    objects[1] = f"<< /Type /Pages /Kids [{' '.join(kids)}] /Count {len(kids)} >>".encode()
    out = bytearray(b"%PDF-1.4\n%\xe2\xe3\xcf\xd3\n")
    offsets = []
    for k, body in enumerate(objects, start=1):
        offsets.append(len(out))
        out += b"%d 0 obj\n" % k + body + b"\nendobj\n"
    xref = len(out)
    out += b"xref\n0 %d\n0000000000 65535 f \n" % (len(objects) + 1)
    out += b"".join(b"%010d 00000 n \n" % o for o in offsets)
    out += b"trailer\n<< /Size %d /Root 1 0 R >>\nstartxref\n%d\n%%%%EOF\n" % (len(objects) + 1, xref)
    Path(path).write_bytes(bytes(out))
    return pages
