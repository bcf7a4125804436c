"""Rules for the fipple tube (docs/tube.md): the supply's jet against the edge-tone window, the printed tube (walls,
windway, the mouth window's bridge and the labium's overhang with the bore vertical), and the cap's modes near the
tone. Each takes the spec and its :class:`matcad.prediction.tube.TubePrediction`."""

from __future__ import annotations

from matcad.acoustics import edgetone
from matcad.rules.finding import Finding
from matcad.rules.printing import FDM_OVERHANG_DEG, MIN_WALL_SLA_MM

FDM_BRIDGE_MAX_MM = 0.0
"""Longest bridge over the mouth window an FDM print of the tube spans without support: none. With the bore
vertical the labium's edge is a bridge of the windway's width, and PrusaSlicer's automatic supports fill it at the
template's 3.5 mm (453–458 mm³; 366 mm³ for a plain flat-topped window, docs/tube.md), where shop practice for PLA
would say 10 mm bridges: every printed part of a kit prints without support, so any window on FDM is flagged."""
SLA_WINDWAY_MIN_MM = 0.3
"""Narrowest slot an SLA print keeps open after washing (shop practice)."""


def edge_tone(spec, p) -> list[Finding]:
    """The supply's jet speed U = Q/(h B) against the first mode's edge-tone window (St 0.125-0.375)."""
    t = spec.tube
    u = edgetone.jet_speed_m_s(t.supply_flow_l_min, t.windway_height, t.windway_width)
    w1, w2 = p.windows
    flows = f"{w1.u_min_m_s * t.windway_height * t.windway_width * 0.06:.2f}-" \
            f"{w1.u_max_m_s * t.windway_height * t.windway_width * 0.06:.2f} L/min"
    if u > w1.u_max_m_s:
        level = "error"
        msg = (f"jet {u:.0f} m/s at {t.supply_flow_l_min:g} L/min is above mode 1's window "
               f"({w1.u_min_m_s:.0f}-{w1.u_max_m_s:.0f} m/s): the tube overblows toward {w2.f_hz:.0f} Hz")
    elif u < w1.u_min_m_s:
        level = "error"
        msg = (f"jet {u:.0f} m/s at {t.supply_flow_l_min:g} L/min is below mode 1's window "
               f"({w1.u_min_m_s:.0f}-{w1.u_max_m_s:.0f} m/s): the tube will not speak")
    else:
        return [Finding("tube.edge_tone", "info", round(u, 3), [round(w1.u_min_m_s, 3), round(w1.u_max_m_s, 3)],
                        f"jet {u:.0f} m/s at {t.supply_flow_l_min:g} L/min lies in mode 1's window "
                        f"({w1.u_min_m_s:.0f}-{w1.u_max_m_s:.0f} m/s, St = {w1.f_hz * t.edge_distance * 1e-3 / u:.2f}"
                        f"); it overblows above {w1.u_max_m_s:.0f} m/s")]
    return [Finding("tube.edge_tone", level, round(u, 3), [round(w1.u_min_m_s, 3), round(w1.u_max_m_s, 3)], msg,
                    f"set tube.supply_flow_l_min within {flows}, or change tube.edge_distance (U_opt = 4 f W)")]


def tube_print(spec, p) -> list[Finding]:
    """The printed tube, bore vertical: its wall, the windway slot, and for a fipple the window's bridge and the
    labium's overhang (a transverse mouth has neither)."""
    t, m = spec.tube, spec.machine
    out = []
    limit = 2 * m.nozzle if m.printer == "fdm" else MIN_WALL_SLA_MM
    if t.wall < limit:
        out.append(Finding("tube.wall", "error", t.wall, limit, f"tube.wall = {t.wall:g} mm is thinner than "
                           f"{limit:g} mm", f"raise tube.wall to >= {limit:g} mm"))
    slot = m.nozzle if m.printer == "fdm" else SLA_WINDWAY_MIN_MM
    if t.windway_height < slot:
        out.append(Finding("tube.windway", "error", t.windway_height, slot,
                           f"windway {t.windway_height:g} mm is narrower than the {m.printer} printer keeps open "
                           f"({slot:g} mm)", "raise tube.windway_height (and tube.edge_distance with it, W ~ 4 h)"))
    if t.mouth == "transverse":  # its edge is vertical: no bridge, no bevel (matcad.parts.tube.transverse_tube)
        return out
    if m.printer == "fdm" and t.windway_width > FDM_BRIDGE_MAX_MM:
        out.append(Finding("tube.window_bridge", "warning", t.windway_width, FDM_BRIDGE_MAX_MM,
                           f"the labium's edge is a {t.windway_width:g} mm bridge over the mouth window with the bore "
                           "vertical: the slicer fills the window, windway and needle seat with support (docs/tube.md)",
                           'set tube.mouth = "transverse" (prints without support), print on an SLA printer '
                           '(machine.printer = "sla"), or print with supports and clear the windway with a feeler '
                           "gauge"))
    if m.printer == "fdm" and t.edge_angle > FDM_OVERHANG_DEG:
        out.append(Finding("tube.labium_overhang", "warning", t.edge_angle, FDM_OVERHANG_DEG,
                           f"the labium's bevel overhangs {t.edge_angle:g} deg from vertical: FDM sags the edge",
                           f"set tube.edge_angle <= {FDM_OVERHANG_DEG:g} deg"))
    return out


def cap_modes(spec, p) -> list[Finding]:
    """A cap mode near the tone (from the prediction's notes): two resonances may compete."""
    return [Finding("tube.cap_mode", "warning", None, None, note,
                    "stiffen or thicken the cap (end_cap.top_thickness, silicone.grade) to move its modes away")
            for note in p.notes if note.startswith("a cap mode")]


RULES = (edge_tone, tube_print, cap_modes)
