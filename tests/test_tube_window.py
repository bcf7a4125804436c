"""The fipple window's 3-D FEM rung (matcad.acoustics.mouth3d on matcad.acoustics.fem_cut's meshes): the mesher
against a closed-form volume, the potential-flow δ against Norris & Sheng's flanged end and against the
axisymmetric exterior FEM, and the template's window against the band's mouth range (docs/tube.md)."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from matcad.acoustics import fem_cut
from matcad.acoustics import mouth3d as M
from matcad.acoustics import tube as T
from matcad.spec import load

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "acoustac-tube.toml"


@pytest.fixture(scope="module")
def td():
    return T.tube_design(load(TEMPLATE))


def _ball(q):
    return 1.0 - np.linalg.norm(q, axis=0)


def test_cut_mesh_of_a_ball_is_conforming_and_second_order():
    """A unit ball cut from graded grids: every boundary node lies on the sphere (no cracks between cut
    neighbours: a crack would leave boundary facets inside), every tetrahedron is positive, and the volume's
    error falls as h² (4.1x per halving, measured)."""
    from skfem import MeshTet

    errors = []
    for h in (0.2, 0.1, 0.05):
        xs = fem_cut.graded(-1.2, 1.2, h, -1.2, 1.2)
        p, t = fem_cut.mesh(xs, xs, xs, _ball)
        v = fem_cut.volumes(p, t)
        assert v.min() > 0
        errors.append(v.sum() / (4 / 3 * math.pi) - 1)
        m = MeshTet(p, t)
        radius = np.linalg.norm(m.p[:, np.unique(m.facets[:, m.boundary_facets()])], axis=0)
        assert np.allclose(radius, 1.0, atol=1e-9)
    assert errors[0] < errors[1] < errors[2] < 0
    assert 3.5 < errors[0] / errors[1] < 4.7 and 3.5 < errors[1] / errors[2] < 4.7


def test_merged_grid_lines_keep_planes_and_drop_slivers():
    lines = fem_cut.merged(np.array([0.0, 0.1, 0.2000000001, 0.3, 0.41]), 0.025, (0.2, 0.4))
    assert list(lines) == [0.0, 0.1, 0.2, 0.3, 0.4]


def test_baffled_pipe_converges_to_norris_and_sheng():
    """The route's closed form: a pipe ending in an infinite rigid baffle, δ = 0.8216 a (Norris & Sheng 1989).
    The error falls under refinement at order > 1 (the rim's singularity limits it: 1.4 measured from level 4 to
    8) and is 3.5 % at level 8, from below (cut edges are chamfered by O(h))."""
    errors = [M.end_correction(M.Mouth("baffled", 2.0), level).delta_mm / (0.8216 * 2.0) - 1 for level in (4, 8)]
    assert errors[0] < errors[1] < 0
    assert errors[1] > -0.04
    assert math.log(errors[0] / errors[1]) / math.log(2) > 1.0


def test_far_box_and_driven_plane_do_not_move_delta(monkeypatch):
    """The monopole condition on the far box makes δ independent of the box (20 a against 40 a)."""
    mouth = M.Mouth("baffled", 2.0)
    near = M.end_correction(mouth, 4).delta_mm
    monkeypatch.setattr(M, "FAR_PER_A", 40.0)
    assert M.end_correction(mouth, 4).delta_mm == pytest.approx(near, rel=2e-3)


@pytest.mark.slow
def test_unflanged_thick_pipe_against_the_axisymmetric_fem(td):
    """The second route: the template's 1.2 mm wall (0.6 a) ending in free space, δ by the 3-D FEM against the
    axisymmetric exterior FEM (level 16, ka = 0.048): −4.5 % at level 8 and −1.8 % at level 12, from below."""
    long = dataclasses.replace(td, mouth="unflanged", length=60.0)
    reference = T.phase_correction_mm(long, T.exterior_fem(long, 16).f0_hz)
    mouth = M.Mouth("unflanged", td.bore_diameter / 2, td.tube_wall)
    errors = [M.end_correction(mouth, level).delta_mm / reference - 1 for level in (8, 12)]
    assert -0.05 < errors[0] < errors[1] < 0 and errors[1] > -0.025


def test_window_fem_is_the_fem_route_of_predict_and_inside_the_band(td):
    """`predict --model fem` on a fipple tube: the line with the 3-D FEM's δ (no longer refused); at level 4 the
    window's δ lies inside MOUTH_RANGE × Rayleigh's, so the FEM route's f1 lies inside the rigid line's mouth band."""
    from matcad.prediction.tube import MOUTH_RANGE, predict_tube

    delta, f1 = T.window_fem(td, 4)
    rayleigh = T.mouth_correction_mm(td)
    assert MOUTH_RANGE[0] < delta / rayleigh < MOUTH_RANGE[1]
    assert f1 == pytest.approx(T.line_hz(td, correction_factor=delta / rayleigh), rel=1e-12)
    p = predict_tube(load(TEMPLATE), fem_level=4)
    assert p.routes_hz["3-D window FEM + line, level 4 (rigid)"] == pytest.approx(f1, rel=1e-12)
    assert any("3-D FEM" in s for s in p.band_sources)
    assert not any("outside the windows" in n for n in p.notes)
    from matcad.spec import from_dict, to_dict

    data = to_dict(load(TEMPLATE))
    data["tube"]["wall"] = 3.0  # 1.5 a: thicker than any studied wall
    notes = predict_tube(from_dict(data)).notes
    assert any(n.startswith("tube.wall = 3 lies outside the windows") and "0.8-2" in n for n in notes)
    with pytest.raises(ValueError, match="no window"):
        T.window_fem(dataclasses.replace(td, mouth="flanged"))
    with pytest.raises(ValueError, match="'fipple', 'transverse', 'baffled', 'unflanged'"):
        M.Mouth("slot", 2.0)


@pytest.mark.slow
def test_template_window_converges_and_extreme_windows_stay_in_the_mouth_range(td):
    """The template's window at levels 6, 8 and 12 (4.48, 4.58, 4.59 mm, 1.09 x Rayleigh's); the two windows of the
    benchmark's ten furthest from Rayleigh's aperture (a thin wall under a wide window, 0.84; a small window in the
    template's wall, 1.32) at level 8 inside MOUTH_RANGE; the thin wall's δ at level 12 (11 % above level 8's: a
    0.8 mm wall is a few cells thick at level 8) too."""
    from matcad.prediction.tube import MOUTH_RANGE, MOUTH_STUDY

    deltas = [T.window_fem(td, level)[0] for level in (6, 8, 12)]
    assert deltas[0] < deltas[1] < deltas[2] and deltas[2] - deltas[1] < 0.02 * deltas[2]
    assert 1.05 < deltas[2] / T.mouth_correction_mm(td) < 1.15
    for wall, b, w, angle in (MOUTH_STUDY[9], MOUTH_STUDY[8]):
        one = dataclasses.replace(td, tube_wall=wall, windway_width=b, edge_distance=w, edge_angle=angle)
        ratio = T.window_fem(one, 8)[0] / T.mouth_correction_mm(one)
        assert MOUTH_RANGE[0] < ratio < MOUTH_RANGE[1]
        if wall == 0.8:
            finer = T.window_fem(one, 12)[0] / T.mouth_correction_mm(one)
            assert 1.05 < finer / ratio < 1.15 and MOUTH_RANGE[0] < finer < MOUTH_RANGE[1]


def _transverse_spec():
    from matcad.spec import from_dict, to_dict

    data = to_dict(load(TEMPLATE))
    data["tube"]["mouth"] = "transverse"
    return from_dict(data)


def test_transverse_window_fem_is_the_predict_route_and_inside_its_range():
    """`predict --model fem` on a transverse mouth: the line with the 3-D FEM's δ of the side window (its sides,
    gable and funnel, matcad.parts.tube.transverse_tube's); at level 4 δ lies inside TRANSVERSE_RANGE × Rayleigh's
    aperture of the window's area, and the band names the transverse study."""
    from matcad.prediction.tube import TRANSVERSE_RANGE, predict_tube

    spec = _transverse_spec()
    td = T.tube_design(spec)
    delta, f1 = T.window_fem(td, 4)
    assert TRANSVERSE_RANGE[0] < delta / T.mouth_correction_mm(td) < TRANSVERSE_RANGE[1]
    p = predict_tube(spec, fem_level=4)
    assert p.routes_hz["3-D window FEM + line, level 4 (rigid)"] == pytest.approx(f1, rel=1e-12)
    assert any("transverse mouth correction" in s for s in p.band_sources)
    assert not any("outside the windows" in n for n in p.notes)
    from matcad.parts.tube import heights_mm

    z = heights_mm(spec)  # the FEM's δ is measured from where the printed part's column starts
    assert M.from_tube(td).mouth_z == pytest.approx(z["edge"] - z["windway_exit"])


@pytest.mark.slow
def test_transverse_window_converges_upward_and_its_extremes_stay_in_the_range():
    """The template's transverse window at levels 8 and 12 (1.19 and 1.23 x Rayleigh's: rising, by < 4 %); the
    study's two extremes (a 2 mm wall, 1.52; a 3 mm wide window, 0.89) at level 8 inside TRANSVERSE_RANGE."""
    from matcad.prediction.tube import TRANSVERSE_RANGE

    td = T.tube_design(_transverse_spec())
    rayleigh = T.mouth_correction_mm(td)
    coarse, fine = (T.window_fem(td, level)[0] / rayleigh for level in (8, 12))
    assert 1.1 < coarse < fine < 1.04 * coarse
    for change in ({"tube_wall": 2.0}, {"edge_distance": 3.0}):
        one = dataclasses.replace(td, **change)
        assert TRANSVERSE_RANGE[0] < T.window_fem(one, 8)[0] / T.mouth_correction_mm(one) < TRANSVERSE_RANGE[1]
