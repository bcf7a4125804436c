"""The riser: a second acrylic sheet (``[riser]``, riser.thickness thick) solvent-bonded on the neck plate, under the
caps, that gives a board two neck lengths (docs/arrays.md).

A taxel whose neck runs on through the riser (``neck.riser``) has its neck hole in the riser too, at the plate's
size (or the same undersize pilot, drilled through both sheets in one pass after bonding); its cap sits on the
riser. Every other taxel's cap sits on the plate in a pocket: a hole through the riser the size of its flange, as
the locator guide's hole, so every flange (cast riser.thickness thicker for a pocketed cap) meets the clamp at one
height (:mod:`matcad.parts.stack`). Outline, dowel and bolt holes are the plate's.
"""

from matcad.parts.features import laser_stack_holes, sheet_kerf_mm
from matcad.parts.flat import Flat, Hole, edge_label
from matcad.parts.guide import cap_holes
from matcad.parts.labels import place_labels
from matcad.parts.neck_plate import neck_holes, neck_label_text, taxel_keepout
from matcad.parts.registry import Kind, Part


def has_riser(spec) -> bool:
    """Whether ``spec`` stacks a [riser] on its plate (the riser part is cut only then)."""
    return spec.riser is not None


def riser_holes(spec, board) -> tuple[Hole, ...]:
    """One hole per taxel of ``board``, in board order: its neck (or undersize pilot, when ``plate.neck_pilot``) where
    its neck runs on through the riser (:func:`matcad.parts.neck_plate.neck_holes`), else the pocket its cap sits
    in, its flange's size (the locator's hole, :func:`matcad.parts.guide.cap_holes`) (mm)."""
    pilot = spec.plate.pilot_undersize if spec.plate.neck_pilot else None
    return tuple(neck_holes((t,), pilot)[0] if t.neck.riser else cap_holes((t,), "locator")[0] for t in board)


def riser_label_text(taxel) -> str:
    """What is engraved beside a board's hole in the riser: a neck's taxel and finished size ("t2 Ø2.6", as on the
    plate under it), a pocket's taxel name."""
    return neck_label_text(taxel) if taxel.neck.riser else taxel.name


def riser(spec) -> Flat:
    """The riser: the plate's outline, every taxel's neck hole or flange pocket (:func:`riser_holes`), the stack's
    dowel and bolt holes, the edge label "RISER <thickness>" and, on a board, each hole's taxel beside it (mm)."""
    from matcad.spec import taxels

    r = spec.riser
    if r is None:
        raise ValueError(f"spec {spec.name!r} has no [riser] table: no riser to cut")
    board = taxels(spec)
    holes = (*riser_holes(spec, board), *laser_stack_holes(spec))
    label = edge_label(f"RISER {r.thickness:g}", spec.plate.width, spec.plate.depth, holes)
    if len(board) > 1:
        label += place_labels([(riser_label_text(t), t.x, t.y) for t in board], taxel_keepout(board, holes),
                              spec.plate.width, spec.plate.depth, taken=label)
    return Flat(name="riser", thickness=r.thickness, thickness_measured=r.thickness_measured,
                thickness_example=r.thickness_example, sheet="riser", kerf=sheet_kerf_mm(spec, "riser"),
                width=spec.plate.width, depth=spec.plate.depth, holes=holes, engrave=label)


PARTS = (Part("riser", Kind.LASER, flag="neck_plate", make=riser, order=15, colour="#b0d4f4", sheet="riser",
              when=has_riser, label="riser (acrylic, bonded on the plate)"),)
