"""Rules for the assembled stack: needle clearance and placement, fasteners in printed parts."""

from __future__ import annotations

from matcad.parts.features import needle_tip_mm
from matcad.rules import Finding

PAPER_THETA_DEG = (30.0, 75.0)
PAPER_Y_MM = (0.0, 3.47)
"""The paper's tested window (Sec. II): outside it the taxel may not sound."""


def needle_clearance(spec) -> list[Finding]:
    """The needle end must not touch the plate, and must still be held by the mount (the bore runs along
    the whole axis, so a tip standing inside the bore still has a clear jet path)."""
    n = spec.needle
    out = []
    if n.tip_clearance <= 0:
        out.append(Finding("needle.collision", "error", n.tip_clearance, "> 0",
                           "the needle end touches the neck plate", "set needle.tip_clearance > 0"))
    tip_z = needle_tip_mm(spec)[2]
    bottom = -(spec.spacer.height + spec.mount.thickness)
    if tip_z <= bottom:
        out.append(Finding("needle.collision", "error", round(-tip_z, 4), round(-bottom, 4),
                           f"the needle tip sits {-tip_z:.2f} mm below the plate, under the mount: nothing "
                           "holds it", "reduce needle.tip_clearance or raise theta"))
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
