"""Printable two-part mold that casts exactly :func:`matcad.parts.end_cap.end_cap`, ``mold.count`` at a time.

Mold frame: the parting plane is z = 0 and is the cap's base (the face that sits on the neck plate). Pour
orientation is as modelled, z up:
- **base** (z < 0): a block holding each cap's outer shape upside down. The cap widens toward the parting
  plane (body, then flange), so it lifts straight out without undercuts.
- **lid** (z > 0): a plate carrying the core pins that form the cavities (drafted toward their tips so they
  release), with sockets over the base's truncated-cone registration keys (clearance per side from the
  printer's fit class), a fill port per cap over the body annulus, vents, and clamp bolt holes.
The only ceiling of each mold cavity in pour orientation is the lid's underside over the flange ring, so
that is where air collects: each cap gets vents around that ring, away from the fill port.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from build123d import Box, Pos, Rot

from matcad.parts.end_cap import cap_envelope, core_pin, end_cap
from matcad.parts.features import bolt_clearance_mm, cap_flange_diameter_mm, cap_height_mm
from matcad.parts.solid import BOTTOM, TOP, cylinder_up, frustum_up

KEY_TOP_RATIO = 0.6
"""Key top diameter / base diameter: a truncated cone that self-centres as the lid closes."""
VENT_ANGLES_DEG = (90.0, 180.0, 270.0)
"""Vents around the flange ring, the fill port sitting at 0°."""


@dataclass(frozen=True)
class MoldLayout:
    """Where things are in the mold frame (mm)."""

    cap_x: tuple[float, ...]
    block_x: float
    block_y: float
    keys: tuple[tuple[float, float], ...]
    bolts: tuple[tuple[float, float], ...]
    fill_ports: tuple[tuple[float, float], ...]
    vents: tuple[tuple[float, float], ...]
    base_height: float


def layout(spec) -> MoldLayout:
    """Positions of caps, keys, bolts, fill ports and vents (mm); pure arithmetic, no CAD."""
    m = spec.mold
    flange_d = cap_flange_diameter_mm(spec)
    pitch = flange_d + m.wall
    cap_x = tuple((i - (m.count - 1) / 2) * pitch for i in range(m.count))
    feature = max(m.key_diameter + 2 * spec.machine.key_clearance, bolt_clearance_mm(m.bolt, "normal"))
    end_zone = feature + m.wall
    block_x = m.count * pitch + m.wall + 2 * end_zone
    block_y = max(flange_d + 2 * m.wall, 2 * feature + 3 * m.wall)
    xe = block_x / 2 - end_zone / 2
    ye = block_y / 4
    r_fill = (spec.cavity.diameter + spec.end_cap.outer_diameter) / 4
    r_vent = (spec.end_cap.outer_diameter + flange_d) / 4
    fill = tuple((x + r_fill, 0.0) for x in cap_x)
    vents = tuple((x + r_vent * math.cos(math.radians(a)), r_vent * math.sin(math.radians(a)))
                  for x in cap_x for a in VENT_ANGLES_DEG)
    return MoldLayout(cap_x, block_x, block_y, keys=((xe, ye), (-xe, -ye)), bolts=((xe, -ye), (-xe, ye)),
                      fill_ports=fill, vents=vents, base_height=cap_height_mm(spec) + m.floor)


def _key(spec, grow: float, x: float, y: float):
    m = spec.mold
    r = m.key_diameter / 2
    return frustum_up(r + grow, r * KEY_TOP_RATIO + grow, m.key_height + grow, x, y, 0.0)


def _upside_down(shape, x: float):
    return Pos(x, 0, 0) * Rot(180, 0, 0) * shape


def mold_base(spec):
    """Base block: top face at z = 0, cap negatives upside down, keys on top, bolt holes (mm)."""
    lay = layout(spec)
    bolt_r = bolt_clearance_mm(spec.mold.bolt, "normal") / 2
    block = Box(lay.block_x, lay.block_y, lay.base_height, align=TOP)
    block = block.fuse(*(_key(spec, 0.0, x, y) for x, y in lay.keys))
    return block.cut(*[_upside_down(cap_envelope(spec), x) for x in lay.cap_x],
                     *[cylinder_up(bolt_r, lay.base_height, x, y, -lay.base_height) for x, y in lay.bolts])


def mold_lid(spec):
    """Lid: bottom face at z = 0, core pins hanging into the caps, key sockets, fill ports, vents, bolts (mm)."""
    lay = layout(spec)
    m = spec.mold
    lid = Box(lay.block_x, lay.block_y, m.lid_thickness, align=BOTTOM)
    lid = lid.fuse(*(_upside_down(core_pin(spec), x) for x in lay.cap_x))
    holes = ([(x, y, m.fill_port / 2) for x, y in lay.fill_ports]
             + [(x, y, m.vent / 2) for x, y in lay.vents]
             + [(x, y, bolt_clearance_mm(m.bolt, "normal") / 2) for x, y in lay.bolts])
    return lid.cut(*[_key(spec, spec.machine.key_clearance, x, y) for x, y in lay.keys],
                   *[cylinder_up(r, m.lid_thickness, x, y, 0.0) for x, y, r in holes])


def cast_caps(spec):
    """The caps as they sit in the closed mold (for checks: they must touch, not cut, the mold) (mm)."""
    return [_upside_down(end_cap(spec), x) for x in layout(spec).cap_x]
