"""The kit's sheets on paper at 1:1 (sheets_1to1.pdf): one page per nested sheet (:mod:`matcad.export.sheets`),
every cut and engraving at its real size, with a 10 mm reference square and a 50 mm scale bar, to check on paper
that a printer, a PDF viewer or the laser's software keeps the scale, and to lay real parts on the drawing before
cutting. Units mm; matplotlib's PDF backend, figures sized in inches so one drawing unit is one millimetre.
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


def _draw_page(fig, plan: CutPlan, page: tuple[float, float, str]) -> None:
    from matplotlib.patches import Circle, PathPatch, Polygon, Rectangle
    from matplotlib.path import Path as MplPath

    pw, ph, name = page
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, pw)
    ax.set_ylim(0, ph)
    ax.set_axis_off()
    x0, y0, x1, y1 = plan.extents
    dx, dy = MARGIN_MM - x0, ph - MARGIN_MM - HEADER_MM - y1  # the sheet's top left under the header
    colour = {layer: stroke for layer, (_, stroke, _) in LAYERS.items()}
    for ox0, oy0, ox1, oy1, r in plan.outlines:
        ax.add_patch(Polygon([(x + dx, y + dy) for x, y in _rounded_outline(ox0, oy0, ox1, oy1, r)], closed=True,
                             fill=False, edgecolor=colour["CUT_OUTER"], linewidth=LINE_PT))
    for c in plan.circles:
        ax.add_patch(Circle((c.x + dx, c.y + dy), c.diameter / 2, fill=False, edgecolor=colour["CUT_INNER"],
                            linewidth=LINE_PT))
    for t in plan.texts:
        loops = engraving_outlines(t)
        vertices = [(x + dx, y + dy) for loop in loops for x, y in loop + loop[:1]]
        codes = [code for loop in loops for code in [MplPath.MOVETO] + [MplPath.LINETO] * (len(loop) - 1)
                 + [MplPath.CLOSEPOLY]]
        ax.add_patch(PathPatch(MplPath(vertices, codes), facecolor=colour["ENGRAVE"], edgecolor="none"))
    if plan.reference_square:
        sx, sy, side = plan.reference_square
        ax.add_patch(Rectangle((sx + dx, sy + dy), side, side, fill=False, edgecolor=colour["REFERENCE"],
                               linewidth=LINE_PT))
        ax.text(sx + dx + side / 2, sy + dy - 1.5, f"{side:g} mm", ha="center", va="top", fontsize=6,
                color=colour["REFERENCE"])
    top = ph - MARGIN_MM
    ax.text(MARGIN_MM, top, f"{plan.flat.name}: {plan.flat.thickness:g} mm acrylic ({plan.flat.thickness_status}), "
            f"kerf {plan.kerf:g} mm compensated ({name} page)", ha="left", va="top", fontsize=8)
    ax.text(MARGIN_MM, top - 4.5, f"parts: {', '.join(plan.parts) or plan.flat.name}", ha="left", va="top",
            fontsize=7)
    ax.text(MARGIN_MM, top - 8.5, INSTRUCTION, ha="left", va="top", fontsize=6.5, wrap=True)
    bar_y = top - 17
    ax.plot([MARGIN_MM, MARGIN_MM + SCALE_BAR_MM], [bar_y, bar_y], color="black", linewidth=1.0,
            solid_capstyle="butt")
    for k in range(int(SCALE_BAR_MM / 10) + 1):
        x = MARGIN_MM + 10 * k
        ax.plot([x, x], [bar_y, bar_y + 2], color="black", linewidth=LINE_PT)
    ax.text(MARGIN_MM + SCALE_BAR_MM + 2, bar_y, f"{SCALE_BAR_MM:g} mm", ha="left", va="center", fontsize=7)


def write_scale_pdf(plans: list[CutPlan], path: Path) -> list[dict]:
    """One page per sheet plan at 1:1, byte-for-byte reproducible (no dates, no producer); returns each page's
    sheet, page size (mm) and name."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    pages = []
    with PdfPages(path, metadata={"Creator": None, "Producer": None, "CreationDate": None}) as pdf:
        for plan in plans:
            page = page_size_mm(plan)
            fig = Figure(figsize=(page[0] / MM_PER_INCH, page[1] / MM_PER_INCH))
            FigureCanvasAgg(fig)
            _draw_page(fig, plan, page)
            pdf.savefig(fig)
            pages.append({"sheet": plan.flat.name, "width_mm": page[0], "height_mm": page[1], "page": page[2]})
    return pages
