"""Honest force intervals, by simulation (issue 24): benchmarks/calibration.py's simulation (a taxel following Eq. 5,
calibrated from one or three load cycles each offset by a between-cycle force of sd τ, read in a new cycle at a
uniform force) at a size the default suite affords, 400 trials per case; the benchmark runs 2000 and every row."""

import dataclasses

import numpy as np

from benchmarks.calibration import TRUE, coverage
from matcad.loop.sense import force_interval

TRIALS = 400


def test_one_cycle_covers_at_the_papers_between_cycle_scatter():
    """One cycle, τ = 1 N over 0-15.4 N (the paper's ~1 N): >= 90 % of 95 % intervals hold the true force (94.6 %
    here). Deliberate fault caught: the prior at the 0.7 N assumed before issue 24 covers 83.6 %."""
    share, *_ = coverage(1, 1.0, 15.4, 0.0, TRIALS, True)
    assert share >= 0.90, share


def test_three_cycles_are_not_twice_as_wide_as_needed():
    """Three cycles at τ = 1 N: >= 90 % coverage with a median half-width 1.3 times the one an oracle needs (the
    95th percentile of |error|). Deliberate fault caught: the between-cycle sd from the three offsets alone (no
    prior) gives 1.84 times."""
    share, half, needed, _ = coverage(3, 1.0, 15.4, 0.0, TRIALS, True)
    assert share >= 0.90 and half / needed < 1.6, (share, half, needed)


def test_a_temperature_not_given_is_carried_and_warned():
    """The air ±3 °C off the calibration's and no --temperature-c, on a 0-2 N calibration (τ 0.13 N, where 3 °C
    is ~0.4 N): >= 90 % coverage (99 % here; 55 % without the temperature term), and the reading says what the
    unknown temperature costs."""
    share, *_ = coverage(1, 0.13, 2.0, 3.0, TRIALS, False)
    assert share >= 0.90, share
    heard = np.array([float(TRUE.frequency_hz(7.0))])
    law = dataclasses.replace(TRUE, covariance=(0.0,) * 9, residual_std_mm3=0.01, dof=20, force_range_n=(0.0, 15.0),
                              temperature_c=20.0)
    _, known, quiet = force_interval(law, heard, 20.0)
    _, unknown, warning = force_interval(law, heard, None)
    assert quiet == "" and "--temperature-c" in warning and unknown[0] > 1.5 * known[0], (known, unknown, warning)
