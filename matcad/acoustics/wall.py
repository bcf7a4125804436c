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
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from matcad.acoustics.air import BULK_MODULUS_PA

TABLE_PATH = Path(__file__).parent / "wall_modes.json"
TABLE_AXES = {
    "outer": (1.3, 1.6, 2.0, 2.52, 3.2, 4.0),
    "top": (0.4, 0.8, 1.26, 2.0, 3.0),
    "length": (1.0, 2.0, 3.0, 4.5, 7.0),
    "clamp_fraction": (0.0, 0.17, 0.34, 0.6),
}
"""Cap shapes in cavity radii (outer radius, top thickness, cavity length) and the clamped fraction of the cavity
height; the paper template (b/a 2.52, T/a 1.26, L/a 3.0, clamp 0.34) lies on the grid."""
QUASI_STATIC_RATIO = 3.0
"""The quasi-static wall holds where every wall mode with volume coupling lies ≥ 3× f (docs/physics.md)."""
SIGNIFICANT_MODE = 0.02
"""A mode "couples" when it carries ≥ 2 % of the static volume compliance."""
HYBRID_BAND = 0.15
"""A coupled wall mode within ±15 % of f hybridises with the cavity: two resonances can compete, and the fast
model's error there is larger (measured in docs/error_vs_runtime.md)."""
SWEEP = (0.5, 2.0, 601)
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
    """Wall modes of one cap at one (G, ρ): frequencies (Hz), volume compliances and static compliance (mm³/Pa)."""

    frequencies_hz: np.ndarray
    compliances_mm3_pa: np.ndarray
    static_mm3_pa: float

    def coupled_hz(self) -> np.ndarray:
        """Frequencies of the modes that carry ≥ :data:`SIGNIFICANT_MODE` of the static compliance."""
        return self.frequencies_hz[self.compliances_mm3_pa >= SIGNIFICANT_MODE * self.static_mm3_pa]


@lru_cache(maxsize=1)
def _table():
    data = json.loads(TABLE_PATH.read_text(encoding="utf-8"))
    shape = [len(TABLE_AXES[k]) for k in TABLE_AXES]
    return (np.array(data["frequencies_hz"]).reshape(*shape, -1),
            np.array(data["compliances_mm3_pa"]).reshape(*shape, -1), np.array(data["static_mm3_pa"]).reshape(shape))


def shape_outside_table(shape: CapShape) -> list[str]:
    """Names of the shape ratios outside the table's grid (they are clamped to its edge)."""
    values = _ratios(shape)
    return [name for name, v in zip(TABLE_AXES, values) if not TABLE_AXES[name][0] <= v <= TABLE_AXES[name][-1]]


def _ratios(shape: CapShape):
    a = shape.cavity_radius
    return (shape.outer_radius / a, shape.top_thickness / a, shape.cavity_length / a,
            min(shape.clamp_height / shape.cavity_length, 1.0))


def modes(shape: CapShape, shear_modulus_pa: float, density_kg_m3: float) -> Modes:
    """The cap's wall modes, interpolated multilinearly (in log of the ratios; log frequencies, log static
    compliance, each mode's share of it) from wall_modes.json and scaled to its size, modulus (Pa) and density
    (kg/m³)."""
    freqs, comps, static = _table()
    weights = []
    for name, v in zip(TABLE_AXES, _ratios(shape)):
        axis = np.array(TABLE_AXES[name])
        x = np.clip(v, axis[0], axis[-1])
        i = int(np.clip(np.searchsorted(axis, x) - 1, 0, len(axis) - 2))
        lo, hi = (axis[i], axis[i + 1]) if name == "clamp_fraction" else (math.log(axis[i]), math.log(axis[i + 1]))
        t = ((x if name == "clamp_fraction" else math.log(x)) - lo) / (hi - lo)
        weights.append(((i, 1 - t), (i + 1, t)))
    f = np.zeros(freqs.shape[-1])
    c = np.zeros(comps.shape[-1])
    s = 0.0
    for corner in np.ndindex(2, 2, 2, 2):
        idx = tuple(weights[d][corner[d]][0] for d in range(4))
        w = math.prod(weights[d][corner[d]][1] for d in range(4))
        if w:  # frequencies and the static compliance in log, each mode's share of it linearly
            f += w * np.log(freqs[idx])
            c += w * comps[idx] / static[idx]
            s += w * math.log(static[idx])
    a = shape.cavity_radius
    static_c = math.exp(s) * a**3 * UNIT_SHEAR_PA / shear_modulus_pa
    return Modes(np.exp(f) * math.sqrt(shear_modulus_pa / UNIT_SHEAR_PA * UNIT_DENSITY / density_kg_m3) / a,
                 c * static_c, static_c)


def dynamic_compliance_mm3_pa(f_hz, wall: Modes, loss_factor: float):
    """C_w(f) = ΔV/p of the cap (mm³/Pa, complex; time e^{iωt}): the modal sum, plus the compliance the retained
    modes miss (static minus their sum) as one more mode at the highest retained frequency, so that it acts as a
    spring below the retained modes and as a mass above them, like the modes it stands for."""
    f = np.asarray(f_hz, dtype=float)[..., None]
    g = 1.0 + 1j * loss_factor
    freqs = np.append(wall.frequencies_hz, wall.frequencies_hz[-1])
    comps = np.append(wall.compliances_mm3_pa, max(wall.static_mm3_pa - wall.compliances_mm3_pa.sum(), 0.0))
    return (comps / (g - (f / freqs) ** 2)).sum(axis=-1)


def _cavity_end_response(f_hz, c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length, wall_compliance,
                         side_volume=0.0):
    """|p| at the cavity's closed end per unit pressure at the mouth source (transfer matrices, mm, Pa, s); air of
    ``side_volume`` (mm³) joined to the cavity at the neck is a compliance V/(ρc²) at that junction."""
    c = c_m_s * 1e3
    omega = 2 * np.pi * f_hz
    k = omega / c
    rho = BULK_MODULUS_PA / c**2
    z_cav, z_neck = rho * c / cavity_area, rho * c / neck_area
    p = np.ones_like(omega, dtype=complex)
    u = 1j * omega * wall_compliance * p  # volume velocity into the wall at the closed end
    kl = k * cavity_length
    p, u = np.cos(kl) * p + 1j * z_cav * np.sin(kl) * u, 1j * np.sin(kl) / z_cav * p + np.cos(kl) * u
    if side_volume:
        u = u + 1j * omega * side_volume / BULK_MODULUS_PA * p
    kl = k * neck_length_eff
    p, u = np.cos(kl) * p + 1j * z_neck * np.sin(kl) * u, 1j * np.sin(kl) / z_neck * p + np.cos(kl) * u
    return 1.0 / np.abs(p + rho * c * k * k / (2 * np.pi) * u)


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
               loss_factor: float, side_volume: float = 0.0) -> float:
    """Peak of the cavity pressure with the elastic wall over the peak with a rigid wall (same network, air of
    ``side_volume`` mm³ joined at the neck in both). Below :data:`SELECT_LOSS` the taxel's (Helmholtz) peak is found
    at SELECT_LOSS and followed down to ``loss_factor``: an almost undamped wall mode rings as a sharp spike that can
    out-peak it on the grid (η = 0 on the paper's taxel gave 3033 Hz, a wall mode, for its 5288 Hz), though it is
    not the resonance the jet drives."""
    f = f_tl_hz * np.geomspace(*SWEEP[:2], SWEEP[2])
    geometry = (c_m_s, neck_area, cavity_area, neck_length_eff, cavity_length)
    losses = _losses(loss_factor)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # η = 0 exactly on a wall mode: C = ∞
        compliance = np.stack([dynamic_compliance_mm3_pa(f, wall, eta) for eta in losses])
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


def quasi_static_valid(wall: Modes, f_hz: float) -> bool:
    """True where every wall mode with volume coupling lies ≥ :data:`QUASI_STATIC_RATIO` × f."""
    coupled = wall.coupled_hz()
    return bool(len(coupled) == 0 or coupled.min() >= QUASI_STATIC_RATIO * f_hz)


def mode_near(wall: Modes, f_hz: float) -> float | None:
    """The coupled wall mode (Hz) nearest ``f_hz`` if it lies within :data:`HYBRID_BAND` of it, else None."""
    coupled = wall.coupled_hz()
    if not len(coupled):
        return None
    nearest = float(coupled[np.argmin(np.abs(coupled - f_hz))])
    return nearest if abs(nearest / f_hz - 1) <= HYBRID_BAND else None
