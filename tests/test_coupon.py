"""`matcad coupon`: one laser coupon per sheet with that sheet's kerf, the printed coupon's bores at the needle's
real θ; every size read back from the DXF, the STEP and the STL."""

import json
import math

import ezdxf
import pytest
import trimesh
from build123d import GeomType, import_step

from matcad import spec as spec_mod
from matcad.parts.coupon import (BOLT_SWEEP_MM, DOWEL_SWEEP_MM, NECK_SWEEP_MM, NEEDLE_SWEEP_MM,
                                 PRINTED_DOWEL_SWEEP_MM, SHEET_ROWS)
from matcad.parts.features import bolt_clearance_mm
from tests.conftest import PAPER, run_cli

KERFS = {"plate": 0.27, "guide": 0.14, "spacer": 0.16}


@pytest.fixture(scope="module")
def coupons(tmp_path_factory):
    import tomllib

    import tomli_w

    root = tmp_path_factory.mktemp("coupon")
    data = tomllib.loads(PAPER.read_text())
    for section, kerf in KERFS.items():  # the template's own per-sheet kerfs replaced by these
        data.setdefault(section, {})["laser_kerf"] = kerf
    path = root / "spec.toml"
    path.write_text(tomli_w.dumps(data))
    code, _, err = run_cli("coupon", path, "--out", root / "c", "--json")
    assert code == 0, err
    return spec_mod.load(path), root / "c"


def _finished(spec, purpose):
    base = {"neck": (spec.neck.diameter, NECK_SWEEP_MM), "dowel": (spec.fasteners.dowel_diameter, DOWEL_SWEEP_MM),
            "bolt": (bolt_clearance_mm(spec.fasteners.bolt, spec.fasteners.bolt_fit), BOLT_SWEEP_MM)}[purpose]
    return [base[0] + d for d in base[1]]


@pytest.mark.parametrize("sheet", ["plate", "guide", "spacer"])
def test_one_laser_coupon_per_sheet_with_its_kerf_and_labels(coupons, sheet):
    spec, folder = coupons
    doc = ezdxf.readfile(folder / f"coupon_{sheet}.dxf")
    assert doc.header["$INSUNITS"] == 4 and not doc.audit().has_errors
    finished = [f for purpose in SHEET_ROWS[sheet] for f in _finished(spec, purpose)]
    drawn = sorted(2 * c.dxf.radius for c in doc.modelspace().query("CIRCLE"))
    assert drawn == pytest.approx(sorted(f - KERFS[sheet] for f in finished), abs=1e-6)
    table = json.loads((folder / "report.json").read_text())
    assert table["sheets"][f"coupon_{sheet}"]["kerf_mm"] == KERFS[sheet]
    thickness = {"plate": spec.neck.length, "guide": spec.guide.thickness, "spacer": spec.spacer.height}[sheet]
    assert table["sheets"][f"coupon_{sheet}"]["thickness_mm"] == thickness


def test_printed_coupon_bores_at_the_needle_angle(coupons):
    spec, folder = coupons
    solid = import_step(folder / "coupon_printed.step")
    bores = {}
    for f in solid.faces():
        if f.geom_type == GeomType.CYLINDER:
            d = f.axis_of_rotation.direction
            bores.setdefault(round(2 * f.radius, 4), set()).add(round(math.degrees(math.asin(abs(d.Z))), 3))
    for dx in NEEDLE_SWEEP_MM:
        assert bores[round(spec.needle.outer_diameter + dx, 4)] == {round(spec.needle.theta_deg, 3)}
    for dx in PRINTED_DOWEL_SWEEP_MM:
        assert bores[round(spec.fasteners.dowel_diameter + dx, 4)] == {90.0}
    mesh = trimesh.load_mesh(folder / "coupon_printed.stl")
    assert mesh.is_watertight and mesh.is_volume
    table = json.loads((folder / "report.json").read_text())
    assert mesh.volume == pytest.approx(table["mesh"]["brep_volume_mm3"], rel=1e-3)
    assert [h["theta_deg"] for h in table["printed_holes"] if h["purpose"] == "needle"] == \
        [spec.needle.theta_deg] * len(NEEDLE_SWEEP_MM)


def test_per_sheet_kerf_reaches_the_kit(coupons, tmp_path):
    spec, _ = coupons
    import dataclasses

    from matcad.build import build
    s = dataclasses.replace(spec, outputs=dataclasses.replace(spec.outputs, end_cap_mold=False, needle_mount=False,
                                                              assembly=False))
    build(s, tmp_path / "k")
    for part, sheet in (("neck_plate", "plate"), ("guide_locator", "guide"), ("spacer", "spacer")):
        msp = ezdxf.readfile(tmp_path / "k" / f"{part}.dxf").modelspace()
        xs = [x for x, *_ in msp.query("LWPOLYLINE[layer=='CUT_OUTER']")[0].get_points("xyb")]
        width = spec.spacer.size if part == "spacer" else spec.plate.width
        assert max(xs) - min(xs) == pytest.approx(width + KERFS[sheet], abs=1e-9)


def _bore_from_step(spec, folder, row):
    """The needle bore of a trial mount read back from its STEP, in the design frame: (θ deg, y mm)."""
    from build123d import Pos

    from matcad.parts.needle_mount import needle_bore_diameter_mm

    solid = import_step(folder / row["file"].replace(".stl", ".step"))
    solid = Pos(0, 0, -row["mesh"]["design_to_print"][2][3]) * solid
    bore = next(f for f in solid.faces() if f.geom_type == GeomType.CYLINDER
                and abs(f.radius - needle_bore_diameter_mm(spec) / 2) < 1e-6
                and abs(f.axis_of_rotation.direction.Z) < 0.9999).axis_of_rotation
    d, p = bore.direction, bore.position
    x_hit = p.X - p.Z / d.Z * d.X
    return math.degrees(math.asin(abs(d.Z))), -spec.neck.diameter / 2 - x_hit


def _sweep_rows(folder, field):
    return [row for row in json.loads((folder / "report.json").read_text())["needle_sweep"] if row["varies"] == field]


def test_y_sweep_mounts_measured_on_their_step_files(coupons):
    """The trial set spans the paper's y window at the spec's θ; each bore's y is read back from its STEP."""
    spec, folder = coupons
    from matcad.parts.coupon import Y_SWEEP_MM

    sweep = _sweep_rows(folder, "y")
    assert [row["y_mm"] for row in sweep] == list(Y_SWEEP_MM) and min(Y_SWEEP_MM) == 0.0 and max(Y_SWEEP_MM) == 3.47
    assert [row["notches"] for row in sweep] == list(range(1, len(Y_SWEEP_MM) + 1))
    assert {row["notch_edge"] for row in sweep} == {"+x"}
    for row in sweep:
        theta, y = _bore_from_step(spec, folder, row)
        assert theta == pytest.approx(spec.needle.theta_deg, abs=0.01)
        assert y == pytest.approx(row["y_mm"], abs=0.01)
        assert trimesh.load_mesh(folder / row["file"]).is_watertight


def test_theta_sweep_mounts_measured_on_their_step_files(coupons):
    """The θ trial set (FDM: 60–75°, no bore needing support; SLA: the paper's whole 30–75°) at the spec's y,
    notched on the other edge; each bore's θ and y read back from its STEP."""
    import dataclasses

    from matcad.parts.coupon import theta_sweep_deg
    from matcad.rules.printing import bore_overhang

    spec, folder = coupons
    assert spec.machine.printer == "fdm"
    sweep = _sweep_rows(folder, "theta_deg")
    thetas = [row["theta_deg"] for row in sweep]
    assert thetas == [60.0, 63.75, 67.5, 71.25, 75.0]  # the slicer test prints each without support
    sla = dataclasses.replace(spec, machine=dataclasses.replace(spec.machine, printer="sla"))
    assert theta_sweep_deg(sla) == (30.0, 41.25, 52.5, 63.75, 75.0)
    for theta in thetas:  # none of the FDM set trips the overhang warning either
        assert not bore_overhang(dataclasses.replace(spec, needle=dataclasses.replace(spec.needle, theta_deg=theta)))
    assert [row["notches"] for row in sweep] == list(range(1, len(thetas) + 1))
    assert {row["notch_edge"] for row in sweep} == {"-x"}
    assert len({row["file"] for row in json.loads((folder / "report.json").read_text())["needle_sweep"]}) == 10
    for row in sweep:
        theta, y = _bore_from_step(spec, folder, row)
        print(f"{row['file']}: theta {theta:.4f} deg, y {y:.4f} mm")
        assert theta == pytest.approx(row["theta_deg"], abs=0.01)
        assert y == pytest.approx(spec.needle.y, abs=0.01) and row["y_mm"] == spec.needle.y
        mesh = trimesh.load_mesh(folder / row["file"])
        assert mesh.is_watertight and mesh.volume == pytest.approx(row["mesh"]["brep_volume_mm3"], rel=1e-3)


@pytest.mark.parametrize("sheet", ["plate", "guide", "spacer"])
def test_every_laser_coupon_hole_is_labelled_with_its_size_as_outlines(coupons, sheet):
    """No font text anywhere; under each hole an engraved outline group whose SVG title is the hole's finished
    size, and whose DXF outlines sit just below that hole."""
    import re
    import xml.etree.ElementTree as ET

    import numpy as np

    spec, folder = coupons
    msp = ezdxf.readfile(folder / f"coupon_{sheet}.dxf").modelspace()
    assert not msp.query("TEXT MTEXT")
    engraved = np.array([p[:2] for pl in msp.query("LWPOLYLINE[layer=='ENGRAVE']") for p in pl.get_points("xy")])
    root = ET.parse(folder / f"coupon_{sheet}.svg").getroot()
    ns = "{http://www.w3.org/2000/svg}"
    assert not list(root.iter(f"{ns}text"))
    titles = {}
    for path in next(g for g in root.iter(f"{ns}g") if g.get("id") == "ENGRAVE").iter(f"{ns}path"):
        xs = [float(v) for v in re.findall(r"M ([-\d.]+)", path.get("d"))]
        titles.setdefault(path.find(f"{ns}title").text, []).append(min(xs))
    kerf = KERFS[sheet]
    for c in msp.query("CIRCLE[layer=='CUT_INNER']"):
        finished = 2 * c.dxf.radius + kerf
        assert f"{finished:.2f}" in titles, finished
        below = engraved[(np.abs(engraved[:, 0] - c.dxf.center.x) < finished / 2 + 2)
                         & (engraved[:, 1] < c.dxf.center.y - c.dxf.radius)
                         & (engraved[:, 1] > c.dxf.center.y - c.dxf.radius - 3)]
        assert len(below) > 10, finished


def _even_odd_area(outlines):
    """Filled area (mm²) of glyph loops under the even-odd rule: shoelace areas, each loop signed by how many
    other loops enclose it (matplotlib's point-in-polygon, independent of matcad's nesting)."""
    import numpy as np
    from matplotlib.path import Path

    def shoelace(p):
        x, y = np.array(p).T
        return abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2

    return sum(shoelace(p) * (-1) ** sum(Path(q).contains_point(p[0]) for q in outlines if q is not p)
               for p in outlines)


def test_every_printed_coupon_hole_has_its_size_recessed_next_to_it(coupons, tmp_path):
    """Read back from the STL: under each hole's label rectangle a floor at top − 0.4 mm whose area is the
    label's even-odd glyph area; no floor elsewhere; the STL lost label area x depth against an unlabelled
    coupon tessellated the same way."""
    import numpy as np

    from matcad.export.mesh import write_stl
    from matcad.parts.coupon import (LABEL_GAP_MM, PRINTED_ENGRAVE_MM, PRINTED_LABEL_MM, printed_coupon,
                                     printed_coupon_labels)
    from matcad.parts.flat import engraving_outlines

    spec, folder = coupons
    mesh = trimesh.load_mesh(folder / "coupon_printed.stl")
    top = mesh.bounds[1][2]
    tri = mesh.triangles
    floor = (np.abs(tri[:, :, 2] - (top - PRINTED_ENGRAVE_MM)) < 1e-6).all(axis=1) & (mesh.face_normals[:, 2] > 0.999)
    centres, areas = mesh.triangles_center[floor], mesh.area_faces[floor]
    holes = json.loads((folder / "report.json").read_text())["printed_holes"]
    reach = max(h["diameter_mm"] for h in holes) / 2 + LABEL_GAP_MM
    drift = spec.mount.thickness / math.tan(math.radians(spec.needle.theta_deg))
    claimed = np.zeros(len(centres), bool)
    total = 0.0
    for h in holes:
        mouth = h["x_mm"] + (drift if h["purpose"] == "needle" else 0.0)
        y0 = h["y_mm"] + reach if h["y_mm"] > 0 else h["y_mm"] - reach - PRINTED_LABEL_MM
        box = ((np.abs(centres[:, 0] - mouth) < 3.5) & (centres[:, 1] > y0 - 0.05)
               & (centres[:, 1] < y0 + PRINTED_LABEL_MM + 0.05))
        label = next(t for t in printed_coupon_labels(spec) if t.text == f"{h['diameter_mm']:.2f}"
                     and abs(t.y - y0) < 1e-9)
        expected = _even_odd_area(engraving_outlines(label))
        assert areas[box].sum() == pytest.approx(expected, rel=1e-3), h
        ys = centres[box, 1]
        assert ys.max() - ys.min() > 0.9 * PRINTED_LABEL_MM  # capitals ≥ 2 mm tall
        claimed |= box
        total += expected
    assert claimed.all()
    plain = tmp_path / "plain.stl"
    write_stl(printed_coupon(spec, labelled=False), plain, spec.machine.stl_tolerance,
              spec.machine.stl_angular_tolerance)
    removed = trimesh.load_mesh(plain).volume - mesh.volume
    assert removed == pytest.approx(total * PRINTED_ENGRAVE_MM, rel=1e-2)
    print(f"labels {len(holes)}, glyph area {total:.3f} mm², removed {removed:.3f} mm³, "
          f"expected {total * PRINTED_ENGRAVE_MM:.3f} mm³")


def test_coupon_kit_has_previews_and_a_report_that_names_every_hole(coupons):
    """coupon writes a picture per laser sheet and of the printed coupon, and report.md/.html listing every hole
    of report.json (the same finished sizes) with those pictures."""
    import matplotlib.image as mpimg

    _, folder = coupons
    table = json.loads((folder / "report.json").read_text())
    files = [f["file"] for f in table["figures"]]
    assert sorted(files) == sorted(f"preview_{name}.png" for name in [*table["sheets"], "coupon_printed"])
    for name in files:
        image = mpimg.imread(folder / name)[..., :3]
        assert image.shape[0] > 100 and (image < 0.5).mean() > 0.002  # drawn, not blank
    md = (folder / "report.md").read_text()
    for hole in table["laser_holes"]:
        assert f"| {hole['part']} | {hole['purpose']} | {hole['finished_mm']:.3g} |" in md
    html = (folder / "report.html").read_text()
    assert all(f'src="{name}"' in html for name in files) and "@media print" in html
