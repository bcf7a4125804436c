"""Where things are in the cap mold, and how its cavities vent: pure arithmetic, no CAD kernel (mm).

Mold frame: the parting plane is z = 0 and is the cap's base; pour orientation is z up, the cap upside down in
the base, the lid on top carrying the core pins. A *ceiling* is silicone surface that faces up against the mold
(flatter than :data:`CEILING_TILT_DEG`): a bubble that rises onto it stays there unless an opening is near. Each
cap has two:

- the base face: the annulus from the cavity edge (D/2) to the flange edge, against the lid's underside;
- the core pin's end face (the cavity's closed end, over the sensing membrane), at z = −L.

Openings: a vent along each core pin's axis, through pin and lid (its end face reaches it within the tip radius
minus the vent radius); over the base face, the fill port and two rings of vents, one over the body wall and one
over the flange, as many as it takes for every point of the annulus to lie within ``mold.vent_reach`` of an
opening's edge (:func:`plan_vents`).
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
    reach_tip_mm: float  # farthest point of the core-pin end face from the pin vent's edge
    feasible: bool  # every ceiling within mold.vent_reach with vents that fit


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
    pin_vents: tuple[tuple[float, float], ...]  # one along each core pin's axis
    base_height: float
    plans: tuple[VentPlan, ...]  # per slot

    @property
    def plan(self) -> VentPlan:
        """The slot whose base face vents worst (every slot's, for a mold of identical caps)."""
        return max(self.plans, key=lambda p: (not p.feasible, p.reach_base_mm, p.reach_tip_mm))


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


def base_face_reach_mm(r0: float, r1: float, openings: list[tuple[float, float, float]], samples: int = 48) -> float:
    """Farthest point of the base-face annulus r0 … r1 (cavity edge … flange edge) from the edge of the nearest
    opening, openings given as (radius, angle deg, hole radius); sampled on a polar grid (mm)."""
    import numpy as np

    r, a = np.meshgrid(np.linspace(r0, r1, samples + 1), np.linspace(0, 2 * np.pi, 4 * samples, endpoint=False))
    x, y = (r * np.cos(a)).ravel(), (r * np.sin(a)).ravel()
    gap = np.full(x.shape, np.inf)
    for radius, angle, hole in openings:
        cx, cy = radius * math.cos(math.radians(angle)), radius * math.sin(math.radians(angle))
        gap = np.minimum(gap, np.maximum(0.0, np.hypot(x - cx, y - cy) - hole))
    return float(gap.max())


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
    reach_tip = max(0.0, tip_r - vent / 2)
    best = None
    for n_in in range(1, MAX_VENTS_PER_RING + 1):
        if not _fits(r_in, n_in, max(vent, fill_port)):
            break
        for n_out in range(3, MAX_VENTS_PER_RING + 1):
            if not _fits(r_out, n_out, vent):
                break
            inner = _ring(r_in, n_in, 0.0, skip_first=True)
            outer = _ring(r_out, n_out, 180.0 / n_out, skip_first=False)
            reach = base_face_reach_mm(cavity_d / 2, flange_d / 2, fill + [(r, a, vent / 2) for r, a in inner + outer])
            if best is None or reach < best.reach_base_mm - 1e-9:
                best = VentPlan(inner, outer, reach, reach_tip, False)
            if reach <= vent_reach:
                return VentPlan(inner, outer, reach, reach_tip, reach_tip <= vent_reach)
            if n_out * n_in > 4 * MAX_VENTS_PER_RING:
                break
    if best is None:  # not even the first rings fit: only the fill port vents the base face
        best = VentPlan((), (), base_face_reach_mm(cavity_d / 2, flange_d / 2, fill), reach_tip, False)
    return best


def cap_groups(board) -> list[list]:
    """The taxels of ``board`` grouped by identical cap (cavity and end cap), in order of first appearance."""
    groups: dict[tuple, list] = {}
    for t in board:
        groups.setdefault((t.cavity, t.end_cap), []).append(t)
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
        have = sum(1 for s in slots if (s.cavity, s.end_cap) == (g[0].cavity, g[0].end_cap))
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
    return MoldLayout(cap_x, slots, block_x, block_y, keys=((xe, ye), (-xe, -ye)), bolts=((xe, -ye), (-xe, ye)),
                      fill_ports=fill, vents=vents, pin_vents=tuple((x, 0.0) for x in cap_x),
                      base_height=max(cap_height_mm(s) for s in specs) + m.floor, plans=plans)
