"""The acrylic neck plate: its thickness is the neck length l, one neck hole d per taxel (paper Fig. 2)."""

from matcad.parts.features import laser_stack_holes, sheet_kerf_mm
from matcad.parts.flat import Engraving, Flat, Hole, edge_label
from matcad.parts.registry import Kind, Part


def neck_holes(board, pilot_undersize: float | None) -> tuple[Hole, ...]:
    """One neck hole per taxel of ``board`` at (taxel.x, taxel.y), its neck diameter d, or an undersize pilot
    ``pilot_undersize`` smaller when given (drilled to d after cutting) (mm)."""
    if pilot_undersize is not None:
        return tuple(Hole(t.x, t.y, t.neck.diameter - pilot_undersize, "neck_pilot") for t in board)
    return tuple(Hole(t.x, t.y, t.neck.diameter, "neck") for t in board)


def plate_label_text(board) -> str:
    """The plate's edge label: its neck diameter(s)."""
    return "PLATE d" + "/".join(dict.fromkeys(f"{t.neck.diameter:g}" for t in board))


def neck_plate(spec) -> Flat:
    """Neck plate: outline plate.width x plate.depth, every taxel's neck hole (or undersize pilot) at its
    position, dowel and bolt holes (mm)."""
    from matcad.spec import taxels

    board = taxels(spec)
    label = ()
    if spec.plate.label:
        height = min(2.0, spec.plate.depth / 12)
        label = (Engraving(-spec.plate.width / 4, -spec.plate.depth / 4 - height / 2, height, spec.plate.label),)
    holes = (*neck_holes(board, spec.plate.pilot_undersize if spec.plate.neck_pilot else None),
             *laser_stack_holes(spec))
    label += edge_label(plate_label_text(board), spec.plate.width, spec.plate.depth, holes)
    return Flat(name="neck_plate", thickness=spec.neck.length, thickness_measured=spec.plate.thickness_measured,
                kerf=sheet_kerf_mm(spec, "plate"), width=spec.plate.width, depth=spec.plate.depth, holes=holes,
                engrave=label)


PARTS = (Part("neck_plate", Kind.LASER, flag="neck_plate", make=neck_plate, order=10, colour="#9cc8f0",
              sheet="plate", label="neck plate (acrylic, l thick)"),)
