"""The assembly section (section.svg): the assembled parts cut by a plane, labelled and dimensioned in mm.

The section (:func:`write_section_svg`) is the assembly (:func:`matcad.parts.assembly.assembled_parts`) cut by
the XZ plane (neck and needle axis), plate underside z = 0. Every part present in it gets a name with a leader,
and the design's dimensions are drawn to scale from the spec: D, L (cavity), d, l (neck), the cap's outer
diameter and top thickness, the spacer gap, the needle angle θ and its offset y (paper Fig. 2 names). SVG user
unit = 1 mm; the drawing's y axis points down, so a point (x, z) of the assembly frame is drawn at (x, −z).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

SVG_NS = "http://www.w3.org/2000/svg"
INK = "#203060"
NEEDLE_LABEL = "air-supply needle"
NEEDLE_COLOUR = "#404040"
"""Section fill of the bought needle (drawn for clearance; not a registered part)."""


@dataclass
class _Drawing:
    """SVG elements in drawing coordinates (mm, y down) and their running bounding box."""

    font: float
    elements: list = field(default_factory=list)
    box: list = field(default_factory=lambda: [math.inf, math.inf, -math.inf, -math.inf])

    def _grow(self, x, y):
        self.box = [min(self.box[0], x), min(self.box[1], y), max(self.box[2], x), max(self.box[3], y)]

    def line(self, x0, z0, x1, z1, colour=INK, role="line"):
        self._grow(x0, -z0)
        self._grow(x1, -z1)
        self.elements.append(("line", {"x1": x0, "y1": -z0, "x2": x1, "y2": -z1, "stroke": colour,
                                       "stroke-width": self.font / 14, "class": role}))

    def arrow(self, x, z, dx, dz):
        """Filled arrow head with its tip at (x, z), pointing along (dx, dz)."""
        n = math.hypot(dx, dz) or 1.0
        ux, uz = dx / n, dz / n
        size = self.font * 0.55
        bx, bz = x - ux * size, z - uz * size
        pts = [(x, z), (bx - uz * size / 3, bz + ux * size / 3), (bx + uz * size / 3, bz - ux * size / 3)]
        for px, pz in pts:
            self._grow(px, -pz)
        self.elements.append(("polygon", {"points": " ".join(f"{px:.4f},{-pz:.4f}" for px, pz in pts),
                                          "fill": INK}))

    def text(self, x, z, text, anchor="middle", size=None):
        size = size or self.font
        width = 0.56 * size * len(text)
        left = {"start": x, "middle": x - width / 2, "end": x - width}[anchor]
        self._grow(left, -z - size)
        self._grow(left + width, -z + 0.3 * size)
        self.elements.append(("text", {"x": x, "y": -z, "font-size": size, "text-anchor": anchor, "fill": INK,
                                       "font-family": "sans-serif", "_text": text}))

    def dimension(self, a, b, at, label, vertical):
        """Dimension between coordinates ``a`` and ``b`` (x for horizontal, z for vertical), its line at ``at``
        on the other axis; arrows inward when there is room, outward otherwise."""
        pt = (lambda s: (at, s)) if vertical else (lambda s: (s, at))
        self.line(*pt(a), *pt(b), role="dimension")
        inward = abs(b - a) > 2.5 * self.font * 0.55
        sign = 1 if b > a else -1
        for end, direction in ((a, -sign), (b, sign)):
            d = direction if inward else -direction
            self.arrow(*pt(end), *((0, d) if vertical else (d, 0)))
            if not inward:
                self.line(*pt(end), *pt(end - d * self.font))
        mid = (a + b) / 2
        if vertical:
            self.text(at + 0.4 * self.font, mid - 0.35 * self.font, label, anchor="start")
        else:
            self.text(mid, at + 0.3 * self.font, label)


def _dimensions(spec, draw: _Drawing) -> None:
    from matcad.parts.features import needle_axis_mm
    from matcad.spec import cap_height_mm, neck_length_mm
    from matcad.parts.stack import mount_depth_mm

    D, L = spec.cavity.diameter, spec.cavity.length
    d, l = spec.neck.diameter, neck_length_mm(spec)  # the cap sits on its neck's top: plate, or riser run through
    od, top, gap = spec.end_cap.outer_diameter, spec.end_cap.top_thickness, spec.spacer.height
    f = draw.font
    z_top = l + cap_height_mm(spec)
    # horizontal dimensions stacked above the cap, extension lines up from the features they measure
    for i, (half, label, z_from) in enumerate(((d / 2, f"d = {d:g}", l), (D / 2, f"D = {D:g}", l + L),
                                               (od / 2, f"cap Ø {od:g}", z_top))):
        at = z_top + (1.6 + 1.7 * i) * f
        for x in (-half, half):
            draw.line(x, z_from, x, at + 0.3 * f, colour="#7080a0")
        draw.dimension(-half, half, at, label, vertical=False)
    # vertical chain on the right: spacer gap, l, L, top thickness
    x_feat = spec.plate.width / 2
    x_dim = x_feat + 1.5 * f
    chain = [(-gap, 0.0, f"gap {gap:g}", x_feat), (0.0, l, f"l = {l:g}", x_feat),
             (l, l + L, f"L = {L:g}", D / 2), (l + L, z_top, f"top {top:g}", od / 2)]
    for z0, z1, label, x_from in chain:
        for z in (z0, z1):
            draw.line(x_from, z, x_dim + 0.4 * f, z, colour="#7080a0")
        draw.dimension(z0, z1, x_dim, label, vertical=True)
    # the needle: θ to the plate underside, y from the axis' crossing to the neck's edge
    (px, _, _), (ux, _, uz) = needle_axis_mm(spec)
    theta = spec.needle.theta_deg
    r = 2.2 * f
    arc = [(px - r * math.cos(math.radians(a)), -r * math.sin(math.radians(a)))
           for a in [theta * k / 12 for k in range(13)]]
    for (x0, z0), (x1, z1) in zip(arc, arc[1:]):
        draw.line(x0, z0, x1, z1)
    draw.line(px, 0.0, px - (r + f), 0.0, colour="#7080a0")
    draw.line(px, 0.0, px - (r + f) * ux, -(r + f) * uz, colour="#7080a0")
    draw.text(px - r - 1.3 * f, -0.9 * f, f"θ = {theta:g}°", anchor="end")  # left of the arc, clear of the needle
    z_y = -mount_depth_mm(spec) - 1.2 * f
    for x in (px, -d / 2):
        draw.line(x, 0.0, x, z_y - 0.3 * f, colour="#7080a0")
    draw.dimension(px, -d / 2, z_y, f"y = {spec.needle.y:g}", vertical=False)


def _label_points(spec) -> dict[str, tuple[float, float]]:
    """A point inside each part of the section to start its leader from (assembly frame x, z; mm)."""
    from matcad.parts.features import needle_tip_mm
    from matcad.spec import cap_height_mm
    from matcad.parts.stack import cap_seat_z_mm, clamp_seat_z_mm, locator_z_mm

    w, l, g, gap = spec.plate.width, spec.neck.length, spec.guide.thickness, spec.spacer.height
    tip_x, _, tip_z = needle_tip_mm(spec)
    t = math.radians(spec.needle.theta_deg)
    return {
        "neck_plate": (-w / 2 + 1.0, l / 2), "riser": (-w / 2 + 1.0, (l + locator_z_mm(spec)) / 2),
        "guide_locator": (-w / 2 + 1.0, locator_z_mm(spec) + g / 2),
        "guide_clamp": (-w / 2 + 1.0, clamp_seat_z_mm(spec) + g / 2),
        "end_cap": (-spec.end_cap.outer_diameter / 4,
                    cap_seat_z_mm(spec) + cap_height_mm(spec) - spec.end_cap.top_thickness / 2),
        "needle_mount": (-w / 2 + 1.0, -gap - spec.mount.thickness / 2),
        "needle": (tip_x - 6.0 * math.cos(t), tip_z - 6.0 * math.sin(t)), "spacer": (w / 2 - 1.0, -gap / 2),
    }


def _labels(spec, present: set[str], draw: _Drawing) -> None:
    """Part names (each registered part's section label, and the needle's) in a column left of the drawing,
    leaders to a point in each part, spread so none overlap."""
    from matcad.parts.registry import parts

    names = {p.name: p.section_label for p in parts()} | {"needle": NEEDLE_LABEL}
    points = {name: xz for name, xz in _label_points(spec).items() if name in present}
    x_text = -spec.plate.width / 2 - 2.0 * draw.font
    z_prev = math.inf
    for name, (x, z) in sorted(points.items(), key=lambda kv: -kv[1][1]):
        z_text = min(z, z_prev - 1.5 * draw.font)
        z_prev = z_text
        draw.line(x, z, x_text + 0.3 * draw.font, z_text + 0.35 * draw.font, colour="#404040")
        draw.text(x_text, z_text, names[name], anchor="end")


def annotate_section(spec, path: Path, dimensions: bool = True) -> None:
    """Add part labels and the design's dimensions (mm) to the section SVG at ``path``, growing its canvas; each
    layer's paths are put in a fixed order so the same spec always gives the same bytes."""
    ET.register_namespace("", SVG_NS)
    tree = ET.parse(path)
    root = tree.getroot()
    present = {g.get("id") for g in root.iter(f"{{{SVG_NS}}}g") if g.get("id")}
    for g in root.iter(f"{{{SVG_NS}}}g"):  # the kernel's path order varies run to run; one layer's order is moot
        paths = [el for el in g if el.tag == f"{{{SVG_NS}}}path"]
        for el in paths:
            g.remove(el)
        g.extend(sorted(paths, key=lambda el: el.get("d", "")))
    x, y, w, h = (float(v) for v in root.get("viewBox").split())
    draw = _Drawing(font=max(0.5, 0.03 * max(w, h)))
    draw.box = [x, y, x + w, y + h]
    if dimensions:
        _dimensions(spec, draw)
    _labels(spec, present, draw)
    draw.text(0.0, -draw.box[3] - 1.2 * draw.font, "section through the neck and needle axes; mm")
    group = ET.SubElement(root, f"{{{SVG_NS}}}g", {"id": "dimensions"})
    for tag, attrs in draw.elements:
        text = attrs.pop("_text", None)
        el = ET.SubElement(group, f"{{{SVG_NS}}}{tag}",
                           {k: f"{v:.4f}" if isinstance(v, float) else str(v) for k, v in attrs.items()})
        el.text = text
    pad = draw.font
    x0, y0, x1, y1 = draw.box[0] - pad, draw.box[1] - pad, draw.box[2] + pad, draw.box[3] + pad
    root.set("viewBox", f"{x0:.4f} {y0:.4f} {x1 - x0:.4f} {y1 - y0:.4f}")
    root.set("width", f"{x1 - x0:.4f}mm")
    root.set("height", f"{y1 - y0:.4f}mm")
    ET.indent(tree, space="  ")
    tree.write(path, encoding="utf-8", xml_declaration=True)


def section_colours() -> dict[str, str]:
    """Section fill per layer: each registered part's colour, and the needle's."""
    from matcad.parts.registry import parts

    return {p.name: p.colour for p in parts()} | {"needle": NEEDLE_COLOUR}


def layer_of(name: str) -> str:
    """The section layer (registered part or needle) of an assembled solid's name (spacer_2, end_cap_t3, ...)."""
    for numbered in ("spacer", "end_cap", "needle"):
        if name.startswith(numbered + "_") and name != "needle_mount":
            return numbered
    return name


def section_plane(spec):
    """The section's plane: XZ through the first taxel's neck axis (a row of necks, and the needles' plane:
    every needle is tilted in its own XZ plane) (mm)."""
    from build123d import Plane

    from matcad.spec import taxels

    y = taxels(spec)[0].y
    return Plane.XZ if y == 0.0 else Plane(origin=(0, y, 0), x_dir=(1, 0, 0), z_dir=(0, -1, 0))


def write_section_svg(spec, path, parts=None) -> None:
    """Section of the assembly (``parts``, name → solid in the assembly frame; ``assembled_parts`` unless given)
    through the first taxel's row of necks in the XZ plane (the needles' plane), to scale in mm, with part labels
    and, for a single taxel, the design's dimensions (:func:`annotate_section`; a board's section carries the
    labels only)."""
    from build123d import ExportSVG, Pos, Rot

    from matcad.parts.assembly import assembled_parts
    from matcad.spec import is_array

    parts = parts or assembled_parts(spec)
    plane = section_plane(spec)
    svg = ExportSVG(margin=2.0, line_weight=0.05)
    layers, colours = set(), section_colours()
    for name, solid in parts.items():
        cut = solid & plane
        if not cut or not cut.faces():
            continue
        layer = layer_of(name)
        if layer not in layers:
            svg.add_layer(layer, fill_color=colours[layer], line_color="#000000")
            layers.add(layer)
        if plane.origin.Y:
            cut = Pos(0, -plane.origin.Y, 0) * cut
        svg.add_shape(Rot(-90, 0, 0) * cut, layer=layer)  # XZ plane → drawing plane, z up
    svg.write(str(path))
    annotate_section(spec, path, dimensions=not is_array(spec))
