"""The neck plate under load: how far a taxel pressed with mechanics.max_force_n bends it toward the mount, and what
that does to the pitch of every taxel on it (Hz, mm, N)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from matcad.listening import EDGE_BINS, EXCLUDE_BINS, guard_hz
from matcad.materials import ACRYLIC_MODULUS_MPA
from matcad.parts.stack import plate_beam, plate_deflection_mm, post_bay_mm
from matcad.rules.finding import ArrayRule, Finding

BENDING_GUARD_SHARE = EDGE_BINS / (EXCLUDE_BINS + EDGE_BINS)
"""The share of the band guard (:func:`matcad.listening.guard_hz`) a pitch change from bending may take: its
EDGE_BINS of band edge. The guard is a tone's main lobe (EXCLUDE_BINS) plus EDGE_BINS bins in which the tracker
refuses a ridge as hugging the band's edge; the predicted bands know nothing of the plate bending, so a change
larger than those bins can carry a tone at its band's edge out of the band the loop listens in (2 of 8 bins: 10.8
Hz at 44.1 kHz, 11.7 Hz at 96 kHz)."""
POST_CLEARANCE_MM = 0.5
"""Least gap between a support post and a needle, a bolt's spacer or a dowel hole on the mount's top face: an FDM
part's features print up to ~0.2 mm oversize (:data:`matcad.parts.features.PIN_FIT_ALLOWANCE_MM`), and a needle
set by hand sits a few tenths off its bore's axis."""
POST_MOUTH_GAPS = 3.0
"""Least distance from a support post to a neck's mouth edge, in mount gaps (spacer.height). The 'mount' mouth's
model (:func:`matcad.acoustics.models.mount_end_correction_mm`) takes the gap's radial flow as starting a gap height
beyond the mouth's edge (r = a + h) and unobstructed out to the vent radius; three gaps keep a post well outside
the region where the flow turns from the neck into the gap. What a post does to the radial flow is not modelled:
docs/arrays.md estimates it from the same radial-flow inertance (at most ~5 Hz, 0.1 % of f0, on the capacity
boards)."""


@dataclass(frozen=True)
class Bending:
    """One taxel's plate bending: ``pressed`` (name) carries the force (N), the plate bends ``deflection_mm`` under
    ``heard`` (the same taxel or a neighbour), whose mount gap falls from ``gap_mm`` and pitch moves ``shift_hz``
    (None when the plate reaches the mount: the mouth closes)."""

    pressed: str
    heard: str
    force_n: float
    deflection_mm: float
    gap_mm: float
    shift_hz: float | None


def deflections(spec):
    """The board (:func:`matcad.spec.taxels`) and the plate's deflection under each taxel when each is pressed with
    mechanics.max_force_n: w[pressed, heard] (mm; :func:`matcad.parts.stack.plate_deflection_mm`)."""
    from matcad.spec import taxels

    board = taxels(spec)
    force = spec.mechanics.max_force_n
    return board, np.array([plate_deflection_mm(spec, force, t, board) for t in board])


def bendings(spec) -> list[Bending]:
    """For every taxel pressed with mechanics.max_force_n, every taxel's deflection under it (:func:`deflections`)
    and its pitch change: its f0 by the model `predict` chooses for the wall
    (:data:`matcad.acoustics.registry.CHOSEN`) at the mount gap less that deflection, minus the same at the gap as
    built. The gap is taken as uniform at its value under the taxel (the 'mount' mouth's model,
    :func:`matcad.acoustics.models.mount_end_correction_mm`): the real gap opens again toward the supports, so the
    change is an upper bound there. A mouth other than 'mount' sees no gap: its pitch does not move."""
    from matcad.acoustics.design import design

    board, w = deflections(spec)
    gap = spec.spacer.height
    out = []
    for j, heard in enumerate(board):
        open_ = w[:, j] < gap
        shift = pitch_shift_hz(design(spec, heard), np.where(open_, w[:, j], 0.0), spec.wall.model)
        out += [Bending(t.name, heard.name, spec.mechanics.max_force_n, float(w[i, j]), gap,
                        float(shift[i]) if open_[i] else None) for i, t in enumerate(board)]
    return out


def shift_bound_hz(spec, board, w) -> float:
    """An upper bound of every taxel's pitch change (Hz) that reads neither the cavity nor a model, so a sweep's
    rule memo (:mod:`matcad.sweep.memo`) need not run the model for every cavity: the outer end correction δ is a
    mass at the neck's mouth moving with the neck's air (:func:`matcad.acoustics.models.mouth_end_correction_mm`),
    so by Rayleigh's principle raising it by Δδ lowers ω² by at most the share of the kinetic energy it holds,
    ≤ δ / (l + δ), times Δδ / δ: |Δf| / f ≤ Δδ / (2 (l + δ)). Taken twice over (a neck whose air does not move as
    one), at f = the sample rate (the microphone hears nothing above half of it)."""
    from matcad.acoustics.design import gap_radius_mm
    from matcad.spec import neck_length_mm

    radius = float(gap_radius_mm(spec.plate.width, spec.plate.depth))
    worst = 0.0
    for j, heard in enumerate(board):
        worst = max(worst, float(bound_hz(spec.neck.mouth, heard.neck.diameter / 2, spec.spacer.height,
                                          w[:, j].max(), radius, neck_length_mm(spec, heard),
                                          spec.microphone.sample_rate_hz)))
    return worst


def bound_hz(mouth: str, neck_radius_mm, gap_mm, deflection_mm, gap_radius_mm, neck_length_mm, sample_rate_hz):
    """:func:`shift_bound_hz`'s bound (Hz) for one heard taxel, floats or arrays: the sample rate times the rise of
    the outer end correction when the gap narrows by ``deflection_mm``, over the neck's length plus that
    correction (mm)."""
    from matcad.acoustics.models import mouth_end_correction_mm

    built = mouth_end_correction_mm(mouth, neck_radius_mm, gap_mm, gap_radius_mm)
    bent = mouth_end_correction_mm(mouth, neck_radius_mm, gap_mm - deflection_mm, gap_radius_mm)
    return sample_rate_hz * (bent - built) / (neck_length_mm + built)


def bending_limit_hz(sample_rate_hz: float) -> float:
    """The largest pitch change from bending :func:`plate_bending` lets pass (Hz): :data:`BENDING_GUARD_SHARE` of
    the band guard at ``sample_rate_hz``."""
    return BENDING_GUARD_SHARE * guard_hz(sample_rate_hz)


def post_clearances_mm(spec) -> list[dict]:
    """For each support post (:func:`matcad.parts.features.plate_post_positions_mm`), its (x, y) and how far its
    edge stays from: every needle's jet (the ``board.jet`` rule's cone, :func:`matcad.rules.board
    .disc_jet_clearance_mm`, the post tested as discs at the plate's underside, mid-gap and the mount's top face;
    negative: inside), every needle above the mount (its axis from the bore's mouth in the mount's top face up to
    its tip, each section a circle of r / sin θ, the bore's radius: the needle and its bore's mouth), every neck's
    mouth edge, every bolt's spacer or standoff (a laser spacer square's corner) and every dowel hole in the mount
    (mm)."""
    from matcad.parts.features import (needle_axis_mm, needle_tip_mm,
                                       plate_bolt_positions_mm, plate_dowel_positions_mm, plate_post_positions_mm)
    from matcad.parts.needle_mount import bore_mouth_mm, dowel_hole_radius_mm
    from matcad.rules.board import disc_jet_clearance_mm
    from matcad.spec import taxels

    board = taxels(spec)
    gap, r = spec.spacer.height, spec.plate.post_diameter / 2
    spacer = spec.spacer.size / 2 * (1.0 if spec.spacer.style == "standoff" else 2 ** 0.5)
    dowel = dowel_hole_radius_mm(spec)

    def needle(x, y, t) -> float:
        bx, by, br = bore_mouth_mm(spec, t)
        tip = needle_tip_mm(t)
        return min(math.hypot(x - (bx + (tip[0] - bx) * k / 50), y - by) for k in range(51)) - br - r

    out = []
    for x, y in plate_post_positions_mm(spec):
        jets = [min(disc_jet_clearance_mm(t, x, y, r, z)) for t in board for z in (0.0, -gap / 2, -gap)]
        out.append({"x": x, "y": y, "jet": min(jets),
                    "needle": min(needle(x, y, t) for t in board),
                    "mouth": min(math.hypot(x - t.x, y - t.y) - t.neck.diameter / 2 - r for t in board),
                    "bolt": min(math.hypot(x - bx, y - by) - spacer - r for bx, by in plate_bolt_positions_mm(spec)),
                    "dowel": min(math.hypot(x - dx, y - dy) - dowel - r
                                 for dx, dy in plate_dowel_positions_mm(spec))})
    return out


def support_posts(spec) -> list[Finding]:
    """With plate.support_posts: an error when the board has no line for them (one column), when plate
    .post_diameter is thinner than the printer's thinnest wall, and per post and obstacle when a post stands in a
    needle's jet, within :data:`POST_CLEARANCE_MM` of a needle, a spacer or a dowel hole, or within
    :data:`POST_MOUTH_GAPS` mount gaps of a neck's mouth (:func:`post_clearances_mm`)."""
    from matcad.rules.printing import min_wall_mm

    if not spec.plate.support_posts:
        return []
    rows = post_clearances_mm(spec)
    fix = "set plate.support_posts = false, a smaller plate.post_diameter, or move the taxels ([[taxel]] x, y)"
    if not rows:
        return [Finding("plate.posts", "error", 0, ">= 1", "plate.support_posts = true, but the board has no two "
                        "columns of necks to put posts between", "set plate.support_posts = false")]
    out = []
    wall = min_wall_mm(spec)
    if spec.plate.post_diameter < wall:
        out.append(Finding("plate.posts", "error", spec.plate.post_diameter, wall,
                           f"plate.post_diameter = {spec.plate.post_diameter:g} mm is thinner than the printer's "
                           f"thinnest wall ({wall:g} mm)", f"set plate.post_diameter >= {wall:g}"))
    limits = {"jet": (0.0, "a needle's jet"), "needle": (POST_CLEARANCE_MM, "a needle"),
              "mouth": (POST_MOUTH_GAPS * spec.spacer.height, f"a neck's mouth ({POST_MOUTH_GAPS:g} mount gaps)"),
              "bolt": (POST_CLEARANCE_MM, "a bolt's spacer"), "dowel": (POST_CLEARANCE_MM, "a dowel hole")}
    for row in rows:
        for key, (limit, what) in limits.items():
            if row[key] < limit:
                out.append(Finding("plate.posts", "error", round(row[key], 3), round(limit, 3),
                                   f"the support post at ({row['x']:.2f}, {row['y']:.2f}) "
                                   f"(Ø{spec.plate.post_diameter:g} mm) keeps {row[key]:.2f} mm from {what} "
                                   f"(< {limit:.2f} mm)", fix))
    return out


def plate_bending(spec) -> list[Finding]:
    """A warning when the plate, bent by one taxel pressed with mechanics.max_force_n, moves any taxel's pitch by
    more than :data:`BENDING_GUARD_SHARE` of the band guard, or reaches the mount under a taxel (its mouth closes).
    The pressed taxel's own change is left out of its predicted loaded band; a neighbour's is a pitch change with no
    force on it. The worst pair is named, with the deflection and the gap."""
    if spec.mechanics.max_force_n <= 0:
        return []
    guard = guard_hz(spec.microphone.sample_rate_hz)
    limit = bending_limit_hz(spec.microphone.sample_rate_hz)
    board, w = deflections(spec)
    if w.max() < spec.spacer.height and shift_bound_hz(spec, board, w) <= limit:
        return []
    rows = bendings(spec)
    worst = max(rows, key=lambda b: (b.shift_hz is None, abs(b.shift_hz or 0.0), b.deflection_mm))
    if worst.shift_hz is not None and abs(worst.shift_hz) <= limit:
        return []
    whose = "its own" if worst.heard == worst.pressed else f"{worst.heard}'s"
    how = (f"{worst.pressed} pressed with {worst.force_n:g} N bends the {spec.neck.length:g} mm plate (neck.length) "
           f"{worst.deflection_mm:.3g} mm under {worst.heard} ({_support_text(spec, worst.pressed)})")
    posts = "" if spec.plate.support_posts else ", support posts under it (plate.support_posts = true)"
    fix = ("stiffen the plate: a thicker sheet (neck.length sets every pitch: re-run `matcad design`), a shorter "
           f"board{posts}; or lower mechanics.max_force_n")
    if worst.shift_hz is None:
        return [Finding("plate.bending", "warning", round(worst.deflection_mm, 4), worst.gap_mm,
                        f"{how}: more than the {worst.gap_mm:g} mm mount gap (spacer.height): the plate reaches the "
                        f"mount and closes {worst.heard}'s mouth", fix)]
    return [Finding("plate.bending", "warning", round(worst.shift_hz, 3), round(limit, 3),
                    f"{how}: the mount gap under it falls from {worst.gap_mm:g} to "
                    f"{worst.gap_mm - worst.deflection_mm:.3f} mm and {whose} pitch moves {worst.shift_hz:+.1f} Hz, "
                    f"more than {limit:.1f} Hz ({EDGE_BINS} of the {EXCLUDE_BINS + EDGE_BINS} bins of the "
                    f"{guard:.0f} Hz band guard)", fix)]


def _support_text(spec, pressed: str) -> str:
    """How :func:`matcad.parts.stack.plate_deflection_mm` held the plate when the taxel named ``pressed`` was
    pressed: the beam on the bolt rows, or the strip on the posts."""
    from matcad.parts.features import plate_post_positions_mm
    from matcad.spec import taxels

    if not plate_post_positions_mm(spec):
        axis, span, width = plate_beam(spec)
        return (f"a beam {width:g} mm wide on the bolt rows {span:.1f} mm apart along {axis}, simply supported, "
                f"E = {ACRYLIC_MODULUS_MPA:g} MPa; Roark Table 8.1 case 1e")
    below, above, arm, width = post_bay_mm(spec, next(t for t in taxels(spec) if t.name == pressed))
    return (f"a strip {width:g} mm wide, the cap flange, simply supported on the support lines {above - below:.1f} mm "
            f"apart either side of it and a cantilever {arm:.2f} mm from the post line to the neck, E = "
            f"{ACRYLIC_MODULUS_MPA:g} MPa; Roark Table 8.1 cases 1e and 1a")


def deflection_under_taxel_mm(spec) -> float:
    """What :func:`plate_bending` reads of a one-taxel spec beyond its acoustic design: the plate's deflection under
    the taxel pressed with mechanics.max_force_n (mm; 0 without a force, where the rule reads nothing more). A
    sweep memoises it (:mod:`matcad.sweep.memo`: once per combination of the plate's varied fields) and judges the
    rest on arrays (:func:`bending_warnings`)."""
    if spec.mechanics.max_force_n <= 0:
        return 0.0
    return float(deflections(spec)[1][0, 0])


def bending_warnings(d, deflection_mm, force_n, sample_rate_hz, shift_hz) -> np.ndarray:
    """:func:`plate_bending` on arrays of one-taxel variants (a sweep's): 1 where it warns, else 0. ``d``: the
    variants' :class:`matcad.acoustics.design.Design` of arrays; ``deflection_mm``, ``force_n``, ``sample_rate_hz``:
    per variant (:func:`deflection_under_taxel_mm`); ``shift_hz(rows)``: the pitch change of the variants at index
    ``rows`` with the gap narrowed by their deflection (:func:`pitch_shift_hz`), asked only where
    :func:`shift_bound_hz`'s bound passes the limit, as the rule does. The same tests, in the same arithmetic."""
    gap, w = np.asarray(d.gap_mm, dtype=float), np.asarray(deflection_mm, dtype=float)
    rates, which = np.unique(np.asarray(sample_rate_hz, dtype=float), return_inverse=True)
    limit = np.array([bending_limit_hz(float(r)) for r in rates])[which.reshape(-1)]
    open_ = w < gap
    with np.errstate(invalid="ignore", divide="ignore"):  # a closed gap (not open_) has no bound: never read
        bound = bound_hz(d.mouth, d.neck_diameter / 2, gap, np.where(open_, w, 0.0), d.gap_radius_mm, d.neck_length,
                         sample_rate_hz)
    rows = np.flatnonzero(open_ & (bound > limit) & (np.asarray(force_n) > 0))
    moved = np.zeros(len(gap), dtype=bool)
    if rows.size:
        moved[rows] = np.abs(shift_hz(rows)) > limit[rows]
    return ((np.asarray(force_n) > 0) & (~open_ | moved)).astype(np.int64)


def bending_column(deflection_mm, field, d, design_of, wall_model: str, physics_of) -> np.ndarray:
    """:func:`bending_warnings` as a sweep asks it (:class:`matcad.rules.finding.ArrayRule`'s ``column``): the
    variants' f0 as built from the sweep where it has them (``physics_of``), the same numbers."""
    def shift_hz(rows):
        return pitch_shift_hz(design_of(rows), deflection_mm[rows], wall_model, physics_of(rows))

    return bending_warnings(d, deflection_mm, field("mechanics.max_force_n"), field("microphone.sample_rate_hz"),
                            shift_hz)


def pitch_shift_hz(d, deflection_mm, wall_model: str, built_hz=None):
    """f0 with the mount gap narrowed by ``deflection_mm`` minus f0 as built (Hz), by the model `predict` chooses
    for ``wall_model`` (:data:`matcad.acoustics.registry.CHOSEN`): a Design of arrays of variants, or one design under
    an array of deflections (:func:`bendings`); each entry the arithmetic of that one design. ``built_hz``: f0 as
    built by that model, when the caller has it (a sweep: the search is not run twice)."""
    from matcad.acoustics import registry
    from matcad.acoustics.resonator import resonator

    model = registry.model(registry.CHOSEN[wall_model])
    built = np.asarray(d.gap_mm, dtype=float)
    shape = np.broadcast_shapes(built.shape, np.shape(deflection_mm), np.shape(d.cavity_diameter))
    cavity = np.broadcast_to(d.cavity_diameter, shape)

    def f0(gap):
        many = d.replace(gap_mm=np.broadcast_to(gap, shape), cavity_diameter=cavity)
        return np.broadcast_to(np.asarray(model.f0_hz(resonator(many), d.wall), dtype=float), shape)

    return f0(built - deflection_mm) - (f0(built) if built_hz is None else np.broadcast_to(built_hz, shape))


RULES = (plate_bending, support_posts)
ARRAY_RULES = {plate_bending: ArrayRule("plate.bending", "warning", deflection_under_taxel_mm, bending_column)}
"""Of :data:`RULES`, those a sweep of one-taxel variants judges on arrays rather than once per combination of the
fields they read (plate.bending reads the whole acoustic design wherever the plate bends, so once per variant)."""
