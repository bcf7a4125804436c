"""Paper Eq. 5 and its inverse."""

import numpy as np
import pytest

from matcad.acoustics import load
from matcad.acoustics.load import MAT_PAPER_2024 as PAPER

C, d, l = 343.0, 2.10, 6.35


def test_paper_constants_and_convention():
    # DIGEST: with A = d²/4 Eq. 2 gives ≈ 4.01 kHz at F = 0; with πd²/4 ≈ 7.10 kHz
    assert load.frequency_at_force_hz(PAPER, 0.0, C, d, l) == pytest.approx(4010, abs=5)
    physical = load.LoadCalibration(PAPER.v0_mm3, PAPER.a, PAPER.b, "pi_d2/4")
    assert load.frequency_at_force_hz(physical, 0.0, C, d, l) == pytest.approx(7100, abs=15)
    assert load.force_at_volume_minimum_n(PAPER) == pytest.approx(26.895, abs=0.01)
    assert load.effective_volume_mm3(PAPER, 26.895) == pytest.approx(25.99, abs=0.01)


def test_eq5_closed_form_values():
    for force in (0.0, 5.0, 15.4, 25.0):
        v = 32.21 + 0.0086 * force**2 - 0.4626 * force
        expected = 343e3 / (2 * np.pi) * np.sqrt(d * d / 4 / (l * v))
        assert load.frequency_at_force_hz(PAPER, force, C, d, l) == pytest.approx(expected, rel=1e-12)


def test_frequency_rises_with_force_in_valid_range():
    f = load.frequency_at_force_hz(PAPER, np.linspace(-1, 26.8, 200), C, d, l)
    assert np.all(np.diff(f) > 0)


def test_invalid_forces_give_nan_and_reason():
    f = load.frequency_at_force_hz(PAPER, [27.0, 100.0, np.inf, np.nan], C, d, l)
    assert np.all(np.isnan(f))
    assert "minimum" in load.invalid_reason(PAPER, 27.0)
    assert load.invalid_reason(PAPER, 10.0) == ""
    tiny = load.LoadCalibration(v0_mm3=1.0, a=0.0, b=0.5)
    assert np.isnan(load.frequency_at_force_hz(tiny, 3.0, C, d, l))
    assert "V_eff" in load.invalid_reason(tiny, 3.0)


@pytest.mark.parametrize("cal", [PAPER, load.LoadCalibration(30.0, 0.0, 0.4),
                                 load.LoadCalibration(30.0, 0.001, 0.4),
                                 load.LoadCalibration(30.0, -0.01, -0.1)])
def test_inverse_round_trip(cal):
    top = min(load.force_at_volume_minimum_n(cal), 25.0)
    forces = np.linspace(top - 30.0, top - 1e-3, 101)
    f = load.frequency_at_force_hz(cal, forces, C, d, l)
    ok = np.isfinite(f)
    assert ok.sum() > 50
    back = load.force_at_frequency_n(cal, f[ok], C, d, l)
    np.testing.assert_allclose(back, forces[ok], atol=1e-9)


def test_inverse_out_of_range_is_nan():
    f_max = load.frequency_at_force_hz(PAPER, load.force_at_volume_minimum_n(PAPER), C, d, l)
    assert np.isnan(load.force_at_frequency_n(PAPER, f_max * 1.01, C, d, l))
    assert np.isnan(load.force_at_frequency_n(PAPER, 0.0, C, d, l))
