"""Paper Eq. 5 (matcad.acoustics.eq5.Eq5): its closed form, inverse, slope and rise, and where it has no meaning."""

import numpy as np
import pytest

from matcad.acoustics.eq5 import MAT_PAPER_2024, Eq5, frequency_constant_mm3_hz2

C, d, l = 343.0, 2.10, 6.35
PAPER = MAT_PAPER_2024.bound(C, d, l)


def test_paper_constants_and_convention():
    # DIGEST: with A = d²/4 Eq. 2 gives ≈ 4.01 kHz at F = 0; with πd²/4 ≈ 7.10 kHz
    assert PAPER.frequency_hz(0.0) == pytest.approx(4010, abs=5)
    physical = Eq5(MAT_PAPER_2024.v0_mm3, MAT_PAPER_2024.a, MAT_PAPER_2024.b).bound(C, d, l)
    assert physical.frequency_hz(0.0) == pytest.approx(7100, abs=15)
    assert PAPER.turn_force_n == pytest.approx(26.895, abs=0.01)
    assert PAPER.volume_mm3(26.895) == pytest.approx(25.99, abs=0.01)
    assert PAPER.k_mm3_hz2 == pytest.approx(float(frequency_constant_mm3_hz2(C, d, l)) / np.pi, rel=1e-12)
    with pytest.raises(ValueError, match="not tied to a neck"):
        MAT_PAPER_2024.frequency_hz(0.0)  # constants without K give no frequency


def test_eq5_closed_form_values():
    for force in (0.0, 5.0, 15.4, 25.0):
        v = 32.21 + 0.0086 * force**2 - 0.4626 * force
        expected = 343e3 / (2 * np.pi) * np.sqrt(d * d / 4 / (l * v))
        assert PAPER.frequency_hz(force) == pytest.approx(expected, rel=1e-12)


def test_frequency_rises_with_force_in_valid_range():
    f = PAPER.frequency_hz(np.linspace(-1, 26.8, 200))
    assert np.all(np.diff(f) > 0)


def test_slope_is_the_derivative_and_rise_the_ratio():
    forces = np.array([0.0, 5.0, 15.4, 25.0])
    h = 1e-4
    numeric = (PAPER.frequency_hz(forces + h) - PAPER.frequency_hz(forces - h)) / (2 * h)
    np.testing.assert_allclose(PAPER.slope_hz_per_n(forces), numeric, rtol=1e-6)
    assert PAPER.slope_hz_per_n(0.0) == pytest.approx(PAPER.frequency_hz(0.0) * 0.4626 / (2 * 32.21), rel=1e-12)
    low, high = MAT_PAPER_2024.rise(20.0)  # no K needed: f(F)/f(0) = sqrt(V(0)/V(F))
    assert low == 1.0 and high == pytest.approx(np.sqrt(32.21 / PAPER.volume_mm3(20.0)), rel=1e-12)
    with pytest.raises(ValueError, match="minimum"):
        MAT_PAPER_2024.rise(30.0)


def test_invalid_forces_give_nan_and_reason():
    f = PAPER.frequency_hz([27.0, 100.0, np.inf, np.nan])
    assert np.all(np.isnan(f))
    assert "minimum" in PAPER.invalid_reason(27.0)
    assert PAPER.invalid_reason(10.0) == ""
    tiny = Eq5(v0_mm3=1.0, a=0.0, b=0.5).bound(C, d, l)
    assert np.isnan(tiny.frequency_hz(3.0))
    assert "V_eff" in tiny.invalid_reason(3.0)


@pytest.mark.parametrize("cal", [PAPER, Eq5(30.0, 0.0, 0.4).bound(C, d, l), Eq5(30.0, 0.001, 0.4).bound(C, d, l),
                                 Eq5(30.0, -0.01, -0.1).bound(C, d, l)])
def test_inverse_round_trip(cal):
    top = min(cal.turn_force_n, 25.0)
    forces = np.linspace(top - 30.0, top - 1e-3, 101)
    f = cal.frequency_hz(forces)
    ok = np.isfinite(f)
    assert ok.sum() > 50
    np.testing.assert_allclose(cal.force_n(f[ok]), forces[ok], atol=1e-9)


def test_inverse_out_of_range_is_nan():
    f_max = PAPER.frequency_hz(PAPER.turn_force_n)
    assert np.isnan(PAPER.force_n(f_max * 1.01))
    assert np.isnan(PAPER.force_n(0.0))


def test_a_fit_reproduces_its_data_to_the_noise():
    """Eq. 5 fitted to pairs drawn from a known law with 2 Hz of noise: the fitted curve passes through the data to
    the noise (its reported residual RMS ~2 Hz) and recovers the law to a few Hz over the range."""
    from matcad.acoustics.eq5fit import fit

    true = Eq5(37.8, -0.0086, 0.4626, 37.8 * 4400.0**2)
    forces = np.tile(np.linspace(0.0, 20.0, 21), 2)
    freqs = true.frequency_hz(forces) + np.random.default_rng(5).normal(0.0, 2.0, len(forces))
    fitted = fit(forces, freqs, true.k_mm3_hz2)
    assert 1.0 < fitted.to_dict()["residual_rms_hz"] < 3.0
    grid = np.linspace(0.0, 20.0, 9)
    np.testing.assert_allclose(fitted.law.frequency_hz(grid), true.frequency_hz(grid), atol=3.0)
    np.testing.assert_allclose(fitted.law.force_n(true.frequency_hz(grid)), grid, atol=0.3)
