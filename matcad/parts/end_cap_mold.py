"""Printable two-part mold that casts exactly :func:`matcad.parts.end_cap.end_cap`, ``mold.count`` at a time.

Mold frame: the parting plane is z = 0 and is the cap's base (the face that sits on the neck plate). Pour
orientation is as modelled, z up:
- **base** (z < 0): a block holding each cap's outer shape upside down. The cap widens toward the parting
  plane (body, then flange), so it lifts straight out without undercuts. Two captive hex nuts take the clamp
  bolts (:func:`matcad.parts.mold_layout.clamp_nut`), so the closed mold stands flat.
- **lid** (z > 0): a plate carrying the core pins that form the cavities (drafted toward their tips so they
  release), with sockets over the base's truncated-cone registration keys, a fill port per cap over the body
  annulus, vents over the base face, and clamp bolt holes. Each socket carries three crush ribs line-to-line with
  its key (:data:`RIB_WIDTH_MM`), so the lid centres on the keys with no lateral play; between the ribs the
  socket keeps the printer's key clearance.
Each cavity has two ceilings in pour orientation (see :mod:`matcad.parts.mold_layout`): the base face under
the lid, vented by rings of holes planned so no point is farther than ``mold.vent_reach`` from an opening, and
the core pin's end face over the sensing membrane, which vents round its rim and up the pin's side: no vent runs
through the pin, so nothing is cast inside the cavity. On a board each pocket and each fill port is labelled
with its taxel's name, recessed in the base's parting face and in the lid's top face.
"""

from __future__ import annotations

import math

from matcad.parts.end_cap import cap_envelope, core_pin, end_cap
from matcad.parts.features import bolt_clearance_mm
from matcad.parts.mold_layout import MoldLayout, layout  # noqa: F401  (the layout is part of this part's API)
from matcad.parts.recipe import Recipe, Tool
from matcad.parts.registry import Kind, Part, PrintPose

KEY_TOP_RATIO = 0.6
"""Key top diameter / base diameter: a truncated cone that self-centres as the lid closes."""
RIB_WIDTH_MM = {"fdm": 0.8, "sla": 0.5}
"""Width of a socket's crush ribs: two FDM extrusion lines, or a thin SLA web. Line-to-line with the key, a rib
printed fat is shaved or flexed as the bolts pull the lid down (the crush-rib practice of printed press fits)."""
RIB_ANGLES_DEG = (90.0, 210.0, 330.0)
"""Three ribs 120° apart: each lateral direction pushes the key into at least one of them."""


def _key(diameter: float, height: float, grow: float, x: float, y: float):
    """A registration key ``diameter`` wide at its base and ``height`` tall at (x, y) on the parting plane,
    grown by ``grow`` all round (mm)."""
    from matcad.parts.solid import frustum_up

    r = diameter / 2
    return frustum_up(r + grow, r * KEY_TOP_RATIO + grow, height + grow, x, y, 0.0)


def _ribbed_socket(diameter: float, height: float, clearance: float, printer: str, x: float, y: float):
    """The lid's socket over the key (``diameter``, ``height``) at (x, y): the key grown by ``clearance``
    (``machine.key_clearance``), less three crush ribs that fill the clearance line-to-line with the key in
    :data:`RIB_WIDTH_MM`-wide sectors for ``printer`` (mm)."""
    from build123d import Box, Pos, Rot

    grown = _key(diameter, height, clearance, x, y)
    gap = grown - _key(diameter, height, 0.0, x, y)
    reach = diameter / 2 + clearance + 1.0
    width = RIB_WIDTH_MM[printer]
    sectors = [Pos(x, y, 0) * Rot(0, 0, a) * Pos(reach / 2, 0, 0) * Box(reach, width, 2 * (height + clearance))
               for a in RIB_ANGLES_DEG]
    return grown - gap.intersect(sectors[0].fuse(*sectors[1:]))


def taxel_labels(spec, lay: MoldLayout, keepout) -> tuple:
    """The taxel name over each cap position of a board's mold, placed on the block's face clear of ``keepout``
    circles (x, y, radius); () for a single taxel's mold, whose caps are all the same (mm)."""
    from matcad.parts.labels import PRINTED_LABEL_HEIGHTS_MM, place_labels
    from matcad.spec import taxels

    if len(taxels(spec)) < 2:
        return ()
    return place_labels([(t.name, x, 0.0) for x, t in zip(lay.cap_x, lay.slots)], keepout, lay.block_x,
                        lay.block_y, heights=PRINTED_LABEL_HEIGHTS_MM)


def _flanges(spec, lay: MoldLayout) -> list[tuple[float, float, float]]:
    from matcad.spec import cap_flange_diameter_mm

    return [(x, 0.0, cap_flange_diameter_mm(s) / 2) for x, s in _slot_specs(spec, lay)]


def _features(spec, lay: MoldLayout) -> list[tuple[float, float, float]]:
    """Keys (with their socket clearance) and clamp bolts as keep-out circles (x, y, radius) of the faces (mm)."""
    key = spec.mold.key_diameter / 2 + spec.machine.key_clearance
    bolt = max(bolt_clearance_mm(spec.mold.bolt, "normal"), lay.clamp.across_flats_mm / math.cos(math.pi / 6)) / 2
    return [(x, y, key) for x, y in lay.keys] + [(x, y, bolt) for x, y in lay.bolts]


def base_labels(spec) -> tuple:
    """Taxel names recessed in the base's parting face beside each pocket (mm)."""
    lay = layout(spec)
    return taxel_labels(spec, lay, _flanges(spec, lay) + _features(spec, lay))


def lid_labels(spec) -> tuple:
    """Taxel names recessed in the lid's top face beside each fill port (mm)."""
    lay = layout(spec)
    return taxel_labels(spec, lay, _flanges(spec, lay) + _features(spec, lay))


def _hexagon(x: float, y: float, z: float, circumradius: float):
    from build123d import Wire

    return Wire.make_polygon([(x + circumradius * math.cos(math.radians(60 * k)),
                               y + circumradius * math.sin(math.radians(60 * k)), z) for k in range(6)], close=True)


def _nut_pocket(bolt: str, printer: str, clamp, base_height: float, x: float, y: float) -> list:
    """A clamp nut's hex pocket in the base (``clamp``: :class:`matcad.parts.mold_layout.ClampNut`; closed below
    on FDM, a trap open to the underside of a base ``base_height`` deep on SLA), its funnel roof
    (:func:`matcad.parts.mold_layout.nut_funnel_mm`) and the bolt's clearance hole from it up to the parting
    plane (mm)."""
    from build123d import Face, Solid, Vector

    from matcad.parts.mold_layout import nut_funnel_mm
    from matcad.parts.solid import cylinder_up

    c = clamp
    r = c.across_flats_mm / 2 / math.cos(math.pi / 6)
    hole = bolt_clearance_mm(bolt, "normal") / 2
    z0 = -base_height if c.open_below else c.pocket_bottom_z
    pocket = Solid.extrude(Face(_hexagon(x, y, z0, r)), Vector(0, 0, c.pocket_top_z - z0))
    funnel = Solid.make_loft([_hexagon(x, y, c.pocket_top_z, r),
                              _hexagon(x, y, c.pocket_top_z + nut_funnel_mm(c.bolt, printer), hole)])
    return [pocket, funnel, cylinder_up(hole, -c.pocket_top_z, x, y, c.pocket_top_z)]


def _slot_specs(spec, lay: MoldLayout) -> list[tuple[float, object]]:
    """(x, single-taxel spec of the cap it casts) for every cap position of the mold (mm)."""
    from matcad.spec import taxel_spec

    return [(x, taxel_spec(spec, t)) for x, t in zip(lay.cap_x, lay.slots)]


def _upside_down(shape, x: float):
    from build123d import Pos, Rot

    return Pos(x, 0, 0) * Rot(180, 0, 0) * shape


def _cap_negative(cap_spec, x: float):
    """The outer shape of the cap ``cap_spec`` casts, upside down at x: the base's pocket for it (mm)."""
    return _upside_down(cap_envelope(cap_spec), x)


def _core_pin_at(cap_spec, x: float):
    """The core pin of the cap ``cap_spec`` casts, hanging from the lid at x (mm)."""
    return _upside_down(core_pin(cap_spec), x)


def _slab(width: float, depth: float, height: float, below: bool):
    """A block ``width`` × ``depth`` centred on the axis, from z = -``height`` to 0 if ``below``, else from 0 up
    (mm)."""
    from build123d import Box

    from matcad.parts.solid import BOTTOM, TOP

    return Box(width, depth, height, align=TOP if below else BOTTOM)


def base_extent_mm(spec) -> tuple[float, float, float]:
    """The base's bounding box in its print pose (x, y, z mm): the block (:func:`layout`'s block_x x block_y x
    base_height) and the keys standing mold.key_height on it."""
    lay = layout(spec)
    return lay.block_x, lay.block_y, lay.base_height + spec.mold.key_height


def lid_extent_mm(spec) -> tuple[float, float, float]:
    """The lid's bounding box in its print pose (x, y, z mm; turned over, the same box): the plate (block_x x
    block_y x mold.lid_thickness) and the longest core pin hanging from it (its cavity length L)."""
    lay = layout(spec)
    return lay.block_x, lay.block_y, spec.mold.lid_thickness + max(t.cavity.length for t in lay.slots)


def base_recipe(spec) -> Recipe:
    """Base block: top face at z = 0, cap negatives upside down, keys on top, captive clamp nuts under bolt holes,
    a board's taxel names beside the pockets (mm)."""
    from matcad.parts.labels import PRINTED_LABEL_DEPTH_MM
    from matcad.parts.solid import engraved

    lay = layout(spec)
    m = spec.mold
    return Recipe(Tool(_slab, (lay.block_x, lay.block_y, lay.base_height, True)),
                  add=tuple(Tool(_key, (m.key_diameter, m.key_height, 0.0, x, y)) for x, y in lay.keys),
                  cut=(*(Tool(_cap_negative, (s, x)) for x, s in _slot_specs(spec, lay)),
                       *(Tool(_nut_pocket, (m.bolt, spec.machine.printer, lay.clamp, lay.base_height, x, y))
                         for x, y in lay.bolts),
                       Tool(engraved, (base_labels(spec), 0.0, PRINTED_LABEL_DEPTH_MM))))


def lid_recipe(spec) -> Recipe:
    """Lid: bottom face at z = 0, solid core pins hanging into the caps, ribbed key sockets, fill ports, vents,
    bolt holes, a board's taxel names beside the fill ports on its top face (mm)."""
    from matcad.parts.labels import PRINTED_LABEL_DEPTH_MM
    from matcad.parts.solid import cylinder_up, engraved

    lay = layout(spec)
    m = spec.mold
    bolt = bolt_clearance_mm(m.bolt, "normal") / 2
    socket = (m.key_diameter, m.key_height, spec.machine.key_clearance, spec.machine.printer)
    return Recipe(Tool(_slab, (lay.block_x, lay.block_y, m.lid_thickness, False)),
                  add=tuple(Tool(_core_pin_at, (s, x)) for x, s in _slot_specs(spec, lay)),
                  cut=(*(Tool(_ribbed_socket, (*socket, x, y)) for x, y in lay.keys),
                       *(Tool(cylinder_up, (o.diameter / 2, o.z_top - o.z_bottom, o.x, o.y, o.z_bottom))
                         for o in lay.openings),
                       *(Tool(cylinder_up, (bolt, m.lid_thickness, x, y, 0.0)) for x, y in lay.bolts),
                       Tool(engraved, (lid_labels(spec), m.lid_thickness, PRINTED_LABEL_DEPTH_MM))))


def mold_base(spec):
    """The base (:func:`base_recipe`) as a solid (mm)."""
    return base_recipe(spec).solid()


def mold_lid(spec):
    """The lid (:func:`lid_recipe`) as a solid (mm)."""
    return lid_recipe(spec).solid()


def cast_caps(spec):
    """The caps as they sit in the closed mold (for checks: they must touch, not cut, the mold) (mm)."""
    return [_upside_down(end_cap(s), x) for x, s in _slot_specs(spec, layout(spec))]


PARTS = (Part("end_cap_mold_base", Kind.PRINTED, flag="end_cap_mold", make=mold_base, recipe=base_recipe,
              order=60, colour="#e0c090",
              pose=PrintPose(0.0, "flat underside; cap cavities and keys face up"), extent=base_extent_mm,
              view=("from above: cap pockets, keys, nut pockets", 90.0, -90.0)),
         Part("end_cap_mold_lid", Kind.PRINTED, flag="end_cap_mold", make=mold_lid, recipe=lid_recipe,
              order=70, colour="#e0c090",
              pose=PrintPose(180.0, "outer (top) face; core pins point up, the parting face prints last"),
              extent=lid_extent_mm,
              view=("from above (as printed, pins up): core pins, vents, ribbed key sockets", 90.0, -90.0)))
