"""Venting measured from the exported meshes: the caps as they sit in the closed mold (pour orientation), their
ceilings (up-facing silicone surface), the lid's openings found by casting rays straight up through the lid STL,
and the farthest ceiling point from an opening, against what the report claims; and what the closed mold casts
(the cap and its sprues, nothing inside the cavity). A board's mold is read back the same way in test_board.py."""

import json
import math

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.build import build
from tests.conftest import SINGLE_TEMPLATES
from tests.readback import assert_casts_only_the_caps, assert_vented, design_frame

MOLD_TEMPLATES = [p for p in SINGLE_TEMPLATES if spec_mod.load(p).outputs.end_cap_mold]


@pytest.fixture(scope="module", params=MOLD_TEMPLATES, ids=lambda p: p.stem)
def built(request, tmp_path_factory):
    spec = spec_mod.load(request.param)
    out = tmp_path_factory.mktemp("vent") / spec.name
    build(spec, out)
    return spec, out, json.loads((out / "report.json").read_text())


def test_every_ceiling_reaches_an_opening_within_the_stated_distance(built):
    spec, out, report = built
    reaches = assert_vented(spec, out, report)
    assert len(reaches) == 2 * spec.mold.count  # base face and core-pin end of every cap
    assert {z for _, z, _ in reaches} == {0.0, -spec.cavity.length}


def test_the_closed_mold_casts_the_cap_and_its_sprues_only(built):
    assert_casts_only_the_caps(*built)


def test_pour_guide_in_the_report(built):
    spec, out, report = built
    c = report["casting"]
    md = (out / "report.md").read_text()
    assert c["batch_g"] >= 10.0 and c["batch_g"] >= c["needed_g"]
    assert f"{c['batch_g']:.1f} g" in md and f"{c['pot_life_min']:g} min" in md and "45 °C" in md
    assert "Release" in md and "Trim" in md
    if spec.machine.printer == "sla":
        assert "SLA cure inhibition" in md and "PLA" not in md
    else:
        assert "PLA" in md and "inhibition" not in md


@pytest.mark.slow  # 50-190 s of trimesh.contains; the cast-volume test above proves the same property in ~2 s
def test_nothing_is_cast_inside_any_cavity(built):
    """The cavity (the acoustic volume) read back from the lid STL: a 0.2 mm grid filling each core pin's footprint
    over its length lies inside the lid's solid, so no silicone can be cast there (a vent through the pin cast a
    Ø1 × 7.8 mm thread, 3.7 mm³, before); the rule reports the same 0 mm³."""
    from matcad.parts.end_cap_mold import layout
    from matcad.parts.mold_layout import pin_tip_radius_mm

    spec, out, report = built
    lid = design_frame(out, report, "end_cap_mold_lid.stl")
    step, r = 0.2, pin_tip_radius_mm(spec) - 0.05  # the drafted pin is narrowest at its tip
    g = np.arange(-r, r + 1e-9, step)
    xs, ys, zs = np.meshgrid(g, g, np.arange(-spec.cavity.length + 0.05, -0.05, step))
    keep = np.hypot(xs, ys).ravel() <= r
    grid = np.column_stack([xs.ravel(), ys.ravel(), zs.ravel()])[keep]
    for x in layout(spec).cap_x:
        outside = ~lid.contains(grid + [x, 0.0, 0.0])
        silicone = outside.sum() * step ** 3
        print(spec.name, f"cap at x = {x:.2f}: {len(grid)} points in the cavity, {silicone:.3f} mm³ castable")
        assert silicone == 0.0
    rule = next(f for f in report["findings"] if f["id"] == "mold.cavity_appendage")
    assert rule["level"] == "info" and rule["value"] == 0.0


def test_the_cavity_check_sees_a_vent_through_the_core_pin(monkeypatch):
    """Deliberate fault: the old vent along each core pin's axis (Ø mold.vent from the lid's top down to the pin's
    end) put back into the layout the lid is cut from. The lid loses that channel's volume, and the
    cavity-appendage rule turns it into an error measuring the thread it would cast inside the cavity
    (π/4 · 1² · 4.76 = 3.74 mm³ for the paper's taxel)."""
    from matcad.parts import end_cap_mold
    from matcad.parts.mold_layout import MoldLayout, Opening
    from matcad.rules import check
    from tests.conftest import PAPER

    spec = spec_mod.load(PAPER)
    clean = end_cap_mold.mold_lid(spec).volume
    assert [f.level for f in check(spec) if f.id == "mold.cavity_appendage"] == ["info"]
    honest = MoldLayout.openings.fget

    def with_pin_vent(self):
        return honest(self) + tuple(Opening(x, 0.0, self.vent, -spec.cavity.length, self.lid_thickness, "vent")
                                    for x in self.cap_x)

    monkeypatch.setattr(MoldLayout, "openings", property(with_pin_vent))
    thread = math.pi / 4 * spec.mold.vent ** 2 * spec.cavity.length
    lost = clean - end_cap_mold.mold_lid(spec).volume
    assert lost == pytest.approx(math.pi / 4 * spec.mold.vent ** 2 * (spec.cavity.length + spec.mold.lid_thickness),
                                 rel=1e-3)
    found = [f for f in check(spec) if f.id == "mold.cavity_appendage"]
    assert [f.level for f in found] == ["error"] and found[0].value == pytest.approx(thread, rel=1e-3)
