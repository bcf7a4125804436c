"""The neck plate under load: how far a taxel pressed with mechanics.max_force_n bends it toward the mount, and what
that does to the pitch of every taxel on it (Hz, mm, N)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matcad.listening import EDGE_BINS, EXCLUDE_BINS, guard_hz
from matcad.materials import ACRYLIC_MODULUS_MPA
from matcad.parts.stack import plate_beam, plate_deflection_mm
from matcad.rules.finding import Finding

BENDING_GUARD_SHARE = EDGE_BINS / (EXCLUDE_BINS + EDGE_BINS)
"""The share of the band guard (:func:`matcad.listening.guard_hz`) a pitch change from bending may take: its
EDGE_BINS of band edge. The guard is a tone's main lobe (EXCLUDE_BINS) plus EDGE_BINS bins in which the tracker
refuses a ridge as hugging the band's edge; the predicted bands know nothing of the plate bending, so a change
larger than those bins can carry a tone at its band's edge out of the band the loop listens in (2 of 8 bins: 10.8
Hz at 44.1 kHz, 11.7 Hz at 96 kHz)."""


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
    from matcad.acoustics import registry
    from matcad.acoustics.design import design
    from matcad.acoustics.resonator import resonator

    board, w = deflections(spec)
    gap = spec.spacer.height
    model = registry.model(registry.CHOSEN[spec.wall.model])
    out = []
    for j, heard in enumerate(board):
        d = design(spec, heard)
        open_ = w[:, j] < gap
        variants = np.append(np.where(open_, gap - w[:, j], gap), gap)  # every pressed taxel's gap, then as built
        many = d.replace(gap_mm=variants, cavity_diameter=np.full(len(variants), d.cavity_diameter))
        f = np.broadcast_to(np.asarray(model.f0_hz(resonator(many), d.wall), dtype=float), variants.shape)
        out += [Bending(t.name, heard.name, spec.mechanics.max_force_n, float(w[i, j]), gap,
                        float(f[i] - f[-1]) if open_[i] else None) for i, t in enumerate(board)]
    return out


def shift_bound_hz(spec, board, w) -> float:
    """An upper bound of every taxel's pitch change (Hz) that reads neither the cavity nor a model, so a sweep's
    rule memo (:mod:`matcad.sweep.memo`) need not run the model for every cavity: the outer end correction δ is a
    mass at the neck's mouth moving with the neck's air (:func:`matcad.acoustics.models.mouth_end_correction_mm`),
    so by Rayleigh's principle raising it by Δδ lowers ω² by at most the share of the kinetic energy it holds,
    ≤ δ / (l + δ), times Δδ / δ: |Δf| / f ≤ Δδ / (2 (l + δ)). Taken twice over (a neck whose air does not move as
    one), at f = the sample rate (the microphone hears nothing above half of it)."""
    from matcad.acoustics.design import gap_radius_mm
    from matcad.acoustics.models import mouth_end_correction_mm

    gap = spec.spacer.height
    radius = float(gap_radius_mm(spec.plate.width, spec.plate.depth))
    worst = 0.0
    for j, heard in enumerate(board):
        a = heard.neck.diameter / 2
        built = float(mouth_end_correction_mm(spec.neck.mouth, a, gap, radius))
        bent = float(mouth_end_correction_mm(spec.neck.mouth, a, gap - w[:, j].max(), radius))
        worst = max(worst, spec.microphone.sample_rate_hz * (bent - built) / (spec.neck.length + built))
    return worst


def plate_bending(spec) -> list[Finding]:
    """A warning when the plate, bent by one taxel pressed with mechanics.max_force_n, moves any taxel's pitch by
    more than :data:`BENDING_GUARD_SHARE` of the band guard, or reaches the mount under a taxel (its mouth closes).
    The pressed taxel's own change is left out of its predicted loaded band; a neighbour's is a pitch change with no
    force on it. The worst pair is named, with the deflection and the gap."""
    if spec.mechanics.max_force_n <= 0:
        return []
    guard = guard_hz(spec.microphone.sample_rate_hz)
    limit = BENDING_GUARD_SHARE * guard
    board, w = deflections(spec)
    if w.max() < spec.spacer.height and shift_bound_hz(spec, board, w) <= limit:
        return []
    rows = bendings(spec)
    worst = max(rows, key=lambda b: (b.shift_hz is None, abs(b.shift_hz or 0.0), b.deflection_mm))
    if worst.shift_hz is not None and abs(worst.shift_hz) <= limit:
        return []
    axis, span, width = plate_beam(spec)
    whose = "its own" if worst.heard == worst.pressed else f"{worst.heard}'s"
    how = (f"{worst.pressed} pressed with {worst.force_n:g} N bends the {spec.neck.length:g} mm plate (neck.length) "
           f"{worst.deflection_mm:.3g} mm under {worst.heard} (a beam {width:g} mm wide on the bolt rows {span:.1f} "
           f"mm apart along {axis}, simply supported, E = {ACRYLIC_MODULUS_MPA:g} MPa; Roark Table 8.1 case 1e)")
    fix = ("stiffen the plate: a thicker sheet (neck.length sets every pitch: re-run `matcad design`), a shorter "
           "board, or a support under the plate between its bolt rows (not modelled); or lower mechanics.max_force_n")
    if worst.shift_hz is None:
        return [Finding("plate.bending", "warning", round(worst.deflection_mm, 4), worst.gap_mm,
                        f"{how}: more than the {worst.gap_mm:g} mm mount gap (spacer.height): the plate reaches the "
                        f"mount and closes {worst.heard}'s mouth", fix)]
    return [Finding("plate.bending", "warning", round(worst.shift_hz, 3), round(limit, 3),
                    f"{how}: the mount gap under it falls from {worst.gap_mm:g} to "
                    f"{worst.gap_mm - worst.deflection_mm:.3f} mm and {whose} pitch moves {worst.shift_hz:+.1f} Hz, "
                    f"more than {limit:.1f} Hz ({EDGE_BINS} of the {EXCLUDE_BINS + EDGE_BINS} bins of the "
                    f"{guard:.0f} Hz band guard)", fix)]


RULES = (plate_bending,)
