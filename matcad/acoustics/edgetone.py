"""The fipple's edge-tone operating window: which jet speeds make a flue tube speak in its first mode, and where it
overblows into the next. Speeds m/s, lengths mm, flows L/min, pressures Pa. Sources: docs/tube.md.

A jet leaving the windway is deflected by the tube's sound; the deflection travels down the jet at about half the
jet's speed U (Cremer & Ising 1967; Fletcher 1976, JASA 60:926; Fletcher & Rossing 1998, "The Physics of Musical
Instruments", §16.3 and §17.3-17.4). The tube is driven when that travel over the edge distance W takes about half
a period, i.e. at a Strouhal number St = f W / U near :data:`ST_OPTIMUM`; the phase condition is met well enough
for St within :data:`ST_WINDOW` (jet delay between a quarter and three quarters of a period). A faster jet lowers
St: below the window's lower end the first mode stops and the tube overblows into the next mode (for a closed-open
tube about 3 f1), whose St is three times higher. The window is a design rule of thumb (±50 % on St), not a
prediction of the sounding threshold; the flow that a real fipple needs also depends on h/W and the edge's offset.
"""

from __future__ import annotations

from dataclasses import dataclass

AIR_DENSITY_KG_M3 = 1.2
ST_OPTIMUM = 0.25
"""Half a period of jet delay with the jet's waves at 0.5 U: f W / (0.5 U) = 1/2."""
ST_WINDOW = (0.125, 0.375)
"""A quarter to three quarters of a period of jet delay."""


@dataclass(frozen=True)
class Window:
    """The jet speeds (m/s) that drive one mode of frequency ``f_hz``: lowest (St at the window's top), optimum and
    highest (beyond which the tube overblows); the windway's flow (L/min) and the Bernoulli blowing pressure (Pa)
    at the optimum."""

    mode: int
    f_hz: float
    u_min_m_s: float
    u_optimum_m_s: float
    u_max_m_s: float
    flow_optimum_l_min: float
    pressure_optimum_pa: float

    def speaks(self, u_m_s: float) -> bool:
        return self.u_min_m_s <= u_m_s <= self.u_max_m_s


def jet_speed_m_s(flow_l_min: float, windway_height_mm: float, windway_width_mm: float) -> float:
    """The mean jet speed (m/s) of a flow (L/min) through a windway of h × B (mm): U = Q / (h B)."""
    return flow_l_min / 60e3 / (windway_height_mm * windway_width_mm * 1e-6)


def window(f_hz: float, mode: int, edge_distance_mm: float, windway_height_mm: float,
           windway_width_mm: float) -> Window:
    """The edge-tone window of a mode at ``f_hz`` for an edge ``edge_distance_mm`` (W) from a windway of
    h × B (mm): U = f W / St over :data:`ST_WINDOW`, optimum at :data:`ST_OPTIMUM`."""
    w_m = edge_distance_mm * 1e-3
    u_opt = f_hz * w_m / ST_OPTIMUM
    area_m2 = windway_height_mm * windway_width_mm * 1e-6
    return Window(mode=mode, f_hz=f_hz, u_min_m_s=f_hz * w_m / ST_WINDOW[1], u_optimum_m_s=u_opt,
                  u_max_m_s=f_hz * w_m / ST_WINDOW[0], flow_optimum_l_min=u_opt * area_m2 * 60e3,
                  pressure_optimum_pa=0.5 * AIR_DENSITY_KG_M3 * u_opt**2)


# --- the MAT taxel's needle jet ------------------------------------------------------------------------------------

PAPER_JET = {"f_hz": 4000.0, "neck_diameter_mm": 2.10, "flow_l_min": 1.5, "needle_diameter_mm": 1.52}
"""The one operating point a MAT taxel is known to sing at (paper Sec. II and IV): ~4.0 kHz measured, a 2.10 mm
neck, about 1.5 L/min through a 1.52 mm needle 2.10 mm from the orifice at 75°, a combination the authors chose
by sweeping distance and angle for signal clarity and strength."""
MAT_ST_SPAN = (ST_WINDOW[0] / ST_OPTIMUM, ST_WINDOW[1] / ST_OPTIMUM)
"""A MAT taxel's Strouhal window relative to the paper's operating point: the flue's ±50 % on St
(:data:`ST_WINDOW` about :data:`ST_OPTIMUM`) carried over, centred on the paper's point — an assumption (the paper
reports one point, chosen for the strongest, clearest tone, not the range over which the taxel speaks)."""
MACH_LIMIT = 0.3
"""Jet Mach number above which the edge-tone picture (an incompressible jet) and a needle's steady flow no longer
hold (the usual incompressibility bound, |Δρ/ρ| ≈ M²/2 ≈ 5 %)."""


def needle_jet_speed_m_s(flow_l_min: float, needle_diameter_mm: float) -> float:
    """The mean jet speed (m/s) of a flow (L/min) out of a needle of diameter ``needle_diameter_mm`` taken as its
    bore: U = Q / (π d² / 4). The paper gives one needle diameter; a needle's bore is smaller than its outside, but
    St relative to the paper's (:func:`mat_strouhal_ratio`) does not depend on which is used as long as the needle
    has the paper's bore-to-outside ratio."""
    import math

    return flow_l_min / 60e3 / (math.pi / 4 * (needle_diameter_mm * 1e-3) ** 2)


def mat_strouhal(f_hz: float, neck_diameter_mm: float, flow_l_min: float, needle_diameter_mm: float) -> float:
    """St = f d / U of a MAT taxel at ``f_hz`` whose neck (d, mm) the needle's jet (:func:`needle_jet_speed_m_s`)
    crosses."""
    return f_hz * neck_diameter_mm * 1e-3 / needle_jet_speed_m_s(flow_l_min, needle_diameter_mm)


def mat_strouhal_ratio(f_hz: float, neck_diameter_mm: float, flow_l_min: float, needle_diameter_mm: float) -> float:
    """A MAT taxel's St over the paper's (:data:`PAPER_JET`): 1 at the paper's operating point; St ∝ f d D² / Q,
    so the ratio is free of the bore-or-outside question (:func:`needle_jet_speed_m_s`)."""
    return mat_strouhal(f_hz, neck_diameter_mm, flow_l_min, needle_diameter_mm) / mat_strouhal(**PAPER_JET)


def matched_flow_l_min(f_hz: float, neck_diameter_mm: float, flow_l_min: float, needle_diameter_mm: float) -> float:
    """The flow (L/min) that puts a MAT taxel's jet at the paper's operating point, from its flow now: St ∝ 1/Q, so
    ``flow_l_min`` times :func:`mat_strouhal_ratio`."""
    return flow_l_min * mat_strouhal_ratio(f_hz, neck_diameter_mm, flow_l_min, needle_diameter_mm)
