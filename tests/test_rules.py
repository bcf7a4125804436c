"""Each design rule fires on a spec that breaks it, at the right level, and not on the paper's taxel."""

import pytest

from matcad import spec as spec_mod
from matcad.rules import check
from tests.conftest import PAPER, ROOT, spec_with


def _paper_with(**over):
    return spec_with(PAPER, **over)


def _levels(spec, rule_id):
    return {f.level for f in check(spec) if f.id == rule_id}


@pytest.mark.parametrize("over,rule,level", [
    ({"mold__wall": 0.6}, "print.wall", "error"),                       # < 2 x 0.4 mm nozzle
    ({"machine__key_clearance": 0.05}, "print.key_clearance", "warning"),
    ({"machine__key_clearance": 0.8}, "print.key_clearance", "warning"),
    ({"mold__fill_port": 3.0}, "mold.fill_port_fit", "error"),          # wider than the 2.41 mm cap wall
    ({"mold__fill_port": 1.5}, "mold.fill_port", "warning"),
    ({"mold__vent": 2.5}, "mold.vents", "error"),                       # wider than the 2 mm flange ring
    ({"plate__width": 13.0}, "laser.web", "error"),                     # bolt holes run into the flange hole
    ({"machine__laser_min_feature": 1.4}, "laser.feature", "error"),    # dowel holes drawn 1.55 - 0.25 mm
    ({"neck__length": 6.0}, "laser.stock", "info"),                     # 6 mm is stock
    ({"neck__length": 6.1}, "laser.stock", "warning"),                  # 6.1 mm is not
    ({"fasteners__dowel_fit_laser": "press"}, "fit.dowel_laser", "error"),
    ({"fasteners__dowel_fit_printed": "clearance"}, "fit.dowel_printed", "warning"),
    ({"needle__tip_clearance": 0.0}, "needle.collision", "error"),
    ({"needle__tip_clearance": 12.0}, "needle.collision", "error"),     # tip below the mount
    ({"needle__theta_deg": 85.0}, "needle.theta", "warning"),
    ({"needle__y": 4.0}, "needle.y", "warning"),
    ({"microphone__sample_rate_hz": 8000.0}, "acoustic.band_high", "error"),
    ({"microphone__floor_hz": 5000.0}, "acoustic.band_low", "warning"),
    ({"end_cap__outer_diameter": 4.5}, "cap.wall", "warning"),
    ({"guide__thickness_measured": False}, "seal.squeeze", "error"),    # +-0.55 mm swallows 0.1 mm
    ({"end_cap__flange_squeeze": 0.04}, "seal.squeeze", "error"),       # below the 0.05 mm caliper tolerance
    ({"end_cap__flange_squeeze": 0.7}, "seal.squeeze", "warning"),      # 0.75 mm of a 2.2 mm flange > 30 %
    ({"mold__vent_reach": 0.5}, "mold.vent_reach", "error"),
    ({"machine__printer": "sla"}, "mold.cure_inhibition", "warning"),
    ({"needle__theta_deg": 55.0}, "print.bore_overhang", "warning"),
])
def test_rule_fires(over, rule, level):
    assert level in _levels(_paper_with(**over), rule)


@pytest.mark.parametrize("rule", ["print.wall", "mold.fill_port_fit", "mold.fill_port", "laser.web",
                                  "fit.dowel_laser", "needle.collision", "needle.theta", "needle.y",
                                  "acoustic.band_high", "acoustic.band_low", "cap.wall", "print.key_clearance",
                                  "laser.drawn_size", "laser.feature"])
def test_paper_taxel_passes(rule):
    assert not _levels(spec_mod.load(PAPER), rule)


def test_paper_neck_taper_warning_and_pilot_downgrades_it():
    assert "warning" in {f.level for f in check(spec_mod.load(PAPER))
                         if f.id == "laser.taper" and "neck hole" in f.message}
    piloted = _paper_with(plate__neck_pilot=True)
    neck = [f for f in check(piloted) if f.id == "laser.taper" and "neck" in f.message and "pilot" in f.message]
    assert neck and all(f.level == "info" for f in neck)


def test_silicone_batch_volume_and_mass():
    spec = spec_mod.load(PAPER)
    batch = next(f for f in check(spec) if f.id == "silicone.batch")
    from matcad.parts.features import cap_volume_mm3
    needed = cap_volume_mm3(spec) * 1.3 / 1000 * 1.08
    assert f"{needed:.2f} g" in batch.message  # what the cap needs, stated
    assert batch.value == pytest.approx(max(needed, 10.0), abs=1e-3)  # what to mix: a realistic minimum batch
    assert "PLA" in batch.message and "SLA" not in batch.message


def test_silicone_batch_and_bom_lay_out_no_mold(monkeypatch):
    """The batch to mix is the casting guide's, without the mold's layout and vent plan (a laser-only kit has no
    mold; its vent search was most of the rules' time)."""
    from matcad.parts import casting
    from matcad.report.data import silicone_bom
    from matcad.rules.printing import silicone_batch

    spec = spec_mod.load(PAPER)
    guide = casting.casting_guide(spec)

    def no_layout(spec):
        raise AssertionError("the batch laid out the mold")

    monkeypatch.setattr(casting, "layout", no_layout)
    (batch,) = silicone_batch(spec)
    assert batch.value == round(guide.batch_g, 3) and guide.batch_reason in batch.message
    bom = silicone_bom(spec)
    assert (bom["caps_per_pour"], bom["cast_volume_ml"], bom["needed_mass_g"], bom["batch_mass_g"]) == (
        guide.caps, guide.cast_volume_ml, guide.needed_g, guide.batch_g)


def test_sla_mold_gets_the_inhibition_warning_and_no_pla_wording():
    sla = _paper_with(machine__printer="sla")
    found = {f.id: f for f in check(sla)}
    assert found["mold.cure_inhibition"].level == "warning" and "platinum" in found["mold.cure_inhibition"].message
    assert "PLA" not in found["silicone.batch"].message and "SLA resin" in found["silicone.batch"].message
    assert "mold.cure_inhibition" not in {f.id for f in check(spec_mod.load(PAPER))}


def test_every_rule_module_is_registered_once():
    """check() runs the modules of matcad.rules.registry: every module of matcad/rules/ that declares RULES is
    there exactly once (a forgotten module would fail silently), and each TAXEL_RULES is a subset of its RULES."""
    import importlib
    import pkgutil

    import matcad.rules
    from matcad.rules.registry import PREDICTION_MODULES, SPEC_MODULES, TUBE_MODULES

    registered = [m.__name__ for m in SPEC_MODULES + PREDICTION_MODULES + TUBE_MODULES]
    declaring = sorted(name for _, name, _ in pkgutil.iter_modules(matcad.rules.__path__, "matcad.rules.")
                       if hasattr(importlib.import_module(name), "RULES"))
    assert sorted(registered) == declaring and len(set(registered)) == len(registered)
    for module in SPEC_MODULES:
        assert set(getattr(module, "TAXEL_RULES", ())) <= set(module.RULES), module.__name__
        assert set(getattr(module, "INFO_RULES", ())) <= set(module.RULES), module.__name__


def test_info_rules_only_inform():
    """A rule listed in INFO_RULES (a sweep skips it) gives only info findings, on every template and on designs
    at the ends of the ranges (fails if such a rule gains a warning or an error)."""
    import dataclasses

    from matcad.rules.registry import SPEC_MODULES

    rules = [r for m in SPEC_MODULES for r in getattr(m, "INFO_RULES", ())]
    assert rules
    specs = [spec_mod.load(p) for p in sorted((ROOT / "templates").glob("*.toml"))]
    paper = spec_mod.load(PAPER)
    specs += [dataclasses.replace(paper, cavity=dataclasses.replace(paper.cavity, diameter=d, length=length),
                                  end_cap=dataclasses.replace(paper.end_cap, outer_diameter=3 * d))
              for d in (2.2, 6.0) for length in (0.5, 12.0)]
    for spec in specs:
        for rule in rules:
            assert {f.level for f in rule(spec)} <= {"info"}, (rule.__name__, spec.name)


def test_laser_parts_are_made_once_per_spec_and_again_for_another():
    """The laser rules ask for one spec's kit in turn: the same spec object gets the very parts made for it (one
    build for five rules), any other spec its own, made from its own values (fails if the cache keys on equality
    or outlives a change)."""
    import dataclasses

    from matcad.parts.catalogue import laser_parts

    spec = spec_mod.load(ROOT / "templates" / "mat-laser-only.toml")
    first = laser_parts(spec)
    assert all(a is b for a, b in zip(first, laser_parts(spec))) and first is not laser_parts(spec)
    wider = dataclasses.replace(spec, neck=dataclasses.replace(spec.neck, diameter=spec.neck.diameter + 0.2))
    again = laser_parts(wider)
    assert not any(a is b for a, b in zip(first, again))
    plate = {f.name: f for f in again}["neck_plate"]
    assert {h.diameter for h in plate.holes if h.purpose == "neck"} != \
        {h.diameter for h in {f.name: f for f in first}["neck_plate"].holes if h.purpose == "neck"}
    assert [f.name for f in laser_parts(spec)] == [f.name for f in first]
