"""Rules for the printed mold and mount: walls, key clearance, fill port and vents, cure, silicone batch."""

from __future__ import annotations

from matcad.parts.features import cap_volume_mm3
from matcad.rules import Finding

MIN_WALL_SLA_MM = 0.8
KEY_CLEARANCE_MIN_MM = {"fdm": 0.15, "sla": 0.05}
KEY_CLEARANCE_MAX_MM = 0.5
MIN_FILL_PORT_MM = 2.0
MIN_SILICONE_WALL_MM = 1.0


def _min_wall_mm(spec) -> float:
    return 2 * spec.machine.nozzle if spec.machine.printer == "fdm" else MIN_WALL_SLA_MM


def printable_walls(spec) -> list[Finding]:
    limit = _min_wall_mm(spec)
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
                           f"vents ({m.vent:g} mm) do not fit on the flange ring ({ring:g} mm), the cavity's "
                           "only high point in pour orientation: air would be trapped",
                           "reduce mold.vent or widen end_cap.flange_width"))
    elif spec.machine.printer == "fdm" and m.vent < 2 * spec.machine.nozzle:
        out.append(Finding("mold.vents", "warning", m.vent, 2 * spec.machine.nozzle,
                           f"{m.vent:g} mm vents may print closed with a {spec.machine.nozzle:g} mm nozzle",
                           "enlarge mold.vent or drill the vents open"))
    else:
        out.append(Finding("mold.vents", "info", m.vent, ring,
                           "3 vents per cap on the flange ring (the only ceiling in pour orientation), fill "
                           "port over the body wall", ""))
    return out


def cap_wall(spec) -> list[Finding]:
    wall = (spec.end_cap.outer_diameter - spec.cavity.diameter) / 2
    if wall < MIN_SILICONE_WALL_MM:
        return [Finding("cap.wall", "warning", round(wall, 4), MIN_SILICONE_WALL_MM,
                        f"silicone wall {wall:.2f} mm around the cavity tears on demolding and balloons "
                        "under blowing pressure", "raise end_cap.outer_diameter")]
    return []


def silicone_batch(spec) -> list[Finding]:
    cap = cap_volume_mm3(spec)
    cast = cap * spec.mold.count
    batch = cast * spec.silicone.waste_factor
    mass = batch / 1000 * spec.silicone.density_g_cm3
    return [Finding("silicone.batch", "info", round(batch / 1000, 4), None,
                    f"{spec.mold.count} cap(s) of {cap:.1f} mm^3 = {cast / 1000:.3f} ml cast; mix "
                    f"{batch / 1000:.3f} ml = {mass:.2f} g (x{spec.silicone.waste_factor:g} for cups and vents), "
                    "1A:1B by weight, degas; cure <= 45 C in PLA molds", "")]


RULES = (printable_walls, key_clearance, fill_and_vents, cap_wall, silicone_batch)
