"""The elastic wall's driven response and its peak (:mod:`matcad.acoustics.wall`'s network, numpy only): the cap's
dynamic compliance, the pressure at the cavity's closed end per unit drive, and the peak of that response over
frequency found by a root find (:func:`peaks`) or by the 601-point reference scan (:func:`scanned_peaks`).
Lengths mm, frequencies Hz, compliances mm³/Pa. A wall is anything with the fields of
:class:`matcad.acoustics.wall.Modes` (frequencies_hz, compliances_mm3_pa, static_mm3_pa).
"""

from __future__ import annotations

import math
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from matcad.acoustics.air import BULK_MODULUS_PA

SWEEP = (0.5, 2.0, 601)
"""The reference scan: 601 log-spaced frequencies from 0.5 to 2 × f_TL."""


def dynamic_compliance_mm3_pa(f_hz, wall, loss_factor):
    """C_w(f) = ΔV/p of the cap (mm³/Pa, complex; time e^{iωt}): the modal sum, plus the compliance the retained
    modes miss (static minus their sum) as one more mode at the highest retained frequency, so that it acts as a
    spring below the retained modes and as a mass above them, like the modes it stands for. ``f_hz`` (..., F)
    against caps (...): the result is (..., F)."""
    f = np.asarray(f_hz, dtype=float)[..., None]
    loss = np.asarray(loss_factor, dtype=float)
    g = 1.0 + 1j * loss.reshape(loss.shape + (1,) * (f.ndim - loss.ndim))  # caps' losses against (..., F, modes)
    freqs = np.concatenate([wall.frequencies_hz, wall.frequencies_hz[..., -1:]], axis=-1)
    rest = np.maximum(wall.static_mm3_pa - wall.compliances_mm3_pa.sum(axis=-1), 0.0)
    comps = np.concatenate([wall.compliances_mm3_pa, np.asarray(rest)[..., None]], axis=-1)
    if freqs.ndim > 1:  # caps (..., modes) against frequencies (..., F, 1)
        freqs, comps = freqs[..., None, :], comps[..., None, :]
    return (comps / (g - (f / freqs) ** 2)).sum(axis=-1)


def cavity_end_response(f_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall_compliance,
                        side_volume=0.0):
    """|p| at the cavity's closed end per unit pressure at the mouth source (transfer matrices, mm, Pa, s); air of
    ``side_volume`` (mm³) joined to the cavity at the neck is a compliance V/(ρc²) at that junction. The wall's
    compliance (mm³/Pa) is complex, or 0 for a rigid wall (:func:`drive_squared`'s arithmetic)."""
    wall = np.asarray(wall_compliance)
    return 1.0 / np.sqrt(drive_squared(f_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length,
                                       wall.real, wall.imag, side_volume))


def drive_squared(f_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall_real, wall_imag,
                  side_volume=0.0):
    """|D|² = 1/|H|²: the squared mouth pressure per unit pressure at the cavity's closed end (arrays broadcast
    together; mm, Pa, s). From the closed end, where the wall of compliance ``wall_real`` + i ``wall_imag`` (mm³/Pa,
    e^{iωt}) takes the volume velocity iωC p, through the cavity's and the neck's lossless transfer matrices
    [[cos kL, i Z sin kL], [i sin kL / Z, cos kL]] (Z = ρc/area), ``side_volume``'s compliance V/(ρc²) joined at
    the neck, to the mouth's radiation load ρck²/(2π) (mouth pressure p + ρck²/(2π) u). Real and imaginary parts
    carried apart: the same products as complex arithmetic, ~2× faster in numpy."""
    c = c_m_s * 1e3
    omega = 2 * np.pi * f_hz
    k = omega / c
    rho = BULK_MODULUS_PA / c**2
    z = rho * c / cavity_area
    cos, sin = np.cos(k * cavity_length), np.sin(k * cavity_length)
    u_re, u_im = -omega * wall_imag, omega * wall_real  # iωC at p = 1
    p_re, p_im = cos - z * sin * u_im, z * sin * u_re
    u_re, u_im = cos * u_re, sin / z + cos * u_im
    if np.any(side_volume):
        s = omega * side_volume / BULK_MODULUS_PA
        u_re, u_im = u_re - s * p_im, u_im + s * p_re
    z = rho * c / neck_area
    cos, sin = np.cos(k * neck_length_eff), np.sin(k * neck_length_eff)
    p_re, p_im, u_re, u_im = (cos * p_re - z * sin * u_im, cos * p_im + z * sin * u_re,
                              cos * u_re - sin / z * p_im, cos * u_im + sin / z * p_re)
    load = rho * c * k * k / (2 * np.pi)
    q_re, q_im = p_re + load * u_re, p_im + load * u_im
    return q_re * q_re + q_im * q_im


def peak_hz(f_grid, response):
    """Frequency of the largest value of ``response`` on the grid (last axis), refined by a parabola through
    1/|H|²; rows of grids give one peak each."""
    i = np.clip(np.argmax(response, axis=-1), 1, response.shape[-1] - 2)[..., None] + np.arange(-1, 2)
    y = 1.0 / np.take_along_axis(response, i, axis=-1) ** 2
    x = np.log(np.take_along_axis(np.broadcast_to(f_grid, response.shape), i, axis=-1))
    denom = y[..., 0] - 2 * y[..., 1] + y[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(denom > 0, 0.5 * (y[..., 0] - y[..., 2]) / denom, 0.0)
    return np.exp(x[..., 1] + np.clip(shift, -1, 1) * (x[..., 2] - x[..., 1]))


@lru_cache(maxsize=1)
def grid_ratios() -> np.ndarray:
    return np.geomspace(*SWEEP[:2], SWEEP[2])


BLOCK_ROWS = 32
"""Driven responses evaluated per numpy pass of the reference scan (32 × 601 frequencies × ~21 modes)."""
COARSE_POINTS = 97
"""Points of the coarse scan over :data:`SWEEP`'s range that brackets the peaks before they are refined (a step of
1.45 % in f: two peaks 2.8 % apart, a near-tie doublet, stay two candidates; 49 points merged them)."""
WINDOWS = 4
WINDOW_POINTS = 4
"""The coarse scan in two passes: its even points (every second: 49), then its odd points nearest the
:data:`WINDOWS` lowest local minima of those, :data:`WINDOW_POINTS` around each (±3 steps: 16 points). An odd point
not evaluated takes the larger of its two neighbours, which cannot make or unmake a local minimum; near the
minima the grid is the full one. The coarse scan only brackets, so it runs in single precision (|D|² ~3× faster:
numpy's float32 cosines are vectorised); the refinement is in double. The candidates so found are the 97-point
double-precision grid's: on 200 000 random variants the peaks agree with the one-pass scan's to < 1e-8 (and 4
windows are needed: with 2 or 3, one in ~10^5 found another of four near-tie peaks), with 65 evaluations instead of
97 (tests/test_wall_peak.py)."""
CANDIDATES = 2
"""Local maxima of the coarse scan refined per row (the highest two); the highest refined one is the peak."""
RIVAL = 3.0
"""A candidate after the highest is refined only where its coarse |D|² is within this factor of the highest's: a
parabola's refinement lowers a minimum by far less (on 60 000 random variants the second candidate won only where
its coarse value was within 1.09× of the first's; 11 % of rows have one within 3×)."""
FIRST_WIDTH = 0.2
REFINE_STEPS = 6
SMALLEST_WIDTH = 1e-7
"""Parabolas that refine a peak after the coarse scan's own: each through three points centred on the last vertex,
the first :data:`FIRST_WIDTH` coarse steps wide, each next one as wide as the last step taken (Newton's step with a
finite-difference derivative and curvature: superlinear), at least :data:`SMALLEST_WIDTH` in log f."""
CONVERGED = 1e-9
MORE_STEPS = 12
"""A search's parabolas go on past :data:`REFINE_STEPS`, up to MORE_STEPS more, on the rows whose last step was
longer than CONVERGED (log f): after six, 8 of 20 000 random variants were still 1e-6 to 1.3e-4 from their peak (a
flat minimum: the steps shrink slowly), the rest within 1e-9 (tests/test_wall_peak.py)."""
DIRECT_WIDTH = 0.02
"""Width (log f) of the first parabola that refines a rigid wall's peak from f_TL."""
FOLLOW_WIDTH = 1e-4
"""Width (log f) of the one parabola that follows a peak from a known start (:func:`peaks`' ``start``): 100× a
sensitivity's step (:data:`matcad.sweep.fast.RELATIVE_STEP`), the distance its peak moves. One Newton step with a
finite-difference derivative and curvature lands within ~3e-7 of the peak (the parabola's bias, from |D|²'s third
derivative); the two designs of a central difference share that bias, so, the wall's peak and the rigid one it is
divided by both followed, their slope is the derivative to ~3e-8 (median; 3e-6 on 99 % of random variants), where
six parabolas of shrinking width reached the peak itself to 1e-10 but left 1e-6 / 7e-5 in the slope: their last
widths, 1e-7 in log f, hit |D|²'s rounding (tests/test_wall_peak.py)."""
FAST_BLOCK = 1024
"""Rows per numpy pass of the root find (1024 × 49 frequencies × ~22 modes: ~9 MB a temporary; with the one-pass
scan's 97, 256 rows was 1.5× slower, 2048 no faster)."""


def peaks(geometry: tuple, wall, loss_factor, start=None) -> np.ndarray:
    """Peak frequency (Hz) of the driven response per row: ``geometry`` = (f_TL, c, A, S, l_eff, L, V_side) arrays
    of one shape, and the wall (None: rigid) with its loss, broadcast against it. The peak is a minimum of |D(f)|² =
    1/|H|² (the mouth's pressure per unit closed-end pressure): bracketed by a coarse scan of :data:`COARSE_POINTS`
    (in the two passes of :data:`WINDOWS`), then each of the :data:`CANDIDATES` lowest local minima that may win
    (:data:`RIVAL`) refined by parabolas through |D|² in log f of shrinking width (:data:`REFINE_STEPS`: Newton's
    step with a finite-difference derivative and curvature), the lowest refined one kept; a rigid wall has one peak,
    refined from f_TL. The same f0 as the 601-point scan :func:`scanned_peaks` to < 1e-4 on the templates and on
    99.5 % of random variants; where they differ by more it is the scan's grid error (a 200 001-point search agrees
    with the root find to 1e-5; tested). ~10× faster than the scan (benchmarks/sweep.py). ``start`` (log offsets
    from f_TL, broadcast against the rows) follows each row's peak from there instead, with a wall or without: no
    search, one parabola of :data:`FOLLOW_WIDTH` (a design moved a little from one whose peak is known, as a
    sensitivity's are: see FOLLOW_WIDTH for what it is good to)."""
    rows, shape, n = rows_of(geometry, wall, loss_factor, start)
    rows, inverse = distinct_rows(rows)
    m = len(rows["f_tl"])
    out = np.empty(m)
    for start in range(0, m, FAST_BLOCK):
        block = {k: v[start:start + FAST_BLOCK] for k, v in rows.items()}
        out[start:start + FAST_BLOCK] = _block_peak(block, wall is not None)
    return (out if inverse is None else out[inverse]).reshape(shape)


def distinct_rows(rows: dict) -> tuple[dict, np.ndarray | None]:
    """The distinct rows of :func:`rows_of`'s inputs and, for each input row, the index of its distinct row
    (None when every row is distinct). A peak depends on its own row only, so searching each distinct row once gives
    the same numbers: a calibrated sweep's drawn taxel is one design repeated over every variant of a chunk. Rows
    that differ in their scalar inputs differ, so those are compared first: a sweep's variants, all distinct, are
    told so without their wall's modes (a tenth of the columns)."""
    scalars = [np.asarray(v, dtype=float) for v in rows.values() if np.ndim(v) == 1]
    if scalars and distinct(np.column_stack(scalars)) is None:
        return rows, None
    kinds = distinct(np.column_stack([np.asarray(v, dtype=float).reshape(len(v), -1) for v in rows.values()]))
    if kinds is None:
        return rows, None
    first, inverse = kinds
    return {k: v[first] for k, v in rows.items()}, inverse


def distinct(table: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(first, inverse) of the 2-D float ``table``'s distinct rows, compared bit for bit: the index of one row of
    each kind, and each row's kind (``table[first][inverse]`` is ``table``); None when every row is distinct. One
    hash of each row's bits and one sort of the hashes: distinct hashes are distinct rows; where some repeat, every
    row is checked against its kind's first row (``np.unique(axis=0)``, a sort of whole rows ~10x slower on a
    sweep's chunk, where the hashes collide)."""
    bits = np.ascontiguousarray(table, dtype=float).view(np.uint64).reshape(len(table), -1)
    hashes = (bits * _multipliers(bits.shape[1])).sum(axis=1)  # modulo 2^64
    ordered = np.sort(hashes)
    if not (ordered[1:] == ordered[:-1]).any():  # distinct hashes: distinct rows (equal rows hash alike)
        return None
    _, first, inverse = np.unique(hashes, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    if not np.array_equal(bits[first][inverse], bits):
        _, first, inverse = np.unique(bits, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
    return None if len(first) == len(table) else (first, inverse)


@lru_cache(maxsize=8)
def _multipliers(columns: int) -> np.ndarray:
    """Odd 64-bit multipliers of :func:`distinct`'s row hash, one per column: Knuth's MMIX linear congruential
    sequence (fixed; numpy.random is not loaded for it)."""
    out, x = [], 0x9E3779B97F4A7C15
    for _ in range(columns):
        x = (x * 6364136223846793005 + 1442695040888963407) % 2**64
        out.append(x | 1)
    return np.array(out, dtype=np.uint64)


def rows_of(geometry: tuple, wall, loss_factor, start=None):
    """The broadcast inputs of :func:`peaks` flattened to rows: {name: (n,) or (n, modes)}, the shape, n."""
    parts = [*geometry] if wall is None else [*geometry, wall.static_mm3_pa, np.asarray(loss_factor, dtype=float)]
    if start is not None:
        parts.append(np.asarray(start, dtype=float))
    shape = np.broadcast_shapes(*(np.shape(x) for x in parts))
    n = math.prod(shape)
    rows = {name: np.broadcast_to(x, shape).reshape(n) for name, x in zip(("f_tl", "c", "A", "S", "l", "L", "side"),
                                                                        geometry)}
    if wall is not None:
        m = wall.frequencies_hz.shape[-1]
        rows["freqs"] = np.broadcast_to(wall.frequencies_hz, shape + (m,)).reshape(n, m)
        rows["comps"] = np.broadcast_to(wall.compliances_mm3_pa, shape + (m,)).reshape(n, m)
        rows["static"] = np.broadcast_to(wall.static_mm3_pa, shape).reshape(n)
        rows["loss"] = np.broadcast_to(loss_factor, shape).reshape(n)
    if start is not None:
        rows["start"] = np.broadcast_to(start, shape).reshape(n)
    return rows, shape, n


def d_squared(rows: dict, x, elastic: bool) -> np.ndarray:
    """|D|² = 1/|H|² of each row at log offsets ``x`` (n, k) from its f_TL."""
    f = rows["f_tl"][:, None] * np.exp(x)
    net = [rows[k][:, None] for k in ("c", "A", "S", "l", "L")]
    wall = modal_parts(rows, f) if elastic else (0.0, 0.0)
    return drive_squared(f, *net, *wall, rows["side"][:, None])


def _block_peak(rows: dict, elastic: bool) -> np.ndarray:
    """Peak frequency (Hz) of each row of a block (:func:`peaks`): with a wall, the coarse scan's candidates
    refined; a rigid wall's one peak refined from f_TL."""
    n = len(rows["f_tl"])
    if elastic and "start" not in rows:
        return rows["f_tl"] * np.exp(scanned_x(rows))
    start, width, steps = (rows["start"], FOLLOW_WIDTH, 1) if "start" in rows else (np.zeros(n), DIRECT_WIDTH, None)
    x, _, _ = _refine(rows, start[:, None], np.ones((n, 1), dtype=bool), width, elastic, steps)
    return rows["f_tl"] * np.exp(x[:, 0])


def modal_parts(rows: dict, f) -> tuple[np.ndarray, np.ndarray]:
    """(real, imaginary) parts of :func:`dynamic_compliance_mm3_pa` of each row at frequencies ``f`` (n, k), in
    real arithmetic: c/(1 + iη − u) = c(1 − u − iη)/((1 − u)² + η²) with u = f²/f_i² (the same sum, ~3× faster
    than numpy's complex division)."""
    if "inverse_f2" not in rows:
        freqs = np.concatenate([rows["freqs"], rows["freqs"][:, -1:]], axis=-1)
        rest = np.maximum(rows["static"] - rows["comps"].sum(axis=-1), 0.0)
        with np.errstate(over="ignore"):  # a mode beyond 1e154 Hz (a massless wall): f² = inf, 1/f² = 0, its limit
            rows["inverse_f2"] = (1.0 / freqs**2)[:, None, :]
        rows["modal_c"] = np.concatenate([rows["comps"], rest[:, None]], axis=-1)[:, None, :]
    eta = rows["loss"][:, None, None]
    one_minus_u = (f * f)[..., None] * rows["inverse_f2"]
    np.subtract(1.0, one_minus_u, out=one_minus_u)  # in place: two (n, k, modes) temporaries, not five (1.7x)
    w = one_minus_u * one_minus_u
    w += eta * eta
    np.divide(rows["modal_c"], w, out=w)
    return np.einsum("nkm,nkm->nk", w, one_minus_u), -eta[..., 0] * w.sum(axis=-1)


def scanned_x(rows: dict) -> np.ndarray:
    """Log peak offsets from f_TL of rows with a wall: the coarse scan's (:data:`COARSE_POINTS`, in the two passes
    of :data:`WINDOWS`) :data:`CANDIDATES` lowest local minima of |D|², each refined, the lowest kept."""
    lo, hi = math.log(SWEEP[0]), math.log(SWEEP[1])
    step = (hi - lo) / (COARSE_POINTS - 1)
    n = len(rows["f_tl"])
    grid = np.linspace(lo, hi, COARSE_POINTS)
    y = _two_pass(rows, grid, np.float32)
    wild = np.flatnonzero(~np.isfinite(y).all(axis=-1))  # past single precision's range: these rows in double
    if wild.size:
        y[wild] = _two_pass({name: rows[name][wild] for name in INPUTS}, grid, np.float64)
    padded = np.pad(y, ((0, 0), (1, 1)), constant_values=np.inf)
    minima = (y <= padded[:, :-2]) & (y < padded[:, 2:])
    order = np.argsort(np.where(minima, y, np.inf), axis=-1)[:, :CANDIDATES]
    x = grid[order] + _vertex(padded[np.arange(n)[:, None, None], order[..., None] + np.arange(3)], step)
    real = np.take_along_axis(minima, order, axis=-1)  # fewer local minima than candidates: the rest drop out
    coarse = np.take_along_axis(y, order, axis=-1)
    rival = real & (coarse <= RIVAL * coarse[:, :1])  # the lowest always refined; another where it may win
    peak, best, _ = _refine(rows, x[:, :1], real[:, :1], FIRST_WIDTH * step, True)
    peak, best = peak[:, 0], best[:, 0]
    for k in range(1, order.shape[1]):
        some = np.flatnonzero(rival[:, k])
        if some.size:
            x_k, best_k, _ = _refine({name: value[some] for name, value in rows.items()}, x[some, k:k + 1],
                                     real[some, k:k + 1], FIRST_WIDTH * step, True)
            wins = best_k[:, 0] < best[some]
            peak[some[wins]], best[some[wins]] = x_k[wins, 0], best_k[wins, 0]
    return peak


INPUTS = ("f_tl", "c", "A", "S", "l", "L", "side", "freqs", "comps", "static", "loss")
"""The inputs of a row with a wall (:func:`rows_of`)."""


def _two_pass(rows: dict, grid: np.ndarray, dtype) -> np.ndarray:
    """|D|² of each row on ``grid`` (odd length) as :data:`WINDOWS` says, in ``dtype``: on the even points and on
    the odd points near the lowest minima of those, elsewhere the larger neighbour. In single precision a value
    past its range is left inf or NaN, unwarned (:func:`scanned_x` takes such a row again in double)."""
    n, odd = len(rows["f_tl"]), len(grid) // 2
    with np.errstate(**({"all": "ignore"} if dtype == np.float32 else {})):
        values = {name: np.asarray(rows[name], dtype=dtype) for name in INPUTS}
        grid = grid.astype(dtype)
        even = d_squared(values, np.broadcast_to(grid[::2], (n, odd + 1)), True).astype(float)
        padded = np.pad(even, ((0, 0), (1, 1)), constant_values=np.inf)
        minima = (even <= padded[:, :-2]) & (even < padded[:, 2:])
        order = np.argsort(np.where(minima, even, np.inf), axis=-1)[:, :WINDOWS]
        near = np.arange(-WINDOW_POINTS // 2, WINDOW_POINTS // 2)  # odd point k lies between even points k, k + 1
        at = np.clip(order[..., None] + near, 0, odd - 1).reshape(n, -1)
        y = np.empty((n, len(grid)))
        y[:, ::2] = even
        y[:, 1::2] = np.maximum(even[:, :-1], even[:, 1:])
        found = d_squared(values, grid[2 * at + 1], True)
    keep = np.repeat(np.take_along_axis(minima, order, axis=-1), WINDOW_POINTS, axis=-1)  # no minimum: no window
    odd_y = y[:, 1::2]
    np.put_along_axis(odd_y, at, np.where(keep, found, np.take_along_axis(odd_y, at, axis=-1)), axis=-1)
    return y


def _refine(rows: dict, x, real, width: float, elastic: bool, steps: int | None = None):
    """Minima of |D|² refined from log offsets ``x`` (n, k) by ``steps`` parabolas, or as a search (``steps``
    None) by :data:`REFINE_STEPS` and then, for the rows not yet converged, up to :data:`MORE_STEPS` more: (x, |D|²
    at the last centre (inf where not ``real``), the last step's size)."""
    n, k = x.shape
    h = np.full(x.shape, width)
    y = shift = None
    for _ in range(REFINE_STEPS if steps is None else steps):
        x, h, y, shift = _parabola(rows, x, h, elastic)
    for _ in range(MORE_STEPS if steps is None else 0):
        loose = np.flatnonzero(np.any(real & (np.abs(shift) > CONVERGED), axis=-1))
        if not loose.size:
            break
        x[loose], h[loose], y[loose], shift[loose] = _parabola({name: value[loose] for name, value in rows.items()},
                                                              x[loose], h[loose], elastic)
    return x, np.where(real, y[..., 1], np.inf), np.abs(shift)


def _parabola(rows: dict, x, h, elastic: bool):
    """One step of :func:`_refine` from ``x`` with half-widths ``h`` (n, k): (x, h, the three |D|² (n, k, 3), the
    step)."""
    n, k = x.shape
    y = d_squared(rows, (x[..., None] + h[..., None] * np.array([-1.0, 0.0, 1.0])).reshape(n, 3 * k),
                  elastic).reshape(n, k, 3)
    shift = _vertex(y, h)
    return np.clip(x + shift, math.log(SWEEP[0]), math.log(SWEEP[1])), np.maximum(np.abs(shift), SMALLEST_WIDTH), y, \
        shift


def _vertex(y, h):
    """Offset of the vertex of the parabola through ``y`` (..., 3) at -h, 0, h, kept within ±2h; downhill by h
    where the three points do not curve up (an end of the range: an infinite neighbour moves nothing)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = y[..., 0] - 2 * y[..., 1] + y[..., 2]
        shift = np.where(denom > 0, 0.5 * h * (y[..., 0] - y[..., 2]) / denom, np.sign(y[..., 0] - y[..., 2]) * h)
    return np.clip(np.nan_to_num(shift, nan=0.0, posinf=0.0, neginf=0.0), -2 * h, 2 * h)


def scanned_peaks(geometry: tuple, wall, loss_factor) -> np.ndarray:
    """The reference for :func:`peaks`: the largest value of the driven response on the 601-point grid of
    :data:`SWEEP` per row, refined by a parabola through 1/|H|² (in blocks of :data:`BLOCK_ROWS`)."""
    rows, shape, n = rows_of(geometry, wall, loss_factor)
    out = np.empty(n)
    for start in range(0, n, BLOCK_ROWS):
        r = {k: v[start:start + BLOCK_ROWS] for k, v in rows.items()}
        f = r["f_tl"][:, None] * grid_ratios()
        compliance = 0.0 if wall is None else \
            dynamic_compliance_mm3_pa(f, SimpleNamespace(frequencies_hz=r["freqs"], compliances_mm3_pa=r["comps"], static_mm3_pa=r["static"]), r["loss"])
        net = [r[k][:, None] for k in ("c", "A", "S", "l", "L")]
        out[start:start + BLOCK_ROWS] = peak_hz(f, cavity_end_response(f, *net, compliance, r["side"][:, None]))
    return out.reshape(shape)
