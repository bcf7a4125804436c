"""A board's two neck lengths (a [riser], docs/arrays.md) as the acoustics sees them: a neck through the riser is one
longer bore, a cap in a riser's pocket is clamped over the riser too; the fast wall model against the coupled FEM on
those taller clamps, and its wall-mode table against the elastic FEM at the clamp fractions the pockets reach."""

import dataclasses
import json

import numpy as np
import pytest

from matcad.acoustics import fem, fsi, registry, wall
from matcad.acoustics.design import design
from matcad.acoustics.resonator import resonator
from matcad.acoustics.uncertainty import budget, sheet_tolerance_mm
from matcad.spec import SpecError, cap_flange_thickness_mm, from_dict, load_spec, neck_length_mm, taxel_spec, taxels
from tests.conftest import PAPER, ROOT

MODEL_ERRORS = json.loads((ROOT / "matcad" / "acoustics" / "model_errors.json").read_text())


def _spec(path=PAPER, riser=None, through=False, **tables):
    """The template at ``path`` with a riser ``riser`` mm thick (None: none), its neck through it or not, and
    tables updated."""
    _, data = load_spec(path)
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in data.items()}
    data.pop("calibration", None)  # the physics, not the paper's anchor
    for table, values in tables.items():
        data[table] = {**data.get(table, {}), **values}
    if riser is not None:
        data["riser"] = {"thickness": riser}
        data["neck"]["riser"] = through
    return from_dict(data)


def _f0s(d):
    """Every cheap model's f0 (Hz) of design ``d`` at the wall's geometric-mean modulus."""
    res = resonator(d)
    out = {}
    for m in registry.MODELS:
        if not m.cheap or d.wall.model not in m.walls:
            continue
        shear, loss = m.wall_arguments(d.wall)
        out[m.name] = float(m.f0_hz(res, shear_modulus_pa=shear, loss_factor=loss))
    return out


def test_a_neck_through_the_riser_is_one_longer_bore():
    plate, riser = 6.35, 3.0
    through = _spec(riser=riser, through=True)
    thick = _spec(neck={"length": plate + riser})
    assert neck_length_mm(through) == plate + riser
    assert cap_flange_thickness_mm(through) == cap_flange_thickness_mm(thick)  # the cap sits on the riser
    a, b = design(through), design(thick)
    assert dataclasses.replace(a, making=b.making) == b
    f_through, f_thick = _f0s(a), _f0s(b)
    assert set(f_through) == {"lumped", "end_corrected", "transmission_line", "soft_wall", "elastic_wall"}
    assert f_through == f_thick
    assert f_through["transmission_line"] < _f0s(design(_spec()))["transmission_line"] * 0.95  # longer neck: lower
    # the budget: both sheets' tolerances add (ISO 7823-1 cast sheets, not calipered here)
    line = next(x for x in budget(a, resonator(a), "transmission_line", f_through["transmission_line"])
                if x.source.startswith("neck length"))
    sheets = sheet_tolerance_mm(plate, False) + sheet_tolerance_mm(riser, False)
    assert f"+-{sheets:.3g} mm" in line.tolerance and "riser" in line.tolerance
    one = next(x for x in budget(b, resonator(b), "transmission_line", f_thick["transmission_line"])
               if x.source.startswith("neck length"))
    assert line.low_hz < one.low_hz < 0 < one.high_hz < line.high_hz


def test_a_cap_in_a_pocket_is_clamped_over_the_riser_too():
    riser = 1.5
    pocket = _spec(riser=riser, through=False)
    assert neck_length_mm(pocket) == 6.35
    guide = pocket.guide.thickness
    assert cap_flange_thickness_mm(pocket) == pytest.approx(guide + pocket.end_cap.flange_squeeze + riser)
    thicker_guide = _spec(guide={"thickness": guide + riser})  # the same clamp, one sheet
    a, b = design(pocket), design(thicker_guide)
    assert a.cap_clamp_height == pytest.approx(b.cap_clamp_height, abs=1e-12)
    assert _f0s(a) == pytest.approx(_f0s(b), rel=1e-12)
    assert _f0s(a)["elastic_wall"] != _f0s(design(_spec()))["elastic_wall"]  # the clamp reaches the wall model


def test_each_taxel_of_a_board_has_its_own_neck_and_clamp():
    _, data = load_spec(ROOT / "templates" / "mat-array-4.toml")
    data = {**data, "riser": {"thickness": 1.5}, "taxel": [dict(t) for t in data["taxel"]]}
    data["taxel"][0]["neck_riser"] = True
    board = from_dict(data)
    (t1, t2, *_), plate = taxels(board), board.neck.length
    assert [design(board, t).neck_length for t in taxels(board)] == [plate + 1.5, plate, plate, plate]
    assert design(board, t2).cap_clamp_height == pytest.approx(design(board, t1).cap_clamp_height + 1.5)
    for t in (t1, t2):  # one taxel's spec keeps its riser, so per-taxel physics sees the same taxel
        assert design(taxel_spec(board, t)) == design(board, t)
    data["riser"] = None
    with pytest.raises(SpecError, match=r"taxel\[1\]\.neck_riser.*\[riser\]"):
        from_dict(data)


@pytest.mark.parametrize("riser", [1.5, 3.0])
def test_the_wall_model_follows_the_coupled_fem_on_a_pocketed_cap(riser):
    """The paper's cap in a riser pocket: 0.65 and 0.97 of its cavity clamped (0.34 on the plate). The fast model
    stays within its own measured error where its checks pass (model_errors.json, the budget's model line)."""
    spec = _spec(riser=riser, through=False)
    d = design(spec)
    res = resonator(d)
    fraction = d.cap_clamp_height / d.cavity_length
    assert 0.6 < fraction < 1.0
    shape = wall.CapShape(d.cavity_diameter / 2, d.cavity_length, d.cap_outer_diameter / 2, d.cap_top_thickness,
                          d.cap_clamp_height)
    assert wall.shape_in_table(shape)  # the table now reaches a fully clamped wall
    elastic = registry.model("elastic_wall")
    shear, loss = elastic.wall_arguments(d.wall)
    fast = float(elastic.f0_hz(res, shear_modulus_pa=shear, loss_factor=loss))
    rigid = float(registry.model("transmission_line").f0_hz(res))
    coupled = fsi.solve(fem.geometry(d), fsi.cap(d, shear, loss), rigid, fem.DEFAULT_LEVEL, res.c_m_s).f0_hz
    assert abs(fast / coupled - 1) < MODEL_ERRORS["elastic_wall"]["max_abs"]


@pytest.mark.parametrize("fraction", [0.47, 0.65, 0.75, 0.85, 0.95])
def test_the_wall_table_matches_the_elastic_fem_between_its_clamp_nodes(fraction):
    """The paper's cap in cavity radii (on the grid's other axes) clamped between the table's nodes (0.34, 0.6, then
    every 0.1 to a fully clamped wall): its static compliance and first coupled mode within 1.5 % of the elastic FEM
    the table is built from (off the grid in the other axes the interpolation errs ~3 %, test_wall.py)."""
    outer, top, length = 2.52, 1.26, 3.0
    shape = wall.CapShape(cavity_radius=1.0, cavity_length=length, outer_radius=outer, top_thickness=top,
                          clamp_height=fraction * length)
    table = wall.modes(shape, wall.UNIT_SHEAR_PA, wall.UNIT_DENSITY)
    direct = fsi.unit_cap_modes(outer, top, length, fraction)
    assert table.static_mm3_pa == pytest.approx(direct.static_mm3_pa, rel=0.015)  # measured 0.01-1.03 %
    coupled = np.array(direct.frequencies_hz)[np.array(direct.compliances_mm3_pa) >= 0.1 * direct.static_mm3_pa]
    table_coupled = table.frequencies_hz[table.compliances_mm3_pa >= 0.1 * table.static_mm3_pa]
    assert table_coupled[0] == pytest.approx(coupled[0], rel=0.015)  # measured 0.19-0.74 %
