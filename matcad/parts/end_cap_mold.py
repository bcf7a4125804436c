"""Printable two-part mold that casts exactly :func:`matcad.parts.end_cap.end_cap`, ``mold.count`` at a time.

Mold frame: the parting plane is z = 0 and is the cap's base (the face that sits on the neck plate). Pour
orientation is as modelled, z up:
- **base** (z < 0): a block holding each cap's outer shape upside down. The cap widens toward the parting
  plane (body, then flange), so it lifts straight out without undercuts.
- **lid** (z > 0): a plate carrying the core pins that form the cavities (drafted toward their tips so they
  release), with sockets over the base's truncated-cone registration keys (clearance per side from the
  printer's fit class), a fill port per cap over the body annulus, vents, and clamp bolt holes.
Each cavity has two ceilings in pour orientation (see :mod:`matcad.parts.mold_layout`): the base face under
the lid, vented by rings of holes planned so no point is farther than ``mold.vent_reach`` from an opening, and
the core pin's end face over the sensing membrane, vented along the pin's axis.
"""

from __future__ import annotations

from matcad.parts.end_cap import cap_envelope, core_pin, end_cap
from matcad.parts.features import bolt_clearance_mm
from matcad.parts.mold_layout import MoldLayout, layout  # noqa: F401  (the layout is part of this part's API)
from matcad.parts.registry import Kind, Part, PrintPose

KEY_TOP_RATIO = 0.6
"""Key top diameter / base diameter: a truncated cone that self-centres as the lid closes."""


def _key(spec, grow: float, x: float, y: float):
    from matcad.parts.solid import frustum_up

    m = spec.mold
    r = m.key_diameter / 2
    return frustum_up(r + grow, r * KEY_TOP_RATIO + grow, m.key_height + grow, x, y, 0.0)


def _slot_specs(spec, lay: MoldLayout) -> list[tuple[float, object]]:
    """(x, single-taxel spec of the cap it casts) for every cap position of the mold (mm)."""
    from matcad.spec import taxel_spec

    return [(x, taxel_spec(spec, t)) for x, t in zip(lay.cap_x, lay.slots)]


def _upside_down(shape, x: float):
    from build123d import Pos, Rot

    return Pos(x, 0, 0) * Rot(180, 0, 0) * shape


def mold_base(spec):
    """Base block: top face at z = 0, cap negatives upside down, keys on top, bolt holes (mm)."""
    from build123d import Box

    from matcad.parts.solid import TOP, cylinder_up

    lay = layout(spec)
    bolt_r = bolt_clearance_mm(spec.mold.bolt, "normal") / 2
    block = Box(lay.block_x, lay.block_y, lay.base_height, align=TOP)
    block = block.fuse(*(_key(spec, 0.0, x, y) for x, y in lay.keys))
    return block.cut(*[_upside_down(cap_envelope(s), x) for x, s in _slot_specs(spec, lay)],
                     *[cylinder_up(bolt_r, lay.base_height, x, y, -lay.base_height) for x, y in lay.bolts])


def mold_lid(spec):
    """Lid: bottom face at z = 0, core pins (each vented along its axis) hanging into the caps, key sockets, fill
    ports, vents, bolts (mm)."""
    from build123d import Box

    from matcad.parts.solid import BOTTOM, cylinder_up

    lay = layout(spec)
    m = spec.mold
    lid = Box(lay.block_x, lay.block_y, m.lid_thickness, align=BOTTOM)
    slots = _slot_specs(spec, lay)
    lid = lid.fuse(*(_upside_down(core_pin(s), x) for x, s in slots))
    holes = ([(x, y, m.fill_port / 2) for x, y in lay.fill_ports]
             + [(x, y, m.vent / 2) for x, y in lay.vents]
             + [(x, y, bolt_clearance_mm(m.bolt, "normal") / 2) for x, y in lay.bolts])
    return lid.cut(*[_key(spec, spec.machine.key_clearance, x, y) for x, y in lay.keys],
                   *[cylinder_up(r, m.lid_thickness, x, y, 0.0) for x, y, r in holes],
                   *[cylinder_up(m.vent / 2, s.cavity.length + m.lid_thickness, x, y, -s.cavity.length)
                     for (x, y), (_, s) in zip(lay.pin_vents, slots)])


def cast_caps(spec):
    """The caps as they sit in the closed mold (for checks: they must touch, not cut, the mold) (mm)."""
    return [_upside_down(end_cap(s), x) for x, s in _slot_specs(spec, layout(spec))]


PARTS = (Part("end_cap_mold_base", Kind.PRINTED, flag="end_cap_mold", make=mold_base, order=60, colour="#e0c090",
              pose=PrintPose(0.0, "flat underside; cap cavities and keys face up"),
              view=("from above: cap cavities, fill ports, vents", 90.0, -90.0)),
         Part("end_cap_mold_lid", Kind.PRINTED, flag="end_cap_mold", make=mold_lid, order=70, colour="#e0c090",
              pose=PrintPose(180.0, "outer (top) face; core pins point up, the parting face prints last"),
              view=("from above (as printed, pins up): core pins, vents, key sockets", 90.0, -90.0)))
