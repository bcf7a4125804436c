"""Test coupons that sweep the sizes that matter, so users can measure their own laser and printer.

Laser coupon (neck-plate sheet): a row of neck holes d − 0.2 … d + 0.2 mm and a row of dowel holes from pin
size up, each engraved with its finished size and cut with the spec's kerf compensation. Printed coupon
(mount process): needle bores and dowel holes swept around their fit, ascending left to right. Pick the
size that fits and feed the difference back (machine.laser_kerf, fasteners fits).
"""

from __future__ import annotations

from matcad.parts.flat import Engraving, Flat, Hole

NECK_SWEEP_MM = (-0.2, -0.15, -0.1, -0.05, 0.0, 0.05, 0.1, 0.15, 0.2)
DOWEL_SWEEP_MM = (0.0, 0.05, 0.1, 0.15, 0.2)
NEEDLE_SWEEP_MM = (-0.05, 0.0, 0.05, 0.1, 0.15, 0.2, 0.3)
PRINTED_DOWEL_SWEEP_MM = (-0.1, -0.05, 0.0, 0.05, 0.1, 0.2)
LABEL_MM = 1.2
MARGIN_MM = 3.0


def _row(sizes, y, pitch, purpose, x0):
    return [Hole(x0 + i * pitch, y, size, purpose) for i, size in enumerate(sizes)]


def laser_coupon(spec) -> Flat:
    """Flat coupon in the neck plate's sheet: neck and dowel sweeps with engraved sizes (mm)."""
    necks = [spec.neck.diameter + dx for dx in NECK_SWEEP_MM]
    dowels = [spec.fasteners.dowel_diameter + dx for dx in DOWEL_SWEEP_MM]
    pitch = max(necks[-1], dowels[-1]) + 2 * MARGIN_MM
    width = len(necks) * pitch + MARGIN_MM
    row_h = max(necks[-1], dowels[-1]) + LABEL_MM + 2 * MARGIN_MM
    depth = 2 * row_h
    x0 = -width / 2 + MARGIN_MM / 2 + pitch / 2
    holes = (_row(necks, row_h / 2 + LABEL_MM / 2, pitch, "neck", x0)
             + _row(dowels, -row_h / 2 + LABEL_MM / 2, pitch, "dowel", x0))
    labels = tuple(Engraving(h.x - 0.9 * LABEL_MM, h.y - h.diameter / 2 - 0.5 - LABEL_MM, LABEL_MM,
                             f"{h.diameter:.2f}") for h in holes)
    return Flat(name="coupon_laser", thickness=spec.neck.length, thickness_measured=spec.plate.thickness_measured,
                width=width, depth=depth, holes=tuple(holes), engrave=labels)


def printed_coupon_holes(spec) -> list[Hole]:
    """Needle bores and dowel holes of the printed coupon, ascending left to right (mm)."""
    needles = [spec.needle.outer_diameter + dx for dx in NEEDLE_SWEEP_MM]
    dowels = [spec.fasteners.dowel_diameter + dx for dx in PRINTED_DOWEL_SWEEP_MM]
    pitch = max(needles[-1], dowels[-1]) + 2 * MARGIN_MM
    x0 = -(len(needles) - 1) * pitch / 2
    row = max(needles[-1], dowels[-1]) / 2 + MARGIN_MM
    return _row(needles, row, pitch, "needle", x0) + _row(dowels, -row, pitch, "dowel", x0)


def printed_coupon(spec):
    """The printed coupon: a bar of mount thickness with the swept holes through it (mm)."""
    from build123d import Box

    from matcad.parts.solid import BOTTOM, cylinder_up

    holes = printed_coupon_holes(spec)
    width = max(h.x for h in holes) - min(h.x for h in holes) + 2 * (max(h.diameter for h in holes) + MARGIN_MM)
    depth = 2 * (max(abs(h.y) for h in holes) + max(h.diameter for h in holes) / 2 + MARGIN_MM)
    bar = Box(width, depth, spec.mount.thickness, align=BOTTOM)
    for h in holes:
        bar -= cylinder_up(h.diameter / 2, spec.mount.thickness, h.x, h.y)
    return bar
