"""Rules for the assembled stack: needle clearance and placement, fasteners in printed parts."""

from __future__ import annotations

import math

from matcad.parts.features import needle_tip_mm
from matcad.rules import Finding

PAPER_THETA_DEG = (30.0, 75.0)
PAPER_Y_MM = (0.0, 3.47)
"""The paper's tested window (Sec. II): outside it the taxel may not sound."""


def needle_clearance(spec) -> list[Finding]:
    n = spec.needle
    tip_z = needle_tip_mm(spec)[2]
    lowest_face = tip_z - n.outer_diameter / 2 * math.cos(math.radians(n.theta_deg))
    out = []
    if n.tip_clearance <= 0:
        out.append(Finding("needle.collision", "error", n.tip_clearance, "> 0",
                           "the needle end touches the neck plate", "set needle.tip_clearance > 0"))
    if lowest_face <= -spec.spacer.height:
        out.append(Finding("needle.collision", "error", round(-lowest_face, 4), spec.spacer.height,
                           f"the needle end reaches {-lowest_face:.2f} mm below the plate, into the mount "
                           f"(gap {spec.spacer.height:g} mm): it cannot stand in the gap",
                           "raise spacer.height or theta, or reduce needle.tip_clearance"))
    return out


def needle_window(spec) -> list[Finding]:
    out = []
    t, y = spec.needle.theta_deg, spec.needle.y
    if not PAPER_THETA_DEG[0] <= t <= PAPER_THETA_DEG[1]:
        out.append(Finding("needle.theta", "warning", t, list(PAPER_THETA_DEG),
                           f"theta = {t:g} deg is outside the paper's tested 30-75 deg; it may not sound",
                           "stay within 30-75 deg (paper chose 75)"))
    if not PAPER_Y_MM[0] <= y <= PAPER_Y_MM[1]:
        out.append(Finding("needle.y", "warning", y, list(PAPER_Y_MM),
                           f"y = {y:g} mm is outside the paper's tested 0-3.47 mm; it may not sound",
                           "stay within 0-3.47 mm"))
    return out


def printed_fits(spec) -> list[Finding]:
    if spec.fasteners.dowel_fit_printed == "clearance":
        return [Finding("fit.dowel_printed", "warning", "clearance", "slip | press",
                        "clearance-fit dowels in the mount do not locate the stack", "use 'press' or 'slip'")]
    return []


RULES = (needle_clearance, needle_window, printed_fits)
