"""The needle's jet against the taxel's pitch (Hz, mm, L/min, m/s): a MAT taxel is an edge-tone-driven resonator like
a flue, so a jet that crosses its neck too fast or too slowly for its pitch will not drive it (paper Sec. VI-B: flow
changes "can induce overblowing"). The only operating point known is the paper's; the window about it is the flue's
(:mod:`matcad.acoustics.edgetone`). Sources: docs/arrays.md."""

from __future__ import annotations

from matcad.acoustics import edgetone
from matcad.rules.finding import Finding


def limits(f0_hz, neck_diameter_mm, flow_l_min, needle_diameter_mm, speed_of_sound_m_s):
    """(St over the paper's, the jet speed that would match the paper's point (m/s), past Mach
    :data:`~matcad.acoustics.edgetone.MACH_LIMIT`?, outside :data:`~matcad.acoustics.edgetone.MAT_ST_SPAN`?) of
    one taxel or of arrays of variants."""
    import numpy as np

    ratio = edgetone.mat_strouhal_ratio(f0_hz, neck_diameter_mm, flow_l_min, needle_diameter_mm)
    u_matched = edgetone.needle_jet_speed_m_s(flow_l_min, needle_diameter_mm) * ratio  # St ∝ 1/U
    lo, hi = edgetone.MAT_ST_SPAN
    return (ratio, u_matched, np.asarray(u_matched) > edgetone.MACH_LIMIT * np.asarray(speed_of_sound_m_s),
            (np.asarray(ratio) < lo) | (np.asarray(ratio) > hi))


def jet_strouhal(spec, p) -> list[Finding]:
    """St = f0 d / U of the taxel's needle jet (:func:`matcad.acoustics.edgetone.mat_strouhal_ratio`) against the
    paper's operating point: info inside :data:`~matcad.acoustics.edgetone.MAT_ST_SPAN` of it, a warning outside
    (too fast a jet for the pitch: it may overblow; too slow: it may not speak), and a warning when the jet that
    would match the paper's point passes Mach :data:`~matcad.acoustics.edgetone.MACH_LIMIT` (the limit of the
    picture, reached when f d > 0.3 c St_paper). Each names the flow that matches the paper's point."""
    needle, d, c = spec.needle, spec.neck.diameter, p.speed_of_sound_m_s
    ratio, u_matched, fast_jet, outside = limits(p.f0_hz, d, needle.flow_l_min, needle.outer_diameter, c)
    u = edgetone.needle_jet_speed_m_s(needle.flow_l_min, needle.outer_diameter)
    matched = edgetone.matched_flow_l_min(p.f0_hz, d, needle.flow_l_min, needle.outer_diameter)
    lo, hi = edgetone.MAT_ST_SPAN
    where = (f"jet {u:.1f} m/s at {needle.flow_l_min:g} L/min through the {needle.outer_diameter:g} mm needle across "
             f"the {d:g} mm neck at {p.f0_hz:.0f} Hz: St {ratio:.2f} x the paper's operating point (4.0 kHz, "
             f"2.10 mm, 1.5 L/min); {matched:.2f} L/min ({u_matched:.1f} m/s) matches it")
    out = []
    if fast_jet:
        out.append(Finding("jet.strouhal", "warning", round(u_matched, 2), round(edgetone.MACH_LIMIT * c, 2),
                           f"{where}: above Mach {edgetone.MACH_LIMIT:g}, where the jet stops acting as an "
                           "incompressible edge tone; no measurement says such a taxel speaks",
                           "a narrower neck or a lower pitch for this taxel"))
    if outside:
        how = "too slow for its pitch: it may not speak" if ratio > hi else \
            "too fast for its pitch: it may overblow to a higher mode"
        out.append(Finding("jet.strouhal", "warning", round(ratio, 3), [lo, hi], f"{where}: the jet is {how} "
                           f"(the flue's ±50 % window on St about the paper's point, an assumption)",
                           f"set needle.flow_l_min (a board taxel's needle_flow_l_min) near {matched:.2f} L/min"))
    return out or [Finding("jet.strouhal", "info", round(ratio, 3), [lo, hi], where, "")]


def array_counts(f0_hz, neck_diameter_mm, flow_l_min, needle_diameter_mm, speed_of_sound_m_s) -> dict:
    """What :data:`RULES` find on arrays of variants: {(rule id, level): count per variant} (:func:`limits`)."""
    import numpy as np

    _, _, fast_jet, outside = limits(f0_hz, neck_diameter_mm, flow_l_min, needle_diameter_mm, speed_of_sound_m_s)
    return {("jet.strouhal", "warning"): fast_jet.astype(int) + outside.astype(int)}


RULES = (jet_strouhal,)
