"""Eq. 5 fitted to measured pairs (matcad.acoustics.eq5fit): the O(n) random-offset least squares against a dense
generalised least squares built here, bounded memory at 10^6 points, and outliers judged by an exact leave-one-out
variance that cannot go negative with a `cycle` column (issue 24: a normal point was named an outlier with a
studentized residual of 2.47e149)."""

import tracemalloc

import numpy as np
import pytest

from matcad.acoustics.eq5 import Eq5
from matcad.acoustics.eq5fit import fit, weighted_least_squares

TRUE = Eq5(37.8, -0.0086, 0.4626, 37.8 * 4400.0 ** 2)


def cycles_data(seed, cycles, tau_n, points=11, top=20.0, sigma_hz=2.0):
    rng = np.random.default_rng(seed)
    forces = np.tile(np.linspace(0.0, top, points), cycles)
    labels = np.repeat(np.arange(cycles), points)
    offsets = rng.normal(0.0, tau_n, cycles)
    return forces, TRUE.frequency_hz(forces + offsets[labels]) + rng.normal(0.0, sigma_hz, len(forces)), labels


def dense_gls(force, y, w, scale, index, k, sigma2, tau2):
    """The textbook generalised least squares with V = σ²I + τ²ZZᵀ written out as n × n matrices."""
    n = len(force)
    x = np.column_stack([np.ones(n), -force / scale, -(force / scale) ** 2]) * w[:, None]
    z = (index[:, None] == np.arange(k)[None, :]) * w[:, None]
    vi = np.linalg.inv(sigma2 * np.eye(n) + tau2 * z @ z.T)
    cov = np.linalg.inv(x.T @ vi @ x)
    return cov @ x.T @ vi @ (y * w), cov


@pytest.mark.parametrize("cycles", [1, 2, 5])
def test_linear_time_least_squares_equals_the_dense_one(cycles):
    force, freq, labels = cycles_data(3, cycles, 0.8, points=9)
    y = TRUE.k_mm3_hz2 / freq ** 2
    w = (freq / freq.mean()) ** 3
    tau2 = 0.05
    ls = weighted_least_squares(force, y, w, 20.0, labels, cycles, tau2, np.inf)
    assert ls.tau2 == tau2 and ls.dof_within == len(force) - 2 - cycles
    coef, cov = dense_gls(force, y, w, 20.0, labels, cycles, ls.sigma2, tau2)
    np.testing.assert_allclose(ls.coef, coef, rtol=1e-9)
    np.testing.assert_allclose(ls.cov, cov, rtol=1e-7, atol=1e-12 * np.abs(cov).max())


def test_a_million_points_fit_in_bounded_memory():
    """10^6 points (10 cycles): the fit holds a few arrays of n numbers, never n × n (8 TB at 10^6). Peak traced
    memory per point stays under 400 bytes (measured ~225 MB in all: benchmarks/calibration.py)."""
    rng = np.random.default_rng(1)
    n = 10 ** 6
    forces = rng.uniform(0.0, 20.0, n)
    labels = np.arange(n) % 10
    freqs = TRUE.frequency_hz(forces + rng.normal(0.0, 0.5, 10)[labels]) + rng.normal(0.0, 2.0, n)
    tracemalloc.start()
    try:
        fitted = fit(forces, freqs, TRUE.k_mm3_hz2, cycles=labels)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 400 * n, peak / 1e6
    assert fitted.cycles == 10 and fitted.law.residual_std_mm3 > 0
    np.testing.assert_allclose(fitted.law.force_n(TRUE.frequency_hz([2.0, 10.0, 18.0])), [2.0, 10.0, 18.0], atol=0.5)


def test_no_normal_point_is_an_outlier_with_cycles():
    """Cycles offset from each other (τ = 0.7 N) and 2 Hz noise, nothing planted: over 100 data sets the outlier
    test (5 % family-wise) names a point in at most ~10 % of them, and every studentized residual is a sane number.
    Before issue 24 the leave-one-out variance went negative with a `cycle` column and a normal point could be named
    with a studentized residual of 2.47e149."""
    named, largest = 0, 0.0
    for seed in range(100):
        force, freq, labels = cycles_data(seed, 3, 0.7)
        fitted = fit(force, freq, TRUE.k_mm3_hz2, cycles=labels)
        named += bool(fitted.outliers)
        largest = max([largest] + [abs(r) for _, r in fitted.outliers])
    assert named <= 10 and largest < 10.0, (named, largest)


def test_a_planted_outlier_is_found_with_cycles():
    force, freq, labels = cycles_data(7, 3, 0.7)
    freq[15] += 25.0
    fitted = fit(force, freq, TRUE.k_mm3_hz2, cycles=labels)
    assert [i for i, _ in fitted.outliers] == [15]
    assert 5.0 < abs(fitted.outliers[0][1]) < 100.0


def test_one_cycle_carries_its_own_offset_in_v0():
    """One cycle: Cov(V0) holds the assumed between-cycle variance τ² (the calibration's own cycle offset sits in
    V0), on top of the residual scatter; the other entries are those of the plain weighted fit."""
    force, freq, _ = cycles_data(2, 1, 0.0)
    plain = fit(force, freq, TRUE.k_mm3_hz2, cycle_std_n=0.0).law
    assumed = fit(force, freq, TRUE.k_mm3_hz2, cycle_std_n=1.0).law
    tau_y = assumed.cycle_std_mm3
    assert tau_y == pytest.approx(1.0 * abs(plain.b + plain.a * 20.0), rel=0.05)
    np.testing.assert_allclose(assumed.cov - plain.cov, np.diag([tau_y ** 2, 0.0, 0.0]), atol=1e-9 * tau_y ** 2)


@pytest.mark.parametrize("decimals", [None, 2, 1])
@pytest.mark.parametrize("cycles", [1, 3])
@pytest.mark.parametrize("k_free", [False, True])
def test_an_exact_fit_names_no_outlier(decimals, cycles, k_free):
    """Pairs computed from Eq. 5 with no noise, at full precision (round-off only) or written to 0.01/0.1 Hz (the
    data's resolution): no point of a perfect fit is an outlier. Before the floor on the residual scale (the
    data's resolution, float round-off) the leave-one-out scatter of round-off was ~0 and up to 17 % of such data
    sets named a point (studentized residuals up to 169 while the residual RMS printed 0.00 Hz)."""
    rng = np.random.default_rng(11)
    named = []
    for trial in range(60):
        points = int(rng.integers(5, 20))
        forces = np.concatenate([np.round(np.sort(rng.uniform(0.0, 20.0, points)), 2) for _ in range(cycles)])
        labels = np.repeat(np.arange(cycles), points)
        freqs = TRUE.frequency_hz(forces)
        if decimals is not None:
            freqs = np.round(freqs, decimals)
        fitted = fit(forces, freqs, TRUE.k_mm3_hz2, TRUE.v0_mm3 if k_free else None, cycles=labels)
        if fitted.outliers:
            named.append((trial, fitted.outliers, fitted.to_dict()["residual_rms_hz"]))
    assert not named, named


@pytest.mark.parametrize("decimals,jump_hz", [(None, 1e-6), (2, 0.2), (0, 20.0)])
def test_the_floor_is_no_coarser_than_the_data(decimals, jump_hz):
    """The floor is the data's own resolution (a step of 10^-decimals Hz, sd step/√12) or round-off, not a blanket
    tolerance: on exact pairs a jump of 20 steps at one point (1e-6 Hz at full precision) is still named."""
    forces = np.linspace(0.0, 20.0, 12)
    freqs = TRUE.frequency_hz(forces)
    if decimals is not None:
        freqs = np.round(freqs, decimals)
    freqs[5] += jump_hz
    assert [i for i, _ in fit(forces, freqs, TRUE.k_mm3_hz2).outliers] == [5]
