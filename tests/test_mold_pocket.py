"""The cap mold's pocket measured on the built base solid against the cap it casts: every cap position's
cylindrical walls (flange and body) and its flat faces (the flange's step, the pocket's floor), in mm."""

import math

import pytest
from build123d import GeomType

from matcad import spec as spec_mod
from matcad.parts.end_cap_mold import layout, mold_base
from matcad.spec import cap_flange_diameter_mm, cap_flange_thickness_mm, cap_height_mm
from matcad.spec import taxel_spec
from tests.conftest import TEMPLATES

MOLD_TEMPLATES = [p for p in TEMPLATES if spec_mod.load(p).outputs.end_cap_mold]
TOL_MM = 1e-6


def _on_axis(face, x: float) -> bool:
    """Whether ``face``'s axis is vertical and passes through (x, 0): a wall of the pocket at cap position x."""
    axis = face.axis_of_rotation
    return abs(abs(axis.direction.Z) - 1.0) < 1e-9 and math.hypot(axis.position.X - x, axis.position.Y) < TOL_MM


def _pocket(base, x: float) -> tuple[list, list]:
    """The pocket at cap position ``x`` as measured: its walls [radius, z low, z high, ...] (cylinders about the
    vertical axis through (x, 0)) and the flat faces inside its widest wall [z, area, ...], each sorted, rounded
    to 1e-6 mm (mold frame: parting plane z = 0, the cap upside down below it)."""
    faces = base.faces()
    walls = sorted({(round(f.radius, 6), round(f.bounding_box().min.Z, 6), round(f.bounding_box().max.Z, 6))
                    for f in faces if f.geom_type == GeomType.CYLINDER and _on_axis(f, x)})
    reach = max((r for r, _, _ in walls), default=0.0) + TOL_MM
    flats = set()
    for f in faces:
        box = f.bounding_box()
        if (f.geom_type == GeomType.PLANE and box.max.Z - box.min.Z < TOL_MM and box.max.Z < -TOL_MM
                and max(abs(box.min.X - x), abs(box.max.X - x), abs(box.min.Y), abs(box.max.Y)) <= reach):
            flats.add((round(box.max.Z, 6), round(f.area, 6)))
    return [v for wall in walls for v in wall], [v for flat in sorted(flats) for v in flat]


@pytest.mark.parametrize("path", MOLD_TEMPLATES, ids=lambda p: p.stem)
def test_mold_pocket_is_the_cap(path):
    """Each pocket is exactly its cap upside down: the flange's wall at the flange radius down to the flange
    thickness, the body's wall at the outer radius down to the cap height, a ring step and a floor of the
    closed-form areas. A pocket 0.1 mm wider or deeper than the cap fails (the cap would cast oversize and not
    seat in its guides)."""
    spec = spec_mod.load(path)
    lay = layout(spec)
    base = mold_base(spec)
    for x, taxel in zip(lay.cap_x, lay.slots):
        cap = taxel_spec(spec, taxel)
        flange_r, body_r = cap_flange_diameter_mm(cap) / 2, cap.end_cap.outer_diameter / 2
        tf, h = cap_flange_thickness_mm(cap), cap_height_mm(cap)
        walls, flats = _pocket(base, x)
        assert walls == pytest.approx([body_r, -h, -tf, flange_r, -tf, 0.0], abs=1e-5), (taxel.name, walls)
        assert flats == pytest.approx([-h, math.pi * body_r**2, -tf, math.pi * (flange_r**2 - body_r**2)],
                                      rel=1e-6, abs=1e-5), (taxel.name, flats)
