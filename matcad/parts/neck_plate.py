"""The acrylic neck plate: its thickness is the neck length l, one neck hole d per taxel (paper Fig. 2).

On a board every neck is engraved with its taxel's name and finished diameter ("t2 Ø2.6") beside it, outside the
cap flange that seals on the plate, so a pilot-cut plate says which hole is drilled to which size; the fabrication
steps, the drill list of the bill of materials and the drawings use the same names.
"""

from matcad.parts.features import laser_stack_holes, sheet_kerf_mm
from matcad.parts.flat import Engraving, Flat, Hole, edge_label
from matcad.parts.labels import place_labels
from matcad.parts.registry import Kind, Part


def neck_holes(board, pilot_undersize: float | None) -> tuple[Hole, ...]:
    """One neck hole per taxel of ``board`` at (taxel.x, taxel.y), its neck diameter d, or an undersize pilot
    ``pilot_undersize`` smaller when given, drilled to d after cutting (mm). Each names its taxel."""
    if pilot_undersize is not None:
        return tuple(Hole(t.x, t.y, t.neck.diameter - pilot_undersize, "neck_pilot", taxel=t.name,
                          drill_to=t.neck.diameter) for t in board)
    return tuple(Hole(t.x, t.y, t.neck.diameter, "neck", taxel=t.name) for t in board)


def plate_label_text(board) -> str:
    """The plate's edge label: its neck diameter(s)."""
    return "PLATE d" + "/".join(dict.fromkeys(f"{t.neck.diameter:g}" for t in board))


def neck_label_text(taxel) -> str:
    """What is engraved beside a board's neck: the taxel's name and the neck's finished diameter (mm)."""
    return f"{taxel.name} Ø{taxel.neck.diameter:g}"


def taxel_keepout(board, holes) -> list[tuple[float, float, float]]:
    """Circles (x, y, radius) a label on a stack layer must keep out of: every cap flange (its seal on the plate,
    the locator's hole, the face the clamp presses) and every hole (mm)."""
    from matcad.spec import cap_flange_diameter_mm

    return ([(t.x, t.y, cap_flange_diameter_mm(t) / 2) for t in board]
            + [(h.x, h.y, h.diameter / 2) for h in holes])


def neck_plate(spec) -> Flat:
    """Neck plate: outline plate.width x plate.depth, every taxel's neck hole (or undersize pilot) at its
    position, dowel and bolt holes, the edge label and, on a board, each neck's name and finished size (mm)."""
    from matcad.spec import taxels

    board = taxels(spec)
    label = ()
    if spec.plate.label:
        height = min(2.0, spec.plate.depth / 12)
        label = (Engraving(-spec.plate.width / 4, -spec.plate.depth / 4 - height / 2, height, spec.plate.label),)
    holes = (*neck_holes(board, spec.plate.pilot_undersize if spec.plate.neck_pilot else None),
             *laser_stack_holes(spec))
    label += edge_label(plate_label_text(board), spec.plate.width, spec.plate.depth, holes)
    if len(board) > 1:
        label += place_labels([(neck_label_text(t), t.x, t.y) for t in board], taxel_keepout(board, holes),
                              spec.plate.width, spec.plate.depth, taken=label)
    return Flat(name="neck_plate", thickness=spec.neck.length, thickness_measured=spec.plate.thickness_measured,
                thickness_example=spec.plate.thickness_example, sheet="plate",
                kerf=sheet_kerf_mm(spec, "plate"), width=spec.plate.width, depth=spec.plate.depth, holes=holes,
                engrave=label)


def drill_plan(spec) -> list[dict]:
    """The neck pilots to drill after cutting, one row per taxel: name, position, pilot as cut and the finished
    size to drill it to (mm); empty when the necks are cut to size."""
    if not (spec.outputs.neck_plate and spec.plate.neck_pilot):
        return []
    from matcad.spec import taxels

    return [{"taxel": h.taxel, "x_mm": h.x, "y_mm": h.y, "pilot_mm": h.diameter, "drill_mm": h.drill_to}
            for h in neck_holes(taxels(spec), spec.plate.pilot_undersize)]


PARTS = (Part("neck_plate", Kind.LASER, flag="neck_plate", make=neck_plate, order=10, colour="#9cc8f0",
              sheet="plate", label="neck plate (acrylic, l thick)"),)
