"""Where things are in the cap mold, and how its cavities vent: pure arithmetic, no CAD kernel (mm).

Mold frame: the parting plane is z = 0 and is the cap's base; pour orientation is z up, the cap upside down in
the base, the lid on top carrying the core pins. A *ceiling* is silicone surface that faces up against the mold
(flatter than :data:`CEILING_TILT_DEG`): a bubble that rises onto it stays there unless an opening is near. Each
cap has two:

- the base face: the annulus from the cavity edge (D/2) to the flange edge, against the lid's underside;
- the core pin's end face (the cavity's closed end, over the sensing membrane), at z = −L.

A bubble leaves a ceiling through an opening above it, or over the ceiling's edge where the surface beyond rises
(a wall steeper than the ceiling limit) toward a vented ceiling. The core pin's end face has no opening: its rim
meets the pin's side, which rises to the base face, so every point of it lies within the tip radius D_tip/2 of
an escape, and the base face is vented. No vent runs through the pin: one would cast a silicone thread standing
on the membrane inside the cavity (the acoustic volume), to be pulled out of a blind hole. Over the base face
the fill port and two rings of vents, one over the body wall and one over the flange, as many as it takes for
every point of the annulus to lie within ``mold.vent_reach`` of an opening's edge (:func:`plan_vents`); their
sprues stand on the sealing face and are trimmed flush (the casting guide says how).

The clamp bolts screw into captive nuts in the base (:func:`clamp_nut`), so the closed mold stands flat on its
base: on FDM the print pauses to drop the nuts into closed pockets, on SLA they press into traps open below.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from matcad.parts.features import bolt_clearance_mm
from matcad.spec import cap_flange_diameter_mm, cap_height_mm

CEILING_TILT_DEG = 10.0
"""A silicone surface facing up within this angle of horizontal is a ceiling: 20 000 cps silicone does not let
a bubble slide along it in its pot life."""
VENT_SPACING_MARGIN_MM = 0.4
"""Least solid between two neighbouring vent holes in the lid (the printer must leave a wall)."""
MAX_VENTS_PER_RING = 24


@dataclass(frozen=True)
class VentPlan:
    """Openings over one cap's base face, relative to its axis: (radius, angle in degrees) per opening."""

    inner: tuple[tuple[float, float], ...]  # over the body wall, the fill port's ring (fill port not included)
    outer: tuple[tuple[float, float], ...]  # over the flange
    reach_base_mm: float  # farthest point of the base-face ceiling from an opening's edge
    reach_tip_mm: float  # farthest point of the core-pin end face from its rim, where the pin's side rises
    feasible: bool  # every ceiling within mold.vent_reach with vents that fit


@dataclass(frozen=True)
class ClampNut:
    """How a mold clamp bolt holds: from the lid's top through the lid and base into a captive hex nut in the base
    (mold frame, mm). ``length_mm`` is the stock bolt length (None when the base is too thin for the nut), its end
    flush with the nut's underside; the pocket spans ``pocket_bottom_z`` … ``pocket_top_z``, ``across_flats_mm``
    wide, open below on SLA (a trap the nut presses into) and closed on FDM, where the print pauses at
    ``pause_print_z`` (print frame, bed at 0) to drop the nut in."""

    bolt: str
    length_mm: float | None
    nut_height_mm: float
    pocket_bottom_z: float
    pocket_top_z: float
    across_flats_mm: float
    open_below: bool
    pause_print_z: float | None


@dataclass(frozen=True)
class Opening:
    """A channel through the lid that silicone can rise into: centre (x, y), diameter, from ``z_bottom`` up to
    ``z_top`` (mold frame), and what it is (``fill`` or ``vent``) (mm). The lid is cut from these, and the
    cavity-volume check (:func:`appendages`) reads the same list."""

    x: float
    y: float
    diameter: float
    z_bottom: float
    z_top: float
    kind: str


@dataclass(frozen=True)
class MoldLayout:
    """Where things are in the mold frame (mm)."""

    cap_x: tuple[float, ...]
    slots: tuple  # the taxel whose cap each position casts (:func:`mold_slots`)
    block_x: float
    block_y: float
    keys: tuple[tuple[float, float], ...]
    bolts: tuple[tuple[float, float], ...]
    fill_ports: tuple[tuple[float, float], ...]
    vents: tuple[tuple[float, float], ...]  # ring vents over the base face
    base_height: float
    plans: tuple[VentPlan, ...]  # per slot
    clamp: ClampNut
    fill_port: float = 2.0
    vent: float = 1.0
    lid_thickness: float = 3.0

    @property
    def openings(self) -> tuple[Opening, ...]:
        """Every fill port and vent as a channel from the parting plane through the lid (mm)."""
        return (tuple(Opening(x, y, self.fill_port, 0.0, self.lid_thickness, "fill") for x, y in self.fill_ports)
                + tuple(Opening(x, y, self.vent, 0.0, self.lid_thickness, "vent") for x, y in self.vents))

    @property
    def plan(self) -> VentPlan:
        """The slot whose base face vents worst (every slot's, for a mold of identical caps)."""
        return max(self.plans, key=lambda p: (not p.feasible, p.reach_base_mm, p.reach_tip_mm))

    @property
    def nut_insert(self) -> str:
        """How the captive clamp nuts go into the printed base: dropped into the FDM pockets at the print's pause,
        or pressed into the SLA traps once the base is printed (the print job's note and the print step)."""
        c = self.clamp
        if c.open_below:
            return (f"press an {c.bolt} nut into each of the {len(self.bolts)} hex traps under the mold base, up to "
                    "the trap's top")
        return f"insert {len(self.bolts)} {c.bolt} nuts into the mold base's hex pockets"


def fill_radius_mm(spec) -> float:
    """Fill port (and inner vent ring) radius: the middle of the body wall (mm)."""
    return (spec.cavity.diameter + spec.end_cap.outer_diameter) / 4


def outer_ring_radius_mm(spec) -> float:
    """Outer vent ring radius: the middle of the flange ring (mm)."""
    return (spec.end_cap.outer_diameter + cap_flange_diameter_mm(spec)) / 4


def pin_tip_radius_mm(spec) -> float:
    """Core-pin end-face radius: D/2 narrowed by the draft over L (mm)."""
    from matcad.acoustics.geometry import drafted_tip_diameter_mm

    return float(drafted_tip_diameter_mm(spec.cavity.diameter, spec.cavity.length, spec.mold.draft_deg)) / 2


def _ring(radius: float, count: int, phase_deg: float, skip_first: bool) -> tuple[tuple[float, float], ...]:
    step = 360.0 / count
    return tuple((radius, phase_deg + k * step) for k in range(1 if skip_first else 0, count))


def base_face_reach_mm(r0: float, r1: float, openings: list[tuple[float, float, float]], samples: int = 48,
                       every: int = 1) -> float:
    """Farthest point of the base-face annulus r0 … r1 (cavity edge … flange edge) from the edge of the nearest
    opening, openings given as (radius, angle deg, hole radius); sampled on a polar grid (mm). ``every`` > 1 takes
    every so many grid points only: a lower bound of the full grid's value (its maximum over fewer points)."""
    import numpy as np

    x, y = _polar_grid(r0, r1, samples)
    x, y = x[::every], y[::every]
    gap = np.full(x.shape, np.inf)
    for radius, angle, hole in openings:
        cx, cy = radius * math.cos(math.radians(angle)), radius * math.sin(math.radians(angle))
        gap = np.minimum(gap, np.sqrt((x - cx) ** 2 + (y - cy) ** 2) - hole)  # sqrt, not hypot: 6x faster
    return float(max(0.0, gap.max()))


@functools.lru_cache(maxsize=16)
def _polar_grid(r0: float, r1: float, samples: int):
    """The sample points (x, y, mm) of :func:`base_face_reach_mm`'s annulus, made once per annulus."""
    import numpy as np

    r, a = np.meshgrid(np.linspace(r0, r1, samples + 1), np.linspace(0, 2 * np.pi, 4 * samples, endpoint=False))
    return (r * np.cos(a)).ravel(), (r * np.sin(a)).ravel()


def _fits(radius: float, count: int, hole: float) -> bool:
    return count == 1 or 2 * radius * math.sin(math.pi / count) >= hole + VENT_SPACING_MARGIN_MM


def plan_vents(spec) -> VentPlan:
    """The fewest vents (inner ring, with the fill port, then outer ring) that bring every point of the
    base-face ceiling within ``mold.vent_reach`` of an opening's edge (mm)."""
    m = spec.mold
    return _plan(spec.cavity.diameter, spec.end_cap.outer_diameter, cap_flange_diameter_mm(spec),
                 pin_tip_radius_mm(spec), m.fill_port, m.vent, m.vent_reach)


@functools.lru_cache(maxsize=64)
def _plan(cavity_d: float, outer_d: float, flange_d: float, tip_r: float, fill_port: float, vent: float,
          vent_reach: float) -> VentPlan:
    r_in, r_out = (cavity_d + outer_d) / 4, (outer_d + flange_d) / 4
    fill = [(r_in, 0.0, fill_port / 2)]
    reach_tip = tip_r  # the end face's centre to its rim, where the pin's side rises to the base face
    tried = []
    for n_in in range(1, MAX_VENTS_PER_RING + 1):
        if not _fits(r_in, n_in, max(vent, fill_port)):
            break
        for n_out in range(3, MAX_VENTS_PER_RING + 1):
            if not _fits(r_out, n_out, vent):
                break
            inner = _ring(r_in, n_in, 0.0, skip_first=True)
            outer = _ring(r_out, n_out, 180.0 / n_out, skip_first=False)
            openings = fill + [(r, a, vent / 2) for r, a in inner + outer]
            tried.append((inner, outer, openings))
            # a fifth of the grid first: its reach is a lower bound, so above vent_reach the rings fail for sure
            if base_face_reach_mm(cavity_d / 2, flange_d / 2, openings, every=5) <= vent_reach:
                reach = base_face_reach_mm(cavity_d / 2, flange_d / 2, openings)
                if reach <= vent_reach:
                    return VentPlan(inner, outer, reach, reach_tip, reach_tip <= vent_reach)
            if n_out * n_in > 4 * MAX_VENTS_PER_RING:
                break
    best = None  # no rings reach everywhere: the ones that come nearest (the first of equals), on the full grid
    for inner, outer, openings in tried:
        reach = base_face_reach_mm(cavity_d / 2, flange_d / 2, openings)
        if best is None or reach < best.reach_base_mm - 1e-9:
            best = VentPlan(inner, outer, reach, reach_tip, False)
    if best is None:  # not even the first rings fit: only the fill port vents the base face
        best = VentPlan((), (), base_face_reach_mm(cavity_d / 2, flange_d / 2, fill), reach_tip, False)
    return best


def cap_key(t) -> tuple:
    """What makes the cap of the taxel ``t`` the cap it is: its cavity, its end cap, and whether its neck runs on
    through a [riser] (else, where there is a riser, its cap sits in a pocket of it with a thicker flange:
    :func:`matcad.spec.cap_flange_thickness_mm`; without a riser no neck runs through one, and a tube has no neck)."""
    return t.cavity, t.end_cap, t.neck is not None and t.neck.riser


def cap_groups(board) -> list[list]:
    """The taxels of ``board`` grouped by identical cap (:func:`cap_key`), in order of first appearance."""
    groups: dict[tuple, list] = {}
    for t in board:
        groups.setdefault(cap_key(t), []).append(t)
    return list(groups.values())


def mold_slots(board, count: int) -> tuple:
    """The taxel whose cap each of a mold's ``count`` positions casts: the board's caps taken in turn, group by
    group (a mold of ``count`` >= the board's taxels casts a whole board per pour, spares of the first caps
    after it), then ordered so identical caps sit side by side."""
    groups = cap_groups(board)
    order = [t for g in groups for t in g]
    slots = [order[i % len(order)] for i in range(count)]
    rank = {id(g[0]): i for i, g in enumerate(groups)}
    first = {id(t): id(g[0]) for g in groups for t in g}
    return tuple(sorted(slots, key=lambda t: rank[first[id(t)]]))


def pours_per_board(board, count: int) -> dict:
    """How many pours of one mold (or how many molds poured at once) cast one cap for every taxel of ``board``:
    per cap group, its taxels over the slots it has; 0 slots means the mold cannot cast that cap at all."""
    slots = mold_slots(board, count)
    rows = []
    for g in cap_groups(board):
        have = sum(1 for s in slots if cap_key(s) == cap_key(g[0]))
        rows.append({"taxels": [t.name for t in g], "slots_per_mold": have,
                     "pours": -(-len(g) // have) if have else None})
    pours = [r["pours"] for r in rows]
    return {"caps_per_mold": count, "groups": rows,
            "molds_per_board": None if None in pours else max(pours)}


def cap_x_mm(flanges: list[float], wall: float) -> tuple[float, ...]:
    """Centres along x of caps with these flange diameters in a row, ``wall`` apart, centred on 0 (mm)."""
    n = len(flanges)
    if len(set(flanges)) == 1:  # identical caps: an even pitch (the single-taxel layout, bit for bit)
        pitch = flanges[0] + wall
        return tuple((i - (n - 1) / 2) * pitch for i in range(n))
    x = [-(sum(flanges) + (n - 1) * wall) / 2 + flanges[0] / 2]
    for a, b in zip(flanges, flanges[1:]):
        x.append(x[-1] + (a + b) / 2 + wall)
    return tuple(x)


def layout(spec) -> MoldLayout:
    """Positions of caps, keys, bolts, fill ports and vents in the mold frame (mm): ``mold.count`` caps of the
    board (:func:`mold_slots`) in a row, each slot with its own flange, fill radius and vent plan."""
    from matcad.spec import taxel_spec, taxels

    m = spec.mold
    slots = mold_slots(taxels(spec), m.count)
    specs = [taxel_spec(spec, t) for t in slots]
    flanges = [cap_flange_diameter_mm(s) for s in specs]
    cap_x = cap_x_mm(flanges, m.wall)
    feature = max(m.key_diameter + 2 * spec.machine.key_clearance, bolt_clearance_mm(m.bolt, "normal"))
    end_zone = feature + m.wall
    if len(set(flanges)) == 1:
        block_x = m.count * (flanges[0] + m.wall) + m.wall + 2 * end_zone
    else:
        block_x = sum(flanges) + (m.count + 1) * m.wall + 2 * end_zone
    block_y = max(max(flanges) + 2 * m.wall, 2 * feature + 3 * m.wall)
    xe = block_x / 2 - end_zone / 2
    ye = block_y / 4
    plans = tuple(plan_vents(s) for s in specs)

    def at(x, r, a):
        return (x + r * math.cos(math.radians(a)), r * math.sin(math.radians(a)))

    fill = tuple(at(x, fill_radius_mm(s), 0.0) for x, s in zip(cap_x, specs))
    vents = tuple(at(x, r, a) for x, p in zip(cap_x, plans) for r, a in p.inner + p.outer)
    base_height = max(cap_height_mm(s) for s in specs) + m.floor
    return MoldLayout(cap_x, slots, block_x, block_y, keys=((xe, ye), (-xe, -ye)), bolts=((xe, -ye), (-xe, ye)),
                      fill_ports=fill, vents=vents, base_height=base_height, plans=plans,
                      clamp=clamp_nut(m.bolt, spec.machine.printer, base_height, m.lid_thickness),
                      fill_port=m.fill_port, vent=m.vent, lid_thickness=m.lid_thickness)


def _overlap_mm2(d: float, r1: float, r2: float) -> float:
    """Area shared by two discs of radii r1, r2 whose centres are d apart (mm²)."""
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return math.pi * min(r1, r2) ** 2
    a1 = r1 * r1 * math.acos((d * d + r1 * r1 - r2 * r2) / (2 * d * r1))
    a2 = r2 * r2 * math.acos((d * d + r2 * r2 - r1 * r1) / (2 * d * r2))
    return a1 + a2 - 0.5 * math.sqrt((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2))


def appendages(spec, lay: MoldLayout | None = None) -> list[dict]:
    """What each cap position casts beyond the cap itself (mm³): the silicone the openings over it can hold
    (sprues on its sealing face, above the parting plane, trimmed off) and the part of it that lies inside the
    cavity — the acoustic volume — where a channel runs down into the core pin (a pin vent would cast a thread
    standing on the membrane). One row per slot: taxel, sprues (count), sprue volume, volume inside the cavity,
    taken at the pin's root diameter over the channel's depth below the parting plane (an upper bound for a
    drafted pin)."""
    from matcad.spec import taxel_spec

    lay = lay or layout(spec)
    rows = []
    for x, taxel in zip(lay.cap_x, lay.slots):
        cap = taxel_spec(spec, taxel)
        flange_r, pin_r = cap_flange_diameter_mm(cap) / 2, cap.cavity.diameter / 2
        own = [o for o in lay.openings if math.hypot(o.x - x, o.y) < flange_r + o.diameter / 2]
        sprue = sum(math.pi * o.diameter ** 2 / 4 * max(o.z_top, 0.0) for o in own)
        inside = sum(_overlap_mm2(math.hypot(o.x - x, o.y), o.diameter / 2, pin_r)
                     * min(max(-o.z_bottom, 0.0), cap.cavity.length) for o in own)
        rows.append({"taxel": taxel.name, "x_mm": x, "sprues": len(own), "sprue_mm3": sprue,
                     "inside_cavity_mm3": inside})
    return rows


NUT_ACROSS_FLATS_MM = {"M2": 4.0, "M2.5": 5.0, "M3": 5.5}
NUT_HEIGHT_MM = {"M2": 1.6, "M2.5": 2.0, "M3": 2.4}
"""ISO 4032 hex nut: width across flats s and height m (mm)."""
NUT_POCKET_CLEARANCE_MM = {"fdm": 0.3, "sla": 0.15}
"""Nut pocket across flats over the nut's: a printed hole comes out undersize, FDM more than SLA (mm)."""
NUT_HEADROOM_MM = 0.2
"""Pocket height over the nut's: the layer that closes an FDM pocket must not touch the nut (mm)."""
NUT_ROOF_MM = 1.0
"""Base material kept between the top of a nut pocket's funnel roof and the parting plane (mm)."""


def nut_funnel_mm(bolt: str, printer: str) -> float:
    """Height of the roof over a clamp nut's hex pocket: a hexagonal funnel from the pocket to a hexagon inscribed in
    the bolt's clearance hole (a corner standing out of the hole would leave a ledge the slicer supports), its
    corners overhanging :data:`matcad.parts.print_profile.FDM_MAX_OVERHANG_DEG` from vertical, the steepest
    PrusaSlicer's default FDM profile prints without support (measured) (mm)."""
    from matcad.parts.print_profile import FDM_MAX_OVERHANG_DEG

    pocket = (NUT_ACROSS_FLATS_MM[bolt] + NUT_POCKET_CLEARANCE_MM[printer]) / 2 / math.cos(math.pi / 6)
    hole = bolt_clearance_mm(bolt, "normal") / 2  # the top hexagon inscribed in the hole: no ledge at its corners
    return (pocket - hole) / math.tan(math.radians(FDM_MAX_OVERHANG_DEG))
NUT_FLOOR_MM = {"fdm": 1.0, "sla": 0.0}
"""Under the nut: FDM closes the pocket below (five 0.2 mm layers), SLA leaves the trap open to the bed (mm)."""


def clamp_nut(bolt: str, printer: str, base_height: float, lid_thickness: float) -> ClampNut:
    """Where a mold clamp bolt's captive nut sits (mold frame, mm): the longest stock bolt
    (:data:`matcad.parts.features.ISO_4762_LENGTHS_MM`) whose end, flush with the nut's underside, stays
    :data:`NUT_FLOOR_MM` above the base's underside while the pocket keeps :data:`NUT_ROOF_MM` under the parting
    plane. On FDM the pocket's top is raised to a layer boundary of the base's print profile and the print pauses
    before the layer that closes it."""
    from matcad.parts.features import ISO_4762_LENGTHS_MM
    from matcad.parts.print_profile import profile

    m, s = NUT_HEIGHT_MM[bolt], NUT_ACROSS_FLATS_MM[bolt] + NUT_POCKET_CLEARANCE_MM[printer]
    roof = nut_funnel_mm(bolt, printer) + NUT_ROOF_MM
    fits = [length for length in ISO_4762_LENGTHS_MM
            if lid_thickness - length >= -base_height + NUT_FLOOR_MM[printer]
            and lid_thickness - length + m + NUT_HEADROOM_MM <= -roof]
    length = max(fits) if fits else None
    bottom = lid_thickness - (length if length is not None else lid_thickness + base_height)
    top = bottom + m + NUT_HEADROOM_MM
    pause = None
    if printer == "fdm" and length is not None:
        base = profile(printer, "end_cap_mold_base")
        top_print = base.layer_top_mm(top + base_height)
        top = top_print - base_height
        pause = round(top_print + base.layer_mm / 2, 6)
    return ClampNut(bolt, length, m, round(bottom if printer == "fdm" else -base_height, 6), round(top, 6), s,
                    printer == "sla", pause)
