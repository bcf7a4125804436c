"""Lines that belong to a comb — mains hum or buzz, a voice — and so not to a taxel, whose neighbours are not a comb.

*Mains combs* (:func:`mains_zone`): a line with lines of similar level (within :data:`COMB_LEVEL_DB`) on a mains
grid (spacing 50, 60, 100 or 120 Hz, hosting lines at ≥ :data:`COMB_GRID_FRACTION` of its places) belongs to hum or
buzz: its bins are removed before tracking. *Harmonic combs* (:func:`in_harmonic_comb`): the tracked line with
lines at multiples of a spacing in the speech pitch range is a harmonic of a voice or any periodic sound; voicing
does not count it. Frequencies Hz, levels dB over the local floor (:func:`matcad.loop.spectrum.levels`).
"""

from __future__ import annotations

import numpy as np

from matcad.loop.stats import nanmedian_rows

COMB_SPACINGS_HZ = (50.0, 60.0, 100.0, 120.0)
COMB_LEVEL_DB = 10.0
COMB_GRID_FRACTION = 0.6
COMB_ZONE_BINS = 3
HARMONIC_SPACING_HZ = (80.0, 400.0)
HARMONIC_TESTS = (((-2, -1, 1, 2), 3, 2, 8.0), ((-4, -3, -2, -1, 1, 2, 3, 4), 5, 1, 6.0))
"""(multiples of Δ, how many must hold a line, within ± bins, line level dB): a line with such neighbours, Δ in
the speech pitch range HARMONIC_SPACING_HZ, is a harmonic (see :func:`in_harmonic_comb`)."""


def mains_comb(lines: np.ndarray, freqs: np.ndarray, df: float) -> np.ndarray:
    """Lines (frames × bins at ``freqs`` Hz, spacing ``df`` Hz; dB, −inf where none) that sit on a mains grid m·S
    (S = 50, 60, 100, 120 Hz) which hosts lines at ≥ COMB_GRID_FRACTION of its places in the frame, unless
    COMB_LEVEL_DB above the grid's median line."""
    from matcad.loop.spectrum import running_max

    near = running_max(lines, 3)
    f0 = freqs[0]
    members = np.zeros(lines.shape, dtype=bool)
    for spacing in COMB_SPACINGS_HZ:
        m = np.arange(np.ceil(f0 / spacing), np.floor(freqs[-1] / spacing) + 1)
        grid = np.round((m * spacing - f0) / df).astype(int)
        grid = grid[(grid >= 1) & (grid < lines.shape[1] - 1)]
        if len(grid) < 8:
            continue
        hosted = near[:, grid]
        ok = np.isfinite(hosted)
        comb = np.mean(ok, axis=1) >= COMB_GRID_FRACTION
        if not np.any(comb):
            continue
        level = nanmedian_rows(np.where(ok, hosted, np.nan)[comb])
        on_grid = np.zeros(lines.shape[1], dtype=bool)
        on_grid[np.concatenate([grid - 1, grid, grid + 1])] = True
        members[comb] |= on_grid[None, :] & np.isfinite(lines[comb]) & (lines[comb] < level[:, None] + COMB_LEVEL_DB)
    return members


def mains_zone(lines: np.ndarray, freqs: np.ndarray, df: float) -> np.ndarray:
    """Bins (frames × bins) within ±COMB_ZONE_BINS of a :func:`mains_comb` line: removed before tracking."""
    from matcad.loop.spectrum import running_max

    return running_max(mains_comb(lines, freqs, df).astype(np.uint8), 2 * COMB_ZONE_BINS + 1).astype(bool)


def in_harmonic_comb(lines: np.ndarray, p: np.ndarray, df: float) -> np.ndarray:
    """Per frame (rows of ``lines``, dB over the floor, −inf where no line, bins ``df`` Hz wide): True when the line
    at bin ``p`` is one of a harmonic comb of spacing Δ in HARMONIC_SPACING_HZ (a voice, or any periodic sound), not
    a taxel. Two tests (:data:`HARMONIC_TESTS`): lines ≥ 8 dB within ±2 bins at 3 of ±Δ, ±2Δ (resolved
    harmonics), or lines ≥ 6 dB within ±1 bin at 5 of ±Δ … ±4Δ (a wider comb of weaker, partly smeared harmonics).
    Each neighbour must also be within COMB_LEVEL_DB of the line. A taxel's own skirt (jet noise through the
    resonator, ~±100 Hz) reaches ±Δ, not ±3Δ."""
    from matcad.loop.spectrum import running_max

    k, n = lines.shape
    rows = np.arange(k)
    level = lines[rows, p]
    d = np.arange(int(HARMONIC_SPACING_HZ[0] / df), int(HARMONIC_SPACING_HZ[1] / df) + 1)
    found = np.zeros(k, dtype=bool)
    for orders, hits, tolerance, line_db in HARMONIC_TESTS:
        need = np.maximum(line_db, level - COMB_LEVEL_DB)
        near = running_max((lines >= need[:, None]).astype(np.uint8), 2 * tolerance + 1, "constant") > 0
        at = p[:, None, None] + np.array(orders)[None, :, None] * d[None, None, :]
        hit = near[rows[:, None, None], np.clip(at, 0, n - 1)] & (at >= 0) & (at < n)
        found |= np.any(hit.sum(axis=1) >= hits, axis=1)
    return np.isfinite(level) & found
