"""The median the loop takes of tracks and levels, without ``numpy.median``'s import of ``numpy.ma`` (~14 ms of the
~0.3 s a whole `analyze` costs: numpy's median checks for NaN through ``np.ma.isMaskedArray``)."""

from __future__ import annotations

import numpy as np


def median(values) -> float:
    """The median of ``values`` (any shape, taken flat; the units of the values): the same number as
    ``np.median`` (the middle value, or the mean of the two middle ones; NaN when any value is NaN)."""
    a = np.asarray(values, dtype=float).ravel()
    n = a.size
    if n == 0:
        return float("nan")
    k = n // 2
    part = np.partition(a, ([k - 1, k] if n % 2 == 0 else [k]) + [-1])  # -1: a NaN sorts last
    if np.isnan(part[-1]):
        return float("nan")
    return float(np.mean(part[k - 1:k + 1])) if n % 2 == 0 else float(part[k])


def percentile(values, q) -> float | np.ndarray:
    """The ``q``-th percentile(s) (0-100, a number or a list) of ``values`` taken flat, in the values' units: the same
    numbers as ``np.percentile``'s default (linear between the two nearest ranks, numpy's own interpolation
    formula), without its import of ``numpy.ma``; NaN where any value is NaN."""
    a = np.asarray(values, dtype=float).ravel()
    t = np.asarray(q, dtype=float) / 100
    if a.size == 0:
        return float("nan") if t.ndim == 0 else np.full(t.shape, np.nan)
    virtual = (a.size - 1) * t
    below = np.floor(virtual).astype(np.intp)
    above = np.minimum(below + 1, a.size - 1)
    part = np.partition(a, sorted({*below.ravel().tolist(), *above.ravel().tolist(), a.size - 1}))
    low, high = part[below], part[above]
    gamma = virtual - below
    diff = high - low
    out = np.where(gamma >= 0.5, high - diff * (1 - gamma), low + diff * gamma)
    out = np.where(np.isnan(part[-1]), np.nan, out)
    return float(out) if out.ndim == 0 else out


def nanmedian_rows(values) -> np.ndarray:
    """The median of each row of ``values`` (along the last axis, NaN values left out; NaN for a row without any
    value), in the values' units: the same numbers as ``np.nanmedian(values, axis=-1)``, which loads ``numpy.ma``
    for small arrays."""
    a = np.asarray(values, dtype=float)
    ordered = np.sort(a, axis=-1)  # NaN last
    count = np.sum(~np.isnan(a), axis=-1)
    low = np.take_along_axis(ordered, np.maximum((count - 1) // 2, 0)[..., None], axis=-1)[..., 0]
    high = np.take_along_axis(ordered, np.minimum(count // 2, a.shape[-1] - 1)[..., None], axis=-1)[..., 0]
    return np.where(count > 0, (low + high) / 2, np.nan)
