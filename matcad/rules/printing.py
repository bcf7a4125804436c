"""Rules for the printed mold and mount: walls, key clearance, fill port and vents, cure, silicone batch."""

from __future__ import annotations

import dataclasses

from matcad.materials import grade
from matcad.parts.casting import MIN_BATCH_G, MOLD_MATERIALS, pour
from matcad.parts.coupon import FDM_THETA_MIN_DEG
from matcad.parts.mold_layout import NUT_ROOF_MM, appendages, layout, plan_vents
from matcad.parts.registry import Kind, wanted
from matcad.rules.finding import Finding, fits_bed

MIN_WALL_SLA_MM = 0.8
KEY_CLEARANCE_MIN_MM = {"fdm": 0.15, "sla": 0.05}
KEY_CLEARANCE_MAX_MM = 0.5
MIN_FILL_PORT_MM = 2.0
MIN_SILICONE_WALL_MM = 1.0


def min_wall_mm(spec) -> float:
    """The thinnest printed wall (mm): two nozzle widths on FDM, :data:`MIN_WALL_SLA_MM` on SLA."""
    return 2 * spec.machine.nozzle if spec.machine.printer == "fdm" else MIN_WALL_SLA_MM


def printable_walls(spec) -> list[Finding]:
    limit = min_wall_mm(spec)
    walls = {"mold.wall": spec.mold.wall, "mold.floor": spec.mold.floor,
             "mold.lid_thickness": spec.mold.lid_thickness}
    name, thinnest = min(walls.items(), key=lambda kv: kv[1])
    out = []
    if spec.outputs.end_cap_mold and thinnest < limit:
        out.append(Finding("print.wall", "error", thinnest, limit,
                           f"{name} = {thinnest:g} mm is thinner than {limit:g} mm "
                           f"({'2 x nozzle' if spec.machine.printer == 'fdm' else 'SLA minimum'})",
                           f"raise {name} to >= {limit:g} mm"))
    return out


def key_clearance(spec) -> list[Finding]:
    c = spec.machine.key_clearance
    lo = KEY_CLEARANCE_MIN_MM[spec.machine.printer]
    if c < lo:
        return [Finding("print.key_clearance", "warning", c, lo,
                        f"key clearance {c:g} mm per side is tight for {spec.machine.printer}: the lid may not "
                        "close", f"set machine.key_clearance >= {lo:g}")]
    if c > KEY_CLEARANCE_MAX_MM:
        return [Finding("print.key_clearance", "warning", c, KEY_CLEARANCE_MAX_MM,
                        f"key clearance {c:g} mm per side lets the core pin wander off-centre",
                        f"set machine.key_clearance <= {KEY_CLEARANCE_MAX_MM:g}")]
    return []


def fill_and_vents(spec) -> list[Finding]:
    if not spec.outputs.end_cap_mold:
        return []
    m = spec.mold
    out = []
    body_annulus = (spec.end_cap.outer_diameter - spec.cavity.diameter) / 2
    if m.fill_port > body_annulus:
        out.append(Finding("mold.fill_port_fit", "error", m.fill_port, round(body_annulus, 4),
                           f"fill port {m.fill_port:g} mm is wider than the cap wall it must pour into "
                           f"({body_annulus:.2f} mm): it would open onto the core pin",
                           "reduce mold.fill_port or thicken the cap (end_cap.outer_diameter)"))
    elif m.fill_port < MIN_FILL_PORT_MM:
        out.append(Finding("mold.fill_port", "warning", m.fill_port, MIN_FILL_PORT_MM,
                           f"fill port {m.fill_port:g} mm is too narrow for syringe filling of "
                           "20 000 cps silicone", f"mold.fill_port >= {MIN_FILL_PORT_MM:g} mm"))
    ring = spec.end_cap.flange_width
    if m.vent > ring:
        out.append(Finding("mold.vents", "error", m.vent, ring,
                           f"vents ({m.vent:g} mm) do not fit on the flange ring ({ring:g} mm): the base face "
                           "over the flange could not be vented", "reduce mold.vent or widen end_cap.flange_width"))
        return out
    if spec.machine.printer == "fdm" and m.vent < 2 * spec.machine.nozzle:
        out.append(Finding("mold.vents", "warning", m.vent, 2 * spec.machine.nozzle,
                           f"{m.vent:g} mm vents may print closed with a {spec.machine.nozzle:g} mm nozzle",
                           "enlarge mold.vent or drill the vents open"))
    plan = plan_vents(spec)
    n = len(plan.inner) + len(plan.outer)
    reach = max(plan.reach_base_mm, plan.reach_tip_mm)
    if plan.reach_tip_mm > m.vent_reach:
        out.append(Finding("mold.vent_reach", "error", round(plan.reach_tip_mm, 3), m.vent_reach,
                           f"the core pin's end face (over the membrane) is {2 * plan.reach_tip_mm:.2f} mm wide: its "
                           f"centre lies {plan.reach_tip_mm:.2f} mm from the rim where a bubble can rise, more than "
                           f"{m.vent_reach:g} mm; a vent through the pin would cast a thread inside the cavity",
                           "raise mold.vent_reach (degas the mix and pour slowly), or narrow the cavity "
                           "(cavity.diameter, mold.draft_deg)"))
    elif not plan.feasible:
        out.append(Finding("mold.vent_reach", "error", round(reach, 3), m.vent_reach,
                           f"no vent layout brings every cavity ceiling within {m.vent_reach:g} mm of an opening "
                           f"(best: {reach:.2f} mm with {n} vents per cap): bubbles would stay in the cap",
                           "raise mold.vent_reach, or change mold.vent / mold.fill_port"))
    else:
        out.append(Finding("mold.vent_reach", "info", round(reach, 3), m.vent_reach,
                           f"per cap: {n} vents over the base face (farthest ceiling point "
                           f"{plan.reach_base_mm:.2f} mm from an opening); the core pin's end face over the membrane "
                           f"vents round its rim and up the pin (every point within {plan.reach_tip_mm:.2f} mm of "
                           "the rim), no vent through the pin; fill port over the body wall", ""))
    return out


def cavity_appendages(spec) -> list[Finding]:
    """Nothing may be cast inside a cap's cavity (its acoustic volume): every opening over a cap position is
    measured against the core pin it stands over (:func:`matcad.parts.mold_layout.appendages`). Silicone inside is
    an error (a thread on the membrane changes the volume and the pitch, and tears the membrane when pulled out);
    the sprues on the sealing face are an info line with their count and volume, trimmed flush."""
    if not spec.outputs.end_cap_mold:
        return []
    rows = appendages(spec)
    inside = [r for r in rows if r["inside_cavity_mm3"] > 1e-9]
    if inside:
        worst = max(inside, key=lambda r: r["inside_cavity_mm3"])
        return [Finding("mold.cavity_appendage", "error", round(worst["inside_cavity_mm3"], 4), 0.0,
                        f"{worst['taxel']}'s cap would carry {worst['inside_cavity_mm3']:.2f} mm³ of silicone cast "
                        "inside its cavity (an opening runs down into the core pin): it changes the acoustic volume "
                        "and tears the membrane when pulled out", "vent the pin's end round its rim, not through it")]
    worst = max(rows, key=lambda r: r["sprue_mm3"])
    return [Finding("mold.cavity_appendage", "info", 0.0, 0.0,
                    f"per cap: 0 mm³ cast inside the cavity; {worst['sprues']} sprues (fill port and vents, at most "
                    f"{worst['sprue_mm3']:.1f} mm³) stand on the sealing face, trimmed flush after demolding", "")]


def clamp_nut(spec) -> list[Finding]:
    """The mold base must be tall enough for its captive clamp nuts: a stock bolt that reaches through the nut,
    with material above the pocket to carry the clamp and under it on FDM."""
    if not spec.outputs.end_cap_mold:
        return []
    lay = layout(spec)
    c = lay.clamp
    if c.length_mm is None:
        return [Finding("mold.clamp_nut", "error", round(lay.base_height, 3), "a captive nut",
                        f"the {lay.base_height:.2f} mm mold base cannot hold a captive {c.bolt} nut "
                        f"({c.nut_height_mm:g} mm) with {NUT_ROOF_MM:g} mm above it for any stock bolt length",
                        "raise mold.floor, or choose a smaller mold.bolt")]
    return []


def cap_wall(spec) -> list[Finding]:
    wall = (spec.end_cap.outer_diameter - spec.cavity.diameter) / 2
    if wall < MIN_SILICONE_WALL_MM:
        return [Finding("cap.wall", "warning", round(wall, 4), MIN_SILICONE_WALL_MM,
                        f"silicone wall {wall:.2f} mm around the cavity tears on demolding and balloons "
                        "under blowing pressure", "raise end_cap.outer_diameter")]
    return []


def silicone_batch(spec) -> list[Finding]:
    """The silicone to mix for one pour (:func:`matcad.parts.casting.pour`; no mold layout: a laser-only kit has
    none), its pot life and cure."""
    p, g, mold = pour(spec), grade(spec.silicone.grade), MOLD_MATERIALS[spec.machine.printer]
    return [Finding("silicone.batch", "info", round(p.batch_g, 3), MIN_BATCH_G,
                    f"{p.caps} cap(s) = {p.cast_volume_ml:.3f} ml cast; mix {p.batch_g:.1f} g of "
                    f"{g.label} ({g.mix_ratio}): {p.batch_reason}; pot life {g.pot_life_min:g} min, "
                    f"cure {g.cure_h_room:g} h at 23 C or <= {mold.max_cure_c:g} C in {mold.label} molds",
                    "")]


FDM_OVERHANG_DEG = 90.0 - FDM_THETA_MIN_DEG
"""Steepest bore-ceiling overhang (from vertical) the mount prints without support on FDM: 30°, the needle angle
PrusaSlicer was measured to need no support at (:data:`matcad.parts.coupon.FDM_THETA_MIN_DEG`), not the
45° rule of thumb it still supported at."""


def bore_overhang(spec) -> list[Finding]:
    """The needle bore's ceiling overhangs by 90° − θ from vertical in the mount's print pose (flat face down)."""
    overhang = 90.0 - spec.needle.theta_deg
    if spec.outputs.needle_mount and spec.machine.printer == "fdm" and overhang > FDM_OVERHANG_DEG:
        return [Finding("print.bore_overhang", "warning", overhang, FDM_OVERHANG_DEG,
                        f"needle_mount: at theta = {spec.needle.theta_deg:g} deg the bore's ceiling overhangs "
                        f"{overhang:g} deg from vertical: FDM sags it (or the slicer fills it with support)",
                        "print with supports and drill the bore to size, or print the mount on an SLA printer")]
    return []


def sla_inhibition(spec) -> list[Finding]:
    if not (spec.outputs.end_cap_mold and spec.machine.printer == "sla"):
        return []
    return [Finding("mold.cure_inhibition", "warning", "sla", "post-cured or barrier-coated",
                    MOLD_MATERIALS["sla"].inhibition, "post-cure the SLA mold fully, or barrier-coat it; "
                    "cast a test drop")]


def _volume_mm(spec) -> tuple[float, float, float]:
    m = spec.machine
    return m.print_volume_x, m.print_volume_y, m.print_volume_z


def _oversize(spec) -> list:
    """The printed parts ``spec`` asks for that do not fit the build volume: (part, its extent in mm)."""
    volume = _volume_mm(spec)
    return [(p, p.extent(spec)) for p in wanted(spec, Kind.PRINTED) if not fits_bed(p.extent(spec), volume)]


def _caps_that_fit(spec) -> int:
    """The most caps per mold (mold.count, at most the spec's) whose mold base and lid fit the build volume; 0 when
    not even one does."""
    for count in range(spec.mold.count - 1, 0, -1):
        fewer = dataclasses.replace(spec, mold=dataclasses.replace(spec.mold, count=count))
        if not any(p.flag == "end_cap_mold" for p, _ in _oversize(fewer)):
            return count
    return 0


def print_bed(spec) -> list[Finding]:
    """Every printed part, as its print pose's bounding box (:attr:`matcad.parts.registry.Part.extent`, the
    arithmetic its solid is made of), must fit the printer's build volume (``machine.print_volume_x/y/z``), turned
    either way round on the bed: a part that does not fit cannot be printed."""
    volume = _volume_mm(spec)
    out = []
    for part, (x, y, z) in _oversize(spec):
        fit = _caps_that_fit(spec) if part.flag == "end_cap_mold" else 0
        fix = (f"set mold.count = {fit} (the most caps per mold that fit; pour it more often), or " if fit else "")
        out.append(Finding("print.bed", "error", [round(x, 3), round(y, 3), round(z, 3)], list(volume),
                           f"{part.name}: {x:.1f} x {y:.1f} x {z:.1f} mm in its print pose does not fit the "
                           f"printer's build volume machine.print_volume_x/y/z = {volume[0]:g} x {volume[1]:g} x "
                           f"{volume[2]:g} mm (either way round on the bed)",
                           fix + "enter a printer with a larger build volume (machine.print_volume_x/y/z)"))
    return out


RULES = (printable_walls, key_clearance, fill_and_vents, cap_wall, silicone_batch, sla_inhibition, bore_overhang,
         cavity_appendages, clamp_nut, print_bed)
TAXEL_RULES = (fill_and_vents, cap_wall, bore_overhang)
INFO_RULES = (silicone_batch,)
"""Rules that only inform (level ``info``, never error or warning): a sweep, which counts errors and warnings, does
not run them."""
"""The rules that read one taxel's own geometry: a board runs them on each taxel (:func:`matcad.rules.check`)."""
