"""Which parts a spec asks for. Laser parts are plain data; 3-D parts load build123d only when asked."""

from __future__ import annotations

import math
from dataclasses import dataclass

from matcad.parts.flat import Flat
from matcad.parts.guide import ROLES, guide
from matcad.parts.neck_plate import neck_plate
from matcad.parts.spacer import spacer


def laser_parts(spec) -> list[Flat]:
    """Every laser part ``[outputs]`` asks for (design intent, finished sizes)."""
    parts = []
    if spec.outputs.neck_plate:
        parts.append(neck_plate(spec))
    if spec.outputs.guides:
        parts += [guide(spec, role) for role in ROLES]
    if spec.outputs.spacers and spec.spacer.style == "laser":
        parts.append(spacer(spec))
    return parts


@dataclass(frozen=True)
class PrintPose:
    """How a 3-D part is exported: rotated ``rx_deg`` about x from its design frame, then lifted so its lowest
    point is z = 0 (the bed). ``bed_face`` names the face that lies on the bed, ``printed`` is False for the
    cast silicone cap (a reference shape, not a print)."""

    rx_deg: float
    bed_face: str
    printed: bool = True

    def matrix(self, z_min_rotated: float) -> list[list[float]]:
        """4 x 4 transform from the design frame to the exported (print) frame (mm)."""
        c, s = (round(f(math.radians(self.rx_deg)), 12) + 0.0 for f in (math.cos, math.sin))  # exact for 180°
        return [[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, 0.0], [0.0, s, c, -z_min_rotated], [0.0, 0.0, 0.0, 1.0]]


PRINT_POSES = {
    "end_cap": PrintPose(0.0, "base (the sealing face), cavity opening down: cast, not printed", printed=False),
    "end_cap_mold_base": PrintPose(0.0, "flat underside; cap cavities and keys face up"),
    "end_cap_mold_lid": PrintPose(180.0, "outer (top) face; core pins point up, the parting face prints last"),
    "needle_mount": PrintPose(0.0, "flat underside; standoffs and the needle bore's mouth face up"),
    "coupon_printed": PrintPose(0.0, "flat underside"),
}
"""Print orientation of every exported 3-D part: flat face down, no overhang that needs support."""


def in_print_pose(name: str, solid):
    """``solid`` (design frame) turned into its print pose: (solid, 4 x 4 matrix design → print frame)."""
    from build123d import Pos, Rot

    pose = PRINT_POSES[name]
    turned = Rot(pose.rx_deg, 0, 0) * solid if pose.rx_deg else solid
    z_min = turned.bounding_box(optimal=True).min.Z
    return Pos(0, 0, -z_min) * turned, pose.matrix(z_min)


def printed_parts(spec) -> dict[str, object]:
    """Name → build123d solid, in its design frame, for every 3-D part ``[outputs]`` asks for (imports the CAD
    kernel). The exporter turns each into :data:`PRINT_POSES`."""
    parts = {}
    if spec.outputs.end_cap_mold:
        from matcad.parts.end_cap import end_cap
        from matcad.parts.end_cap_mold import mold_base, mold_lid

        parts["end_cap"] = end_cap(spec)
        parts["end_cap_mold_base"] = mold_base(spec)
        parts["end_cap_mold_lid"] = mold_lid(spec)
    if spec.outputs.needle_mount:
        from matcad.parts.needle_mount import needle_mount

        parts["needle_mount"] = needle_mount(spec)
    return parts


def needs_cad_kernel(spec) -> bool:
    """Whether building ``spec`` needs build123d (any STL/STEP output)."""
    o = spec.outputs
    return o.end_cap_mold or o.needle_mount or o.assembly
