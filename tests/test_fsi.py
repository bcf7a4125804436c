"""The coupled elastic-cap + air FEM against its limits: rigid cap, massless cap, a thick tube's closed-form
breathing frequency, and mesh convergence with a fitted rate."""

import dataclasses
import math

import numpy as np
import pytest

from matcad.acoustics import fem, fsi, models

C = 343.0
PAPER_AIR = fem.FemGeometry(neck_radius=1.05, neck_length=6.35, cavity_radius=1.59, cavity_tip_radius=1.59,
                            cavity_length=4.76, mouth="mount", gap=1.59, gap_radius=12.0)
PAPER_CAP = fsi.Cap(outer_radius=4.0, top_thickness=2.0, clamp_height=1.6, density_kg_m3=1080.0,
                    shear_modulus_pa=0.35e6, loss_factor=0.1)


def _fit_rate(hs, values):
    """Order p of |f_h − f_h/2| ∝ h^p from successive differences."""
    d = np.abs(np.diff(values))
    return np.polyfit(np.log(hs[:-1]), np.log(d), 1)[0]


def test_thick_tube_breathing_closed_form_and_rate():
    # free incompressible tube in plane strain: u_r = A/r exactly, ω² = 2G(1 − a²/b²)/(ρ a² ln(b/a))
    exact = float(models.wall_breathing_hz(0.3e6, 1080.0, 3.18, 8.0))
    levels = np.array([2, 4, 8, 16])
    f = np.array([fsi.plane_strain_tube_modes_hz(1.59, 4.0, 0.3e6, 1080.0, lv)[0] for lv in levels])
    assert f[2] == pytest.approx(exact, rel=1e-5)
    errors = np.abs(f / exact - 1)
    rate = np.polyfit(np.log(1.0 / levels), np.log(errors), 1)[0]
    assert rate > 3.0  # P2 eigenvalues converge at O(h^4) for a smooth mode
    # the frequency scales as sqrt(G/ρ)/size
    scaled = fsi.plane_strain_tube_modes_hz(3.18, 8.0, 1.2e6, 1080.0, 8)[0]
    assert scaled == pytest.approx(f[2], rel=1e-9)


@pytest.mark.parametrize("mouth", ["mount", "baffled"])
def test_stiff_cap_reproduces_rigid_fem(mouth):
    g = dataclasses.replace(PAPER_AIR, mouth=mouth)
    rigid = fem.solve(g, 2 * math.pi * 5200 / (C * 1e3), fem.DEFAULT_LEVEL, C).f0_hz
    stiff = fsi.solve(g, dataclasses.replace(PAPER_CAP, shear_modulus_pa=1e11), 5000, fem.DEFAULT_LEVEL, C)
    assert stiff.f0_hz == pytest.approx(rigid, rel=1e-3)
    assert min(stiff.wall_modes_hz) > 50 * stiff.f0_hz


def test_massless_cap_is_its_static_compliance_on_the_same_mesh():
    cap = dataclasses.replace(PAPER_CAP, density_kg_m3=1e-6, loss_factor=0.0)
    cm = fsi.coupled_mesh(PAPER_AIR, cap, 4)
    system = fsi._assemble(cm, PAPER_AIR, cap)
    rho = fsi.air_density_t_mm3(C)
    coupled = fsi._peak(lambda f: fsi._response(system, cap, f, C, rho), 4500)[0]
    static = fsi._peak(lambda f: fsi.static_response(system, cap, f, C, rho), 4500)[0]
    rigid = fsi._peak(lambda f: fsi._response(system, None, f, C, rho), 5000)[0]
    assert coupled == pytest.approx(static, rel=3e-4)
    assert coupled < 0.9 * rigid  # a massless (spring-only) wall lowers f


def test_massive_cap_raises_pitch_above_its_breathing_modes():
    # the template's Dragon Skin cap at G = 0.6 MPa: wall modes ~2-4 kHz, below f: mass-like, f goes up
    run = fsi.solve(PAPER_AIR, dataclasses.replace(PAPER_CAP, shear_modulus_pa=0.6e6), 5000, 4, C)
    rigid = fsi.solve(PAPER_AIR, None, 5000, 4, C).f0_hz
    assert run.f0_hz > 1.02 * rigid
    assert run.wall_modes_hz[0] < 0.5 * run.f0_hz
    assert 3 < run.q < 100


@pytest.mark.slow
def test_coupled_fem_converges_with_a_rate():
    levels = np.array([4, 8, 16])  # level 2 is pre-asymptotic (its first wall mode is off by 1 %)
    f = np.array([fsi.solve(PAPER_AIR, PAPER_CAP, 5000, lv, C, wall_modes=0).f0_hz for lv in levels])
    rate = _fit_rate(1.0 / levels, f)
    assert rate > 1.0
    assert abs(f[-2] / f[-1] - 1) < 2e-3  # the default level is within 0.2 % of the next
