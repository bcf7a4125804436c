"""Test coupons that sweep the sizes that matter, so users can measure their own laser and printer.

Laser coupons, one per sheet, each cut with that sheet's kerf: the neck plate's sheet (and a riser's) sweeps neck
holes d − 0.2 … d + 0.2 mm and dowel holes, the guide sheet dowel and bolt holes, the spacer sheet bolt holes; every
hole engraved with its finished size. Printed coupon (mount process): needle bores at the needle's real angle θ
and vertical dowel holes swept around their fit, ascending left to right. Pick the size that fits and feed the
difference back (<sheet>.laser_kerf, fasteners fits).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

from matcad.parts.features import bolt_clearance_mm, sheet_kerf_mm, sheet_thickness_mm
from matcad.parts.flat import Engraving, Flat, Hole, engraving_outlines
from matcad.parts.print_profile import FDM_MAX_OVERHANG_DEG
from matcad.parts.registry import Kind, PrintPose, parts

if TYPE_CHECKING:
    from matcad.spec import Spec

NECK_SWEEP_MM = (-0.2, -0.15, -0.1, -0.05, 0.0, 0.05, 0.1, 0.15, 0.2)
DOWEL_SWEEP_MM = (0.0, 0.05, 0.1, 0.15, 0.2)
NEEDLE_SWEEP_MM = (-0.05, 0.0, 0.05, 0.1, 0.15, 0.2, 0.3)
PRINTED_DOWEL_SWEEP_MM = (-0.1, -0.05, 0.0, 0.05, 0.1, 0.2)
LABEL_MM = 1.2
MARGIN_MM = 3.0
PRINTED_LABEL_MM = 2.0
"""Cap height of the printed coupon's size labels (mm). DejaVu Sans strokes are roughly 0.09 em, so about
0.25 mm wide at this size (estimate, not measured): narrower than a 0.4 mm nozzle's line; not yet checked in a
slicer that the recessed strokes survive."""
PRINTED_ENGRAVE_MM = 0.4
"""Depth of the printed labels: two 0.2 mm layers."""
LABEL_GAP_MM = 1.0


BOLT_SWEEP_MM = (-0.2, -0.1, 0.0, 0.1, 0.2)
PRINTED_COUPON_POSE = PrintPose(0.0, "flat underside")
"""How coupon_printed.stl is exported."""
SHEET_ROWS = {"plate": ("neck", "dowel"), "riser": ("neck", "dowel"), "guide": ("dowel", "bolt"), "spacer": ("bolt",)}
"""Which fits each sheet's coupon sweeps: the holes that sheet really carries."""


def _row(sizes: Sequence[float], y: float, pitch: float, purpose: str, x0: float) -> list[Hole]:
    return [Hole(x0 + i * pitch, y, size, purpose) for i, size in enumerate(sizes)]


def _sweep(spec: Spec, purpose: str) -> list[float]:
    if purpose == "neck":
        return [spec.neck.diameter + dx for dx in NECK_SWEEP_MM]
    if purpose == "dowel":
        return [spec.fasteners.dowel_diameter + dx for dx in DOWEL_SWEEP_MM]
    return [bolt_clearance_mm(spec.fasteners.bolt, spec.fasteners.bolt_fit) + dx for dx in BOLT_SWEEP_MM]


def coupon_sheets(spec: Spec) -> list[str]:
    """The sheets (keys of features.SHEETS) the kit cuts: one laser coupon each."""
    sheets = [p.sheet for p in parts() if p.kind is Kind.LASER and (p.when is None or p.when(spec))]
    return list(dict.fromkeys(sheets))


def laser_coupon(spec: Spec, sheet: str = "plate") -> Flat:
    """Flat coupon cut from ``sheet`` with that sheet's kerf: a row per fit it carries, each hole engraved with
    its finished size (mm)."""
    rows = [_sweep(spec, purpose) for purpose in SHEET_ROWS[sheet]]
    biggest = max(max(r) for r in rows)
    pitch = biggest + 2 * MARGIN_MM
    width = max(len(r) for r in rows) * pitch + MARGIN_MM
    row_h = biggest + LABEL_MM + 2 * MARGIN_MM
    depth = len(rows) * row_h
    x0 = -width / 2 + MARGIN_MM / 2 + pitch / 2
    holes = []
    for i, (purpose, sizes) in enumerate(zip(SHEET_ROWS[sheet], rows)):
        y = depth / 2 - (i + 0.5) * row_h + LABEL_MM / 2
        holes += _row(sizes, y, pitch, purpose, x0)
    labels = tuple(Engraving(h.x - 0.9 * LABEL_MM, h.y - h.diameter / 2 - 0.5 - LABEL_MM, LABEL_MM,
                             f"{h.diameter:.2f}") for h in holes)
    thickness, measured = sheet_thickness_mm(spec, sheet)
    return Flat(name=f"coupon_{sheet}", thickness=thickness, thickness_measured=measured, sheet=sheet,
                thickness_example=getattr(spec, sheet).thickness_example,
                kerf=sheet_kerf_mm(spec, sheet), width=width, depth=depth, holes=tuple(holes), engrave=labels)


def printed_coupon_holes(spec: Spec) -> list[Hole]:
    """Needle bores and dowel holes of the printed coupon, ascending left to right (mm)."""
    needles = [spec.needle.outer_diameter + dx for dx in NEEDLE_SWEEP_MM]
    dowels = [spec.fasteners.dowel_diameter + dx for dx in PRINTED_DOWEL_SWEEP_MM]
    pitch = max(needles[-1], dowels[-1]) + 2 * MARGIN_MM
    x0 = -(len(needles) - 1) * pitch / 2
    row = max(needles[-1], dowels[-1]) / 2 + MARGIN_MM
    return _row(needles, row, pitch, "needle", x0) + _row(dowels, -row, pitch, "dowel", x0)


def _drift_mm(spec: Spec) -> float:
    """How far a needle bore at θ travels in x through the coupon bar (mm)."""
    import math

    return spec.mount.thickness / math.tan(math.radians(spec.needle.theta_deg))


def printed_coupon_labels(spec: Spec) -> list[Engraving]:
    """Each printed hole's finished size (mm, 2 decimals), centred on the hole's mouth in the bar's top face:
    above the needle row, below the dowel row, :data:`LABEL_GAP_MM` clear of the widest hole, capitals
    :data:`PRINTED_LABEL_MM` tall."""
    holes = printed_coupon_holes(spec)
    reach = max(h.diameter for h in holes) / 2 + LABEL_GAP_MM
    labels = []
    for h in holes:
        text = f"{h.diameter:.2f}"
        xs = [x for poly in engraving_outlines(Engraving(0.0, 0.0, PRINTED_LABEL_MM, text)) for x, _ in poly]
        mouth = h.x + (_drift_mm(spec) if h.purpose == "needle" else 0.0)
        y0 = h.y + reach if h.y > 0 else h.y - reach - PRINTED_LABEL_MM
        labels.append(Engraving(mouth - (min(xs) + max(xs)) / 2, y0, PRINTED_LABEL_MM, text))
    return labels


def printed_coupon(spec: Spec, labelled: bool = True):
    """The printed coupon: a bar of mount thickness; needle bores at the needle's θ (as in the mount, so a bore
    that passes here passes there: a tilted printed bore comes out smaller than a vertical one), dowel holes
    vertical as in the mount; each size recessed :data:`PRINTED_ENGRAVE_MM` into the top face (printed face up,
    no support) unless ``labelled`` is False (mm)."""
    import math

    from build123d import Box, Pos

    from matcad.parts.solid import BOTTOM, cylinder_up, engraved, tilted_cylinder

    holes = printed_coupon_holes(spec)
    t = spec.mount.thickness
    theta = math.radians(spec.needle.theta_deg)
    drift = _drift_mm(spec)
    half = (t / 2 + 1.0) / math.sin(theta)  # half-length along the axis, 1 mm past each face
    width = (max(h.x for h in holes) - min(h.x for h in holes) + drift
             + 2 * (max(h.diameter for h in holes) / math.sin(theta) + MARGIN_MM))
    depth = 2 * (max(abs(h.y) for h in holes) + max(h.diameter for h in holes) / 2 + LABEL_GAP_MM
                 + PRINTED_LABEL_MM + MARGIN_MM)
    bar = Pos(drift / 2, 0, 0) * Box(width, depth, t, align=BOTTOM)
    for h in holes:
        if h.purpose == "needle":
            centre = (h.x + drift / 2, h.y, t / 2)
            end = (centre[0] + half * math.cos(theta), h.y, t / 2 + half * math.sin(theta))
            bar -= tilted_cylinder(h.diameter / 2, 2 * half, end, spec.needle.theta_deg)
        else:
            bar -= cylinder_up(h.diameter / 2, t, h.x, h.y)
    if labelled:
        bar = bar.cut(*engraved(printed_coupon_labels(spec), t, PRINTED_ENGRAVE_MM))
    return bar


Y_SWEEP_MM = (0.0, 0.87, 1.74, 2.6, 3.47)
"""Needle offsets y the trial set spans: the paper's tested window 0–3.47 mm (Sec. II) in four steps."""
THETA_WINDOW_DEG = (30.0, 75.0)
"""Needle angles θ the paper tested (Sec. II), deg."""
THETA_STEPS = 5
FDM_THETA_MIN_DEG = 90.0 - FDM_MAX_OVERHANG_DEG
"""Lowest needle angle θ (deg) whose bore FDM prints without support, and so the lowest θ of the FDM trial set and
the ``print.bore_overhang`` rule's limit: 60°, a bore ceiling overhanging
:data:`matcad.parts.print_profile.FDM_MAX_OVERHANG_DEG` = 30° from vertical."""
NOTCH_MM = 1.0


def theta_sweep_deg(spec: Spec) -> tuple[float, ...]:
    """θ values (deg) of the trial set: :data:`THETA_STEPS` evenly over the paper's window 30–75° (Sec. II), cut
    to what the spec's printer makes without support: an FDM bore's ceiling overhangs 90° − θ from vertical, and a
    slicer supports it below :data:`FDM_THETA_MIN_DEG` = 60°, so FDM spans 60–75°; SLA spans 30–75°."""
    lo, hi = THETA_WINDOW_DEG
    if spec.machine.printer == "fdm":
        lo = max(lo, FDM_THETA_MIN_DEG)
    return tuple(round(lo + (hi - lo) * i / (THETA_STEPS - 1), 4) for i in range(THETA_STEPS))


def needle_sweeps(spec: Spec) -> dict[str, tuple[tuple[float, ...], int]]:
    """The trial sets `matcad coupon` prints: needle field → (values, notch edge: +1 = +x, −1 = −x). y over
    :data:`Y_SWEEP_MM` at the spec's θ; θ over :func:`theta_sweep_deg` at the spec's y (mm, deg)."""
    return {"y": (Y_SWEEP_MM, 1), "theta_deg": (theta_sweep_deg(spec), -1)}


def needle_sweep_mounts(spec: Spec, field: str, values: Sequence[float],
                        edge: int = 1) -> dict[str, tuple[float, object]]:
    """A set of needle mounts, one per value of needle ``field`` (``"y"`` mm or ``"theta_deg"`` deg), the rest as
    in the spec, to print together and try on the same plate: file stem → (value, solid). Mount i carries i + 1
    notches on its ``edge`` × x edge (+1: +x, −1: −x), so neither a set's members nor the sets can be mixed up;
    the coupon report lists which is which. Notches sit 3 mm apart on the half-pitch grid, never on the needle
    plane y = 0, where a low-θ bore leaves the block through its −x face."""
    import dataclasses
    import math

    from build123d import Box, Pos

    from matcad.parts.needle_mount import needle_mount
    from matcad.parts.solid import TOP

    out = {}
    for i, value in enumerate(values):
        trial = dataclasses.replace(spec, needle=dataclasses.replace(spec.needle, **{field: value}))
        mount = needle_mount(trial)
        top = -spec.spacer.height
        notches = [Pos(edge * spec.plate.width / 2, (k - math.ceil(i / 2) + 0.5) * 3 * NOTCH_MM, top)
                   * Box(2 * NOTCH_MM, NOTCH_MM, spec.mount.thickness, align=TOP) for k in range(i + 1)]
        out[f"needle_mount_{field.removesuffix('_deg')}{value:.2f}"] = (value, mount.cut(*notches))
    return out
