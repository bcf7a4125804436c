"""Rules for a board of taxels on one neck plate: every cap on the plate, neighbours apart, each needle's jet
clear of its neighbours' necks, the plate's ligaments. Lengths in mm.

A single taxel has no neighbours: these rules return nothing for it, so its findings are those of the per-part
rules alone (laser webs, stack, printing), as before boards existed. Sources and limits: docs/arrays.md.
"""

from __future__ import annotations

import math

from matcad.parts.features import (bolt_clearance_mm, needle_axis_mm, needle_tip_mm, pin_hole_diameter_mm,
                                   plate_bolt_positions_mm, plate_dowel_positions_mm)
from matcad.parts.stack import mount_depth_mm
from matcad.rules.finding import Finding
from matcad.spec import cap_flange_diameter_mm

JET_HALF_ANGLE_DEG = 12.0
"""Opening half-angle of the needle's free jet, to where its speed falls to ~10 % of the centre line's. A round
turbulent jet's half-speed radius grows as r½ = S x with S ≈ 0.094-0.10 (Pope, *Turbulent Flows*, 2000, Table 5.1;
Hussein, Capp & George 1994); with its near-Gaussian profile the 10 % edge lies at 1.82 r½, so tan α ≈ 0.17-0.18
(α ≈ 10°). We take 12° for margin: the needle's laminar exit at these flows spreads less, not more."""
LIGAMENT_PER_SHEET = 1.0
"""Least acrylic between two holes of the neck plate, in sheet thicknesses: the sheet-cutting rule of thumb of
about one material thickness between cut features (laser and sheet-cutting design guides, e.g. Xometry's
"Distance Between Features"). Below it a bolted or drilled cast-acrylic plate may crack between the holes; it is
a rule of thumb, not a measured strength, so its finding is a warning."""
JET_SAMPLES = 72
"""Points around each of three circles (centre, half radius, rim) of a neighbour's neck mouth tested against the
jet."""


def _board(spec):
    from matcad.spec import taxels

    board = taxels(spec)
    return board if len(board) > 1 else ()


def _position_fields(spec) -> str:
    return "the [[taxel]] x, y" if spec.taxel else "array.pitch_x, array.pitch_y"


def _stack_holes(spec) -> list[tuple[str, float, float, float]]:
    """(what, x, y, diameter) of the plate's bolt and dowel holes (mm)."""
    bolt = bolt_clearance_mm(spec.fasteners.bolt, spec.fasteners.bolt_fit)
    dowel = pin_hole_diameter_mm(spec.fasteners.dowel_diameter, "laser", spec.fasteners.dowel_fit_laser)
    return ([("bolt", x, y, bolt) for x, y in plate_bolt_positions_mm(spec)]
            + [("dowel", x, y, dowel) for x, y in plate_dowel_positions_mm(spec)])


def plate_fit(spec) -> list[Finding]:
    """Every cap's flange (the locator's hole) inside the plate outline and clear of every bolt and dowel hole:
    an error per taxel and problem, naming plate.width / plate.depth / plate.bolt_inset and the taxel's position."""
    out = []
    w, d = spec.plate.width, spec.plate.depth
    holes = _stack_holes(spec)
    for t in _board(spec):
        r = cap_flange_diameter_mm(t) / 2
        edge = min(w / 2 - abs(t.x), d / 2 - abs(t.y)) - r
        if edge < 0:
            out.append(Finding("board.outside", "error", round(edge, 4), ">= 0",
                               f"{t.name} at ({t.x:g}, {t.y:g}): its cap flange (Ø{2 * r:g}) reaches {-edge:.2f} mm "
                               f"past the {w:g} x {d:g} mm plate",
                               f"enlarge plate.width / plate.depth or move {t.name} in ({_position_fields(spec)})"))
        for what, x, y, size in holes:
            gap = math.hypot(t.x - x, t.y - y) - r - size / 2
            if gap < 0:
                out.append(Finding("board.on_fastener", "error", round(gap, 4), ">= 0",
                                   f"{t.name}'s cap flange overlaps the {what} hole at ({x:.2f}, {y:.2f}) by "
                                   f"{-gap:.2f} mm: the locator guide would have no wall between them",
                                   "enlarge plate.width / plate.depth (the bolts sit plate.bolt_inset from the "
                                   f"corners) or move {t.name} ({_position_fields(spec)})"))
    return out


def spacing(spec) -> list[Finding]:
    """Neighbouring caps apart: the locator guide's web between two flanges (and so the clamp's between two
    bodies) at least ``machine.laser_min_feature``; overlapping flanges are an error. The mold needs no check
    here: it lays its caps ``mold.wall`` apart whatever the plate does (print.wall checks that wall)."""
    out = []
    limit = spec.machine.laser_min_feature
    board = _board(spec)
    for i, a in enumerate(board):
        for b in board[i + 1:]:
            web = math.hypot(a.x - b.x, a.y - b.y) - (cap_flange_diameter_mm(a) + cap_flange_diameter_mm(b)) / 2
            if web < limit:
                out.append(Finding("board.spacing", "error" if web <= 0 else "warning", round(web, 4), limit,
                                   f"{a.name} and {b.name}: the locator guide keeps {web:.2f} mm between their cap "
                                   f"flanges (< machine.laser_min_feature = {limit:g} mm)",
                                   f"move them apart ({_position_fields(spec)}) or narrow end_cap.flange_width"))
    return out


def jet_clearance_mm(jet, neck) -> tuple[float, float]:
    """How far the neck mouth of taxel ``neck`` stays outside the jet of taxel ``jet``'s needle (negative: inside),
    as (free jet, jet along the plate): :func:`disc_jet_clearance_mm` on the mouth, a disc in the plate's
    underside (mm; inf where the jet never passes)."""
    return disc_jet_clearance_mm(jet, neck.x, neck.y, neck.neck.diameter / 2)


def disc_jet_clearance_mm(jet, x: float, y: float, radius: float, z: float = 0.0) -> tuple[float, float]:
    """How far a disc of ``radius`` centred on (``x``, ``y``, ``z``), parallel to the plate, stays outside the jet
    of taxel ``jet``'s needle (negative: inside), as (free jet, jet along the plate): the free jet is a cone of
    half-angle :data:`JET_HALF_ANGLE_DEG` from the needle's tip along its axis up to the plate underside; past there
    the jet runs along the plate in its axis' direction (+x), still widening at that angle with the distance
    travelled (mm; inf where it never passes). A neck's mouth is the disc at z = 0; a support post, a column
    through the gap, is tested as discs at several z."""
    tip = needle_tip_mm(jet)
    mouth, u = needle_axis_mm(jet)
    spread = math.tan(math.radians(JET_HALF_ANGLE_DEG))
    r0 = jet.needle.outer_diameter / 2
    s_plate = sum((m - p) * c for m, p, c in zip(mouth, tip, u))
    free = wall = math.inf
    disc = [(f * radius, 2 * math.pi * k / JET_SAMPLES) for f in (0.0, 0.5, 1.0)
            for k in range(JET_SAMPLES)]  # the mouth is an opening: the jet may cross its middle, not its rim
    for rho, a in disc:
        q = (x + rho * math.cos(a), y + rho * math.sin(a), z)
        rel = [qi - ti for qi, ti in zip(q, tip)]
        s = sum(r * c for r, c in zip(rel, u))
        if 0 < s <= s_plate:
            free = min(free, math.sqrt(max(sum(r * r for r in rel) - s * s, 0.0)) - (r0 + s * spread))
        along = q[0] - mouth[0]
        if along > 0:
            wall = min(wall, abs(q[1] - mouth[1]) - (r0 + (s_plate + along) * spread))
    return free, wall


def jet_interference(spec) -> list[Finding]:
    """No needle's jet may reach another taxel's neck: inside the free jet (it blows straight across the
    neighbour's mouth) is an error; inside the jet running along the plate is a warning (a wall jet decays with
    distance, but it still sweeps that mouth and can make it sound or shift its tone). The caps sit above the
    plate, out of the jet's way; only the necks open into it. Half-angle :data:`JET_HALF_ANGLE_DEG`."""
    out = []
    board = _board(spec)
    for a in board:
        for b in board:
            if a is b:
                continue
            free, wall = jet_clearance_mm(a, b)
            if free < 0 or wall < 0:
                gap, level, where = ((free, "error", "in its free jet, between the needle's tip and the plate")
                                     if free < 0 else (wall, "warning", "in the jet running along the plate"))
                out.append(Finding("board.jet", level, round(gap, 3), ">= 0",
                                   f"{a.name}'s needle jet (±{JET_HALF_ANGLE_DEG:g}°) covers {b.name}'s neck "
                                   f"mouth by {-gap:.2f} mm, {where}",
                                   f"offset {b.name} in y from {a.name} (the jets blow toward +x), or move them "
                                   f"apart ({_position_fields(spec)})"))
    return out


def plate_ligaments(spec) -> list[Finding]:
    """Acrylic between two neck holes, and between a neck and a bolt or dowel hole, at least
    :data:`LIGAMENT_PER_SHEET` plate sheets (neck.length): a warning per pair, with the ligament and the limit.
    The same in a [riser] (:func:`riser_ligaments`). The plate's bending under mechanics.max_force_n is
    :mod:`matcad.rules.plate`'s."""
    return _ligaments(spec, "neck plate", spec.neck.length, lambda t: ("neck", t.neck.diameter), lambda t: t.name)


def riser_ligaments(spec) -> list[Finding]:
    """:func:`plate_ligaments` in the [riser]: between its taxel holes (a neck run on through it, else the pocket of
    a cap's flange, :func:`matcad.parts.riser.riser_holes`) and to its bolt and dowel holes, at least
    :data:`LIGAMENT_PER_SHEET` riser sheets (riser.thickness); nothing without a riser."""
    if spec.riser is None:
        return []
    from matcad.parts.riser import riser_holes

    def hole(t):
        h = riser_holes(spec, (t,))[0]
        return ("neck" if t.neck.riser else "pocket"), h.finished_mm

    return _ligaments(spec, "riser", spec.riser.thickness, hole, lambda t: f"{t.name}'s {hole(t)[0]}")


def _ligaments(spec, sheet: str, thickness: float, hole, other) -> list[Finding]:
    """Webs of a sheet ``thickness`` thick (mm) between every two taxels' holes and from each to the stack's bolt and
    dowel holes, each below :data:`LIGAMENT_PER_SHEET` sheets a warning: ``hole(taxel)`` is (what, finished diameter
    mm) of a taxel's hole in ``sheet``, ``other(taxel)`` how a message names it as the second of a pair."""
    out = []
    board = _board(spec)
    limit = LIGAMENT_PER_SHEET * thickness
    pairs = [(a, other(b), math.hypot(a.x - b.x, a.y - b.y) - (hole(a)[1] + hole(b)[1]) / 2)
             for i, a in enumerate(board) for b in board[i + 1:]]
    pairs += [(t, f"{what} hole at ({x:.2f}, {y:.2f})", math.hypot(t.x - x, t.y - y) - (hole(t)[1] + size) / 2)
              for t in board for what, x, y, size in _stack_holes(spec)]
    for a, b, web in pairs:
        if web < limit:
            out.append(Finding("board.ligament", "warning", round(web, 4), round(limit, 4),
                               f"{sheet}: {web:.2f} mm of acrylic between {a.name}'s {hole(a)[0]} and {b} "
                               f"(< {limit:g} mm, {LIGAMENT_PER_SHEET:g} x the {thickness:g} mm sheet)",
                               f"move the taxels apart ({_position_fields(spec)}) or enlarge plate.width / "
                               "plate.depth"))
    return out


def mold_slots(spec) -> list[Finding]:
    """The cap mold (``mold.count`` caps per mold) must hold every distinct cap of the board, or some taxel's cap
    is never cast: an error naming mold.count; an info line with how many pours (or molds) one board takes."""
    from matcad.parts.mold_layout import pours_per_board

    board = _board(spec)
    if not board or not spec.outputs.end_cap_mold:
        return []
    molds = pours_per_board(board, spec.mold.count)
    missing = [name for g in molds["groups"] if not g["slots_per_mold"] for name in g["taxels"]]
    if missing:
        return [Finding("board.mold", "error", spec.mold.count, len(molds["groups"]),
                        f"mold.count = {spec.mold.count} caps per mold holds fewer positions than the board's "
                        f"{len(molds['groups'])} different caps: no mold casts {', '.join(missing)}",
                        f"set mold.count >= {len(molds['groups'])}")]
    return [Finding("board.mold", "info", molds["molds_per_board"], "", f"one mold holds {spec.mold.count} caps: "
                    f"{molds['molds_per_board']} pour(s) (or molds poured at once) cast one cap for every taxel")]


def _bore_points(spec, taxel, samples: int = 240):
    """Points along ``taxel``'s needle axis from the plate underside down to the mount's underside (mm)."""
    mouth, u = needle_axis_mm(taxel)
    run = mount_depth_mm(spec) / max(u[2], 1e-9)
    return [tuple(m - run * k / samples * c for m, c in zip(mouth, u)) for k in range(samples + 1)]


def bore_crossings(spec) -> list[Finding]:
    """Two needles' bores must not meet between the plate and the mount's underside (the needles would collide
    and neither bore would hold its needle): an error per pair with the least distance between the axes against
    the sum of the bore radii. Parallel bores (equal θ, different y or x) never meet; taxels with different θ in
    one row can."""
    board = _board(spec)
    out = []
    radius = {t.name: pin_hole_diameter_mm(t.needle.outer_diameter, spec.machine.printer, t.needle.fit) / 2
              for t in board}
    points = {t.name: _bore_points(spec, t) for t in board}
    for i, a in enumerate(board):
        for b in board[i + 1:]:
            if abs(a.y - b.y) > radius[a.name] + radius[b.name]:
                continue  # each axis stays in its own y plane
            least = min(math.dist(p, q) for p in points[a.name] for q in points[b.name])
            limit = radius[a.name] + radius[b.name]
            if least < limit:
                out.append(Finding("board.bores", "error", round(least, 3), round(limit, 3),
                                   f"{a.name}'s and {b.name}'s needle bores come {least:.2f} mm apart in the mount "
                                   f"(bore radii add to {limit:.2f} mm): the needles would collide",
                                   "give taxels in one row the same needle_theta_deg, or offset them in y"))
    return out


RULES = (plate_fit, spacing, jet_interference, plate_ligaments, riser_ligaments, mold_slots, bore_crossings)
