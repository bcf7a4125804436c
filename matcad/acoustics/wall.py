"""The fast elastic-wall model: the silicone cap as a few wall modes (with mass, stiffness and loss) coupled to
the transmission line. Pure numpy; no FEM at run time. Lengths mm, frequencies Hz, moduli Pa, compliances mm³/Pa.

The cap's dynamic volume compliance (cavity volume swept per unit cavity pressure) is the modal sum, its static
limit made exact (C_w(0) = C_0, the static compliance under uniform pressure):

    C_w(ω) = Σ c_i / (1 + iη − ω²/ω_i²)    (plus the remainder C_0 − Σ c_i as one more mode at the last ω_i)

with ω_i the cap's in-vacuo modes and c_i = Φ_i²/ω_i² their volume compliances (Φ_i: volume swept per unit
mass-normalised amplitude), from the coupled FEM's elastic operator (:mod:`matcad.acoustics.fsi`) on a grid of cap
shapes, shipped as wall_modes.json (built by benchmarks/wall_modes_table.py) and interpolated multilinearly.
Linear elasticity scales them exactly: ω_i ∝ sqrt(G/ρ)/a and c_i ∝ a³/G. Below its modes the wall is a spring
(C_w > 0, f down); above them a mass (C_w < 0, f up).

The cavity is the transmission line of :func:`matcad.acoustics.models.transmission_line_hz` terminated at its
closed end by the wall admittance iωC_w; the neck (with its end corrections) is driven at the mouth through the
radiation resistance ρck²/(2π). As for the coupled FEM, the resonance reported is the peak of |p| at the
cavity's closed end over frequency; the model returns f_TL × (peak with wall / peak with a rigid wall), so it
tends exactly to the transmission line as G → ∞.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from matcad.acoustics.peaks import (SWEEP, cavity_end_response as _cavity_end_response,  # noqa: F401
                                     distinct, dynamic_compliance_mm3_pa, grid_ratios as _grid, peaks as _peaks,
                                     scanned_peaks as _scanned_peaks)

TABLE_PATH = Path(__file__).parent / "wall_modes.json"
TABLE_AXES = {
    "outer": (1.3, 1.6, 2.0, 2.52, 3.2, 4.0),
    "top": (0.4, 0.8, 1.26, 2.0, 3.0),
    "length": (1.0, 2.0, 3.0, 4.5, 7.0),
    "clamp_fraction": (0.0, 0.17, 0.34, 0.6, 0.7, 0.8, 0.9, 1.0),
}
"""Cap shapes in cavity radii (outer radius, top thickness, cavity length) and the clamped fraction of the cavity
height; the paper template (b/a 2.52, T/a 1.26, L/a 3.0, clamp 0.34) lies on the grid. The clamp runs to a wall held
over its whole height: a cap in a riser's pocket is clamped over the riser too (0.65-0.97 of the paper's cavity on
a 1.5-3 mm riser; every 0.1 from 0.6, where the modes move fastest)."""
QUASI_STATIC_RATIO = 3.0
"""The quasi-static wall holds where every wall mode with volume coupling lies ≥ 3× f (docs/physics.md)."""
SIGNIFICANT_MODE = 0.02
"""A mode "couples" when it carries ≥ 2 % of the static volume compliance."""
HYBRID_BAND = 0.15
"""A coupled wall mode within ±15 % of f hybridises with the cavity: two resonances can compete, and the fast
model's error there is larger (measured in docs/error_vs_runtime.md)."""
SELECT_LOSS = 0.05
"""Below this loss factor (the lowest any grade's range reaches) the resonance is followed from it, not picked as
the grid's largest peak (:func:`peak_ratio`)."""
FOLLOW_STEPS = 8
FOLLOW_FLOOR = 1e-4
"""Geometric steps of the loss factor from SELECT_LOSS to this, then the loss factor asked for (0 included)."""
UNIT_SHEAR_PA = 1e6
UNIT_DENSITY = 1000.0
"""The table's cap is at a = 1 mm, G = 1 MPa, ρ = 1000 kg/m³."""


@dataclass(frozen=True)
class CapShape:
    """A cap in millimetres: cavity radius a, length L; outer radius b; top thickness T; clamped height t_c."""

    cavity_radius: float
    cavity_length: float
    outer_radius: float
    top_thickness: float
    clamp_height: float


@dataclass(frozen=True)
class Modes:
    """Wall modes of one cap at one (G, ρ): frequencies (Hz), volume compliances and static compliance (mm³/Pa).
    For arrays of caps (or moduli) the fields carry those leading axes: (..., modes) and (...)."""

    frequencies_hz: np.ndarray
    compliances_mm3_pa: np.ndarray
    static_mm3_pa: float

    def coupled_hz(self) -> np.ndarray:
        """Frequencies of the modes that carry ≥ :data:`SIGNIFICANT_MODE` of the static compliance (one cap)."""
        return self.frequencies_hz[_coupled(self)]


@lru_cache(maxsize=1)
def _table():
    """The table as arrays over its grid (outer, top, length, clamp, mode): log frequencies, compliances, static
    compliance and its log; and the grid's axes and nodes (in log, but the clamp fraction)."""
    data = json.loads(TABLE_PATH.read_text(encoding="utf-8"))
    shape = [len(TABLE_AXES[k]) for k in TABLE_AXES]
    freqs = np.array(data["frequencies_hz"]).reshape(*shape, -1)
    comps = np.array(data["compliances_mm3_pa"]).reshape(*shape, -1)
    static = np.array(data["static_mm3_pa"]).reshape(shape)
    axes = {name: np.array(values) for name, values in TABLE_AXES.items()}
    nodes = {name: (x if name == "clamp_fraction" else np.log(x)) for name, x in axes.items()}
    return np.log(freqs), comps, static, np.log(static), axes, nodes


def shape_outside_table(shape: CapShape) -> list[str]:
    """Names of the shape ratios outside the table's grid (they are clamped to its edge); one cap."""
    return [name for name, v in zip(TABLE_AXES, _ratios(shape))
            if not TABLE_AXES[name][0] <= v <= TABLE_AXES[name][-1]]


def shape_in_table(shape: CapShape):
    """True where every shape ratio lies on the table's grid: a bool for one cap, a bool array for arrays of caps."""
    inside = np.logical_and.reduce([(TABLE_AXES[name][0] <= v) & (v <= TABLE_AXES[name][-1])
                                    for name, v in zip(TABLE_AXES, _ratios(shape))])
    return bool(inside) if np.ndim(inside) == 0 else inside


def _ratios(shape: CapShape):
    a = shape.cavity_radius
    return (np.divide(shape.outer_radius, a), np.divide(shape.top_thickness, a), np.divide(shape.cavity_length, a),
            np.minimum(np.divide(shape.clamp_height, shape.cavity_length), 1.0))


def _interpolated(shape: CapShape):
    """The table interpolated at the cap's ratios (arrays of caps too): log frequencies and shares (..., modes), and
    the log static compliance (...), of the unit cap. Arrays of caps are interpolated once per distinct cap (a
    sweep's chunk of 4 096 variants holds a few: the cap follows the cavity alone), the same numbers."""
    ratios = _ratios(shape)
    lead = np.broadcast_shapes(*(np.shape(r) for r in ratios))
    if not lead:
        return _interpolated_at(ratios)
    ratios = [np.broadcast_to(r, lead).reshape(-1) for r in ratios]
    kinds = distinct(np.column_stack(ratios))
    first, inverse = kinds if kinds is not None else (slice(None), slice(None))
    f, c, s = _interpolated_at([r[first] for r in ratios])
    return f[inverse].reshape(lead + f.shape[-1:]), c[inverse].reshape(lead + c.shape[-1:]), s[inverse].reshape(lead)


def _interpolated_at(ratios):
    """:func:`_interpolated` at the shape ratios ``ratios`` (:func:`_ratios`' four: floats, or arrays that
    broadcast together)."""
    log_f, comps, static, log_static, axes, nodes = _table()
    corners = []
    for name, v in zip(TABLE_AXES, ratios):
        axis, node = axes[name], nodes[name]
        x = np.clip(v, axis[0], axis[-1])
        i = np.clip(np.searchsorted(axis, x) - 1, 0, len(axis) - 2)
        t = ((x if name == "clamp_fraction" else np.log(x)) - node[i]) / (node[i + 1] - node[i])
        corners.append(((i, 1 - t), (i + 1, t)))
    f = s = c = 0.0
    for corner in np.ndindex(2, 2, 2, 2):  # frequencies and the static compliance in log, the shares linearly
        idx = tuple(corners[d][corner[d]][0] for d in range(4))
        w = corners[0][corner[0]][1] * corners[1][corner[1]][1] * corners[2][corner[2]][1] * corners[3][corner[3]][1]
        f = f + w[..., None] * log_f[idx]
        c = c + w[..., None] * comps[idx] / static[idx][..., None]
        s = s + w * log_static[idx]
    return f, c, s


def modes(shape: CapShape, shear_modulus_pa, density_kg_m3) -> Modes:
    """The cap's wall modes, interpolated multilinearly (in log of the ratios; log frequencies, log static
    compliance, each mode's share of it) from wall_modes.json and scaled to its size, modulus (Pa) and density
    (kg/m³). The shape's fields, the modulus and the density may be arrays that broadcast together (a sweep's
    variants, or one cap at several moduli): the fields of :class:`Modes` then carry those leading axes."""
    f, c, s = _interpolated(shape)
    a = np.asarray(shape.cavity_radius, dtype=float)
    g = np.asarray(shear_modulus_pa, dtype=float)
    static_c = np.exp(s) * a**3 * UNIT_SHEAR_PA / g
    scale = np.sqrt(g / UNIT_SHEAR_PA * UNIT_DENSITY / np.asarray(density_kg_m3, dtype=float))
    return Modes(np.exp(f) * scale[..., None] / a[..., None], c * static_c[..., None], static_c)


def _refine_hz(f_grid, response, i: int) -> float:
    """Frequency of the grid maximum ``i`` of ``response``, refined by a parabola through 1/|H|² in log f."""
    i = int(np.clip(i, 1, len(f_grid) - 2))
    y = 1.0 / response[i - 1:i + 2] ** 2
    x = np.log(f_grid[i - 1:i + 2])
    denom = y[0] - 2 * y[1] + y[2]
    shift = 0.5 * (y[0] - y[2]) / denom if denom > 0 else 0.0
    return float(np.exp(x[1] + np.clip(shift, -1, 1) * (x[2] - x[1])))


def _followed_peak_hz(f_grid, responses) -> float:
    """The largest peak of ``responses[0]``, followed through the rows after it (each time to the nearest local
    maximum of the next row) and refined on the last."""
    i = int(np.argmax(responses[0]))
    for r in responses[1:]:
        maxima = np.flatnonzero((r[1:-1] > r[:-2]) & (r[1:-1] >= r[2:])) + 1
        if len(maxima):
            i = int(maxima[np.argmin(np.abs(maxima - i))])
    return _refine_hz(f_grid, responses[-1], i)


def _losses(loss_factor: float) -> np.ndarray:
    """The loss factors the Helmholtz branch is followed through: ``loss_factor`` alone from
    :data:`SELECT_LOSS` up, else from SELECT_LOSS down to it (geometric steps to :data:`FOLLOW_FLOOR`, then it)."""
    if loss_factor >= SELECT_LOSS:
        return np.array([loss_factor])
    return np.append(np.geomspace(SELECT_LOSS, max(loss_factor, FOLLOW_FLOOR), FOLLOW_STEPS), loss_factor)


def peak_ratio(f_tl_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall: Modes,
               loss_factor, side_volume=0.0, scan: bool = False, near=None, near_rigid=None):
    """Peak of the cavity pressure with the elastic wall over the peak with a rigid wall (same network, air of
    ``side_volume`` mm³ joined at the neck in both): a float for one design, an array for arrays of designs, moduli
    or loss factors (each row the same arithmetic as one design: the root find of :func:`matcad.acoustics.peaks.peaks`, so the
    numbers do not depend on the batch). Below :data:`SELECT_LOSS` (one design) the taxel's (Helmholtz) peak is
    found at SELECT_LOSS and followed down to ``loss_factor``: an almost undamped wall mode rings as a sharp spike
    that can out-peak it on the grid (η = 0 on the paper's taxel gave 3033 Hz, a wall mode, for its 5288 Hz), though
    it is not the resonance the jet drives. Its peaks are found by a root find (:mod:`matcad.acoustics.peaks`), or with ``scan``
    by the 601-point reference scan. ``near`` (the ratio of a design close to this one, broadcast against it) makes
    the root find follow the peak from that ratio instead of searching the band: a sensitivity's moved designs, whose
    peak lies on the branch of the design they were moved from (below SELECT_LOSS each design is followed anyway);
    ``near_rigid`` (that design's rigid-wall peak over this f_TL, :func:`peak_ratios`) follows the rigid network's
    peak from there too."""
    return peak_ratios(f_tl_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall, loss_factor,
                       side_volume, scan, near, near_rigid)[0]


def peak_ratios(f_tl_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall: Modes,
                loss_factor, side_volume=0.0, scan: bool = False, near=None, near_rigid=None):
    """(:func:`peak_ratio`, the rigid network's peak over f_TL that it divides by), from one search of each."""
    geometry = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (
        f_tl_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, side_volume)))
    search = _scanned_peaks if scan else _peaks
    rigid = search(tuple(geometry), None, 0.0, **({} if near_rigid is None or scan else
                                                  {"start": np.log(np.asarray(near_rigid, dtype=float))}))
    if np.any(np.asarray(loss_factor) < SELECT_LOSS):  # row by row, each following its Helmholtz branch
        shape = np.broadcast_shapes(geometry[0].shape, np.shape(wall.static_mm3_pa), np.shape(loss_factor))
        m = wall.frequencies_hz.shape[-1]
        freqs = np.broadcast_to(wall.frequencies_hz, shape + (m,))
        comps = np.broadcast_to(wall.compliances_mm3_pa, shape + (m,))
        static, loss = np.broadcast_to(wall.static_mm3_pa, shape), np.broadcast_to(loss_factor, shape)
        rows = [np.broadcast_to(g, shape) for g in geometry]
        ratio = np.empty(shape)
        for i in np.ndindex(shape):
            ratio[i] = _followed_ratio(*(float(g[i]) for g in rows[:6]),
                                       Modes(freqs[i], comps[i], float(static[i])), float(loss[i]), float(rows[6][i]))
    else:
        follow = {} if near is None or scan else {"start": np.log(np.asarray(near, dtype=float) * rigid / geometry[0])}
        ratio = search(tuple(geometry), wall, loss_factor, **follow) / rigid
    rigid = np.broadcast_to(rigid / geometry[0], np.shape(ratio))
    return tuple(float(x) if np.ndim(x) == 0 else np.asarray(x) for x in (ratio, rigid))


def _followed_ratio(f_tl_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall: Modes,
                    loss_factor: float, side_volume: float) -> float:
    """:func:`peak_ratio` of one design below :data:`SELECT_LOSS`: its Helmholtz peak followed down the losses."""
    f = f_tl_hz * _grid()
    geometry = (c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # η = 0 exactly on a wall mode: C = ∞
        compliance = np.stack([dynamic_compliance_mm3_pa(f, wall, eta) for eta in _losses(loss_factor)])
        soft = np.nan_to_num(_cavity_end_response(f, *geometry, compliance, side_volume), nan=0.0, posinf=0.0)
    rigid = _cavity_end_response(f, *geometry, 0.0, side_volume)
    return _followed_peak_hz(f, soft) / _refine_hz(f, rigid, int(np.argmax(rigid)))


DOUBLET_LEVEL = 0.5
"""A second peak of the cavity pressure at least this fraction of the highest (−6 dB) makes a doublet: the taxel
may sing at either, and which one wins depends on what no model here resolves (the jet, losses, the cap as cast)."""


def doublet_hz(f_tl_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall: Modes,
               loss_factor: float, side_volume: float = 0.0) -> float | None:
    """The other peak of a doublet (Hz, on the same scale as :func:`peak_ratio`'s f_TL × ratio), or None: the
    highest local maximum of the driven response with the wall, besides the highest, if it reaches
    :data:`DOUBLET_LEVEL` of it."""
    f = f_tl_hz * np.geomspace(*SWEEP[:2], SWEEP[2])
    geometry = (c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # η = 0 exactly on a wall mode: C = ∞
        soft = np.nan_to_num(_cavity_end_response(f, *geometry, dynamic_compliance_mm3_pa(f, wall, loss_factor),
                                                  side_volume), nan=0.0, posinf=0.0)
    response = _cavity_end_response(f, *geometry, 0.0, side_volume)
    rigid = _refine_hz(f, response, int(np.argmax(response)))
    inner = np.flatnonzero((soft[1:-1] > soft[:-2]) & (soft[1:-1] >= soft[2:])) + 1
    if len(inner) < 2:
        return None
    order = inner[np.argsort(soft[inner])[::-1]]
    top, second = order[0], order[1]
    if soft[second] < DOUBLET_LEVEL * soft[top]:
        return None
    return f_tl_hz * _refine_hz(f, soft, int(second)) / rigid


def _coupled(wall: Modes):
    return wall.compliances_mm3_pa >= SIGNIFICANT_MODE * np.asarray(wall.static_mm3_pa)[..., None]


def quasi_static_valid(wall: Modes, f_hz):
    """True where every wall mode with volume coupling lies ≥ :data:`QUASI_STATIC_RATIO` × f (arrays of caps and
    frequencies give a bool array)."""
    f = np.asarray(f_hz, dtype=float)[..., None]
    ok = np.all(~_coupled(wall) | (wall.frequencies_hz >= QUASI_STATIC_RATIO * f), axis=-1)
    return bool(ok) if np.ndim(ok) == 0 else ok


def mode_coupled_near(wall: Modes, f_hz):
    """True where a coupled wall mode lies within :data:`HYBRID_BAND` of ``f_hz`` (arrays give a bool array)."""
    f = np.asarray(f_hz, dtype=float)[..., None]
    near = np.any(_coupled(wall) & (np.abs(wall.frequencies_hz / f - 1) <= HYBRID_BAND), axis=-1)
    return bool(near) if np.ndim(near) == 0 else near


def mode_near(wall: Modes, f_hz: float) -> float | None:
    """The coupled wall mode (Hz) nearest ``f_hz`` if it lies within :data:`HYBRID_BAND` of it, else None; one cap."""
    coupled = wall.coupled_hz()
    if not len(coupled):
        return None
    nearest = float(coupled[np.argmin(np.abs(coupled - f_hz))])
    return nearest if abs(nearest / f_hz - 1) <= HYBRID_BAND else None
