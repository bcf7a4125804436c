"""Two neck lengths on one board: a [riser] sheet bonded on the neck plate (docs/arrays.md). The 4-taxel template
with a 1.5 mm riser that t2's and t4's necks run on through is built by the command line and read back from its
files: the riser's DXF (necks where they run through, flange pockets elsewhere, the stack's holes, its label), the
cast caps' flanges (thicker for a cap in a pocket), the assembly's heights, the bolt span, the report and the
fabrication plan; each riser rule fires on a spec made to break it and not on the board. A spec without a riser
builds as before: no riser file, no riser key, the heights of the stack without it."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import tomllib

import ezdxf
import pytest

from matcad import spec as spec_mod
from matcad.parts.features import (ISO_273_CLEARANCE_MM, bolt_nominal_mm, pin_hole_diameter_mm,
                                   plate_bolt_positions_mm, plate_dowel_positions_mm, sheet_kerf_mm)
from matcad.parts.stack import bolt_span_mm, clamp_seat_z_mm, squeeze_range_mm
from matcad.spec import taxel_spec, taxels
from tests.conftest import ROOT, run_cli
from tests.test_build_outputs import _glyph_area, _label_area

ARRAY = ROOT / "templates" / "mat-array-4.toml"
PAPER = ROOT / "templates" / "mat-paper.toml"
RISER_MM = 1.5
RISER_KERF_MM = 0.16
SQUEEZE_MM = 0.2
"""The caps' flange squeeze: a pocketed cap is squeezed over both calipered sheets' ±0.05 mm, which swallows the
template's 0.1 mm (seal.squeeze's error, tested below)."""
THROUGH = ("t2", "t4")
"""The taxels whose necks run on through the riser; t1's and t3's caps sit in its pockets."""
FAST_MECHANICS = 'material = "neo_hookean"\nsteps = 4\n'
"""A coarse cap mechanics for the board's loaded bands (as tests/conftest.py's FAST_MECHANICS): seconds on a cold
cache, where the grade's law takes a minute; the loaded bands are not what these tests read."""
LASER_ONLY = "[outputs]\nend_cap_mold = false\nneedle_mount = false\nassembly = false\n"


def riser_toml(through=THROUGH, riser: str = "") -> str:
    """The array template with a [riser] (``riser``: more of its lines), the squeeze raised to SQUEEZE_MM and
    ``neck_riser = true`` on the taxels named in ``through`` (TOML text)."""
    text = ARRAY.read_text(encoding="utf-8").replace('name = "mat-array-4"', 'name = "riser-4"')
    text = text.replace("[guide]", f"[riser]\nthickness = {RISER_MM}\nthickness_measured = true\n"
                        f"thickness_example = true\nlaser_kerf = {RISER_KERF_MM}\n{riser}\n[guide]", 1)
    text = text.replace("top_thickness = 2.0\n", f"top_thickness = 2.0\nflange_squeeze = {SQUEEZE_MM}\n", 1)
    text = text.replace("[mechanics]\n", f"[mechanics]\n{FAST_MECHANICS}", 1)
    head, *entries = text.split("[[taxel]]\n")
    return head + "".join(f"[[taxel]]\n{'neck_riser = true' + chr(10) if f't{i}' in through else ''}{entry}"
                          for i, entry in enumerate(entries, 1))


def riser_spec(through=THROUGH, riser: str = ""):
    return spec_mod.from_dict(tomllib.loads(riser_toml(through, riser)))


@pytest.fixture(scope="module")
def spec():
    return riser_spec()


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """`matcad build SPEC --out DIR --force` of the riser board's laser parts, in a fresh interpreter: (spec, folder,
    report.json). Forced: the longer necks move t2's and t4's bands onto t1's and t3's (bands.overlap), which is the
    band rules' business, not this file's."""
    folder = tmp_path_factory.mktemp("riser")
    path = folder / "riser.toml"
    path.write_text(riser_toml() + LASER_ONLY, encoding="utf-8")
    code, out, err = run_cli("build", path, "--out", folder / "kit", "--force")
    assert code == 0 and "Traceback" not in err, err
    report = json.loads((folder / "kit" / "report.json").read_text())
    assert report["verdict"] == "fail"  # built despite its rule errors, which it reports
    return spec_mod.load(path), folder / "kit", report


# --- the riser's cut file --------------------------------------------------------------------------------------

def _circles(path, layer="CUT_INNER"):
    msp = ezdxf.readfile(path).modelspace()
    return [(c.dxf.center.x, c.dxf.center.y, 2 * c.dxf.radius) for c in msp.query(f"CIRCLE[layer=='{layer}']")]


def _at(circles, x, y):
    found = [c for c in circles if math.hypot(c[0] - x, c[1] - y) < 1e-6]
    assert len(found) == 1, (x, y, circles)
    return found[0][2]


def test_riser_dxf_has_necks_through_it_and_pockets_elsewhere(built):
    """riser.dxf, read back: at t2 and t4 the neck's undersize pilot (d − plate.pilot_undersize, as on the plate:
    drilled through both sheets in one pass), at t1 and t3 the pocket of the cap's flange (the locator's hole), at
    the plate's dowels and bolts their holes, each drawn smaller by the riser's own kerf; the outline is the plate's
    grown by it. The report's holes say which taxel each belongs to and what a pilot is drilled to."""
    spec, out, report = built
    kerf = sheet_kerf_mm(spec, "riser")
    assert kerf == RISER_KERF_MM
    circles = _circles(out / "riser.dxf")
    board = taxels(spec)
    assert len(circles) == len(board) + 2 + 4
    for t in board:
        drawn = _at(circles, t.x, t.y)
        if t.name in THROUGH:
            assert drawn == pytest.approx(t.neck.diameter - spec.plate.pilot_undersize - kerf, abs=1e-6)
        else:
            flange = t.end_cap.outer_diameter + 2 * t.end_cap.flange_width
            assert flange == 12.0 and drawn == pytest.approx(flange - kerf, abs=1e-6)
    dowel = pin_hole_diameter_mm(spec.fasteners.dowel_diameter, "laser", spec.fasteners.dowel_fit_laser)
    for x, y in plate_dowel_positions_mm(spec):
        assert _at(circles, x, y) == pytest.approx(dowel - kerf, abs=1e-6)
    bolt = ISO_273_CLEARANCE_MM[spec.fasteners.bolt][spec.fasteners.bolt_fit]
    for x, y in plate_bolt_positions_mm(spec):
        assert _at(circles, x, y) == pytest.approx(bolt - kerf, abs=1e-6)
    # the plate's stack holes at the same places: the dowels line the two sheets up for bonding
    plate = _circles(out / "neck_plate.dxf")
    for x, y in plate_dowel_positions_mm(spec) + plate_bolt_positions_mm(spec):
        _at(plate, x, y)
    outline = ezdxf.readfile(out / "riser.dxf").modelspace().query("LWPOLYLINE[layer=='CUT_OUTER']")[0]
    xs, ys = zip(*((x, y) for x, y, *_ in outline.get_points("xyb")))
    assert max(xs) - min(xs) == pytest.approx(spec.plate.width + kerf, abs=1e-6)
    assert max(ys) - min(ys) == pytest.approx(spec.plate.depth + kerf, abs=1e-6)
    rows = {h["taxel"]: h for h in report["as_built"]["laser_holes"] if h["part"] == "riser" and h["taxel"]}
    assert {n for n, h in rows.items() if h["purpose"] == "neck_pilot"} == set(THROUGH)
    assert all(rows[n]["drill_to_mm"] == next(t.neck.diameter for t in board if t.name == n) for n in THROUGH)
    assert {n for n, h in rows.items() if h["purpose"] == "cap"} == {"t1", "t3"}


def test_riser_is_engraved_with_its_thickness_and_each_holes_taxel(built):
    """The riser's engraving, read back from the DXF: "RISER 1.5" on its edge, a through-neck's taxel and finished
    size ("t2 Ø2.6", as on the plate under it), a pocket's taxel name, each the glyph area of its text."""
    from matcad.parts.riser import riser

    spec, out, _ = built
    flat = riser(spec)
    texts = [e.text for e in flat.engrave]
    assert texts[0] == f"RISER {RISER_MM:g}"
    assert sorted(texts[1:]) == ["t1", "t2 Ø2.6", "t3", "t4 Ø2.4"]
    msp = ezdxf.readfile(out / "riser.dxf").modelspace()
    loops = [[tuple(p[:2]) for p in e.get_points("xy")] for e in msp.query("LWPOLYLINE[layer=='ENGRAVE']")]
    for e in flat.engrave:
        assert _label_area(loops, e) == pytest.approx(_glyph_area(e), rel=1e-3), e.text


def test_riser_has_its_own_sheet_caliper_row_and_coupon(built):
    """The riser is cut from its own sheet (sheet_riser.dxf, its thickness and kerf in the sheets table and the bill
    of materials), calipered before the mold is printed, and its kerf coupon sweeps necks and dowels."""
    from matcad.parts.coupon import SHEET_ROWS, coupon_sheets, laser_coupon

    spec, out, report = built
    sheet = next(s for s in report["sheets"] if s["sheet"] == "riser")
    assert sheet["parts"] == ["riser"] and sheet["thickness_mm"] == RISER_MM and sheet["kerf_mm"] == RISER_KERF_MM
    assert (out / "sheet_riser.dxf").exists()
    assert len(_circles(out / "sheet_riser.dxf")) == len(_circles(out / "riser.dxf"))
    bom = next(s for s in report["bom"]["sheets"] if s["thickness_mm"] == RISER_MM)
    assert "1 x riser" in bom["parts"]
    row = next(c for c in report["fabrication"]["caliper"] if c["sheet"] == "riser")
    assert row["part"] == "riser" and row["before_mold"] and row["status"] == "example"
    # the guide sheet is 1.5 mm too, and keeps its own row
    assert any(c["sheet"] == "guide" for c in report["fabrication"]["caliper"])
    assert "riser" in coupon_sheets(spec) and SHEET_ROWS["riser"] == ("neck", "dowel")
    coupon = laser_coupon(spec, "riser")
    assert (coupon.thickness, coupon.kerf) == (RISER_MM, RISER_KERF_MM)


# --- the stack's heights ---------------------------------------------------------------------------------------

def test_bolt_span_and_bom_include_the_riser(built):
    """The bolts and dowels span the riser too: mount top to clamp top = spacer + plate + riser + guide + squeeze +
    guide (mm), and the bill of materials asks for that plus the thread in the mount."""
    spec, _, report = built
    span = spec.spacer.height + spec.neck.length + RISER_MM + spec.guide.thickness + SQUEEZE_MM + spec.guide.thickness
    assert bolt_span_mm(spec) == pytest.approx(span, abs=1e-9) and span == pytest.approx(12.64)
    engage = min(2.0 * bolt_nominal_mm(spec.fasteners.bolt), spec.mount.thickness)
    assert report["bom"]["bolts"]["min_length_mm"] == pytest.approx(span + engage)
    assert report["bom"]["dowels"]["min_length_mm"] == pytest.approx(span + engage)
    assert clamp_seat_z_mm(spec) == pytest.approx(spec.neck.length + RISER_MM + spec.guide.thickness + SQUEEZE_MM)
    for through in (False, True):  # one taxel, its neck through the riser or its cap in a pocket: one clamp height
        one = _paper_with_riser(through)
        seat = one.neck.length + RISER_MM + one.guide.thickness + one.end_cap.flange_squeeze
        assert clamp_seat_z_mm(one) == pytest.approx(seat), through
        assert bolt_span_mm(one) == pytest.approx(seat + one.guide.thickness + one.spacer.height), through


def test_assembly_stacks_the_riser_and_seats_each_cap(spec):
    """assembly's solids: the riser from the plate's top up one riser sheet, its necks drilled to size (its volume
    is the sheet less every hole at its finished size), the locator on it, each cap on its seat (t2, t4 on the
    riser, t1, t3 in their pockets on the plate) and the clamp resting on every flange's top at one height."""
    from matcad.parts.assembly import assembled_parts
    from matcad.spec import cap_flange_thickness_mm

    parts = assembled_parts(spec)
    l, g = spec.neck.length, spec.guide.thickness
    box = parts["riser"].bounding_box()
    assert (box.min.Z, box.max.Z) == (pytest.approx(l), pytest.approx(l + RISER_MM))
    board = taxels(spec)
    holes = [t.neck.diameter if t.name in THROUGH else 12.0 for t in board]
    holes += [pin_hole_diameter_mm(spec.fasteners.dowel_diameter, "laser", spec.fasteners.dowel_fit_laser)] * 2
    holes += [ISO_273_CLEARANCE_MM[spec.fasteners.bolt][spec.fasteners.bolt_fit]] * 4
    sheet = spec.plate.width * spec.plate.depth - sum(math.pi / 4 * d * d for d in holes)
    assert parts["riser"].volume == pytest.approx(sheet * RISER_MM, rel=1e-6)
    assert parts["guide_locator"].bounding_box().min.Z == pytest.approx(l + RISER_MM)
    clamp = parts["guide_clamp"].bounding_box().min.Z
    assert clamp == pytest.approx(l + RISER_MM + g + SQUEEZE_MM)
    for t in board:
        seat = parts[f"end_cap_{t.name}"].bounding_box().min.Z
        assert seat == pytest.approx(l + (RISER_MM if t.name in THROUGH else 0.0)), t.name
        assert seat + cap_flange_thickness_mm(spec, t) == pytest.approx(clamp), t.name


def _flange_mm(body) -> float:
    """A cast cap's flange thickness read from its mesh (base on z = 0): the highest vertex beyond the body's radius
    (mm)."""
    centre = (body.bounds[0] + body.bounds[1]) / 2
    r = ((body.vertices[:, 0] - centre[0]) ** 2 + (body.vertices[:, 1] - centre[1]) ** 2) ** 0.5
    return float(body.vertices[r > r.max() - 0.5, 2].max())


def test_cast_caps_have_the_flange_of_their_seat(spec, tmp_path):
    """end_cap.stl of the riser board, written as the build writes it and read back: one body per taxel (the four
    caps differ), each as tall as its cavity and top and of its cast volume; the flange of a pocketed cap (t1, t3)
    guide + squeeze + riser = 3.2 mm thick, of a cap on the riser (t2, t4) guide + squeeze = 1.7 mm."""
    import trimesh

    from matcad.build import write_printed_part
    from matcad.parts.end_cap import board_caps
    from matcad.parts.features import cap_volume_mm3

    write_printed_part("end_cap", board_caps(spec), spec, tmp_path)
    bodies = trimesh.load_mesh(tmp_path / "end_cap.stl").split(only_watertight=True)
    board = taxels(spec)
    assert len(bodies) == len(board)
    for t in board:
        want = cap_volume_mm3(taxel_spec(spec, t))
        body = min(bodies, key=lambda b: abs(b.volume - want))
        assert body.volume == pytest.approx(want, rel=5e-3), t.name
        assert body.bounds[1][2] == pytest.approx(t.cavity.length + t.end_cap.top_thickness, abs=1e-3)
        pocket = spec.guide.thickness + SQUEEZE_MM + RISER_MM
        assert _flange_mm(body) == pytest.approx(pocket - (RISER_MM if t.name in THROUGH else 0.0), abs=1e-3), t.name


def test_a_cap_in_a_pocket_is_not_the_same_cap_on_the_riser(spec):
    """t3 given t1's cavity and neck: in a pocket too, one cap casts both (one group, one mold slot each pour);
    with its neck run through the riser, its cap is another (its flange 1.5 mm thinner): a group, and a mold
    position, of its own."""
    from matcad.parts.mold_layout import cap_groups, layout, pours_per_board
    from matcad.spec import cap_flange_thickness_mm

    entries = list(spec.taxel)
    for through in (False, True):
        entries[2] = dataclasses.replace(entries[2], cavity_length=None, neck_diameter=None, neck_riser=through)
        board_spec = dataclasses.replace(spec, taxel=tuple(entries))
        groups = [[t.name for t in g] for g in cap_groups(taxels(board_spec))]
        assert groups == ([["t1"], ["t2"], ["t3"], ["t4"]] if through else [["t1", "t3"], ["t2"], ["t4"]]), through
        assert pours_per_board(taxels(board_spec), 4)["molds_per_board"] == 1
        flanges = {t.name: cap_flange_thickness_mm(board_spec, t) for t in layout(board_spec).slots}
        assert flanges["t3"] == pytest.approx(1.7 if through else 3.2)


def test_mold_casts_the_pocketed_flanges_thicker(spec, tmp_path):
    """end_cap_mold_base.stl, read back in the mold frame (parting plane z = 0, the caps upside down): between the
    through caps' flange (1.7 mm) and the pocketed caps' (3.2 mm), the base's section holds the flange's circle
    (Ø12) at t1's and t3's pockets and only the body's (Ø8) at t2's and t4's."""
    from matcad.build import write_printed_part
    from matcad.parts.end_cap_mold import layout, mold_base
    from tests.readback import design_frame, nearest_circle, section_circles

    checks = write_printed_part("end_cap_mold_base", mold_base(spec), spec, tmp_path)
    base = design_frame(tmp_path, {"meshes": {"end_cap_mold_base.stl": checks}}, "end_cap_mold_base.stl")
    circles = section_circles(base, -2.5)
    for x, t in zip(layout(spec).cap_x, layout(spec).slots):
        r = nearest_circle(circles, x, 0.0)[2]
        assert r == pytest.approx(4.0 if t.name in THROUGH else 6.0, abs=0.02), t.name


# --- the report and the fabrication plan -----------------------------------------------------------------------

def test_report_gives_the_riser_and_each_taxels_neck(built):
    """report.json's as_built.riser and taxels, report.md's and report.html's riser line: the sheet, the taxels whose
    necks run through it, every taxel's neck length (plate 6.35 mm, + 1.5 mm through the riser), seat and flange."""
    _, out, report = built
    riser = report["as_built"]["riser"]
    assert (riser["thickness_mm"], riser["status"], riser["laser_kerf_mm"]) == (RISER_MM, "example", RISER_KERF_MM)
    assert riser["through"] == list(THROUGH) and riser["pocketed"] == ["t1", "t3"]
    necks = {r["name"]: r["neck_length_mm"] for r in riser["taxels"]}
    assert necks == {"t1": 6.35, "t2": pytest.approx(7.85), "t3": 6.35, "t4": pytest.approx(7.85)}
    assert {r["name"]: r["neck_length_mm"] for r in report["taxels"]} == necks
    assert {r["name"]: r["cap_seat"] for r in report["taxels"]} == {"t1": "plate", "t2": "riser", "t3": "plate",
                                                                   "t4": "riser"}
    md, html = (out / "report.md").read_text(), (out / "report.html").read_text()
    for text in (md, html):
        assert "riser: 1.5 mm sheet" in text and "necks through it: t2, t4" in text
        assert "t2 neck l 7.85 mm, cap on the riser, flange 1.7 mm" in text
        assert "t1 neck l 6.35 mm, cap on the plate in a pocket of the riser, flange 3.2 mm" in text


def test_fabrication_bonds_the_riser_before_drilling_through_both_sheets(spec):
    """The plan cuts the riser from its sheet, bonds it on the plate on the dowels with solvent cement before any
    neck is drilled, drills t2's and t4's necks through both sheets in one pass, casts t1's and t3's flanges
    thicker and seats each cap where it sits."""
    from matcad.parts.catalogue import laser_parts
    from matcad.report.fabrication import fabrication

    plan = fabrication(spec, laser_parts(spec))
    steps = plan["steps"]
    where = [s["where"] for s in steps]
    bond = next(i for i, s in enumerate(steps) if s["do"].startswith("Bond the 1.5 mm riser"))
    drill = where.index("drill")
    cut = next(i for i, s in enumerate(steps) if "sheet_riser.dxf" in s["files"])
    assert cut < bond < drill
    assert "dowels" in steps[bond]["do"] and "solvent cement" in steps[bond]["do"]
    assert steps[drill]["files"] == ["neck_plate.dxf", "riser.dxf"]
    assert "t2, t4: their necks run on through the bonded riser" in steps[drill]["do"]
    assert "one pass" in steps[drill]["do"]
    cast = next(s for s in steps if s["do"].startswith("Cast the caps"))
    assert "t1, t3: flanges cast 3.2 mm thick" in cast["do"] and "t2, t4: flanges cast 1.7 mm thick" in cast["do"]
    stack = next(s for s in steps if s["do"].startswith("Stack on the mount"))
    assert "riser.dxf" in stack["files"] and "t1, t3 down through the riser's pockets onto the plate" in stack["do"]
    assert "riser.thickness" in steps[0]["do"]
    seal = {c["seat"]: c for c in plan["seal"]["caps"]}
    assert seal["plate"]["taxels"] == ["t1", "t3"] and seal["plate"]["flange_mm"] == pytest.approx(3.2)
    assert seal["plate"]["sheet_tolerance_mm"] == pytest.approx(0.10)  # guide's 0.05 + riser's 0.05, calipered
    assert seal["riser"]["sheet_tolerance_mm"] == pytest.approx(0.05)


# --- design rules ----------------------------------------------------------------------------------------------

def _paper_with_riser(through: bool):
    data = tomllib.loads(PAPER.read_text(encoding="utf-8"))
    data["riser"] = {"thickness": RISER_MM}
    data["neck"]["riser"] = through
    return spec_mod.from_dict(data)


def test_idle_riser_is_a_warning_and_a_used_one_is_not(spec):
    """riser.idle: a [riser] no neck runs through (the paper's taxel, its cap in a pocket) warns; with its neck run
    through, with the board's t2 and t4 through, or with no riser at all, nothing."""
    from matcad.rules.stack import riser_idle

    found = riser_idle(_paper_with_riser(False))
    assert [(f.id, f.level) for f in found] == [("riser.idle", "warning")]
    assert found[0].message.startswith("riser: ") and "neck_riser = true" in found[0].fix
    assert riser_idle(_paper_with_riser(True)) == []
    assert riser_idle(spec) == []
    assert riser_idle(spec_mod.load(ARRAY)) == []


def test_idle_riser_reaches_check_and_the_cli(tmp_path):
    """The finding reaches `matcad check --json` of the spec file, beside the error it brings: the paper's 0.1 mm
    squeeze over a nominal riser's tolerance and the guide's (exit 1)."""
    path = tmp_path / "idle.toml"
    path.write_text(PAPER.read_text(encoding="utf-8") + "\n[riser]\nthickness = 1.5\n", encoding="utf-8")
    code, out, err = run_cli("check", path, "--json")
    assert code == 1 and "Traceback" not in err, err
    found = {(f["id"], f["level"]) for f in json.loads(out)["findings"]}
    assert {("riser.idle", "warning"), ("seal.squeeze", "error")} <= found


def test_pocketed_seal_is_judged_over_both_sheets(spec):
    """seal.squeeze per taxel: a pocketed cap (t1, t3) is squeezed over the guide's and the riser's tolerance (both
    calipered: ±0.10 mm), a cap on the riser over the guide's (±0.05 mm); with the riser nominal the pocketed
    flange's squeeze can be swallowed (an error naming the riser), the through caps' not."""
    from matcad.rules import check

    pocket, through = (taxel_spec(spec, t) for t in taxels(spec)[:2])
    assert squeeze_range_mm(pocket) == pytest.approx((0.1, 0.3, 0.1))
    assert squeeze_range_mm(through) == pytest.approx((0.15, 0.25, 0.05))
    loose = riser_spec()
    loose = dataclasses.replace(loose, riser=dataclasses.replace(loose.riser, thickness_measured=False,
                                                                 thickness_example=False))
    seals = {f.message.split(":")[0]: f for f in check(loose) if f.id == "seal.squeeze"}
    assert seals["t1, t3"].level == "error" and "riser.thickness" in seals["t1, t3"].fix
    assert "guide and riser sheets' ±0.60 mm" in seals["t1, t3"].message  # 0.05 calipered + 0.4 + 0.1 x 1.5 nominal
    assert seals["t2, t4"].level != "error"


def test_riser_ligament_between_a_pocket_and_a_neck(spec):
    """board.ligament in the riser: t1 moved to (3, 10.5) leaves 8.32 − (12 + 2.6) / 2 = 1.02 mm of riser between
    its pocket and t2's neck, under one 1.5 mm riser sheet: a warning naming both; the board as built has none."""
    from matcad.rules.board import riser_ligaments

    assert riser_ligaments(spec) == []
    entries = list(spec.taxel)
    entries[0] = dataclasses.replace(entries[0], x=3.0)
    moved = dataclasses.replace(spec, taxel=tuple(entries))
    found = riser_ligaments(moved)
    hit = [f for f in found if "t1's pocket and t2's neck" in f.message]
    assert len(hit) == 1 and hit[0].message.startswith("riser: ") and hit[0].level == "warning"
    assert hit[0].value == pytest.approx(math.hypot(4.5, 7.0) - 7.3, abs=1e-4) and hit[0].limit == RISER_MM


def test_laser_rules_judge_the_riser_sheet(spec):
    """The laser rules take the riser as every sheet: its own laser.stock line (a 1.5 mm guide does not hide it),
    its webs (laser.web) and its nested sheet on the bed (laser.bed)."""
    from matcad.rules import laser

    loose = dataclasses.replace(spec, riser=dataclasses.replace(spec.riser, thickness_measured=False,
                                                                thickness_example=False))
    stock = [f for f in laser.stock_thickness(loose) if f.message.startswith("riser:")]
    assert [(f.level, f.value) for f in stock] == [("warning", RISER_MM)]
    assert any(f.message.startswith("guide_locator:") for f in laser.stock_thickness(loose))
    fussy = dataclasses.replace(spec, machine=dataclasses.replace(spec.machine, laser_min_feature=3.0))
    assert any(f.message.startswith("riser:") for f in laser.feature_and_web(fussy))
    small = dataclasses.replace(spec, machine=dataclasses.replace(spec.machine, laser_bed_x=40.0, laser_bed_y=40.0))
    assert any("(riser)" in f.message for f in laser.laser_bed(small))


def test_a_neck_riser_without_a_riser_is_refused_without_a_traceback(tmp_path):
    """Bad input exits 2 with a message, no traceback: a neck_riser with the [riser] table left out, a riser 0 thick."""
    for name, text in (("orphan", re.sub(r"\[riser\]\n(?:[^\n\[]+\n)*", "", riser_toml())),
                       ("thin", riser_toml().replace(f"thickness = {RISER_MM}\n", "thickness = 0\n", 1))):
        assert "neck_riser = true" in text
        path = tmp_path / f"{name}.toml"
        path.write_text(text, encoding="utf-8")
        code, _, err = run_cli("check", path)
        assert code == 2 and "Traceback" not in err, (name, err)


# --- without a riser, as before --------------------------------------------------------------------------------

def test_a_board_without_a_riser_is_stacked_as_before():
    """No [riser]: no riser part, every cap on the plate, the clamp at l + guide + squeeze exactly (float for float
    the formula before the riser), the caps grouped by cavity and cap alone, no riser key in the report data."""
    from matcad.parts.catalogue import laser_parts
    from matcad.parts.mold_layout import cap_groups
    from matcad.report.data import as_built
    from matcad.report.fabrication import seal

    plain = spec_mod.load(ARRAY)
    assert plain.riser is None and "riser" not in [f.name for f in laser_parts(plain)]
    assert clamp_seat_z_mm(plain) == plain.neck.length + (plain.guide.thickness + plain.end_cap.flange_squeeze)
    assert bolt_span_mm(plain) == clamp_seat_z_mm(plain) + plain.guide.thickness + plain.spacer.height
    by_cap = {}
    for t in taxels(plain):
        by_cap.setdefault((t.cavity, t.end_cap), []).append(t)
    assert cap_groups(taxels(plain)) == list(by_cap.values())
    assert "riser" not in as_built(plain) and "caps" not in seal(plain)
    assert as_built(plain)["neck_length_mm"] == plain.neck.length
