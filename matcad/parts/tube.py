"""The printed fipple tube of a ``kind = "tube"`` spec (docs/tube.md), built in its print pose: bore vertical, the
block on the bed. Lengths mm.

From the bed up: the block (z 0 → ``block_length``) with the supply needle's seat (a hole from the bed face, closed
by a 30°-from-vertical cone, not a flat ceiling) feeding the windway, a slot h × B centred on the bore's wall line;
the mouth window (z ``block_length`` → ``block_length`` + W) cut through the wall over the windway's width; above it
the labium, the wall's edge at the bore's wall line bevelled outward at ``edge_angle`` from vertical; the bore
(``length`` from the edge); the cap's seat, a flange of the cap flange's diameter reached by a 30°-from-vertical
cone so that nothing overhangs more than the FDM limit. The one thing that starts in mid-air is the labium's tip, a
bridge B long over the window (docs/tube.md: why, and what the slicer makes of it). The cap (the MAT cap, its cavity
the bore continued) is glued on the seat's face.

Not a registered part (:mod:`matcad.parts.registry`): its flag would enter every MAT spec's [outputs] and change
their outputs; the tube kit lists its parts in :mod:`matcad.tube_build`.
"""

from __future__ import annotations

import math

from matcad.parts.solid import cylinder_up, frustum_up
from matcad.spec import cap_flange_diameter_mm
from matcad.spec.tube import EDGE_LAND_MM, SEAT_CONE_DEG, transverse_floor_mm, transverse_window_mm

SEAT_THICKNESS_MM = 1.5
NEEDLE_SEAT_DEPTH_FRACTION = 0.5
"""The needle's seat reaches this fraction of the block; the windway runs the rest."""


def heights_mm(spec) -> dict:
    """z of the tube's levels in its print pose (mm): the window's bottom (``windway_exit``), where the air column
    starts (``edge``: the fipple's edge, a transverse window's sides' top, :func:`transverse_tube`), the seat's cone,
    the top."""
    t = spec.tube
    a, outer = t.bore_diameter / 2, t.bore_diameter / 2 + t.wall
    seat_r = cap_flange_diameter_mm(spec) / 2
    if t.mouth == "transverse":
        exit_ = transverse_floor_mm(a, t.wall)
        edge = exit_ + transverse_window_mm(t.windway_height, t.windway_width, t.edge_distance)[0]
    else:
        exit_, edge = t.block_length, t.block_length + t.edge_distance
    top = edge + t.length
    cone = max(seat_r - outer, 0.0) / math.tan(math.radians(SEAT_CONE_DEG))
    return {"windway_exit": exit_, "edge": edge, "cone_start": top - SEAT_THICKNESS_MM - cone,
            "top": top, "bore_radius": a, "outer_radius": outer, "seat_radius": seat_r}


def seat_taper_mm(spec) -> float:
    """Height of the cone that closes the needle's seat into the windway (mm): from the needle's radius to a
    quarter of the windway's height (inside the slot, so no face is tangent to it) at :data:`SEAT_CONE_DEG` from
    vertical; 0 when the needle is no wider than the slot."""
    needle_r, h = spec.needle.outer_diameter / 2, spec.tube.windway_height
    return max(needle_r - h / 4, 0.0) / math.tan(math.radians(SEAT_CONE_DEG)) if needle_r > h / 2 else 0.0


def fipple_tube(spec):
    """The tube's solid (build123d) in its print pose (mm): block on the bed (z = 0), bore vertical and open upward
    (no roof to bridge; the other pose, block on top, closes the bore under a roof PrusaSlicer supports from the
    bed up the whole bore, where support cannot be removed). The bore's floor on the block is a 30° funnel."""
    from build123d import Box, Plane, Polygon, Pos, extrude

    t = spec.tube
    z = heights_mm(spec)
    a, outer = z["bore_radius"], z["outer_radius"]
    body = _shell(spec, z) - cylinder_up(a, z["top"] - t.block_length, z=t.block_length)  # the bore, on the block
    roof = a / math.tan(math.radians(SEAT_CONE_DEG))  # the block's face under the bore: a funnel
    body -= frustum_up(1e-3, a, roof, z=t.block_length - roof)
    h, b = t.windway_height, t.windway_width
    seat_depth = NEEDLE_SEAT_DEPTH_FRACTION * t.block_length
    needle_r = spec.needle.outer_diameter / 2
    body -= cylinder_up(needle_r, seat_depth, x=a)  # the needle's seat, from the bed
    if needle_r > h / 2:  # its ceiling: a cone at the FDM limit into the windway, not a flat roof (docs/tube.md)
        body -= frustum_up(needle_r, h / 4, seat_taper_mm(spec), x=a, z=seat_depth)
    body -= Pos(a, 0, seat_depth / 2 + t.block_length / 2) * Box(h, b, t.block_length - seat_depth + 1e-3)
    # the window, from the axis (inside the bore for |y| < B/2 <= a: no face tangent to it) out through the wall;
    # not from beyond the axis, where it would nick the far wall and leave a flat sliver of ceiling there
    window_h = t.edge_distance
    body -= Pos((outer + 1.0) / 2, 0, t.block_length + window_h / 2) * Box(outer + 1.0, b, window_h)
    # the labium: above the window, the wall outside the plane through the edge (x = a, z = edge) tilted edge_angle
    # from vertical is cut away over the window's width; the bevel's underside overhangs edge_angle
    reach, tip = outer + 1.0, a + EDGE_LAND_MM
    rise = (reach - tip) / math.tan(math.radians(t.edge_angle))
    bevel = Plane.XZ * Polygon((tip, z["edge"]), (reach, z["edge"]), (reach, z["edge"] + rise), align=None)
    # and inside, the bore's curved wall over the window's width cut back to the same tip at the FDM limit from
    # vertical: the labium is a wedge with a straight tip, and no ceiling wider than its land is left over the window
    inner_rise = tip / math.tan(math.radians(SEAT_CONE_DEG))
    inner = Plane.XZ * Polygon((tip, z["edge"]), (0.0, z["edge"]), (0.0, z["edge"] + inner_rise), align=None)
    body = body - extrude(bevel, amount=b / 2, both=True) - extrude(inner, amount=b / 2, both=True)
    return body


def tube_solid(spec):
    """The printed tube of ``spec`` in its print pose (build123d, mm): :func:`transverse_tube` for a transverse
    mouth, else :func:`fipple_tube` (the flanged and unflanged mouths are its edge-blown window, docs/tube.md)."""
    return transverse_tube(spec) if spec.tube.mouth == "transverse" else fipple_tube(spec)


def _shell(spec, z: dict):
    """The tube's outside (mm): the wall's cylinder from the bed, the seat's cone, the seat."""
    outer, seat_r = z["outer_radius"], z["seat_radius"]
    body = cylinder_up(outer, z["cone_start"])
    body += frustum_up(outer, seat_r, z["top"] - SEAT_THICKNESS_MM - z["cone_start"], z=z["cone_start"])
    return body + cylinder_up(seat_r, SEAT_THICKNESS_MM, z=z["top"] - SEAT_THICKNESS_MM)


def _teardrop(radius: float, length: float):
    """A horizontal hole of ``radius`` with a pointed top (its sides tangent at :data:`SEAT_CONE_DEG` from
    vertical, the apex 2r above the axis at 30°): a solid along −y from y = 0, its axis at x = z = 0 (mm)."""
    from build123d import Circle, Plane, Polygon, extrude

    half = math.radians(SEAT_CONE_DEG)
    apex = radius / math.sin(half)
    roof = Polygon((-radius * math.cos(half), radius * math.sin(half)), (radius * math.cos(half),
                   radius * math.sin(half)), (0.0, apex), align=None)
    return extrude(Plane.XZ * Circle(radius), amount=length) + extrude(Plane.XZ * roof, amount=length)


def transverse_tube(spec):
    """The tube with a transverse mouth (the flute's arrangement) in its print pose (mm): bore vertical, open
    upward, its floor a funnel (:func:`matcad.spec.tube.transverse_floor_mm`). The window is cut through the wall on
    +x, W wide along y and as high as the windway's width B plus the rise of its pointed top, under a gable roof at
    30° from vertical (:func:`matcad.spec.tube.transverse_window_mm`). The windway (h along x, B along z, a pointed
    top) runs along +y, centred on the bore's wall line x = a, through a boss built from the bed beside the tube
    (``block_length`` long), from the needle's horizontal seat (a teardrop, its top pointed) at the boss's far end to
    the window's upstream side; its jet crosses the window and strikes the far side, the edge: vertical, the wall's
    full thickness, as a transverse flute's embouchure hole. Nothing overhangs more than 30° from vertical and
    nothing starts in mid-air, so PrusaSlicer's automatic supports add none (docs/tube.md, the kit)."""
    from build123d import Box, Plane, Polygon, Pos, extrude

    t = spec.tube
    z = heights_mm(spec)
    a, outer = z["bore_radius"], z["outer_radius"]
    h, b, w, floor = t.windway_height, t.windway_width, t.edge_distance, z["windway_exit"]
    sides, gable = transverse_window_mm(h, b, w)
    needle_r = spec.needle.outer_diameter / 2
    y0, seat_depth = -w / 2, NEEDLE_SEAT_DEPTH_FRACTION * t.block_length
    centre = floor + b / 2  # the needle's axis, at the windway's mid-height
    boss_top = max(floor + sides, centre + 2 * needle_r) + t.wall
    boss_x = (a - needle_r - t.wall, a + needle_r + t.wall)
    body = _shell(spec, z)
    body += Pos(sum(boss_x) / 2, y0 - t.block_length / 2, boss_top / 2) * Box(boss_x[1] - boss_x[0], t.block_length,
                                                                              boss_top)
    body -= cylinder_up(a, z["top"] - floor, z=floor)  # the bore
    roof = a / math.tan(math.radians(SEAT_CONE_DEG))
    body -= frustum_up(1e-3, a, roof, z=floor - roof)  # its floor, a funnel
    window = Plane.YZ * Polygon((y0, floor), (-y0, floor), (-y0, floor + sides), (0.0, floor + sides + gable),
                                (y0, floor + sides), align=None)
    body -= extrude(window, amount=outer + 1.0)  # from the axis out through the wall on +x
    point = h / 2 / math.tan(math.radians(SEAT_CONE_DEG))
    windway = Plane.XZ * Polygon((a - h / 2, floor), (a + h / 2, floor), (a + h / 2, floor + b),
                                 (a, floor + b + point), (a - h / 2, floor + b), align=None)
    body -= extrude(windway, amount=t.block_length - seat_depth + 1e-3).moved(Pos(0, y0, 0))
    return body - _teardrop(needle_r, seat_depth + 1e-3).moved(Pos(a, y0 - t.block_length + seat_depth, centre))
