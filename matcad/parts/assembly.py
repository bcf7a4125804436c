"""Every part in its assembled place (assembly frame: plate underside z = 0, neck axis = z) and a section.

Stack, bottom to top: needle mount, spacers (gap = spacer.height), neck plate (0..l), locator guide around
the cap's flange, the cap on the plate, the clamp guide resting on the flange (unclamped: the flange's
squeeze shows as a gap that the bolts close).
"""

from build123d import Compound, ExportSVG, Plane, Pos, Rot

from matcad.parts.end_cap import end_cap
from matcad.parts.features import plate_bolt_positions_mm
from matcad.parts.guide import guide
from matcad.parts.neck_plate import neck_plate
from matcad.parts.needle_mount import needle, needle_mount, taxel_needle
from matcad.parts.registry import parts as registered_parts
from matcad.parts.solid import flat_solid
from matcad.parts.spacer import spacer
from matcad.parts.stack import clamp_seat_z_mm
from matcad.render.section import annotate_section

NEEDLE_COLOUR = "#404040"
"""Section fill of the bought needle (drawn for clearance; not a registered part)."""


def section_colours() -> dict[str, str]:
    """Section fill per layer: each registered part's colour, and the needle's."""
    return {p.name: p.colour for p in registered_parts()} | {"needle": NEEDLE_COLOUR}


def drilled(plate, neck_diameters: tuple[float, ...]):
    """The neck plate as assembled: the pilot-cut necks (in board order) drilled to their finished diameters
    (mm)."""
    import dataclasses

    finished = iter(neck_diameters)
    holes = tuple(dataclasses.replace(h, diameter=next(finished), purpose="neck") if h.purpose == "neck_pilot"
                  else h for h in plate.holes)
    return dataclasses.replace(plate, holes=holes)


def assembled_parts(spec) -> dict[str, object]:
    """Name → solid in the assembly frame (mm). Spacers are numbered when laser-cut; a board's caps and needles
    are named after their taxels (end_cap_t1, needle_t1, ...)."""
    from matcad.taxel import taxel_spec, taxels

    board = taxels(spec)
    plate_t = spec.neck.length
    parts = {
        "neck_plate": flat_solid(drilled(neck_plate(spec), tuple(t.neck.diameter for t in board))),
        "guide_locator": flat_solid(guide(spec, "locator"), plate_t),
        "guide_clamp": flat_solid(guide(spec, "clamp"), clamp_seat_z_mm(spec)),
    }
    if len(board) == 1:
        parts |= {"end_cap": Pos(0, 0, plate_t) * end_cap(spec), "needle_mount": needle_mount(spec),
                  "needle": needle(spec)}
    else:
        parts |= {f"end_cap_{t.name}": Pos(t.x, t.y, plate_t) * end_cap(taxel_spec(spec, t)) for t in board}
        parts["needle_mount"] = needle_mount(spec)
        parts |= {f"needle_{t.name}": taxel_needle(t) for t in board}
    if spec.spacer.style == "laser":
        one = flat_solid(spacer(spec), -spec.spacer.height)
        for i, (x, y) in enumerate(plate_bolt_positions_mm(spec), 1):
            parts[f"spacer_{i}"] = Pos(x, y, 0) * one
    return parts


def layer_of(name: str) -> str:
    """The section layer (registered part or needle) of an assembled solid's name (spacer_2, end_cap_t3, ...)."""
    for numbered in ("spacer", "end_cap", "needle"):
        if name.startswith(numbered + "_") and name != "needle_mount":
            return numbered
    return name


def assembly(spec, parts=None) -> Compound:
    """All parts (``assembled_parts`` unless given) as one labelled compound (for assembly.step)."""
    children = []
    for name, solid in (parts or assembled_parts(spec)).items():
        solid.label = name
        children.append(solid)
    return Compound(label=spec.name, children=children)


def section_plane(spec):
    """The section's plane: XZ through the first taxel's neck axis (a row of necks, and the needles' plane:
    every needle is tilted in its own XZ plane) (mm)."""
    from matcad.taxel import taxels

    y = taxels(spec)[0].y
    return Plane.XZ if y == 0.0 else Plane(origin=(0, y, 0), x_dir=(1, 0, 0), z_dir=(0, -1, 0))


def write_section_svg(spec, path, parts=None) -> None:
    """Section of the assembly through the first taxel's row of necks in the XZ plane (the needles' plane), to
    scale in mm, with part labels and, for a single taxel, the design's dimensions
    (:func:`matcad.render.section.annotate_section`; a board's section carries the labels only)."""
    from matcad.taxel import is_array

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
