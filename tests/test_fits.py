"""The fits the report claims (key in socket, flange in locator, self-tap pilot), measured from the files: circle
sections of the STLs (in the frame the report's design-to-print matrix gives back) and circles of the DXF."""

import json

import ezdxf
import numpy as np
import pytest
import trimesh

from matcad import spec as spec_mod
from matcad.build import build
from matcad.parts.features import plate_bolt_positions_mm
from matcad.spec import cap_flange_thickness_mm
from tests.conftest import SINGLE_TEMPLATES
from tests.readback import nearest_circle, section_circles

KIT_TEMPLATES = [p for p in SINGLE_TEMPLATES if spec_mod.load(p).outputs.needle_mount]


@pytest.fixture(scope="module", params=KIT_TEMPLATES, ids=lambda p: p.stem)
def kit(request, tmp_path_factory):
    spec = spec_mod.load(request.param)
    out = tmp_path_factory.mktemp("fits") / spec.name
    build(spec, out)
    report = json.loads((out / "report.json").read_text())
    return spec, out, report, {f["id"]: f for f in report["fabrication"]["fits"]}


def _design_frame(out, report, name):
    mesh = trimesh.load_mesh(out / name)
    mesh.apply_transform(np.linalg.inv(np.array(report["meshes"][name]["design_to_print"])))
    return mesh


def test_key_clearance_measured_at_the_parting_plane(kit):
    """The lid's socket read back at the parting plane: three crush ribs touch the key line-to-line (the nearest
    socket wall in each rib's direction is the key's radius: lid play 0, where a plain socket let the lid shift
    ±machine.key_clearance), the socket between them the key grown by machine.key_clearance."""
    import math

    from matcad.parts.end_cap_mold import RIB_ANGLES_DEG, layout

    spec, out, report, fits = kit
    base, lid = (_design_frame(out, report, f"end_cap_mold_{p}.stl") for p in ("base", "lid"))
    x, y = layout(spec).keys[0]
    z = 1e-3
    key = nearest_circle(section_circles(base, z), x, y)
    section = lid.section(plane_origin=[0.0, 0.0, z], plane_normal=[0.0, 0.0, 1.0])
    loops = [np.asarray(loop)[:, :2] for loop in section.discrete]
    socket = min(loops, key=lambda p: np.hypot(*(p.mean(axis=0) - [x, y])))
    d = np.hypot(socket[:, 0] - x, socket[:, 1] - y)
    angle = np.degrees(np.arctan2(socket[:, 1] - y, socket[:, 0] - x)) % 360
    claim = fits["key"]
    assert 2 * key[2] == pytest.approx(claim["pin_mm"], abs=2e-3)
    assert d.max() == pytest.approx(claim["socket_mm"] / 2, abs=2e-3)
    assert claim["socket_mm"] == pytest.approx(claim["pin_mm"] + 2 * spec.machine.key_clearance, abs=1e-9)
    for a in RIB_ANGLES_DEG:  # each rib's face is the key's own surface
        near = np.abs((angle - a + 180) % 360 - 180) < 5
        assert near.any() and d[near].min() == pytest.approx(key[2], abs=2e-3), (a, d[near].min(), key[2])
    play = 2 * (d[np.abs((angle[:, None] - np.array(RIB_ANGLES_DEG) + 180) % 360 - 180).min(axis=1) < 5].min()
                - key[2])
    assert play == pytest.approx(claim["clearance_mm"], abs=4e-3) and claim["clearance_mm"] == 0.0
    assert math.isfinite(play)


def test_flange_in_locator_measured_from_dxf_and_cap(kit):
    spec, out, report, fits = kit
    locator = next(f for f in _dxf_circles(out / "guide_locator.dxf") if abs(f[0]) < 1e-9 and abs(f[1]) < 1e-9)
    kerf = next(h for h in report["as_built"]["laser_holes"] if h["part"] == "guide_locator")["finished_mm"]
    kerf = kerf - next(h for h in report["as_built"]["laser_holes"] if h["part"] == "guide_locator")["drawn_mm"]
    hole = 2 * locator[2] + kerf  # as cut: drawn + kerf
    cap = _design_frame(out, report, "end_cap.stl")
    flange = max(section_circles(cap, cap_flange_thickness_mm(spec) / 2), key=lambda c: c[2])
    claim = fits["flange"]
    assert hole - 2 * flange[2] == pytest.approx(claim["clearance_mm"], abs=2e-3)
    assert hole == pytest.approx(claim["hole_mm"], abs=1e-6)


def test_self_tap_pilot_measured_in_the_mount(kit):
    spec, out, report, fits = kit
    mount = _design_frame(out, report, "needle_mount.stl")
    z = -spec.spacer.height - spec.mount.thickness / 2
    circles = section_circles(mount, z)
    claim = fits["pilot"]
    for x, y in plate_bolt_positions_mm(spec):
        pilot = nearest_circle(circles, x, y)
        assert (pilot[0], pilot[1]) == pytest.approx((x, y), abs=1e-3)
        assert 2 * pilot[2] == pytest.approx(claim["hole_mm"], abs=2e-3)
        assert 2 * pilot[2] - claim["pin_mm"] == pytest.approx(claim["clearance_mm"], abs=2e-3)
        assert claim["clearance_mm"] < 0  # the bolt cuts its thread: interference, not clearance


def _dxf_circles(path):
    return [(c.dxf.center.x, c.dxf.center.y, c.dxf.radius)
            for c in ezdxf.readfile(path).modelspace().query("CIRCLE[layer=='CUT_INNER']")]


def test_mount_fixing_ears_and_needle_protrusion(kit):
    """Four M3 clearance holes in the ears (read from the STL); the needle protrusion the report states is the
    tip's height over the mount's top face (read from the STL) along the needle."""
    import math

    from matcad.parts.features import bolt_clearance_mm, needle_tip_mm
    from matcad.parts.features import EAR_THICKNESS_MM, FIXING_BOLT, ear_holes_mm

    spec, out, report, _ = kit
    mount = _design_frame(out, report, "needle_mount.stl")
    bottom = float(mount.bounds[0, 2])
    circles = section_circles(mount, bottom + EAR_THICKNESS_MM / 2)
    for x, y in ear_holes_mm(spec):
        hole = nearest_circle(circles, x, y)
        assert (hole[0], hole[1]) == pytest.approx((x, y), abs=1e-3)
        assert 2 * hole[2] == pytest.approx(bolt_clearance_mm(FIXING_BOLT, "normal"), abs=2e-3)
    nz = mount.face_normals[:, 2]
    up = mount.triangles_center[nz > 1 - 1e-9][:, 2]
    areas = mount.area_faces[nz > 1 - 1e-9]
    top = max(set(np.round(up, 4)), key=lambda z: areas[np.round(up, 4) == z].sum())  # the block's top face
    needle = report["bom"]["needle"]
    rise = needle_tip_mm(spec)[2] - top
    assert needle["protrusion_mm"] == pytest.approx(rise / math.sin(math.radians(spec.needle.theta_deg)), abs=1e-3)
    assert needle["protrusion_mm"] > 0
