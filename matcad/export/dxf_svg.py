"""DXF and SVG writers for laser cut plans. Units mm everywhere; one layer / colour per operation.

DXF: $INSUNITS = 4 (mm), native CIRCLE, closed LWPOLYLINE outlines with bulge arcs (no splines), layers
ENGRAVE (text as closed glyph outlines, never font text), CUT_INNER, CUT_OUTER, REFERENCE with distinct ACI
colours, written in that order so a laser that follows file order engraves and cuts every hole (of every part on a
nested sheet) before it frees any part. The bytes are ezdxf's (its R2010 document kept as dxf_template.txt, the
entities written here), so a build never imports ezdxf; :func:`write_dxf_ezdxf` is the reference they are
checked against.
SVG: width/height in mm with a matching viewBox (1 user unit = 1 mm), one stroke colour per operation — for
Glowforge-class lasers that read SVG, not DXF.
"""

from __future__ import annotations

import math
from pathlib import Path
from html import escape as _html_escape

from matcad.parts.flat import CutPlan, engraving_outlines

LAYERS = {
    # name: (DXF ACI colour, SVG stroke, meaning), in cutting order
    "ENGRAVE": (3, "#00a000", "engrave/score first, do not cut through"),
    "CUT_INNER": (5, "#0000ff", "cut through, inner features (holes) before any outline"),
    "CUT_OUTER": (1, "#ff0000", "cut through, part outlines last"),
    "REFERENCE": (6, "#ff00ff", "10 mm reference square to check scale on import; do not cut"),
}
QUARTER_BULGE = math.tan(math.pi / 8)


def escape(text: str) -> str:
    """``&``, ``<`` and ``>`` as XML entities (what xml.sax.saxutils.escape does; that module imports urllib.request,
    http and ssl: ~20 ms of a laser-only build)."""
    return _html_escape(text, quote=False)  # bulge of a 90° arc


def rounded_rect_points(x0, y0, x1, y1, r):
    """Closed rounded rectangle as (x, y, bulge) vertices, counter-clockwise (mm)."""
    r = max(0.0, min(r, (x1 - x0) / 2, (y1 - y0) / 2))
    if r == 0:
        return [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)]
    b = QUARTER_BULGE
    return [(x0 + r, y0, 0.0), (x1 - r, y0, b), (x1, y0 + r, 0.0), (x1, y1 - r, b),
            (x1 - r, y1, 0.0), (x0 + r, y1, b), (x0, y1 - r, 0.0), (x0, y0 + r, b)]


FIRST_HANDLE = 0x34
"""The first entity handle of the template document (ezdxf's R2010 document with the four layers)."""
TEMPLATE = Path(__file__).parent / "dxf_template.txt"
"""ezdxf's R2010 document with the layers and no entity, its handle-dependent values as {appid1}, {appid2}, {dict},
{seed} and the entities as {entities} (built by :func:`dxf_template`, checked by tests/test_fast_pictures.py)."""


def write_dxf(plan: CutPlan, path: Path) -> None:
    """Write ``plan`` as DXF R2010 in mm, byte-for-byte reproducible (no creation time, GUIDs or timestamps): the
    same bytes ezdxf writes (:func:`write_dxf_ezdxf`), the entities' group codes written here into ezdxf's document
    template, so that a build does not import ezdxf (its import alone costs more than numpy's)."""
    out: list[str] = []
    handle = FIRST_HANDLE

    def lwpolyline(points, layer: str) -> None:
        nonlocal handle
        out.append(f"  0\nLWPOLYLINE\n  5\n{handle:X}\n330\n17\n100\nAcDbEntity\n  8\n{layer}\n100\nAcDbPolyline\n"
                   f" 90\n{len(points)}\n 70\n1\n")
        for p in points:
            out.append(f" 10\n{float(p[0])!r}\n 20\n{float(p[1])!r}\n")
            if len(p) > 2 and p[2]:
                out.append(f" 42\n{float(p[2])!r}\n")
        handle += 1

    for t in plan.texts:
        for outline in engraving_outlines(t):
            lwpolyline(outline, "ENGRAVE")
    for c in plan.circles:
        out.append(f"  0\nCIRCLE\n  5\n{handle:X}\n330\n17\n100\nAcDbEntity\n  8\nCUT_INNER\n100\nAcDbCircle\n"
                   f" 10\n{float(c.x)!r}\n 20\n{float(c.y)!r}\n 30\n0.0\n 40\n{float(c.diameter / 2)!r}\n")
        handle += 1
    for x0, y0, x1, y1, r in plan.outlines:
        lwpolyline(rounded_rect_points(x0, y0, x1, y1, r), "CUT_OUTER")
    if plan.reference_square:
        x0, y0, side = plan.reference_square
        lwpolyline(rounded_rect_points(x0, y0, x0 + side, y0 + side, 0.0), "REFERENCE")
    text = TEMPLATE.read_text(encoding="utf-8")
    for key, value in (("{appid1}", handle), ("{appid2}", handle + 1), ("{dict}", handle + 2), ("{seed}", handle + 3),
                       ("{entities}", None)):
        text = text.replace(key, "".join(out) if value is None else f"{value:X}")
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def write_dxf_ezdxf(plan: CutPlan, path: Path) -> None:
    """The reference writer: ``plan`` through ezdxf (R2010, fixed meta data). :func:`write_dxf` writes the same
    bytes without importing ezdxf; this one builds and checks its template."""
    import ezdxf

    fixed, ezdxf.options.write_fixed_meta_data_for_testing = ezdxf.options.write_fixed_meta_data_for_testing, True
    try:
        _write_dxf(plan, path)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = fixed


def dxf_template(plan: CutPlan, folder: Path) -> str:
    """The text of :data:`TEMPLATE`: ezdxf's documents for ``plan`` (one with at least a hole) stripped of its
    entities and with one hole, compared line by line: the lines that differ are the handles given after the
    entities (two APPIDs, a dictionary referenced twice, the handle seed), each one higher with one more entity."""
    from dataclasses import replace

    texts = []
    for k, circles in enumerate(((), plan.circles[:1])):
        write_dxf_ezdxf(replace(plan, texts=(), circles=circles, outlines=(), reference_square=None),
                        folder / f"{k}.dxf")
        texts.append((folder / f"{k}.dxf").read_text(encoding="utf-8").split("\n"))
    a, b = texts
    start = a.index("ENTITIES") + 1
    assert a[start:start + 2] == ["  0", "ENDSEC"] and len(b) == len(a) + 20  # a CIRCLE is 10 tags
    b = b[:start] + b[start + 20:]
    changed = sorted({x for x, y in zip(a, b) if x != y}, key=lambda v: int(v, 16))
    assert len(changed) == 4 and all(int(y, 16) == int(x, 16) + 1 for x, y in zip(a, b) if x != y)
    names = dict(zip(changed, ("{appid1}", "{appid2}", "{dict}", "{seed}")))
    assert int(changed[0], 16) == FIRST_HANDLE
    lines = [names[x] if x != y else x for x, y in zip(a, b)]
    return "\n".join(lines[:start]) + "\n{entities}" + "\n".join(lines[start:])


def _write_dxf(plan: CutPlan, path: Path) -> None:
    import ezdxf
    from ezdxf import units

    doc = ezdxf.new("R2010", setup=False)
    doc.units = units.MM
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    for name, (aci, _, meaning) in LAYERS.items():
        doc.layers.add(name, color=aci).description = meaning
    msp = doc.modelspace()
    for t in plan.texts:
        for outline in engraving_outlines(t):
            msp.add_lwpolyline(outline, format="xy", close=True, dxfattribs={"layer": "ENGRAVE"})
    for c in plan.circles:
        msp.add_circle((c.x, c.y), c.diameter / 2, dxfattribs={"layer": "CUT_INNER"})
    for x0, y0, x1, y1, r in plan.outlines:
        msp.add_lwpolyline(rounded_rect_points(x0, y0, x1, y1, r), format="xyb", close=True,
                           dxfattribs={"layer": "CUT_OUTER"})
    if plan.reference_square:
        x0, y0, side = plan.reference_square
        msp.add_lwpolyline(rounded_rect_points(x0, y0, x0 + side, y0 + side, 0.0), format="xyb", close=True,
                           dxfattribs={"layer": "REFERENCE"})
    for dxftype in sorted(doc.entitydb.dxf_types_in_use()):  # CLASSES in a fixed order, not set (hash) order
        doc.classes.add_class(dxftype)
    doc.saveas(path)


def _svg_rounded_rect(x0, y0, x1, y1, r) -> str:
    # SVG y grows downward: mirror y so the drawing matches the DXF
    r = max(0.0, min(r, (x1 - x0) / 2, (y1 - y0) / 2))
    top, bottom = -y1, -y0
    arc = f"A {r:.6f} {r:.6f} 0 0 1"
    return (f"M {x0 + r:.6f} {top:.6f} H {x1 - r:.6f} {arc} {x1:.6f} {top + r:.6f} V {bottom - r:.6f} "
            f"{arc} {x1 - r:.6f} {bottom:.6f} H {x0 + r:.6f} {arc} {x0:.6f} {bottom - r:.6f} "
            f"V {top + r:.6f} {arc} {x0 + r:.6f} {top:.6f} Z")


def write_svg(plan: CutPlan, path: Path) -> None:
    """Write ``plan`` as SVG with mm size and a 1 unit = 1 mm viewBox; a group per operation."""
    x0, y0, x1, y1 = plan.extents
    margin = 1.0
    vx, vy = x0 - margin, -y1 - margin
    w, h = x1 - x0 + 2 * margin, y1 - y0 + 2 * margin
    stroke = {name: colour for name, (_, colour, _) in LAYERS.items()}
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.6f}mm" height="{h:.6f}mm" '
           f'viewBox="{vx:.6f} {vy:.6f} {w:.6f} {h:.6f}">',
           f"<title>{escape(plan.flat.name)} ({plan.flat.thickness:g} mm sheet, kerf {plan.kerf:g} mm "
           "compensated)</title>"]
    group = 'fill="none" stroke-width="0.1"'
    if plan.texts:
        out.append(f'<g id="ENGRAVE" fill="{stroke["ENGRAVE"]}" stroke="none">')
        for t in plan.texts:
            d = " ".join("M " + " L ".join(f"{x:.4f} {-y:.4f}" for x, y in outline) + " Z"
                         for outline in engraving_outlines(t))
            out.append(f'<path d="{d}" fill-rule="evenodd"><title>{escape(t.text)}</title></path>')
        out.append("</g>")
    out.append(f'<g id="CUT_INNER" stroke="{stroke["CUT_INNER"]}" {group}>')
    out += [f'<circle cx="{c.x:.6f}" cy="{-c.y:.6f}" r="{c.diameter / 2:.6f}"/>' for c in plan.circles]
    out.append("</g>")
    out.append(f'<g id="CUT_OUTER" stroke="{stroke["CUT_OUTER"]}" {group}>')
    out += [f'<path d="{_svg_rounded_rect(*o)}"/>' for o in plan.outlines]
    out.append("</g>")
    if plan.reference_square:
        sx, sy, side = plan.reference_square
        out.append(f'<g id="REFERENCE" stroke="{stroke["REFERENCE"]}" {group}>'
                   f'<rect x="{sx:.6f}" y="{-(sy + side):.6f}" width="{side:.6f}" height="{side:.6f}"/></g>')
    out.append("</svg>")
    Path(path).write_text("\n".join(out) + "\n", encoding="utf-8")
