"""The FEM reference: its mesh, its convergence, and its limits against closed forms."""

import dataclasses
import math

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.acoustics import fem, models
from matcad.prediction import predict
from tests.conftest import PAPER

C = 343.0


def _k(f_hz):
    return 2 * math.pi * f_hz / (C * 1e3)


def _geom(**over):
    base = fem.FemGeometry(neck_radius=1.05, neck_length=6.35, cavity_radius=1.59, cavity_tip_radius=1.59,
                           cavity_length=4.76, mouth="baffled", gap=1.59, gap_radius=12.0)
    return dataclasses.replace(base, **over)


@pytest.mark.parametrize("mouth", ["baffled", "mount"])
def test_mesh_volume_matches_geometry(mouth):
    g = _geom(mouth=mouth, cavity_tip_radius=1.4)  # drafted cavity
    m = fem.mesh(g, 4)
    p = m.p[:, m.t]
    area = 0.5 * np.abs((p[0, 1] - p[0, 0]) * (p[1, 2] - p[1, 0]) - (p[0, 2] - p[0, 0]) * (p[1, 1] - p[1, 0]))
    r_mid, z_mid = p[0].mean(axis=0), p[1].mean(axis=0)
    inside = z_mid > 0
    volume = 2 * math.pi * np.sum(area[inside] * r_mid[inside])  # Pappus, exact for linear triangles
    cavity = math.pi * 4.76 * (1.59**2 + 1.59 * 1.4 + 1.4**2) / 3
    assert volume == pytest.approx(math.pi * 1.05**2 * 6.35 + cavity, rel=1e-9)


def test_converges_on_paper_taxel():
    g = _geom()
    f = [fem.solve(g, _k(5300), level, C).f0_hz for level in (2, 4, 8, 16)]
    steps = np.abs(np.diff(f))
    assert np.all(steps[1:] < steps[:-1])  # each refinement moves it less
    assert abs(f[2] - f[3]) / f[3] < 1e-3  # the default level is within 0.1 % of the next
    assert fem.DEFAULT_LEVEL == 8


def test_quarter_wave_limit():
    # neck as wide as the cavity: a 11.11 mm tube closed at one end, flanged at the other:
    # f = c / (4 (l + L + 0.8216 a)) for ka -> 0 (Norris & Sheng 1989 end correction)
    a = 1.59
    g = _geom(neck_radius=a)
    f = fem.solve(g, _k(7000), 8, C).f0_hz
    assert f == pytest.approx(343e3 / (4 * (6.35 + 4.76 + 0.8216 * a)), rel=0.01)


def test_lumped_limit_small_neck_big_cavity():
    # A << S, compact: the end-corrected lumped model with the flanged (0.82a) and orifice corrections
    a, big_r, big_l, ln = 0.3, 5.0, 10.0, 2.0
    g = _geom(neck_radius=a, neck_length=ln, cavity_radius=big_r, cavity_tip_radius=big_r, cavity_length=big_l)
    l_eff = ln + models.baffled_end_correction_mm(a) + models.step_end_correction_mm(2 * a, 2 * big_r)
    guess = models.transmission_line_hz(C, math.pi * a * a, math.pi * big_r**2, l_eff, big_l)
    f = fem.solve(g, _k(guess), 8, C).f0_hz
    assert f == pytest.approx(float(guess), rel=0.02)


def test_finds_fundamental_not_overtone():
    g = _geom()
    low = fem.solve(g, _k(5300 * 0.8), 4, C).f0_hz
    high = fem.solve(g, _k(5300 * 1.2), 4, C).f0_hz
    assert low == pytest.approx(high, rel=1e-9)  # same mode from either side
    assert low < 343e3 / (4 * (6.35 + 4.76))  # below the first tube mode of the whole length


def test_predict_model_fem_in_json():
    p = predict(spec_mod.load(PAPER), model="fem")  # silicone: the coupled elastic cap + air FEM
    assert p.model == "fem"
    assert p.models["fem"].checks["fundamental_found"]
    assert "coupled elastic cap" in p.models["fem"].source
    assert p.band_hz[0] < p.f0_hz < p.band_hz[1]
    assert p.models["fem"].f0_hz == pytest.approx(p.models["elastic_wall"].f0_hz, rel=0.03)
    rigid = predict(dataclasses.replace(spec_mod.load(PAPER), wall=spec_mod.Wall()), model="fem")
    assert rigid.models["fem"].checks["mode_in_cavity"]


def test_unflanged_mouth_needs_the_tube_wall_and_meshes_the_free_space_around_it():
    """A MAT design's unflanged neck has no wall thickness in the spec: a clear error naming the field; with a wall
    the exterior is the free space around the tube's end, its radiation boundary the arc alone (not the outer
    wall r = a + w that meets it), its triangles unfolded."""
    with pytest.raises(ValueError, match=r"FemGeometry.wall = 0 mm invalid for mouth 'unflanged': must be > 0"):
        fem.mesh(_geom(mouth="unflanged"))
    with pytest.raises(ValueError, match="mouth 'sideways' invalid for the FEM, must be one of"):
        fem.mesh(_geom(mouth="sideways"))
    g = _geom(mouth="unflanged", wall=0.05)
    m = fem.mesh(g, 2)
    big_r, b = fem.EXTERIOR_RADIUS_PER_A * 1.05, 1.05 + 0.05
    facets, _ = fem._boundary_facets(m, g)
    ends = m.p[:, m.facets[:, facets]]
    assert np.allclose(np.hypot(*ends), big_r, rtol=1e-9)
    arc_length = np.sum(np.hypot(*(ends[:, 1] - ends[:, 0])))
    assert arc_length == pytest.approx(big_r * (math.pi / 2 + math.acos(b / big_r)), rel=2e-3)  # below + beside
    p = m.p[:, m.t]
    area = (p[0, 1] - p[0, 0]) * (p[1, 2] - p[1, 0]) - (p[0, 2] - p[0, 0]) * (p[1, 1] - p[1, 0])
    assert np.all(np.abs(area) > 0)
    wall = (p[0].mean(axis=0) > 1.05) & (p[0].mean(axis=0) < b) & (p[1].mean(axis=0) > 0)
    assert not np.any(wall)  # nothing meshed inside the tube's wall



def test_fem_solves_run_blas_on_one_thread():
    # a multi-threaded BLAS inside SuperLU cost the baffled coupled FEM ~5x its CPU on 2 shared cores; the limit
    # must reach scipy's own BLAS, which loads only with scipy.sparse.linalg (a fresh interpreter: nothing loaded)
    import ast
    import subprocess
    import sys

    code = ("from matcad.acoustics import fem\nwith fem.one_blas_thread():\n    import scipy.sparse.linalg\n"
            "    from threadpoolctl import threadpool_info\n"
            "    print([i['num_threads'] for i in threadpool_info() if i['user_api'] == 'blas'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    threads = ast.literal_eval(out)
    assert len(threads) >= 1 and set(threads) == {1}, out
