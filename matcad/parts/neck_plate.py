"""The acrylic neck plate: its thickness is the neck length l, its centre hole the neck d (paper Fig. 2)."""

from matcad.parts.features import laser_stack_holes, sheet_kerf_mm
from matcad.parts.flat import Engraving, Flat, Hole, edge_label
from matcad.parts.registry import Kind, Part


def neck_plate(spec) -> Flat:
    """Neck plate: outline plate.width x plate.depth, neck hole (or undersize pilot), dowel and bolt holes (mm)."""
    if spec.plate.neck_pilot:
        neck = Hole(0.0, 0.0, spec.neck.diameter - spec.plate.pilot_undersize, "neck_pilot")
    else:
        neck = Hole(0.0, 0.0, spec.neck.diameter, "neck")
    label = ()
    if spec.plate.label:
        height = min(2.0, spec.plate.depth / 12)
        label = (Engraving(-spec.plate.width / 4, -spec.plate.depth / 4 - height / 2, height, spec.plate.label),)
    holes = (neck, *laser_stack_holes(spec))
    label += edge_label(f"PLATE d{spec.neck.diameter:g}", spec.plate.width, spec.plate.depth, holes)
    return Flat(name="neck_plate", thickness=spec.neck.length, thickness_measured=spec.plate.thickness_measured,
                kerf=sheet_kerf_mm(spec, "plate"), width=spec.plate.width, depth=spec.plate.depth, holes=holes,
                engrave=label)


PARTS = (Part("neck_plate", Kind.LASER, flag="neck_plate", make=neck_plate, order=10, colour="#9cc8f0",
              sheet="plate", label="neck plate (acrylic, l thick)"),)
