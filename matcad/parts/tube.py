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
from matcad.spec.tube import EDGE_LAND_MM, SEAT_CONE_DEG

SEAT_THICKNESS_MM = 1.5
NEEDLE_SEAT_DEPTH_FRACTION = 0.5
"""The needle's seat reaches this fraction of the block; the windway runs the rest."""


def heights_mm(spec) -> dict:
    """z of the tube's levels in its print pose (mm): window bottom (windway exit), edge, seat cone, top."""
    t = spec.tube
    a, outer = t.bore_diameter / 2, t.bore_diameter / 2 + t.wall
    seat_r = cap_flange_diameter_mm(spec) / 2
    edge = t.block_length + t.edge_distance
    top = edge + t.length
    cone = max(seat_r - outer, 0.0) / math.tan(math.radians(SEAT_CONE_DEG))
    return {"windway_exit": t.block_length, "edge": edge, "cone_start": top - SEAT_THICKNESS_MM - cone,
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
    a, outer, seat_r = z["bore_radius"], z["outer_radius"], z["seat_radius"]
    body = cylinder_up(outer, z["cone_start"])
    body += frustum_up(outer, seat_r, z["top"] - SEAT_THICKNESS_MM - z["cone_start"], z=z["cone_start"])
    body += cylinder_up(seat_r, SEAT_THICKNESS_MM, z=z["top"] - SEAT_THICKNESS_MM)
    body -= cylinder_up(a, z["top"] - t.block_length, z=t.block_length)  # the bore, closed below by the block
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
