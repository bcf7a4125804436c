"""Every template built once; its files read back with the libraries a fabricator's software uses."""

import hashlib
import json
import re
import xml.etree.ElementTree as ET

import ezdxf
import numpy as np
import pytest
import trimesh

from matcad import spec as spec_mod
from matcad.build import build
from matcad.export.dxf_svg import LAYERS
from matcad.output import MANIFEST
from matcad.parts.catalogue import laser_parts
from matcad.parts.features import cap_volume_mm3
from matcad.parts.mold_layout import cap_groups
from matcad.spec import taxel_spec, taxels
from matcad.report import KIT_ARCHIVE, REPORT_FILES
from tests.conftest import TEMPLATES
from tests.readback import expected_bodies


@pytest.fixture(scope="module", params=TEMPLATES, ids=lambda p: p.stem)
def built(request, tmp_path_factory):
    spec = spec_mod.load(request.param)
    out = tmp_path_factory.mktemp(spec.name) / spec.name
    result = build(spec, out)
    return spec, out, result


def _laser(spec):
    return {flat.name: flat for flat in laser_parts(spec)}


def test_report_manifest_matches_files(built):
    spec, out, result = built
    report = json.loads((out / "report.json").read_text())
    listed = {f["file"]: f for f in report["files"]}
    on_disk = {p.name for p in out.iterdir()} - set(REPORT_FILES) - {MANIFEST}
    assert set(listed) == on_disk
    for name, row in listed.items():
        data = (out / name).read_bytes()
        assert row["bytes"] == len(data) and row["sha256"] == hashlib.sha256(data).hexdigest()
    assert report["matcad_version"] and report["spec"]["name"] == spec.name
    assert report["prediction"]["f0_hz"] == pytest.approx(result.prediction.f0_hz)
    assert (out / "report.md").read_text().startswith(f"# {spec.name}")
    # the report says what predict says: for the paper's taxel, physics against the one published measurement
    for warning in report["prediction"]["warnings"]:
        assert warning in (out / "report.md").read_text()
    if spec.name == "mat-paper":
        assert "joined to the cavity" in (out / "report.md").read_text()


def test_dxf_units_layers_holes_outlines(built):
    spec, out, _ = built
    for name, flat in _laser(spec).items():
        kerf = flat.kerf
        doc = ezdxf.readfile(out / f"{name}.dxf")
        assert doc.header["$INSUNITS"] == 4
        auditor = doc.audit()
        assert not auditor.has_errors, auditor.errors
        colours = {layer: doc.layers.get(layer).color for layer in LAYERS}
        assert len(set(colours.values())) == len(LAYERS)
        msp = doc.modelspace()
        assert not msp.query("SPLINE ELLIPSE")
        circles = sorted(round(2 * c.dxf.radius, 9) for c in msp.query("CIRCLE[layer=='CUT_INNER']"))
        expected = sorted(round(h.diameter - kerf, 9) for h in flat.holes) * flat.quantity
        assert len(circles) == len(expected)
        for got, want in zip(circles, sorted(expected)):
            assert abs(got - want) <= 1e-6
        outlines = msp.query("LWPOLYLINE[layer=='CUT_OUTER']")
        assert len(outlines) == flat.quantity and all(p.closed for p in outlines)
        xs = [x for x, y, *_ in outlines[0].get_points("xyb")]
        ys = [y for x, y, *_ in outlines[0].get_points("xyb")]
        assert max(xs) - min(xs) == pytest.approx(flat.width + kerf, abs=1e-6)
        assert max(ys) - min(ys) == pytest.approx(flat.depth + kerf, abs=1e-6)
        refs = msp.query("LWPOLYLINE[layer=='REFERENCE']")
        if spec.outputs.reference_square:
            pts = [p[:2] for p in refs[0].get_points("xy")]
            assert max(p[0] for p in pts) - min(p[0] for p in pts) == pytest.approx(10.0, abs=1e-9)


def test_neck_hole_is_spec_minus_kerf(built):
    spec, out, _ = built
    doc = ezdxf.readfile(out / "neck_plate.dxf")
    kerf = spec.plate.laser_kerf if spec.plate.laser_kerf is not None else spec.machine.laser_kerf
    for t in taxels(spec):  # every taxel's neck at its position (the DXF's origin is the plate centre)
        neck = [c for c in doc.modelspace().query("CIRCLE") if abs(c.dxf.center.x - t.x) < 1e-9
                and abs(c.dxf.center.y - t.y) < 1e-9]
        cut = t.neck.diameter - (spec.plate.pilot_undersize if spec.plate.neck_pilot else 0.0)
        assert len(neck) == 1 and 2 * neck[0].dxf.radius == pytest.approx(cut - kerf, abs=1e-6)


def test_svg_mm_size_viewbox_and_colours(built):
    spec, out, _ = built
    for name in _laser(spec):
        root = ET.parse(out / f"{name}.svg").getroot()
        w, h = (float(re.fullmatch(r"([\d.]+)mm", root.get(k)).group(1)) for k in ("width", "height"))
        vb = [float(v) for v in root.get("viewBox").split()]
        assert vb[2] == pytest.approx(w) and vb[3] == pytest.approx(h)
        groups = {g.get("id"): g for g in root.iter("{http://www.w3.org/2000/svg}g")}
        assert groups["CUT_INNER"].get("stroke") != groups["CUT_OUTER"].get("stroke")
        assert groups["CUT_INNER"].get("stroke") == LAYERS["CUT_INNER"][1]
        radii = sorted(2 * float(c.get("r")) for c in groups["CUT_INNER"])
        flat = _laser(spec)[name]
        assert radii == pytest.approx(sorted(hh.diameter - flat.kerf for hh in flat.holes)
                                      * flat.quantity, abs=1e-6)


def test_stl_watertight_one_body_volume_matches_brep(built):
    spec, out, result = built
    meshes = result.report["meshes"]
    stls = sorted(p.name for p in out.glob("*.stl"))
    assert stls == sorted(meshes)
    for name in stls:
        mesh = trimesh.load_mesh(out / name)
        assert mesh.is_watertight and mesh.is_volume
        assert len(mesh.split(only_watertight=False)) == expected_bodies(spec, name)
        assert mesh.volume == pytest.approx(meshes[name]["brep_volume_mm3"], rel=1e-3)


def test_cap_volume_against_analytic(built):
    spec, out, _ = built
    if not spec.outputs.end_cap_mold:
        assert not (out / "end_cap.stl").exists()
        return
    mesh = trimesh.load_mesh(out / "end_cap.stl")  # a board's distinct caps side by side
    caps = [taxel_spec(spec, group[0]) for group in cap_groups(taxels(spec))]
    assert mesh.volume == pytest.approx(sum(cap_volume_mm3(c) for c in caps), rel=5e-3)


def test_only_asked_outputs_written(built):
    spec, out, _ = built
    names = {p.name for p in out.iterdir()}
    o = spec.outputs
    assert ("end_cap_mold_base.stl" in names) == o.end_cap_mold
    assert ("needle_mount.stl" in names) == o.needle_mount
    assert ("assembly.step" in names) == o.assembly
    assert ("spacer.dxf" in names) == (o.spacers and spec.spacer.style == "laser")


def test_report_markdown_tables_are_well_formed(built):
    _, out, _ = built
    lines = (out / "report.md").read_text().splitlines()
    tables, current = [], []
    for line in lines + [""]:
        if line.startswith("|"):
            current.append(line)
        elif current:
            tables.append(current)
            current = []
    assert len(tables) >= 4  # prediction, budget, rules, files
    for table in tables:
        widths = {len(re.findall(r"(?<!\\)\|", row)) for row in table}
        assert len(widths) == 1, table[0]


def _horizontal_groups(mesh):
    """Coplanar horizontal faces grouped by (normal sign, z rounded to 1 µm): {(sign, z): area} (mm²)."""
    groups = {}
    nz = mesh.face_normals[:, 2]
    for i in np.flatnonzero(np.abs(nz) > 1 - 1e-9):
        key = (int(np.sign(nz[i])), round(float(mesh.triangles[i, :, 2].mean()), 3))
        groups[key] = groups.get(key, 0.0) + float(mesh.area_faces[i])
    return groups


def test_every_printed_stl_lies_on_its_largest_flat_face(built):
    spec, out, result = built
    report = json.loads((out / "report.json").read_text())
    for name, m in report["meshes"].items():
        mesh = trimesh.load_mesh(out / name)
        groups = _horizontal_groups(mesh)
        z_min = round(float(mesh.bounds[0, 2]), 3)
        assert z_min == 0.0, name  # exported standing on the bed
        if not m["printed"]:
            continue
        bed = groups[(-1, z_min)]
        assert bed == max(groups.values()), (name, bed, max(groups.values()))
        extent = mesh.extents[0] * mesh.extents[1]
        assert bed > 0.75 * extent, (name, bed, extent)
        assert m["bed_face"] in (out / "report.md").read_text()


def test_mold_lid_exported_pins_up_with_its_outer_face_on_the_bed(built):
    spec, out, _ = built
    if not spec.outputs.end_cap_mold:
        return
    from matcad.parts import end_cap_mold
    from matcad.parts.features import bolt_clearance_mm

    lay = end_cap_mold.layout(spec)
    mesh = trimesh.load_mesh(out / "end_cap_mold_lid.stl")
    # the lid plate (lid_thickness) is at the bottom, the core pins (cavity length) stand above it
    assert mesh.bounds[1, 2] == pytest.approx(spec.mold.lid_thickness + spec.cavity.length, abs=1e-6)
    vents = len(lay.vents) + len(lay.pin_vents)
    holes = (len(lay.fill_ports) * spec.mold.fill_port ** 2 + vents * spec.mold.vent ** 2
             + len(lay.bolts) * bolt_clearance_mm(spec.mold.bolt, "normal") ** 2) * np.pi / 4
    bed = _horizontal_groups(mesh)[(-1, 0.0)]
    assert bed == pytest.approx(lay.block_x * lay.block_y - holes, rel=2e-3)


def test_seal_squeeze_read_back_from_the_cast_cap(built):
    """The report's squeeze range is the flange measured on end_cap.stl minus the guide sheet ± its tolerance."""
    spec, out, _ = built
    if not spec.outputs.end_cap_mold:
        return
    report = json.loads((out / "report.json").read_text())
    seal = report["fabrication"]["seal"]
    groups = _horizontal_groups(trimesh.load_mesh(out / "end_cap.stl"))
    flange = min(z for sign, z in groups if sign == 1)  # the flange's top: the lowest up-facing step
    t, tol = spec.guide.thickness, seal["sheet_tolerance_mm"]
    assert seal["squeeze_low_mm"] == pytest.approx(flange - (t + tol), abs=1e-3)
    assert seal["squeeze_high_mm"] == pytest.approx(flange - (t - tol), abs=1e-3)
    assert seal["squeeze_low_mm"] > 0  # the templates' measured guide sheet keeps the flange squeezed
    md = (out / "report.md").read_text()
    guide = next(c for c in report["fabrication"]["caliper"] if c["part"].startswith("guide"))
    assert guide["before_mold"] and "before printing the mold" in md


def test_kit_archive_holds_every_file_byte_for_byte(built):
    import zipfile

    _, out, _ = built
    with zipfile.ZipFile(out / KIT_ARCHIVE) as archive:
        assert archive.testzip() is None
        names = set(archive.namelist())
        assert names == {p.name for p in out.iterdir()} - {KIT_ARCHIVE, MANIFEST}
        for name in names:
            assert archive.read(name) == (out / name).read_bytes(), name
