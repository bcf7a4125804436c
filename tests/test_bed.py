"""Fabrication limits of long boards: the printer's build volume and the laser's bed (print.bed, laser.bed), and the
neck plate bent by a pressed taxel (plate.bending): the rules fire with their numbers on specs that break them,
stay silent on the templates, and the plate's closed form holds against statics."""


import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.rules import check
from tests.conftest import PAPER, ROOT, TEMPLATES, spec_with

SLA_ARRAY = ROOT / "templates" / "mat-sla-array.toml"


def _found(spec, rule_id):
    return [f for f in check(spec) if f.id == rule_id]


@pytest.mark.parametrize("template", TEMPLATES, ids=lambda p: p.stem)
def test_templates_fit_the_default_beds_and_do_not_bend(template):
    spec = spec_mod.load(template)
    assert not [f for f in check(spec) if f.id in ("print.bed", "laser.bed", "plate.bending")]


def test_default_beds_by_printer():
    fdm, sla = spec_mod.load(PAPER).machine, spec_mod.load(SLA_ARRAY).machine
    assert (fdm.print_volume_x, fdm.print_volume_y, fdm.print_volume_z) == (250.0, 210.0, 220.0)  # Prusa MK4
    assert (sla.print_volume_x, sla.print_volume_y, sla.print_volume_z) == (120.0, 68.0, 150.0)  # Prusa SL1
    assert (fdm.laser_bed_x, fdm.laser_bed_y) == (300.0, 200.0)  # K40-class
    with pytest.raises(spec_mod.SpecError, match="machine.print_volume_x"):
        spec_with(PAPER, machine__print_volume_x=-5.0)


def test_print_bed_names_part_size_field_and_volume():
    """The paper's mold base is 36.8 x 20.8 x 10.76 mm, its mount 24 x 42 x 8 mm: a 30 x 30 mm bed holds neither
    (even turned), a 10 mm build height only the lid's 7.76 mm."""
    found = {f.message.split(":")[0]: f for f in _found(spec_with(PAPER, machine__print_volume_x=30.0,
                                                              machine__print_volume_y=30.0), "print.bed")}
    assert set(found) == {"end_cap_mold_base", "end_cap_mold_lid", "needle_mount"}
    base = found["end_cap_mold_base"]
    assert base.level == "error" and base.value == pytest.approx([36.8, 20.8, 10.76]) and base.limit == [30, 30, 220]
    assert "36.8 x 20.8 x 10.8 mm" in base.message and "machine.print_volume_x/y/z = 30 x 30 x 220 mm" in base.message
    assert "mold.count" not in base.fix  # one cap per mold already
    assert not _found(spec_with(PAPER, machine__print_volume_x=45.0, machine__print_volume_y=25.0), "print.bed")  # the
    # 24 x 42 mm mount fits a 45 x 25 mm bed only turned
    low = _found(spec_with(PAPER, machine__print_volume_z=10.0), "print.bed")
    assert [f.message.split(":")[0] for f in low] == ["end_cap_mold_base"]  # the lid is 7.76 mm


def test_print_bed_fix_names_the_caps_per_mold_that_fit():
    """Four caps in a 77.2 mm SLA mold (caps 12.95 mm apart + ends): a 60 mm display holds 2 per mold."""
    found = _found(spec_with(SLA_ARRAY, machine__print_volume_x=60.0, machine__print_volume_y=45.0), "print.bed")
    molds = [f for f in found if f.message.startswith("end_cap_mold")]
    assert molds and all("set mold.count = 2" in f.fix for f in molds)
    two = spec_with(SLA_ARRAY, machine__print_volume_x=60.0, machine__print_volume_y=45.0, mold__count=2)
    assert not [f for f in _found(two, "print.bed") if f.message.startswith("end_cap_mold")]


def test_laser_bed_names_sheet_size_and_usable_bed():
    """The paper's plate sheet is 37.25 x 24.25 mm as nested (kerf and reference square); a 50 x 40 mm bed less its
    10 mm margins holds 30 x 20 mm."""
    found = _found(spec_with(PAPER, machine__laser_bed_x=50.0, machine__laser_bed_y=40.0), "laser.bed")
    plate = next(f for f in found if f.message.startswith("sheet_plate"))
    assert plate.level == "error" and plate.value == pytest.approx([37.25, 24.25]) and plate.limit == [30, 20]
    assert "machine.laser_bed_x/y = 50 x 40 mm less 10 mm margins holds 30 x 20 mm" in plate.message
    assert plate.fix.startswith("neck_plate alone does not fit")
    # on 40 x 30 mm the two 24.18 mm guides nest in two rows, 51.4 mm tall: each fits alone, the sheet does not
    rows = {f.message.split(":")[0]: f for f in _found(spec_with(PAPER, machine__laser_bed_x=60.0,
                                                             machine__laser_bed_y=50.0), "laser.bed")}
    assert "sheet_plate" not in rows and rows["sheet_guide"].value == pytest.approx([37.18, 51.36])
    assert "several runs" in rows["sheet_guide"].fix


def test_nesting_follows_the_laser_bed():
    """A narrow bed nests the two guides in two rows instead of one: the sheet is narrower and taller."""
    from matcad.export.sheets import kit_sheets

    wide = kit_sheets(spec_mod.load(PAPER))["guide"].extents
    narrow = kit_sheets(spec_with(PAPER, machine__laser_bed_x=60.0))["guide"].extents
    assert narrow[2] - narrow[0] < wide[2] - wide[0] and narrow[3] - narrow[1] > 2 * (wide[3] - wide[1]) - 1



@pytest.mark.parametrize("template", [t for t in TEMPLATES if "tube" not in t.stem], ids=lambda p: p.stem)
def test_sheet_sizes_are_the_nested_sheets(template):
    """The sizes laser.bed judges (kit_sheet_sizes, no hole moved) are the nested cut files' own, bit for bit:
    name, parts in nesting order and extents, on every template and on beds narrow enough to break its rows."""
    from matcad.export.sheets import kit_sheet_sizes, kit_sheets

    layouts = set()
    for bed_x in (300.0, 90.0, 60.0, 30.0):
        spec = spec_with(template, machine__laser_bed_x=bed_x)
        nested = {sheet: (plan.flat.name, plan.parts, plan.extents) for sheet, plan in kit_sheets(spec).items()}
        assert {sheet: tuple(size) for sheet, size in kit_sheet_sizes(spec).items()} == nested
        layouts.add(tuple(sorted(nested.items())))
    assert len(layouts) >= 2  # the narrow beds nest some sheet in more rows


def test_beam_deflection_against_statics():
    """Roark's case 1e (matcad.mechanics.plate) against the Euler-Bernoulli beam solved from statics alone: the
    bending moment of a simply supported span under a point load, M = W b x / l before the load and W a (l - x) / l
    after, integrated twice (EI w'' = M, w = 0 at both supports) by finite differences; and the textbook centre
    value W l³ / (48 EI)."""
    from matcad.mechanics.plate import deflection_mm, second_moment_mm4

    force, span, width, t, e = 5.0, 132.5, 34.5, 0.8, 3300.0
    ei = e * second_moment_mm4(width, t)
    assert float(deflection_mm(force, span / 2, span / 2, span, width, t, e)) == pytest.approx(
        force * span ** 3 / (48 * ei), rel=1e-12)
    n = 4001
    x = np.linspace(0.0, span, n)
    h = x[1] - x[0]
    for a in (20.0, 66.25, 101.3):
        moment = np.where(x <= a, force * (span - a) * x / span, force * a * (span - x) / span)
        inner = (np.diag(np.full(n - 2, -2.0)) + np.diag(np.ones(n - 3), 1) + np.diag(np.ones(n - 3), -1)) / h ** 2
        w = np.linalg.solve(inner, -moment[1:-1] / ei)  # w measured along the load: w'' = -M / EI
        assert deflection_mm(force, a, x[1:-1], span, width, t, e) == pytest.approx(w, rel=1e-4, abs=1e-9)
    # Maxwell's reciprocity: the deflection at p under a load at q is the deflection at q under a load at p
    assert float(deflection_mm(force, 30.0, 90.0, span, width, t, e)) == pytest.approx(
        float(deflection_mm(force, 90.0, 30.0, span, width, t, e)), rel=1e-12)


def test_plate_bending_on_a_long_plate():
    """The paper's taxel on a 140 mm long plate (bolt rows 133 mm apart) pressed with its 20 N bends the 6.35 mm
    plate 0.58 mm: the mount gap under it falls to ~1.01 mm and the pitch moves by the model's own f0 at that gap,
    far past the quarter of the band guard; on a 3 mm sheet the plate reaches the mount."""
    from matcad.acoustics.predict import predict as predict_design
    from matcad.acoustics.design import design
    from matcad.rules.plate import BENDING_GUARD_SHARE, bendings

    spec = spec_with(PAPER, plate__depth=140.0)
    (row,) = bendings(spec)
    ei = 3300.0 * 24.0 * 6.35 ** 3 / 12
    span = 140.0 - 2 * (2.5 + 1.0)
    assert row.deflection_mm == pytest.approx(20.0 * span ** 3 / (48 * ei), rel=1e-9)
    bent = spec_with(PAPER, plate__depth=140.0, spacer__height=1.59 - row.deflection_mm)
    same_model = predict_design(design(bent)).physics_f0_hz - predict_design(design(spec)).physics_f0_hz
    assert row.shift_hz == pytest.approx(same_model, rel=1e-9)
    (finding,) = _found(spec, "plate.bending")
    assert finding.level == "warning" and finding.value == pytest.approx(row.shift_hz, abs=1e-3)
    assert finding.limit == pytest.approx(BENDING_GUARD_SHARE * 43.07, abs=0.01)
    assert f"{row.deflection_mm:.3g} mm under t1" in finding.message and "bolt rows 133.0 mm apart" in finding.message
    (thin,) = _found(spec_with(PAPER, plate__depth=140.0, neck__length=3.0), "plate.bending")
    assert "reaches the mount" in thin.message and thin.value > 1.59 and thin.limit == 1.59


@pytest.mark.parametrize("path,over", [
    (PAPER, {}), (PAPER, {"plate__depth": 60.0}), (PAPER, {"plate__depth": 140.0}),
    (PAPER, {"plate__depth": 140.0, "neck__length": 4.76}), (PAPER, {"plate__depth": 90.0, "spacer__height": 0.5}),
    (ROOT / "templates" / "mat-laser-only.toml", {"plate__depth": 120.0, "neck__diameter": 3.0}),
    (ROOT / "templates" / "mat-array-4.toml", {"plate__depth": 120.0, "mechanics__max_force_n": 20.0}),
])
def test_the_cavity_free_bound_holds_the_model(path, over):
    """plate.bending skips the model when its bound (no cavity read: a sweep runs it once per neck, not per cavity)
    is under the limit: the bound must hold every pitch change the model gives."""
    from matcad.rules.plate import bendings, deflections, shift_bound_hz

    spec = spec_with(path, **over)
    board, w = deflections(spec)
    assert w.max() < spec.spacer.height
    shifts = [abs(b.shift_hz) for b in bendings(spec)]
    assert max(shifts) <= shift_bound_hz(spec, board, w)
