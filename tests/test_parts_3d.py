"""3-D parts measured as solids: needle bore angle and y, collisions, mold fit, cap volume."""

import json
import math

import pytest
from build123d import GeomType, Pos, import_step

from matcad import spec as spec_mod
from matcad.acoustics.geometry import drafted_cavity_volume_mm3
from matcad.build import build
from matcad.parts import end_cap_mold
from matcad.parts.end_cap import end_cap
from matcad.parts.features import cap_volume_mm3
from matcad.parts.neck_plate import neck_plate
from matcad.parts.needle_mount import needle, needle_bore_diameter_mm, needle_mount
from matcad.parts.solid import flat_solid
from tests.conftest import SINGLE_TEMPLATES

SOLID_TEMPLATES = [p for p in SINGLE_TEMPLATES if spec_mod.load(p).outputs.needle_mount]


def _overlap(a, b) -> float:
    common = a & b
    return common.volume if common else 0.0


@pytest.fixture(scope="module", params=SOLID_TEMPLATES, ids=lambda p: p.stem)
def spec(request):
    return spec_mod.load(request.param)


def _bore_axis(solid, diameter):
    bores = [f for f in solid.faces() if f.geom_type == GeomType.CYLINDER
             and abs(f.radius - diameter / 2) < 1e-6 and abs(f.axis_of_rotation.direction.Z) < 0.9999]
    assert bores, "no inclined bore of the needle's diameter found"
    return bores[0].axis_of_rotation


@pytest.mark.parametrize("theta,y", [(75.0, 1.0), (30.0, 0.0), (52.5, 3.47)])
def test_needle_bore_angle_and_y_measured_on_step(tmp_path, spec, theta, y):
    import dataclasses
    s = dataclasses.replace(spec, needle=dataclasses.replace(spec.needle, theta_deg=theta, y=y))
    out = tmp_path / "b"
    s = dataclasses.replace(s, outputs=dataclasses.replace(s.outputs, end_cap_mold=False, assembly=False,
                                                           neck_plate=False, guides=False, spacers=False))
    build(s, out)
    solid = import_step(out / "needle_mount.step")  # in its print pose: back to the assembly frame
    matrix = json.loads((out / "report.json").read_text())["meshes"]["needle_mount.stl"]["design_to_print"]
    assert matrix[:3] == [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, matrix[2][3]]]  # a pure lift
    solid = Pos(0, 0, -matrix[2][3]) * solid
    axis = _bore_axis(solid, needle_bore_diameter_mm(s))
    d, p = axis.direction, axis.position
    if d.Z < 0:
        d = -d
    assert math.degrees(math.asin(d.Z)) == pytest.approx(theta, abs=0.05)
    x_hit = p.X + (-p.Z / d.Z) * d.X  # where the axis meets the plate underside z = 0
    assert abs(p.Y) < 1e-9 and abs(d.Y) < 1e-9
    assert (-s.neck.diameter / 2 - x_hit) == pytest.approx(y, abs=0.01)


def test_needle_clears_plate_and_mount(spec):
    n = needle(spec)
    assert _overlap(n, flat_solid(neck_plate(spec))) == 0.0
    assert _overlap(n, needle_mount(spec)) == 0.0
    # and the tip stands in the gap: the needle's highest point is below the plate by the clearance
    assert n.bounding_box().max.Z == pytest.approx(-spec.needle.tip_clearance, abs=1e-6)


def test_mold_parts_do_not_intersect_and_cast_the_cap(spec):
    base, lid = end_cap_mold.mold_base(spec), end_cap_mold.mold_lid(spec)
    assert _overlap(base, lid) == 0.0
    caps = end_cap_mold.cast_caps(spec)
    assert len(caps) == spec.mold.count
    for cap in caps:
        assert _overlap(cap, base) == 0.0 and _overlap(cap, lid) == 0.0
        # the cap fills its mold cavity: grown by 0.05 mm it would cut both halves
        grown = cap.bounding_box()
        assert grown.max.Z == pytest.approx(0.0, abs=1e-9)
    assert base.bounding_box().max.Z == pytest.approx(spec.mold.key_height)  # keys stand on the parting plane


def test_cap_volume_closed_form(spec):
    cap = end_cap(spec)
    assert cap.volume == pytest.approx(cap_volume_mm3(spec), rel=1e-9)
    flange = math.pi / 4 * (spec.end_cap.outer_diameter + 2 * spec.end_cap.flange_width) ** 2 \
        * (spec.guide.thickness + spec.end_cap.flange_squeeze)
    body = math.pi / 4 * spec.end_cap.outer_diameter ** 2 * (spec.cavity.length + spec.end_cap.top_thickness
                                                             - spec.guide.thickness - spec.end_cap.flange_squeeze)
    cavity = drafted_cavity_volume_mm3(spec.cavity.diameter, spec.cavity.length, spec.mold.draft_deg)
    assert cap.volume == pytest.approx(flange + body - cavity, rel=1e-9)


def test_mold_has_fill_port_and_vents_through_lid(spec):
    lay = end_cap_mold.layout(spec)
    lid = end_cap_mold.mold_lid(spec)
    holes = [f for f in lid.faces() if f.geom_type == GeomType.CYLINDER
             and abs(f.axis_of_rotation.direction.Z) > 0.9999]
    radii = sorted(round(f.radius, 6) for f in holes)
    assert radii.count(round(spec.mold.fill_port / 2, 6)) == spec.mold.count
    assert radii.count(round(spec.mold.vent / 2, 6)) == len(lay.vents)
    assert len(lay.vents) % spec.mold.count == 0
    # no channel runs down into a core pin: every vertical hole's axis stands off each pin by more than its radius
    pin_r = spec.cavity.diameter / 2
    for f in (h for h in holes if h.radius < pin_r - 1e-6):  # the pins' own sides excluded
        c = f.axis_of_rotation.position
        for x in lay.cap_x:
            assert math.hypot(c.X - x, c.Y) >= pin_r + f.radius - 1e-6, (c.X, c.Y, f.radius, x)


def test_assembly_shows_the_drilled_neck_not_the_pilot(spec):
    """A pilot-cut neck (the SLA template) is assembled drilled to neck.diameter: the plate's bore measured."""
    import dataclasses

    from matcad.parts.assembly import assembled_parts
    piloted = dataclasses.replace(spec, plate=dataclasses.replace(spec.plate, neck_pilot=True))
    plate = assembled_parts(piloted)["neck_plate"]
    bores = [f.radius for f in plate.faces() if f.geom_type == GeomType.CYLINDER
             and abs(f.axis_of_rotation.position.X) < 1e-9 and abs(f.axis_of_rotation.position.Y) < 1e-9]
    assert bores == [pytest.approx(spec.neck.diameter / 2, abs=1e-9)]
