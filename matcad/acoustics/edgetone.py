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
