"""f(F) from the deformed cavity: the FEM's outline entry point, the equivalent cylinder, df/dF and Eq. 5."""

import dataclasses

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.acoustics import fem
from matcad.acoustics.design import design
from matcad.prediction import predict
from matcad.mechanics.frequency import at_forces, equivalent_length_mm, force_curve
from matcad.mechanics.material import preset
from matcad.mechanics.section import section_from_spec
from matcad.mechanics.solver import compress
from tests.conftest import PAPER as PAPER_TOML

PAPER = spec_mod.load(PAPER_TOML)


@pytest.fixture(scope="module")
def curve():
    return compress(section_from_spec(PAPER), preset("neo_hookean", "dragon_skin_30", 0.3), "sticking", 1.6, 8)


def _outline(radius, length, n=9):
    wall = np.column_stack([np.full(n, radius), np.linspace(0, length, n)])
    end = np.column_stack([np.linspace(radius, 0, n), np.full(n, length)])
    return wall, end


def test_fem_outline_entry_point_against_an_independent_mesh():
    """The unloaded outline maps the mesh onto itself (same f); a shorter cylinder's outline gives the f of a
    mesh built for that cylinder directly, to the FEM's own discretisation error (0.3 %)."""
    g = fem.geometry(design(PAPER))
    k = 2 * np.pi * 5000 / 343.2e3
    base = fem.solve(g, k, 4)
    assert fem.solve(g, k, 4, cavity_outline=_outline(g.cavity_radius, g.cavity_length)).f0_hz == pytest.approx(
        base.f0_hz, rel=1e-9)
    short = fem.solve(dataclasses.replace(g, cavity_length=0.7 * g.cavity_length), k, 6).f0_hz
    mapped = fem.solve(g, k, 6, cavity_outline=_outline(g.cavity_radius, 0.7 * g.cavity_length)).f0_hz
    assert mapped == pytest.approx(short, rel=3e-3)
    assert mapped > 1.1 * base.f0_hz


def test_equivalent_length_of_a_flat_and_a_conical_end():
    assert equivalent_length_mm(_outline(1.5, 4.0)[1]) == pytest.approx(4.0, rel=1e-12)
    cone = np.column_stack([np.linspace(1.0, 0.0, 201), np.linspace(4.0, 3.0, 201)])  # z = 3 + r
    assert equivalent_length_mm(cone) == pytest.approx(3 + 2 / 3, rel=1e-4)


def test_force_curve_rises_and_starts_at_the_unloaded_ladder(curve):
    tl = predict(PAPER, model="transmission_line").f0_hz
    fc = force_curve(design(PAPER), curve)
    f = np.array([s.f_hz for s in fc.states])
    assert f[0] == pytest.approx(tl, rel=1e-9)
    assert np.all(np.diff(f) > 0) and fc.turn_force_n is None
    assert all(s > 0 for s in fc.sensitivity_hz_per_n)
    # the Eq. 5 fit reproduces the predicted curve it was fitted to within 0.5 %, in both area conventions
    forces = np.array([s.force_n for s in fc.states])
    for cal in (fc.eq5, fc.eq5_paper_convention):
        back = cal.bound(343.2, PAPER.neck.diameter, PAPER.neck.length).frequency_hz(forces)
        assert back == pytest.approx(f, rel=5e-3)


def test_force_curve_fem_route_and_interpolation(curve):
    fc = force_curve(design(PAPER), curve, f0_hz=5000.0, fem_level=3)
    assert fc.route.startswith("axisymmetric FEM") and fc.fem_note == ""
    fem_f = np.array([s.f_fem_hz for s in fc.states])
    tl_f = np.array([s.f_tl_hz for s in fc.states])
    # the two routes (equivalent cylinder, deformed outline) agree on the relative shift f(F)/f(0) within 1 %
    assert fem_f / fem_f[0] == pytest.approx(tl_f / tl_f[0], rel=0.01)
    assert fc.states[0].f_hz == 5000.0
    top = fc.states[-1].force_n
    rows = at_forces(fc, [0.0, top / 2, top * 2, -1.0])
    assert rows[0][1] == pytest.approx(5000.0)
    assert rows[1][1] is not None and 5000.0 < rows[1][1] < fc.states[-1].f_hz
    assert rows[2][1] is None and "beyond the computed curve" in rows[2][4]
    assert rows[3][1] is None and "compressive" in rows[3][4]
