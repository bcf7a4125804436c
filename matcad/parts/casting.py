"""How to cast the caps in the printed mold: batch, pot life, cure by mold material, release, fill order, sprues.

Material numbers come from :mod:`matcad.materials` (manufacturers' data sheets); mold-material limits and the
platinum cure-inhibition advice are shop practice with the sources named in ``docs/materials.md``. Masses in g,
volumes in ml, temperatures in °C, times in minutes or hours as named.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

from matcad.materials import grade
from matcad.parts.features import cap_volume_mm3
from matcad.parts.mold_layout import layout, mold_slots
from matcad.parts.print_profile import PRINT_FILE

if TYPE_CHECKING:
    from matcad.spec import Spec

MIN_BATCH_G = 10.0
"""Smallest mix worth weighing: on a 0.01 g kitchen/lab scale each part of a 1:1 mix is then weighed to ±0.2 %
(of a 10:1 mix, the 0.9 g curing agent to ±1 %), and the 1–2 g that stays on the cup and stick is a small
fraction. A 0.5 g mix is all cup residue and cannot be ratioed reliably (off-ratio platinum silicone stays
tacky)."""


@dataclass(frozen=True)
class MoldMaterial:
    """A printed mold's material: its name, the warmest cure it stands (°C) and why, and whether it inhibits a
    platinum cure (empty when it does not)."""

    label: str
    max_cure_c: float
    note: str
    inhibition: str = ""


MOLD_MATERIALS = {
    "fdm": MoldMaterial("PLA (FDM)", 45.0, "PLA softens near its glass transition (~55–60 °C): a warm cure must "
                        "stay ≤ 45 °C or the core pins droop"),
    "sla": MoldMaterial("SLA resin", 45.0, "standard SLA resins soften from ~50 °C (heat deflection 50–70 °C): stay "
                        "≤ 45 °C unless the resin's data sheet allows more",
                        "platinum-cure silicone (Dragon Skin, Ecoflex, Sylgard 184) may stay tacky against SLA "
                        "resin: uncured photoinitiator and monomer inhibit the platinum catalyst. Wash the mold "
                        "in IPA, post-cure it fully (UV, then ~2 h at 45 °C or the resin maker's schedule), or "
                        "seal it with a barrier coat (clear acrylic lacquer); cast a test drop first and check "
                        "it cures tack-free where it touched the resin"),
}
"""What the printed mold's material allows; keyed by ``machine.printer``."""

RELEASE_AGENT = ("Mann Ease Release 200 (or another release for silicone-on-plastic), a light coat on the base, "
                 "lid and core pins, dry 10 min; the core pins are thin: do not skip it")


@dataclass(frozen=True)
class CastingGuide:
    """One pour: masses (g), times, temperatures, and the procedure as ordered steps."""

    grade: str
    mold_material: str
    caps: int
    cast_volume_ml: float
    needed_g: float
    batch_g: float
    batch_reason: str
    mix_ratio: str
    pot_life_min: float
    cure_h_room: float
    max_cure_c: float
    cure_note: str
    release: str
    inhibition: str
    vents_per_cap: int
    steps: tuple[str, ...]
    trim: tuple[str, ...]

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Pour:
    """One pour of the mold: its caps, their cast volume (ml), the mass they need with the waste factor and the
    batch to mix (g), and why that batch."""

    caps: int
    cast_volume_ml: float
    needed_g: float
    batch_g: float
    batch_reason: str


def pour(spec: Spec) -> Pour:
    """The pour of ``spec``'s ``mold.count`` caps (:func:`matcad.parts.mold_layout.mold_slots`): batch = max(cast
    volume × waste factor × density, :data:`MIN_BATCH_G`) (g). It needs no mold layout: a kit without a mold (a
    laser-only build) still buys and mixes its silicone."""
    from matcad.spec import taxel_spec, taxels

    caps = spec.mold.count
    volumes = [cap_volume_mm3(taxel_spec(spec, t)) for t in mold_slots(taxels(spec), caps)]
    cast_ml = (volumes[0] * caps if len(set(volumes)) == 1 else sum(volumes)) / 1000
    needed = cast_ml * spec.silicone.waste_factor * spec.silicone.density_g_cm3
    batch = max(needed, MIN_BATCH_G)
    reason = (f"the caps need {needed:.2f} g (x{spec.silicone.waste_factor:g} for cup, sprues and vents); mix at "
              f"least {MIN_BATCH_G:g} g so the ratio can be weighed on a 0.01 g scale and cup residue does not eat "
              "the batch" if needed < MIN_BATCH_G else f"the caps need {needed:.2f} g with x{spec.silicone.waste_factor:g} "
              "for cup, sprues and vents")
    return Pour(caps, cast_ml, needed, batch, reason)


def casting_guide(spec: Spec, jobs: tuple[str, ...] = ()) -> CastingGuide:
    """The pour for ``spec`` (:func:`pour`) and how to make it in the mold laid out for it. ``jobs`` are the 3MF
    files written that hold the mold halves (named in the print step; before a build, the printer's job file and
    its numbered siblings)."""
    from matcad.spec import taxels

    g = grade(spec.silicone.grade)
    mold = MOLD_MATERIALS[spec.machine.printer]
    p = pour(spec)
    lay = layout(spec)
    vents = len(lay.plan.inner) + len(lay.plan.outer)
    c = lay.clamp
    nuts = (f"the {len(lay.bolts)} captive {c.bolt} nuts in the base (pressed into the traps under it after "
            "printing)" if c.open_below else f"the {len(lay.bolts)} {c.bolt} nuts the base print captured at its pause")
    board = len(taxels(spec)) > 1
    held_by = (f"{' and '.join(jobs)} {'hold' if len(jobs) > 1 else 'holds'}" if jobs else
               f"{PRINT_FILE.format(printer=spec.machine.printer)}, or its _1, _2, ... files when the parts take "
               "more than one bed, holds")
    steps = (
        f"Print the mold ({mold.label}): end_cap_mold_base and end_cap_mold_lid as exported "
        f"({held_by} them oriented with their settings; or the STLs, flat face down, no supports). Clear every "
        f"vent with a {spec.mold.vent:g} mm drill or pin.",
        *(("SLA: post-cure the printed mold fully, or barrier-coat it, and cast a test drop (cure inhibition, "
           "above).",) if mold.inhibition else ()),
        f"Release: {RELEASE_AGENT}.",
        "Close the mold: lid on the base, the keys in their ribbed sockets"
        + (" (the taxel names on the lid and the base side by side)" if board else "")
        + f"; {len(lay.bolts)} x {c.bolt} x {c.length_mm or 0:g} mm bolts through the lid into {nuts}, finger-tight "
        "and even until the lid sits on the base; the mold stands flat on its base: set it level, fill ports up.",
        f"Weigh {p.batch_g:.1f} g of {g.label} ({g.mix_ratio}), mix 3 min scraping sides and bottom, degas in vacuum "
        f"if you can; pot life {g.pot_life_min:g} min at 23 °C.",
        f"Fill each cap through its {spec.mold.fill_port:g} mm fill port with a syringe, slowly, one cap at a time: "
        "the silicone runs down the body wall to the bottom of the pocket (the membrane) and rises round the core "
        "pin, pushing the air ahead of it up and out through the vents; air under the pin's end escapes round its "
        f"rim and up its side. The cap is full when silicone stands in every one of its {vents} vents; top the "
        "port up as the level settles.",
        f"Cure {g.cure_h_room:g} h at room temperature (23 °C), or warm at most {mold.max_cure_c:g} °C: "
        f"{mold.note}.",
        "Demold: remove the bolts, lift the lid straight up (the core pins slide out of the cavities, the sprues out "
        "of the lid), then push each cap out of the base by its flange"
        + ("; keep each cap with the taxel name recessed beside its pocket until it is seated in its locator hole"
           if board else "") + ".",
    )
    sprues = vents + 1
    trim = (
        f"{sprues} sprues per cap (the fill port's and {vents} vents') stand on the cap's base face, the face that "
        "seals on the neck plate: lay the cap base face up on the bench, rest a fresh scalpel blade (No. 10 or 11) "
        "flat on the face and slice each sprue off in one stroke at its root; then press the face on a glass "
        "plate: it must sit flat with no nub (a nub holds the flange off the plate and the cavity leaks)",
        "nothing to trim inside the cavity: the core pin has no vent, so the membrane's inside is clean",
    )
    return CastingGuide(grade=g.label, mold_material=mold.label, caps=p.caps, cast_volume_ml=p.cast_volume_ml,
                        needed_g=p.needed_g, batch_g=p.batch_g, batch_reason=p.batch_reason, mix_ratio=g.mix_ratio,
                        pot_life_min=g.pot_life_min, cure_h_room=g.cure_h_room, max_cure_c=mold.max_cure_c,
                        cure_note=mold.note, release=RELEASE_AGENT, inhibition=mold.inhibition,
                        vents_per_cap=vents, steps=steps, trim=trim)
