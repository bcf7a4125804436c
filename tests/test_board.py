"""A board of taxels: the 4-taxel template builds and reads back from its files (necks and guide holes from the
DXF, cavities from the mold lid's STL, needle bores from the mount's STEP), and each board rule fires on a spec
made to break it and not on the template."""

from __future__ import annotations

import dataclasses
import json
import math

import ezdxf
import pytest

from matcad import spec as spec_mod
from matcad.parts.features import needle_axis_mm, pin_hole_diameter_mm, sheet_kerf_mm
from matcad.parts.guide import BODY_CLEARANCE_MM
from matcad.parts.mold_layout import layout, mold_slots, pours_per_board
from matcad.rules import board as board_rules
from matcad.spec import cap_flange_diameter_mm
from matcad.spec import taxels
from tests.conftest import ROOT

ARRAY = ROOT / "templates" / "mat-array-4.toml"
PAPER = ROOT / "templates" / "mat-paper.toml"


@pytest.fixture(scope="module")
def spec():
    return spec_mod.load(ARRAY)


def _moved(spec, index: int, **fields):
    entries = list(spec.taxel)
    entries[index] = dataclasses.replace(entries[index], **fields)
    return dataclasses.replace(spec, taxel=tuple(entries))


def _ids(findings, level=None):
    return [f.id for f in findings if level is None or f.level == level]


# --- rules: silent on the template, firing on a spec broken for each --------------------------------------------

def test_board_rules_pass_the_template(spec):
    findings = [f for rule in board_rules.RULES for f in rule(spec)]
    assert [(f.id, f.level) for f in findings] == [("board.mold", "info")]
    assert findings[0].value == 1  # four different caps, four per mold: one pour casts the board


def test_board_rules_are_silent_for_a_single_taxel():
    paper = spec_mod.load(PAPER)
    assert [f for rule in board_rules.RULES for f in rule(paper)] == []


def test_cap_outside_the_plate_is_an_error_naming_the_plate(spec):
    bad = _moved(spec, 0, x=-14.0)
    found = [f for f in board_rules.plate_fit(bad) if f.id == "board.outside"]
    assert len(found) == 1 and found[0].level == "error"
    assert "plate.width" in found[0].fix and "t1" in found[0].message
    # 36/2 - 14 - 6 = -2 mm: the flange overhangs the edge by 2 mm
    assert found[0].value == pytest.approx(18.0 - 14.0 - cap_flange_diameter_mm(taxels(bad)[0]) / 2)


def test_cap_on_a_bolt_hole_is_an_error_naming_the_bolt_inset(spec):
    bad = _moved(spec, 0, x=-10.0, y=14.0)  # bolt at (-14.5, 18.5): 6.36 mm from the neck, flange r 6 + hole r 1.2
    found = [f for f in board_rules.plate_fit(bad) if f.id == "board.on_fastener"]
    assert found and all(f.level == "error" for f in found) and "plate.bolt_inset" in found[0].fix
    assert found[0].value == pytest.approx(math.hypot(4.5, 4.5) - 6.0 - 2.4 / 2, abs=1e-3)


@pytest.mark.parametrize("y,level", [(-1.5, "error"), (-2.0, "warning")])
def test_neighbouring_flanges_too_close(spec, y, level):
    bad = _moved(spec, 2, y=y)  # t3 under t1 (x = -7.5): 10.5 - y between axes, 12 mm flanges
    found = board_rules.spacing(bad)
    assert [(f.id, f.level) for f in found] == [("board.spacing", level)]
    assert found[0].value == pytest.approx(10.5 - y - 12.0)
    assert "t1" in found[0].message and "t3" in found[0].message


def test_needle_jet_along_the_plate_reaches_a_neighbour_in_line(spec):
    bad = _moved(spec, 1, y=10.5)  # t2 straight downstream (+x) of t1, 15 mm away
    found = board_rules.jet_interference(bad)
    assert [(f.id, f.level) for f in found] == [("board.jet", "warning")]
    assert "t1's needle jet" in found[0].message and "t2's neck" in found[0].message
    # the jet's half-width there: r0 + (s to the plate + distance along it) tan 12°, less the mouth's edge
    t1, t2 = taxels(bad)[:2]
    free, wall = board_rules.jet_clearance_mm(t1, t2)
    assert free == math.inf and found[0].value == pytest.approx(wall, abs=1e-3) and wall < 0


def test_needle_jet_across_a_neighbours_mouth_is_an_error(spec):
    t1 = taxels(spec)[0]
    # a neighbour whose neck sits right where t1's jet meets the plate, on the needle's side of t1's neck
    bad = _moved(spec, 0, needle_theta_deg=30.0, needle_y=3.0)
    mouth, _ = needle_axis_mm(taxels(bad)[0])
    bad = _moved(bad, 1, x=mouth[0] - 0.5, y=t1.y)
    found = [f for f in board_rules.jet_interference(bad) if f.message.startswith("t1's")]
    assert [(f.id, f.level) for f in found] == [("board.jet", "error")] and "free jet" in found[0].message


def test_thin_ligament_between_neck_and_bolt_is_a_warning(spec):
    bad = _moved(spec, 0, x=-8.9, y=12.8)  # 8.0 mm from the (-14.5, 18.5) bolt: flange clear, ligament not
    assert board_rules.plate_fit(bad) == []
    found = board_rules.plate_ligaments(bad)
    assert [(f.id, f.level) for f in found] == [("board.ligament", "warning")]
    want = math.hypot(-8.9 + 14.5, 12.8 - 18.5) - (2.1 + 2.4) / 2
    assert found[0].value == pytest.approx(want, abs=1e-4) and found[0].limit == pytest.approx(6.35)


def test_crossing_needle_bores_are_an_error(spec):
    bad = _moved(spec, 1, y=10.5, needle_theta_deg=30.0)  # t2 in t1's row, its 30° bore runs back under t1
    found = board_rules.bore_crossings(bad)
    assert [(f.id, f.level) for f in found] == [("board.bores", "error")]
    assert "t1" in found[0].message and "t2" in found[0].message and found[0].value < found[0].limit
    assert board_rules.bore_crossings(_moved(spec, 1, y=10.5)) == []  # same θ: parallel bores 15 mm apart


def test_mold_too_small_for_the_board_is_an_error(spec):
    bad = dataclasses.replace(spec, mold=dataclasses.replace(spec.mold, count=2))
    found = board_rules.mold_slots(bad)
    assert [(f.id, f.level) for f in found] == [("board.mold", "error")]
    assert "mold.count" in found[0].message and "t3, t4" in found[0].message


def test_mold_slots_group_identical_caps():
    paper = spec_mod.load(PAPER)
    grid = dataclasses.replace(paper, array=spec_mod.Array(columns=2, rows=2, pitch_x=16.0, pitch_y=16.0))
    board = taxels(grid)
    assert len(board) == 4 and len(mold_slots(board, 2)) == 2
    molds = pours_per_board(board, 2)  # four identical caps, two per mold: two pours
    assert molds["molds_per_board"] == 2 and molds["groups"][0]["slots_per_mold"] == 2
    assert pours_per_board(board, 5)["molds_per_board"] == 1


# --- laser parts read back from the DXF ------------------------------------------------------------------------

def _inner_circles(path):
    msp = ezdxf.readfile(path).modelspace()
    return [(c.dxf.center.x, c.dxf.center.y, 2 * c.dxf.radius) for c in msp.query("CIRCLE[layer=='CUT_INNER']")]


def _at(circles, x, y, tol=1e-6):
    found = [c for c in circles if abs(c[0] - x) < tol and abs(c[1] - y) < tol]
    assert len(found) == 1, (x, y, circles)
    return found[0][2]


@pytest.fixture(scope="module")
def laser_build(tmp_path_factory, spec):
    """The template's laser parts only: build checks every rule (the band rules run the cap mechanics). (spec,
    folder, BuildResult)"""
    from matcad.build import build

    out = tmp_path_factory.mktemp("laser") / "b"
    s = dataclasses.replace(spec, outputs=dataclasses.replace(spec.outputs, end_cap_mold=False, needle_mount=False,
                                                              assembly=False))
    return s, out, build(s, out)


def test_four_necks_read_back_from_the_dxf_at_their_positions(laser_build):
    spec, out, _ = laser_build
    circles = _inner_circles(out / "neck_plate.dxf")
    kerf = sheet_kerf_mm(spec, "plate")  # the template's own kerf for the plate sheet
    cx, cy = _read_centre(out / "neck_plate.dxf")
    for t in taxels(spec):  # pilots, drawn (finished - kerf)
        drawn = _at(circles, cx + t.x, cy + t.y)
        assert drawn == pytest.approx(t.neck.diameter - spec.plate.pilot_undersize - kerf, abs=1e-6)
    assert len(circles) == 4 + 4 + 2  # four necks, four bolts, two dowels


def _read_centre(path):
    """The plate centre in the DXF's coordinates: the middle of its outline."""
    msp = ezdxf.readfile(path).modelspace()
    pts = [p[:2] for p in msp.query("LWPOLYLINE[layer=='CUT_OUTER']")[0].get_points("xy")]
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2


@pytest.mark.parametrize("role", ["locator", "clamp"])
def test_guides_have_each_caps_hole_at_its_position(laser_build, role):
    spec, out, _ = laser_build
    path = out / f"guide_{role}.dxf"
    circles = _inner_circles(path)
    cx, cy = _read_centre(path)
    for t in taxels(spec):
        want = cap_flange_diameter_mm(t) if role == "locator" else t.end_cap.outer_diameter + BODY_CLEARANCE_MM
        assert _at(circles, cx + t.x, cy + t.y) == pytest.approx(want - sheet_kerf_mm(spec, "guide"), abs=1e-6)


def test_report_lists_every_taxel_and_its_needle(laser_build):
    spec, out, _ = laser_build
    report = json.loads((out / "report.json").read_text())
    rows = report["taxels"]
    assert [(r["name"], r["x_mm"], r["y_mm"]) for r in rows] == [(t.name, t.x, t.y) for t in taxels(spec)]
    assert report["bom"]["needle"]["count"] == 4 and "no manifold" in report["bom"]["needle"]["note"]
    f0 = [r["prediction"]["f0_hz"] for r in rows]
    assert f0 == sorted(f0) and all(b / a > 1.08 for a, b in zip(f0, f0[1:]))


def test_report_and_summary_give_every_taxel_not_the_first_as_the_board(laser_build, tmp_path, capsys):
    """report.md's headline and Taxels table carry each taxel's own f0 and band; the first taxel's detailed
    sections say whose they are; `build --json` of a board gives its taxels' bands and no single f0."""
    from matcad.cli import main

    spec, out, _ = laser_build
    report = json.loads((out / "report.json").read_text())
    text = (out / "report.md").read_text()
    head = text.splitlines()[2]
    for row in report["taxels"]:
        p = row["prediction"]
        assert f"{row['name']} {p['f0_hz']:.0f} Hz ({p['band_hz'][0]:.0f}–{p['band_hz'][1]:.0f})" in head
        assert (f"| {row['name']} | {row['x_mm']:g}, {row['y_mm']:g} | {row['cavity']['diameter']:g} × "
                f"{row['cavity']['length']:g} | {row['neck']['diameter']:g} |") in text
    assert "## Prediction of taxel t1 " in text and "## As built of taxel t1 " in text
    assert main(["build", str(out / "report.json"), "--out", str(tmp_path / "again"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["f0_hz"] is None and summary["band_hz"] is None
    assert [(t["name"], t["f0_hz"]) for t in summary["taxels"]] == [(r["name"], r["prediction"]["f0_hz"])
                                                                    for r in report["taxels"]]


def test_headline_and_verdict_line_name_each_taxel_whose_chosen_model_fails(laser_build):
    """The template's t1 (a cap wall mode near f0) is predicted by a model outside its checks: report.md's headline
    and `build`'s verdict line name it with the phrase its band chart uses (the headline said the first taxel's
    status as if the board's; the verdict line nothing), and no other taxel. (t3 and t4, clamped over 0.70 and 1.0
    of their short cavities, lay outside the wall-mode table until it was extended to a wall clamped whole.)"""
    from matcad.render.plots import chosen_model_status

    _, out, result = laser_build
    report = json.loads((out / "report.json").read_text())
    failing = {r["name"]: chosen_model_status(r["prediction"]) for r in report["taxels"]
               if chosen_model_status(r["prediction"])}
    assert set(failing) == {"t1"}
    head = (out / "report.md").read_text().splitlines()[2]
    verdict = next(line for line in result.to_text("b").splitlines() if line.startswith("4 taxels; verdict"))
    for name, status in failing.items():
        assert f"{name}: {status}" in head and f"{name}: {status}" in verdict
    for name in ("t2", "t3", "t4"):
        assert f"{name}:" not in head and f"{name}:" not in verdict


def test_a_boards_section_is_not_captioned_as_dimensioned(spec, tmp_path):
    """write_section_svg labels a board's parts without dimensions: its caption says so and names the taxel whose
    row it cuts (it said "dimensioned" as a single taxel's does)."""
    from matcad.prediction import predict
    from matcad.render.kit import render_figures
    from matcad.spec import taxel_spec

    (tmp_path / "section.svg").write_text("<svg/>")
    first = taxels(spec)[0]
    caption = render_figures(spec, predict(taxel_spec(spec, first)), tmp_path, {}, [])[0]["caption"]
    assert "dimensioned" not in caption and f"through {first.name}'s row of necks" in caption
    single = taxel_spec(spec, first)
    assert "dimensioned" in render_figures(single, predict(single), tmp_path, {}, [])[0]["caption"]


# --- 3-D parts read back from STL / STEP (CAD kernel) ----------------------------------------------------------

@pytest.fixture(scope="module")
def solid_build(tmp_path_factory, spec):
    from matcad.build import build

    out = tmp_path_factory.mktemp("solid") / "b"
    s = dataclasses.replace(spec, outputs=dataclasses.replace(spec.outputs, neck_plate=False, guides=False,
                                                              spacers=False, assembly=False))
    build(s, out)
    return s, out


def test_mold_lid_carries_four_core_pins_of_each_cavity(solid_build):
    import trimesh

    from tests.readback import nearest_circle, section_circles

    spec, out = solid_build
    lid = trimesh.load_mesh(out / "end_cap_mold_lid.stl")  # print pose: lid on the bed, pins up from its top
    lay = layout(spec)
    top = spec.mold.lid_thickness
    slots = lay.slots
    assert sorted(t.name for t in slots) == ["t1", "t2", "t3", "t4"]
    for x, t in zip(lay.cap_x, slots):
        for z, present in ((top + t.cavity.length - 0.05, True), (top + t.cavity.length + 0.05, False)):
            circles = [c for c in section_circles(lid, z) if c[2] > spec.mold.vent / 2 + 0.05]
            near = [c for c in circles if abs(c[0] - x) < 0.3]
            assert bool(near) == present, (t.name, z)
            if present:  # the pin is the cavity: its radius is D/2 (no draft), its axis at the slot, y = 0
                cx, cy, r = nearest_circle(near, x, 0.0)
                assert r == pytest.approx(t.cavity.diameter / 2, abs=0.01) and abs(cy) < 0.01


def test_board_mold_vents_every_cap_and_casts_nothing_inside_a_cavity(solid_build):
    """The board's mold read back from its STLs as tests/test_mold_venting.py reads a single taxel's: every
    ceiling of its four different caps within the vent reach (the base face by its slot's plan, the pin's end
    by its own tip radius: t4's 1.25 mm), and under the parting plane each position casts its own cap's volume
    and nothing more (no silicone inside a cavity)."""
    from tests.readback import assert_casts_only_the_caps, assert_vented

    spec, out = solid_build
    report = json.loads((out / "report.json").read_text())
    slots = layout(spec).slots
    reaches = assert_vented(spec, out, report)
    assert sorted((name, z) for name, z, _ in reaches) == sorted(
        [(t.name, 0.0) for t in slots] + [(t.name, -t.cavity.length) for t in slots])
    rows = assert_casts_only_the_caps(spec, out, report)
    assert [r["taxel"] for r in rows] == [t.name for t in slots]


def test_needle_mount_has_one_bore_per_taxel_aimed_at_its_neck(solid_build):
    from build123d import GeomType, Pos, import_step

    spec, out = solid_build
    matrix = json.loads((out / "report.json").read_text())["meshes"]["needle_mount.stl"]["design_to_print"]
    solid = Pos(0, 0, -matrix[2][3]) * import_step(out / "needle_mount.step")  # back to the assembly frame
    board = taxels(spec)
    axes = {}
    for f in solid.faces():
        if f.geom_type != GeomType.CYLINDER or abs(f.axis_of_rotation.direction.Z) > 0.9999:
            continue
        a = f.axis_of_rotation
        d, p = (a.direction if a.direction.Z > 0 else -a.direction), a.position
        hit = (round(p.X + (-p.Z / d.Z) * d.X, 4), round(p.Y, 4))  # where the axis meets the plate underside
        axes[hit] = (math.degrees(math.asin(d.Z)), f.radius, d.Y)
    assert len(axes) == len(board)
    for t in board:
        (mx, my, _), _ = needle_axis_mm(t)
        theta, radius, dy = axes[(round(mx, 4), round(my, 4))]
        assert theta == pytest.approx(t.needle.theta_deg, abs=0.05) and abs(dy) < 1e-9
        bore = pin_hole_diameter_mm(t.needle.outer_diameter, spec.machine.printer, t.needle.fit)
        assert radius == pytest.approx(bore / 2, abs=1e-6)
        # aimed at its own neck: needle.y from the axis' crossing to the neck's near edge
        assert t.x - t.neck.diameter / 2 - mx == pytest.approx(t.needle.y, abs=1e-6)


def test_assembly_places_every_taxels_cap_and_needle(spec):
    from matcad.parts.assembly import assembled_parts
    from matcad.parts.features import needle_tip_mm

    parts = assembled_parts(spec)
    for t in taxels(spec):
        box = parts[f"end_cap_{t.name}"].bounding_box()
        assert (box.center().X, box.center().Y) == (pytest.approx(t.x, abs=1e-6), pytest.approx(t.y, abs=1e-6))
        assert box.min.Z == pytest.approx(spec.neck.length, abs=1e-6)  # on the plate
        tip = needle_tip_mm(t)
        assert parts[f"needle_{t.name}"].bounding_box().max.Z == pytest.approx(-t.needle.tip_clearance, abs=1e-6)
        assert abs(parts[f"needle_{t.name}"].bounding_box().center().Y - tip[1]) < 1e-6


def test_a_finding_every_taxel_shares_is_listed_once():
    """A board's one-taxel geometry rules run on each taxel (matcad.rules.check); the guide sheet's squeeze, the
    same on every cap of templates/mat-array-4.toml, is one seal.squeeze finding naming t1-t4 (four identical lines
    before), while findings that differ per taxel stay one per taxel."""
    from matcad.rules import check
    from matcad.spec import load

    findings = check(load(ROOT / "templates" / "mat-array-4.toml"))
    seal = [f for f in findings if f.id == "seal.squeeze"]
    assert len(seal) == 1 and seal[0].message.startswith("t1, t2, t3, t4: ")
    assert [f.message.split(":")[0] for f in findings if f.id == "jet.strouhal"] == ["t1", "t2", "t3", "t4"]
