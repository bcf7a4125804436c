"""Real fabrication software reads what matcad writes: admesh and PrusaSlicer on every STL of every template,
LibreCAD on every DXF at 1:1 (its PDF rasterised and the ink measured in mm).

The tools are Debian packages that .ci/run installs (admesh, prusa-slicer, librecad, poppler-utils); there
MATCAD_REQUIRE_CLIENTS=1 turns a missing tool into a failure. Elsewhere the tests skip with that reason.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.build import build, build_coupon
from matcad.parts.catalogue import laser_parts
from matcad.parts.coupon import coupon_sheets, laser_coupon
from matcad.parts.flat import cut_plan
from tests.conftest import SINGLE_TEMPLATES, TEMPLATES, missing_client
from tests.readback import expected_bodies

TOOLS = ("admesh", "prusa-slicer", "librecad", "pdftoppm")
DPI = 254  # 10 pixels per mm


def need(tool):
    if shutil.which(tool) is None:
        missing_client(f"{tool} missing", f"a Debian package that .ci/run installs; apt-get install {tool}",
                       ".ci/run installs it")


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    root = tmp_path_factory.mktemp("clients")
    out = []
    for path in TEMPLATES:
        spec = spec_mod.load(path)
        out.append((spec, build(spec, root / spec.name).out_dir))
    spec = spec_mod.load(SINGLE_TEMPLATES[0])
    out.append((None, build_coupon(spec, root / "coupon")[0]))
    return out


def _stls(builds):
    return [p for _, folder in builds for p in sorted(folder.glob("*.stl"))]


def _bodies(builds) -> dict:
    """STL path → bodies it should hold (a board's cap reference holds its distinct caps)."""
    return {p: expected_bodies(spec, p.name) if spec is not None else 1
            for spec, folder in builds for p in sorted(folder.glob("*.stl"))}


def test_admesh_finds_nothing_to_repair(builds):
    need("admesh")
    stls = _stls(builds)
    bodies = _bodies(builds)
    assert len(stls) >= 9
    for stl in stls:
        text = subprocess.run(["admesh", str(stl)], capture_output=True, text=True, check=True).stdout
        counts = {k.strip(): float(v) for k, v in re.findall(r"([A-Za-z][A-Za-z ]*?)\s*:\s*(-?[\d.]+)", text)}
        assert counts["Number of parts"] == bodies[stl], stl.name
        for key in ("Total disconnected facets", "Degenerate facets", "Edges fixed", "Facets removed", "Facets added", "Facets reversed",
                    "Backwards edges", "Normals fixed"):
            assert counts[key] == 0, (stl.name, key, counts[key])


def test_prusa_slicer_slices_every_stl(builds, tmp_path):
    need("prusa-slicer")
    for stl in _stls(builds):
        gcode = tmp_path / f"{stl.stem}.gcode"
        proc = subprocess.run(["prusa-slicer", "--export-gcode", "--fill-density", "100%", "--fill-pattern",
                               "rectilinear", "--output", str(gcode), str(stl)], capture_output=True, text=True,
                              timeout=600)
        assert proc.returncode == 0, (stl.name, proc.stdout[-500:], proc.stderr[-500:])
        assert gcode.stat().st_size > 1000 and b"G1" in gcode.read_bytes()[:200000]


def support_volume_mm3(gcode_text: str) -> float:
    """Filament volume (mm³) PrusaSlicer extrudes in ';TYPE:Support material*' sections of a G-code file."""
    diameter = float(re.search(r"^; filament_diameter = ([\d.]+)", gcode_text, re.M).group(1))
    relative = re.search(r"^M83\b", gcode_text, re.M) is not None
    e_last, kind, support_mm = 0.0, "", 0.0
    for line in gcode_text.splitlines():
        if line.startswith(";TYPE:"):
            kind = line[6:]
        elif line.startswith("G92"):
            e_last = float(m.group(1)) if (m := re.search(r"E(-?[\d.]+)", line)) else e_last
        elif line.startswith(("G1 ", "G0 ")) and (m := re.search(r"E(-?[\d.]+)", line)):
            e = float(m.group(1))
            step = e if relative else e - e_last
            e_last = e_last + e if relative else e
            if kind.startswith("Support material") and step > 0:
                support_mm += step
    return support_mm * np.pi * diameter ** 2 / 4


def _support_volumes(folders, tmp_path) -> dict:
    """Each printed STL of the build folders as exported (its print pose), sliced with automatic supports enabled:
    {folder/name: support volume mm³}, asserting that supports were on and none was generated."""
    volumes = {}
    for folder in folders:
        report = json.loads((folder / "report.json").read_text())
        meshes = (report["meshes"] if "meshes" in report else
                  {"coupon_printed.stl": report["mesh"]} | {r["file"]: r["mesh"] for r in report["needle_sweep"]})
        for name, mesh in meshes.items():
            if not mesh["printed"]:
                continue
            gcode = tmp_path / f"{folder.name}-{name}.gcode"
            proc = subprocess.run(["prusa-slicer", "--export-gcode", "--support-material", "--support-material-auto",
                                   "--output", str(gcode), str(folder / name)], capture_output=True, text=True,
                                  timeout=600)
            assert proc.returncode == 0, (name, proc.stderr[-500:])
            text = gcode.read_text()
            assert "; support_material = 1" in text  # supports really were on
            volumes[f"{folder.name}/{name}"] = support_volume_mm3(text)
            assert ";TYPE:Support material" not in text, (folder.name, name, volumes[f"{folder.name}/{name}"])
    print("support volume per STL (mm^3):", volumes)
    return volumes


def test_prusa_slicer_with_supports_on_generates_none(builds, tmp_path):
    """Every template's printed STLs (mold halves, needle mounts, caps as printed) sliced with automatic supports
    on: no support. The coupon's y and θ trial mounts are sliced the same way in the slow test below."""
    need("prusa-slicer")
    volumes = _support_volumes([folder for spec, folder in builds if spec is not None], tmp_path)
    assert len(volumes) >= 7  # the templates' mold halves and needle mounts
    # the check can fail: the paper's lid turned back into its design (pour) pose, pins down, needs support
    import trimesh

    folder = next(f for _, f in builds if (f / "end_cap_mold_lid.stl").exists())
    matrix = json.loads((folder / "report.json").read_text())["meshes"]["end_cap_mold_lid.stl"]["design_to_print"]
    lid = trimesh.load_mesh(folder / "end_cap_mold_lid.stl")
    lid.apply_transform(np.linalg.inv(np.array(matrix)))
    pins_down = tmp_path / "lid_pins_down.stl"
    lid.export(pins_down)
    gcode = tmp_path / "pins_down.gcode"
    subprocess.run(["prusa-slicer", "--export-gcode", "--support-material", "--support-material-auto", "--output",
                    str(gcode), str(pins_down)], capture_output=True, check=True, timeout=600)
    pins_down_support = support_volume_mm3(gcode.read_text())
    print(f"lid pins down (as before): {pins_down_support:.1f} mm^3 of support")
    assert pins_down_support > 1.0


@pytest.mark.slow
def test_prusa_slicer_slices_the_coupon_mounts_with_supports_on_generating_none(builds, tmp_path):
    """The printed coupon and its five y and five θ trial mounts, sliced with automatic supports on: no support."""
    need("prusa-slicer")
    volumes = _support_volumes([folder for spec, folder in builds if spec is None], tmp_path)
    assert len(volumes) >= 11


def _ink_extent_mm(ppm_path):
    data = ppm_path.read_bytes()
    magic, size, depth, pixels = data.split(b"\n", 3)
    width, height = map(int, size.split())
    image = np.frombuffer(pixels, dtype=np.uint8).reshape(height, width, 3)
    ink = np.argwhere(image.min(axis=2) < 200)
    (y0, x0), (y1, x1) = ink.min(axis=0), ink.max(axis=0)
    return (x1 - x0) / (DPI / 25.4), (y1 - y0) / (DPI / 25.4)


def test_librecad_renders_every_dxf_at_one_to_one(builds, tmp_path):
    need("librecad")
    need("pdftoppm")
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    checked = 0
    coupon_spec = spec_mod.load(SINGLE_TEMPLATES[0])
    for spec, folder in builds:
        flats = laser_parts(spec) if spec is not None else [laser_coupon(coupon_spec, sheet)
                                                             for sheet in coupon_sheets(coupon_spec)]
        spec = spec or coupon_spec
        for flat in flats:
            plan = cut_plan(flat, spec.outputs.reference_square)
            x0, y0, x1, y1 = plan.extents
            target = tmp_path / f"{spec.name}-{flat.name}"
            target.mkdir()
            subprocess.run(["librecad", "dxf2pdf", "-s", "1", "-c", "-t", str(target), str(folder / f"{flat.name}.dxf")],
                           env=env, capture_output=True, timeout=120, check=True)
            pdf = target / f"{flat.name}.pdf"
            subprocess.run(["pdftoppm", "-r", str(DPI), str(pdf), str(target / "page")], check=True, timeout=120)
            width, height = _ink_extent_mm(next(target.glob("page*.ppm")))
            assert width == pytest.approx(x1 - x0, abs=0.3), flat.name
            assert height == pytest.approx(y1 - y0, abs=0.3), flat.name
            checked += 1
    assert checked >= 10  # every laser part of every template, and the coupon


def test_prusa_slicer_slices_every_print_job_with_its_pause(builds, tmp_path):
    """PrusaSlicer opens each FDM 3MF job as written (no options: the job's own per-object settings) and slices it;
    the G-code pauses (M601) once per pause the report lists, after the part's layer at the stated height and
    before its next layer (print_fdm.3mf of mat-paper: after z = 4.40 mm, at the job's z = 4.50 mm layer)."""
    import json

    from matcad.parts.print_profile import profile

    need("prusa-slicer")
    jobs = 0
    for spec, folder in builds:
        if spec is None or not (folder / "report.json").exists():
            continue
        job = json.loads((folder / "report.json").read_text())["print_job"]
        if not job or job["printer"] != "fdm":
            continue
        for f in job["files"]:
            gcode = tmp_path / f"{spec.name}_{f['file']}.gcode"
            proc = subprocess.run(["prusa-slicer", "--export-gcode", "--output", str(gcode), str(folder / f["file"])],
                                  capture_output=True, text=True, timeout=900)
            assert proc.returncode == 0, (f["file"], proc.stdout[-500:], proc.stderr[-500:])
            lines = gcode.read_text().splitlines()
            stops = [i for i, line in enumerate(lines) if line.strip() == "M601"]
            assert len(stops) == len(f["pauses"]), (f["file"], len(stops))
            for i, pause in zip(stops, f["pauses"]):
                z = float(next(line[3:] for line in reversed(lines[:i]) if line.startswith(";Z:")))
                layer = profile("fdm", pause["part"]).layer_mm
                assert pause["after_layer_z_mm"] <= z + 1e-6 < pause["after_layer_z_mm"] + layer, (z, pause)
            jobs += 1
    assert any(spec is not None and spec.machine.printer == "fdm" and (spec.outputs.end_cap_mold
                                                                       or spec.outputs.needle_mount)
               for spec, _ in builds), "no template prints on FDM: this test would check nothing"
    assert jobs
