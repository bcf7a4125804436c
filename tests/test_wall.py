"""The fast elastic-wall model: its wall-mode table against the elastic FEM it was built from, its limits, and
its pitch shift against the coupled cap + air FEM."""

import dataclasses

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.acoustics import fem, fsi, wall
from matcad.acoustics.design import design
from matcad.acoustics.registry import model
from matcad.acoustics.resonator import resonator, wall_modes
from tests.conftest import PAPER


def test_table_matches_the_elastic_fem_off_grid():
    shape = wall.CapShape(cavity_radius=1.0, cavity_length=2.4, outer_radius=2.8, top_thickness=1.0,
                          clamp_height=0.6)
    table = wall.modes(shape, wall.UNIT_SHEAR_PA, wall.UNIT_DENSITY)
    direct = fsi.unit_cap_modes(2.8, 1.0, 2.4, 0.25)
    assert table.static_mm3_pa == pytest.approx(direct.static_mm3_pa, rel=0.03)
    coupled = np.array(direct.frequencies_hz)[np.array(direct.compliances_mm3_pa) >= 0.1 * direct.static_mm3_pa]
    table_coupled = table.frequencies_hz[table.compliances_mm3_pa >= 0.1 * table.static_mm3_pa]
    assert table_coupled[0] == pytest.approx(coupled[0], rel=0.03)


def test_modes_scale_with_size_modulus_and_density():
    shape = wall.CapShape(1.59, 4.76, 4.0, 2.0, 1.6)
    base = wall.modes(shape, 0.35e6, 1080.0)
    double = wall.modes(wall.CapShape(*(2 * x for x in dataclasses.astuple(shape))), 4 * 0.35e6, 1080.0)
    np.testing.assert_allclose(double.frequencies_hz, base.frequencies_hz, rtol=1e-12)  # f ∝ sqrt(G/ρ)/a
    assert double.static_mm3_pa == pytest.approx(2 * base.static_mm3_pa, rel=1e-12)  # C ∝ a³/G


def test_dynamic_compliance_spring_below_mass_above():
    modes = wall.modes(wall.CapShape(1.59, 4.76, 4.0, 2.0, 1.6), 0.35e6, 1080.0)
    assert wall.dynamic_compliance_mm3_pa(0.0, modes, 0.0) == pytest.approx(modes.static_mm3_pa, rel=1e-12)
    below = wall.dynamic_compliance_mm3_pa(0.3 * modes.frequencies_hz[0], modes, 0.0)
    above = wall.dynamic_compliance_mm3_pa(3 * modes.frequencies_hz[-1], modes, 0.0)
    assert below.real > modes.static_mm3_pa and above.real < 0
    # loss makes the compliance complex with the dissipative sign (time e^{iωt}: Im C < 0)
    assert wall.dynamic_compliance_mm3_pa(5000.0, modes, 0.1).imag < 0


def _fem_shift(spec, shear, loss, level=fem.DEFAULT_LEVEL):
    d = design(spec)
    res = resonator(d)
    geom = fem.geometry(d)
    line = model("transmission_line")
    f_guess = float(line.f0_hz(res))
    rigid = fsi.solve(geom, None, f_guess, level, res.c_m_s).f0_hz
    soft = fsi.solve(geom, fsi.cap(d, shear, loss), f_guess, level, res.c_m_s, wall_modes=0).f0_hz
    fast = float(model("elastic_wall").f0_hz(res, shear_modulus_pa=shear, loss_factor=loss)) / float(line.f0_hz(res))
    return soft / rigid, fast


def test_elastic_wall_shift_matches_coupled_fem_on_the_template():
    fem_ratio, fast_ratio = _fem_shift(spec_mod.load(PAPER), 0.6e6, 0.1)
    assert fem_ratio > 1.03  # mass-like wall: up
    assert fast_ratio == pytest.approx(fem_ratio, rel=0.01)


@pytest.mark.slow
@pytest.mark.parametrize("mouth", ["mount", "baffled"])
def test_elastic_wall_shift_over_moduli(mouth):
    spec = spec_mod.load(PAPER)
    spec = dataclasses.replace(spec, neck=dataclasses.replace(spec.neck, mouth=mouth))
    for shear in (0.1e6, 0.2e6, 0.6e6, 1e6, 3e6, 10e6):
        for loss in (0.1, 0.2):
            fem_ratio, fast_ratio = _fem_shift(spec, shear, loss)
            assert fast_ratio == pytest.approx(fem_ratio, rel=0.015), (shear, loss)


def test_quasi_static_check_follows_the_wall_modes():
    shape = wall.CapShape(1.59, 4.76, 4.0, 2.0, 1.6)
    soft = wall.modes(shape, 0.35e6, 1080.0)
    stiff = wall.modes(shape, 100e6, 1080.0)
    assert not wall.quasi_static_valid(soft, 5000.0) and wall.quasi_static_valid(stiff, 5000.0)
    assert wall_modes(resonator(design(spec_mod.load(PAPER))), 0.35e6).coupled_hz()[0] < 2500


def test_wall_mode_near_f_is_flagged():
    modes = wall.Modes(np.array([1000.0, 2000.0, 3000.0]), np.array([1.0, 0.001, 1.0]), 2.001)
    assert wall.mode_near(modes, 1100.0) == 1000.0
    assert wall.mode_near(modes, 2700.0) == 3000.0  # 11 % away
    assert wall.mode_near(modes, 2000.0) is None  # the 2 kHz mode sweeps almost no volume: not coupled
    assert wall.mode_near(modes, 5000.0) is None
