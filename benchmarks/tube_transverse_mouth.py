"""A prototype, not a part: the tube with a transverse mouth, checked for printing without support (docs/tube.md).

With the bore vertical the fipple's edge is a horizontal bridge. A transverse mouth (the flute's arrangement) turns it:
the windway runs horizontally, tangential to the wall, in a boss from the bed up; the jet crosses a window in the
wall; the edge is the window's far side, vertical. The window's top is a 30°-from-vertical gable and the windway's top
is pointed at 30°. Two variants: the window's sides as high as the windway's rectangle (the windway's pointed top then
opens under the gable's foot), and raised by the pointed top's height. Prints, for each: the steepest downward face
(deg from vertical), the edges where material starts in mid-air (tests/test_tube_build.py), and PrusaSlicer's
support with automatic supports on (mm³). No labium wedge, no needle seat, no acoustics: geometry only.
Run: .venv/bin/python benchmarks/tube_transverse_mouth.py
"""

import math
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import numpy as np  # noqa: E402
import trimesh  # noqa: E402
from build123d import Box, Plane, Polygon, Pos, extrude  # noqa: E402

from benchmarks.tube_supports import sliced  # noqa: E402
from matcad.parts.solid import cylinder_up, frustum_up  # noqa: E402
from matcad.parts.tube import SEAT_CONE_DEG, SEAT_THICKNESS_MM, heights_mm  # noqa: E402
from matcad.spec import load  # noqa: E402
from tests.readback import hanging_edge_length_mm  # noqa: E402

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "acoustac-tube.toml"
WINDOW_BOTTOM_MM = 4.0


def transverse(spec, lift_sides: bool):
    t, z = spec.tube, heights_mm(spec)
    a, outer, seat_r = z["bore_radius"], z["outer_radius"], z["seat_radius"]
    h, b, w, zw = t.windway_height, t.windway_width, t.edge_distance, WINDOW_BOTTOM_MM
    slope = math.tan(math.radians(SEAT_CONE_DEG))
    body = cylinder_up(outer, z["cone_start"])
    body += frustum_up(outer, seat_r, z["top"] - SEAT_THICKNESS_MM - z["cone_start"], z=z["cone_start"])
    body += cylinder_up(seat_r, SEAT_THICKNESS_MM, z=z["top"] - SEAT_THICKNESS_MM)
    y0 = -w / 2
    boss_top = zw + b + 2.0
    body += Pos(2.75, (-8 + y0) / 2, boss_top / 2) * Box(3.0, 8 - y0, boss_top)  # carries the windway, from the bed
    body -= cylinder_up(a, z["top"], z=zw)
    body -= frustum_up(1e-3, a, a / slope, z=zw - a / slope)  # the bore's floor, a funnel
    point = (h / 2) / slope
    side = zw + b + (point if lift_sides else 0.0)
    window = Plane.YZ * Polygon((y0, zw), (y0 + w, zw), (y0 + w, side), (0, side + (w / 2) / slope), (y0, side),
                                align=None)
    body -= extrude(window, amount=outer + 3.0)
    windway = Plane.XZ * Polygon((a - h / 2, zw), (a + h / 2, zw), (a + h / 2, zw + b), (a, zw + b + point),
                                 (a - h / 2, zw + b), align=None)
    return body - extrude(windway, amount=9.0).moved(Pos(0, y0, 0))


def main():
    spec = load(TEMPLATE)
    with tempfile.TemporaryDirectory() as tmp:
        for lift in (False, True):
            solid = transverse(spec, lift)
            name = "lifted" if lift else "flush"
            support, top, volume = sliced(solid, spec, Path(tmp), name)
            mesh = trimesh.load_mesh(Path(tmp) / f"{name}.stl")
            down = mesh.face_normals[:, 2] < 0
            steepest = float(np.degrees(np.arcsin(np.clip(-mesh.face_normals[down & (mesh.triangles_center[:, 2]
                                                                                           > 1e-3), 2], 0, 1))).max())
            print(f"window sides {name:6s}: steepest downward face {steepest:4.1f} deg from vertical, hanging edges "
                  f"{ {float(k): round(v, 3) for k, v in hanging_edge_length_mm(mesh).items()} } (z: mm), support {support:6.1f} mm^3 (highest layer {top:.2f} mm)")


if __name__ == "__main__":
    main()
