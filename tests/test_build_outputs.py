"""Every template built once; its files read back with the libraries a fabricator's software uses."""

import hashlib
import json
import math
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
    vents = len(lay.vents)  # the ring vents over the base faces; no vent runs through a core pin
    holes = (len(lay.fill_ports) * spec.mold.fill_port ** 2 + vents * spec.mold.vent ** 2
             + len(lay.bolts) * bolt_clearance_mm(spec.mold.bolt, "normal") ** 2) * np.pi / 4
    labels = sum(_glyph_area(t) for t in end_cap_mold.lid_labels(spec))  # a board's taxel names recessed in it
    bed = _horizontal_groups(mesh)[(-1, 0.0)]
    assert bed == pytest.approx(lay.block_x * lay.block_y - holes - labels, rel=2e-3)
    assert bool(labels) == (len(taxels(spec)) > 1)


def _glyph_area(engraving) -> float:
    """Area of an engraving's glyphs, holes (the inside of a 4 or an o) left out (mm²)."""
    from matcad.parts.flat import engraving_outlines, even_odd_faces

    def area(loop):
        return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(loop, loop[1:] + loop[:1]))) / 2

    return sum(area(outer) - sum(area(h) for h in inner)
               for outer, inner in even_odd_faces(engraving_outlines(engraving)))


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


LAYER_ORDER = ["ENGRAVE", "CUT_INNER", "CUT_OUTER", "REFERENCE"]


def test_one_nested_file_per_sheet_cut_inner_before_outer(built):
    """Each acrylic sheet's DXF and SVG hold every part cut from it (its quantity), side by side without overlap,
    each hole inside its part, at that sheet's own kerf; entities in cutting order: engraving, inner cuts, outlines."""
    spec, out, _ = built
    report = json.loads((out / "report.json").read_text())
    by_sheet = {}
    for flat in laser_parts(spec):
        by_sheet.setdefault(flat.sheet, []).append(flat)
    assert sorted(s["sheet"] for s in report["sheets"]) == sorted(by_sheet)
    for s in report["sheets"]:
        flats = by_sheet[s["sheet"]]
        assert s["file"] == f"sheet_{s['sheet']}.dxf" and sorted(s["parts"]) == sorted(f.name for f in flats)
        assert {f.kerf for f in flats} == {s["kerf_mm"]}
        msp = ezdxf.readfile(out / s["file"]).modelspace()
        layers = [e.dxf.layer for e in msp]
        assert layers == sorted(layers, key=LAYER_ORDER.index), "cut order: engrave, inner, outer"
        outlines = [e for e in msp if e.dxf.layer == "CUT_OUTER"]
        boxes = []
        for e in outlines:
            pts = np.array([p[:2] for p in e.get_points("xy")])
            boxes.append((*pts.min(axis=0), *pts.max(axis=0)))
        assert len(boxes) == sum(f.quantity for f in flats)
        sizes = sorted((round(b[2] - b[0], 6), round(b[3] - b[1], 6)) for b in boxes)
        assert sizes == sorted((round(f.width + f.kerf, 6), round(f.depth + f.kerf, 6)) for f in flats
                               for _ in range(f.quantity))
        for i, a in enumerate(boxes):  # no two parts overlap: separated along x or y
            for b in boxes[i + 1:]:
                assert a[2] < b[0] or b[2] < a[0] or a[3] < b[1] or b[3] < a[1], (a, b)
        circles = msp.query("CIRCLE[layer=='CUT_INNER']")
        assert sorted(round(2 * c.dxf.radius, 6) for c in circles) == sorted(
            round(h.diameter - f.kerf, 6) for f in flats for h in f.holes for _ in range(f.quantity))
        for c in circles:
            x, y, r = c.dxf.center.x, c.dxf.center.y, c.dxf.radius
            assert any(b[0] < x - r and x + r < b[2] and b[1] < y - r and y + r < b[3] for b in boxes)
        engraved = sum(len(f.engrave) for f in flats for _ in range(f.quantity))
        assert bool(msp.query("LWPOLYLINE[layer=='ENGRAVE']")) == (engraved > 0)
        root = ET.parse(out / s["file"].replace(".dxf", ".svg")).getroot()
        groups = [g.get("id") for g in root.iter("{http://www.w3.org/2000/svg}g") if g.get("id") in LAYER_ORDER]
        assert groups == sorted(groups, key=LAYER_ORDER.index) and "CUT_OUTER" in groups


def test_sheets_pdf_prints_every_sheet_at_one_to_one(built, tmp_path):
    """sheets_1to1.pdf read back with poppler: one page per sheet at its stated paper size; rendered at 254 dpi
    (10 px/mm, no anti-aliasing) its reference square measures 10 mm and every part outline its kerf-compensated
    size."""
    import subprocess

    from PIL import Image
    from scipy import ndimage

    from tests.test_real_clients import need

    need("pdftoppm")  # poppler-utils: a failure in CI (MATCAD_REQUIRE_CLIENTS=1), a skip elsewhere
    spec, out, _ = built
    report = json.loads((out / "report.json").read_text())
    pdf = out / "sheets_1to1.pdf"
    info = subprocess.run(["pdfinfo", "-l", "99", pdf], capture_output=True, text=True, check=True).stdout
    sizes = [tuple(float(v) for v in m) for m in re.findall(r"Page\s+\d+ size:\s+([\d.]+) x ([\d.]+) pts", info)]
    assert len(sizes) == len(report["sheets"])
    text = subprocess.run(["pdftotext", "-layout", pdf, "-"], capture_output=True, text=True, check=True).stdout
    assert "Print at 100 %" in text
    flats = {f.name: f for f in laser_parts(spec)}
    for k, (s, (w_pt, h_pt)) in enumerate(zip(report["sheets"], sizes), start=1):
        page = s["pdf_page"]
        assert (w_pt / 72 * 25.4, h_pt / 72 * 25.4) == pytest.approx((page["width_mm"], page["height_mm"]), abs=0.1)
        stem = tmp_path / f"p{k}"
        subprocess.run(["pdftoppm", "-r", "254", "-aa", "no", "-aaVector", "no", "-png", "-f", str(k), "-l", str(k),
                        "-singlefile", pdf, stem], check=True)
        rgb = np.asarray(Image.open(f"{stem}.png").convert("RGB")).astype(int)
        r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]

        def boxes(mask):
            labels, n = ndimage.label(mask, structure=np.ones((3, 3)))
            return [(sl[1].stop - sl[1].start, sl[0].stop - sl[0].start) for sl in ndimage.find_objects(labels)]

        magenta = boxes((r > 200) & (g < 80) & (b > 200))
        square = max(magenta, key=lambda wh: wh[0] * wh[1])
        assert square[0] == pytest.approx(100, abs=2) and square[1] == pytest.approx(100, abs=2), square  # 10 mm
        red = sorted(boxes((r > 200) & (g < 80) & (b < 80)), key=lambda wh: -wh[0] * wh[1])
        want = sorted(((flats[n].width + flats[n].kerf) * 10, (flats[n].depth + flats[n].kerf) * 10)
                      for n in s["parts"] for _ in range(flats[n].quantity))
        got = sorted(red[:len(want)])
        assert len(got) == len(want)
        for (gw, gh), (ww, wh) in zip(got, want):
            assert (gw, gh) == pytest.approx((ww, wh), abs=3), (got, want)
        print(spec.name, s["sheet"], "square px", square, "outlines px", sorted(red[:len(want)]))


def test_print_job_3mf_read_back(built):
    """The 3MF print job(s) read back by trimesh's 3MF reader: every printed STL once, the same volume, flat on the
    bed (z from 0) inside the printer's bed, footprints apart; each object's slicer settings are its print
    profile's; an FDM mold base carries its nut pause at a layer boundary above the pockets, and the job's notes
    say how the mold base's captive nuts go in on either printer (at the pause, or pressed in after printing)."""
    import zipfile

    from matcad.export.threemf import bed_mm
    from matcad.parts.print_profile import profile

    spec, out, _ = built
    report = json.loads((out / "report.json").read_text())
    stls = sorted(p.stem for p in out.glob("*.stl") if p.stem != "end_cap")  # the cast cap is not printed
    job = report["print_job"]
    if not stls:
        assert job is None and not list(out.glob("*.3mf"))
        return
    printer = spec.machine.printer
    assert job["printer"] == printer
    seen, holders = [], []
    for f in job["files"]:
        scene = trimesh.load(out / f["file"])
        if {"end_cap_mold_base", "end_cap_mold_lid"} & set(scene.geometry):
            holders.append(f["file"])
        boxes = []
        for node in scene.graph.nodes_geometry:
            transform, name = scene.graph[node]
            mesh = scene.geometry[name].copy()
            mesh.apply_transform(transform)
            seen.append(name)
            assert mesh.volume == pytest.approx(trimesh.load_mesh(out / f"{name}.stl").volume, rel=1e-6)
            lo, hi = mesh.bounds
            assert lo[2] == pytest.approx(0.0, abs=1e-6)
            assert lo[0] >= 0 and lo[1] >= 0 and hi[0] <= bed_mm(spec)[0] and hi[1] <= bed_mm(spec)[1]
            boxes.append((lo[0], lo[1], hi[0], hi[1]))
        for i, a in enumerate(boxes):
            for b in boxes[i + 1:]:
                assert a[2] < b[0] or b[2] < a[0] or a[3] < b[1] or b[3] < a[1], (a, b)
        with zipfile.ZipFile(out / f["file"]) as z:
            config = ET.fromstring(z.read("Metadata/Slic3r_PE_model.config"))
            pauses = (ET.fromstring(z.read("Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml"))
                      if "Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml" in z.namelist() else None)
            notes = z.read("Metadata/matcad_print_notes.txt").decode()
        doings = [line.strip() for line in notes.splitlines() if line.strip().startswith(("PAUSE", "AFTER"))]
        if "end_cap_mold_base" in scene.geometry:  # the SLA traps' nuts were only in report.md's print step
            n, bolt = len(end_cap_mold_layout(spec).bolts), end_cap_mold_layout(spec).clamp.bolt
            want = (f"PAUSE after the layer at z = {f['pauses'][0]['after_layer_z_mm']:.2f} mm: insert {n} {bolt} nuts"
                    if printer == "fdm" else f"AFTER PRINTING: press an {bolt} nut into each of the {n} hex traps")
            assert len(doings) == 1 and doings[0].startswith(want), (doings, want)
        else:
            assert not doings, notes
        for obj in config.iter("object"):
            meta = {m.get("key"): m.get("value") for m in obj.iter("metadata") if m.get("type") == "object"}
            p = profile(printer, meta["name"])
            assert float(meta["layer_height"]) == p.layer_mm
            if printer == "fdm":
                assert int(meta["perimeters"]) == p.walls
                assert meta["fill_density"] == f"{p.infill_pct:g}%"
        codes = [] if pauses is None else [c for c in pauses.iter("code")]
        want = [o for o in f["pauses"]]
        assert len(codes) == len(want)
        for code, pause in zip(codes, want):
            assert code.get("gcode") == "M601" and "nut" in code.get("extra")
            p = profile(printer, pause["part"])
            layers = (pause["after_layer_z_mm"] - p.first_layer_mm) / p.layer_mm  # a whole number of layers
            assert layers == pytest.approx(round(layers), abs=1e-6)
            assert float(code.get("print_z")) == pytest.approx(pause["after_layer_z_mm"] + p.layer_mm / 2)
    assert sorted(seen) == stls
    if spec.outputs.end_cap_mold:  # the casting guide names the job files that hold the mold (mat-array-4:
        named = re.findall(r"print_\w+\.3mf", report["casting"]["steps"][0])  # print_sla_1.3mf, no print_sla.3mf)
        assert named == holders, (named, holders)
        c = end_cap_mold_layout(spec).clamp
        assert bool(c.pause_print_z) == (printer == "fdm") and (not c.open_below) == (printer == "fdm")


def end_cap_mold_layout(spec):
    from matcad.parts.end_cap_mold import layout

    return layout(spec)


def _engraved_boxes(msp):
    """Bounding boxes of the ENGRAVE layer's glyph loops, grouped into labels (loops within 0.6 mm) (mm)."""
    loops = []
    for e in msp.query("LWPOLYLINE[layer=='ENGRAVE']"):
        pts = np.array([p[:2] for p in e.get_points("xy")])
        loops.append([*pts.min(axis=0), *pts.max(axis=0)])
    labels = []
    for box in sorted(loops):
        for lab in labels:
            if box[0] <= lab[2] + 0.6 and lab[0] <= box[2] + 0.6 and box[1] <= lab[3] + 0.6 and lab[1] <= box[3] + 0.6:
                lab[:] = [min(lab[0], box[0]), min(lab[1], box[1]), max(lab[2], box[2]), max(lab[3], box[3])]
                break
        else:
            labels.append(list(box))
    return labels


def test_board_drilling_by_taxel_in_files_steps_and_bom(built):
    """A board's neck pilots: each neck hole in the DXF has an engraved label beside it, nearer its own neck than
    any other and clear of every hole; the drill step gives each taxel's pilot and finished size; the BOM one drill
    per finished size, naming its taxels (mat-array-4: 2.1 / 2.6 / 2.7 / 2.4 mm, not one 2.1 mm for all)."""
    from matcad.parts.neck_plate import drill_plan, neck_plate

    spec, out, _ = built
    board = taxels(spec)
    report = json.loads((out / "report.json").read_text())
    plan = drill_plan(spec)
    drill = [s for s in report["fabrication"]["steps"] if s["where"] == "drill"]
    if not plan:
        assert not drill
        return
    text = drill[0]["do"]
    for row in plan:
        t = next(t for t in board if t.name == row["taxel"])
        assert row["drill_mm"] == t.neck.diameter
        if len(board) > 1:
            assert f"{row['taxel']} {row['pilot_mm']:g} → {row['drill_mm']:g} mm" in text, text
    sizes = {}
    for row in plan:
        sizes.setdefault(row["drill_mm"], []).append(row["taxel"])
    assert sorted((d["diameter_mm"], d["taxels"]) for d in report["bom"]["drills"]) == sorted(sizes.items())
    if len(board) < 2:
        return
    msp = ezdxf.readfile(out / "neck_plate.dxf").modelspace()
    necks = [(t.name, t.x, t.y) for t in board]
    holes = [(c.dxf.center.x, c.dxf.center.y, c.dxf.radius) for c in msp.query("CIRCLE")]
    labels = _engraved_boxes(msp)
    flat = neck_plate(spec)
    for e in flat.engrave:
        if not e.text.startswith(tuple(f"{t.name} " for t in board)):
            continue
        name = e.text.split()[0]
        assert e.text == f"{name} Ø{next(t for t in board if t.name == name).neck.diameter:g}"
        box = next(b for b in labels if b[0] <= e.x + 0.3 and b[2] >= e.x and b[1] <= e.y + e.height
                   and b[3] >= e.y)  # the glyphs drawn at this engraving's baseline
        cx, cy = (box[0] + box[2]) / 2, (box[1] + box[3]) / 2
        assert min(necks, key=lambda n: math.hypot(n[1] - cx, n[2] - cy))[0] == name
        for x, y, r in holes:  # the glyphs keep clear of every hole
            nx, ny = min(max(x, box[0]), box[2]), min(max(y, box[1]), box[3])
            assert math.hypot(nx - x, ny - y) > r, (e.text, (x, y, r))
    assert sum(e.text.split()[0] in {t.name for t in board} for e in flat.engrave) == len(board)


def _loop_area(loop) -> float:
    return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(loop, loop[1:] + loop[:1]))) / 2


def _label_area(loops, engraving) -> float:
    """Area of the even-odd regions drawn by the closed ``loops`` lying within an engraving's glyph box (mm²)."""
    from matcad.parts.flat import even_odd_faces
    from matcad.parts.labels import engraving_box

    x0, y0, x1, y1 = engraving_box(engraving)
    inside = [loop for loop in loops if all(x0 - 0.5 <= x <= x1 + 0.5 and y0 - 0.5 <= y <= y1 + 0.5 for x, y in loop)]
    return sum(_loop_area(outer) - sum(_loop_area(h) for h in holes) for outer, holes in even_odd_faces(inside))


def _recessed_mm2(mesh, z: float, engraving) -> float:
    """Open area of a printed part's section at height z within an engraving's box: its recessed glyphs (mm²)."""
    section = mesh.section(plane_origin=[0.0, 0.0, z], plane_normal=[0.0, 0.0, 1.0])
    return _label_area([[tuple(p[:2]) for p in loop[:-1]] for loop in section.discrete], engraving)


def test_board_taxel_names_read_back_from_mold_mount_and_guides(built):
    """A board's taxel names read back from the files: recessed (half the label depth down) in the mold base's
    parting face, the lid's top face and the mount's top face, engraved in each guide's DXF, each the glyph area
    of its own name (t1 … t4 differ) and nearest its own pocket, bore mouth or cap hole."""
    from matcad.parts import end_cap_mold
    from matcad.parts.labels import PRINTED_LABEL_DEPTH_MM, engraving_box
    from matcad.parts.needle_mount import bore_mouth_mm, mount_labels
    from tests.readback import design_frame

    spec, out, _ = built
    board = taxels(spec)
    if len(board) < 2:
        return
    report = json.loads((out / "report.json").read_text())

    def check(labels, area, anchors):
        assert sorted(e.text for e in labels) == sorted(t.name for t in board)
        for e in labels:
            assert area(e) == pytest.approx(_glyph_area(e), rel=1e-3), e.text
            x0, y0, x1, y1 = engraving_box(e)
            own = min(anchors, key=lambda a: math.hypot(a[1] - (x0 + x1) / 2, a[2] - (y0 + y1) / 2))
            assert own[0] == e.text, (e, own)

    half = PRINTED_LABEL_DEPTH_MM / 2
    if spec.outputs.end_cap_mold:
        lay = end_cap_mold_layout(spec)
        pockets = [(t.name, x, 0.0) for x, t in zip(lay.cap_x, lay.slots)]
        base, lid = (design_frame(out, report, f"end_cap_mold_{p}.stl") for p in ("base", "lid"))
        check(end_cap_mold.base_labels(spec), lambda e: _recessed_mm2(base, -half, e), pockets)
        check(end_cap_mold.lid_labels(spec), lambda e: _recessed_mm2(lid, spec.mold.lid_thickness - half, e),
              pockets)
    if spec.outputs.needle_mount:
        mount = design_frame(out, report, "needle_mount.stl")  # the assembly frame: top face at -spacer.height
        mouths = [(t.name, *bore_mouth_mm(spec, t)[:2]) for t in board]
        check(mount_labels(spec), lambda e: _recessed_mm2(mount, -spec.spacer.height - half, e), mouths)
    names = {t.name for t in board}
    for flat in (f for f in laser_parts(spec) if f.name.startswith("guide_")):
        msp = ezdxf.readfile(out / f"{flat.name}.dxf").modelspace()
        loops = [[tuple(p[:2]) for p in e.get_points("xy")] for e in msp.query("LWPOLYLINE[layer=='ENGRAVE']")]
        check([e for e in flat.engrave if e.text in names], lambda e: _label_area(loops, e),
              [(t.name, t.x, t.y) for t in board])


def test_bom_agrees_with_the_casting_guide_and_stock(built):
    """Silicone in the BOM is the casting guide's (one source); the needle line has a count (one per taxel);
    bolts and dowels are stock lengths no shorter than the stack needs."""
    from matcad.parts.features import ISO_4762_LENGTHS_MM

    spec, out, _ = built
    report = json.loads((out / "report.json").read_text())
    bom, casting = report["bom"], report["casting"]
    if casting:
        assert bom["silicone"]["needed_mass_g"] == pytest.approx(casting["needed_g"], abs=1e-9)
        assert f"{casting['needed_g']:.2f} g" in (out / "report.md").read_text()
        assert bom["mold_clamp"]["length_mm"] in ISO_4762_LENGTHS_MM
    if "needle" in bom:
        assert bom["needle"]["count"] == len(taxels(spec))
    for key in ("bolts", "dowels"):
        if key in bom:
            assert bom[key]["length_mm"] >= bom[key]["min_length_mm"]
            assert bom[key]["length_mm"] == int(bom[key]["length_mm"])  # a stock length, not "≥ 15.04 mm"


def test_templates_claim_no_measurement_and_the_seal_warns(built):
    """No template calls a sheet measured without flagging it an example: the squeeze rule reports the guide as
    unverified (a warning with the nominal sheet's range, read back from the cast cap) and step 1 lists it among
    the sheets still to caliper."""
    spec, out, _ = built
    report = json.loads((out / "report.json").read_text())
    for section in (spec.plate, spec.guide, spec.spacer):
        assert not section.thickness_measured or section.thickness_example
    assert {spec.plate.laser_kerf, spec.guide.laser_kerf} != {None}  # per-sheet kerfs in the template
    seal = [f for f in report["findings"] if f["id"] == "seal.squeeze"]
    assert seal and all(f["level"] == "warning" for f in seal)
    s = report["fabrication"]["seal"]
    lo, hi = (s["unverified_low_mm"], s["unverified_high_mm"]) if s["guide_status"] == "example" else (
        s["squeeze_low_mm"], s["squeeze_high_mm"])
    assert (lo, hi) == pytest.approx((-0.45, 0.65), abs=1e-6)
    value = seal[0]["value"]  # the range when the sheet is an example, its low end when nominal
    assert (value if isinstance(value, list) else [value, hi]) == pytest.approx([lo, hi], abs=0.01)
    first = report["fabrication"]["steps"][0]["do"]
    assert f"{spec.guide.thickness:g} mm ({s['guide_status']})" in first


def test_step_names_every_spacer(built):
    spec, out, _ = built
    if not (out / "assembly.step").exists():
        return
    text = (out / "assembly.step").read_text(errors="replace")
    spacers = sorted(set(re.findall(r"'(spacer_\d+)'", text)))
    if spec.outputs.spacers and spec.spacer.style == "laser":
        assert spacers == [f"spacer_{i}" for i in range(1, len(spacers) + 1)] and len(spacers) >= 2


def _runs(row) -> int:
    """Separate stretches of True along a row of pixels, gaps of 3 px or more apart."""
    idx = np.flatnonzero(row)
    return 0 if not len(idx) else 1 + int(np.sum(np.diff(idx) > 3))


def test_previews_show_bores_cavities_and_pockets(built):
    """The pictures read back: the second view of the needle mount (a section through a needle's plane) is cut
    in two by its bore, the cap's (a section through its axis) by its cavity, at mid-height; the mold base seen
    from above shows a drawn rim per pocket and key inside its outline (flat shading alone gave a rectangle, a
    disc and a block with key holes)."""
    from PIL import Image
    from scipy import ndimage

    from matcad.render.previews import BASE_RGB, EDGE_RGB

    spec, out, _ = built
    for name, want in (("needle_mount", "split"), ("end_cap", "split"), ("end_cap_mold_base", "rims")):
        path = out / f"preview_{name}.png"
        if not (out / f"{name}.stl").exists():
            assert not path.exists()
            continue
        rgb = np.asarray(Image.open(path).convert("RGB"), dtype=float) / 255
        right = rgb[:, rgb.shape[1] // 2:]
        fill = np.all(np.abs(right - BASE_RGB) < 0.12, axis=-1)
        rows = np.flatnonzero(fill.any(axis=1))
        if want == "split":
            mid = fill[(rows[0] + rows[-1]) // 2]
            assert _runs(mid) >= 2, (name, _runs(mid))
        else:
            edge = np.all(np.abs(right - EDGE_RGB) < 0.25, axis=-1)
            cols = np.flatnonzero(fill.any(axis=0))
            inner = edge[rows[0] + 4:rows[-1] - 4, cols[0] + 4:cols[-1] - 4]
            _, n = ndimage.label(inner, structure=np.ones((3, 3)))
            assert n >= len(end_cap_mold_layout(spec).cap_x) + 2, (name, n)


def test_bed_rules_extents_are_the_files(built):
    """What print.bed and laser.bed hold to the beds is what the build wrote: each printed STL's bounds (as
    exported, in its print pose) equal its registry extent, and each nested sheet's DXF (outlines and reference
    square) spans the extents the rule reads."""
    from matcad.export.sheets import kit_sheets
    from matcad.parts.registry import Kind, wanted

    spec, out, _ = built
    for part in wanted(spec, Kind.PRINTED):
        lo, hi = trimesh.load_mesh(out / f"{part.name}.stl").bounds
        assert tuple(hi - lo) == pytest.approx(part.extent(spec), abs=1e-3), part.name
    for plan in kit_sheets(spec).values():
        msp = ezdxf.readfile(out / f"{plan.flat.name}.dxf").modelspace()
        pts = np.array([p[:2] for e in msp.query("LWPOLYLINE[layer=='CUT_OUTER' | layer=='REFERENCE']")
                        for p in e.get_points("xy")])
        x0, y0, x1, y1 = plan.extents
        assert (*pts.min(axis=0), *pts.max(axis=0)) == pytest.approx((x0, y0, x1, y1), abs=1e-6), plan.flat.name
