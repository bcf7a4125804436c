"""What to measure, make and assemble, in order: the fabrication plan the report renders (pure data, mm).

Sheets first (they decide the flange the mold casts), then cutting, printing, casting, assembly. Every step
names its sheet or file, so report.md/report.html read as a checklist. Read from the laser parts the build cut
(``flats``), not made again.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from matcad.acoustics.uncertainty import sheet_tolerance_mm
from matcad.parts.features import sheet_row_key, sheet_status
from matcad.parts.print_profile import PRINT_FILE
from matcad.parts.registry import Kind, wanted
from matcad.parts.stack import squeeze_range_mm

if TYPE_CHECKING:
    from matcad.parts.flat import Flat
    from matcad.spec import Spec

WHY_CALIPER = {
    "neck_plate": "its thickness is the neck length l, which sets f",
    "guide_locator": "the cap's flange is cast to this thickness + the squeeze: measure BEFORE printing the mold",
    "guide_clamp": "same sheet as the locator",
    "riser": "it lengthens the necks run through it and thickens the pocketed caps' flanges: measure BEFORE printing "
             "the mold",
    "spacer": "sets the gap under the neck mouth (the jet path)",
}


def sheets_to_caliper(flats: list[Flat]) -> list[dict]:
    """Each sheet of the laser parts ``flats`` once: thickness, tolerance (mm), whether it is marked measured, and
    why it matters."""
    rows, seen = [], set()
    for flat in flats:
        if sheet_row_key(flat) in seen:  # parts listed plate, guides, spacer: a shared sheet keeps its first use
            continue
        seen.add(sheet_row_key(flat))
        status = flat.thickness_status
        rows.append({"sheet_mm": flat.thickness, "part": flat.name, "sheet": flat.sheet, "status": status,
                     "measured": status == "measured",
                     "tolerance_mm": sheet_tolerance_mm(flat.thickness, status == "measured"),
                     "before_mold": flat.sheet in ("guide", "riser"), "why": WHY_CALIPER.get(flat.name, "")})
    return rows


def seal(spec: Spec) -> dict:
    """Flange squeeze over the guide sheet's tolerance (mm), as the rule ``seal.squeeze`` judges it; for a
    template's example sheet also the range until the user calipers theirs (over the nominal tolerance). With a
    [riser], ``caps`` gives it per seat ('riser': caps whose necks run on through it; 'plate': caps in its
    pockets, over both sheets' tolerance), with the taxels and the flange thickness cast."""
    out = _squeeze(spec)
    if spec.riser is None:
        return out
    from matcad.spec import cap_flange_thickness_mm, taxel_spec, taxels

    seats: dict[str, list] = {}
    for t in taxels(spec):
        seats.setdefault("riser" if t.neck.riser else "plate", []).append(t)
    return out | {"caps": [{"seat": seat, "taxels": [t.name for t in group],
                            "flange_mm": cap_flange_thickness_mm(spec, group[0]),
                            "riser_sheet_mm": spec.riser.thickness} | _squeeze(taxel_spec(spec, group[0]))
                           for seat, group in seats.items()]}


def _squeeze(one: Spec) -> dict:
    """:func:`seal` of the cap of the single-taxel spec ``one`` (mm): unverified while a sheet its squeeze hangs on
    (the guide's; a pocketed cap's riser too) is a template's example."""
    from matcad.spec import in_pocket

    lo, hi, tol = squeeze_range_mm(one)
    n_lo, n_hi, n_tol = squeeze_range_mm(one, nominal=True)
    status = sheet_status(one, "guide")
    unverified = status == "example" or (in_pocket(one) and sheet_status(one, "riser") == "example")
    return {"flange_squeeze_mm": one.end_cap.flange_squeeze, "guide_sheet_mm": one.guide.thickness,
            "guide_measured": status == "measured", "guide_status": status, "sheet_tolerance_mm": tol,
            "squeeze_low_mm": lo, "squeeze_high_mm": hi,
            "unverified_low_mm": n_lo if unverified else None,
            "unverified_high_mm": n_hi if unverified else None,
            "nominal_tolerance_mm": n_tol}


def fits(spec: Spec, flats: list[Flat]) -> list[dict]:
    """The fits the kit relies on, as designed (mm): hole, what goes in it, and the clearance claimed (diametral;
    negative = interference), the locator's hole read from the laser parts ``flats``. Each names the files a check
    reads it back from."""
    from matcad.parts.features import SELF_TAP_PILOT_MM, bolt_nominal_mm, pin_hole_diameter_mm
    from matcad.spec import cap_flange_diameter_mm

    rows = []
    if spec.outputs.end_cap_mold:
        from matcad.parts.end_cap_mold import RIB_ANGLES_DEG

        k, c = spec.mold.key_diameter, spec.machine.key_clearance
        rows.append({"id": "key", "fit": f"mold key in lid socket (at the parting plane): {len(RIB_ANGLES_DEG)} crush "
                     f"ribs line-to-line with the key, {c:g} mm clearance per side between them; lid play 0",
                     "hole_mm": k, "pin_mm": k, "clearance_mm": 0.0, "socket_mm": k + 2 * c,
                     "files": ["end_cap_mold_lid.stl", "end_cap_mold_base.stl"]})
    if spec.outputs.guides:
        locator = next(flat for flat in flats if flat.name == "guide_locator")
        hole = next(h for h in locator.holes if h.purpose == "cap").diameter
        rows.append({"id": "flange", "fit": "cap flange in locator guide (line-to-line: the silicone centres "
                     "itself)", "hole_mm": hole, "pin_mm": cap_flange_diameter_mm(spec),
                     "clearance_mm": hole - cap_flange_diameter_mm(spec), "files": ["guide_locator.dxf", "end_cap.stl"]})
    if spec.outputs.needle_mount:
        bolt, pilot = bolt_nominal_mm(spec.fasteners.bolt), SELF_TAP_PILOT_MM[spec.fasteners.bolt]
        rows.append({"id": "pilot", "fit": f"{spec.fasteners.bolt} bolt self-tapping into the mount pilot", "hole_mm": pilot,
                     "pin_mm": bolt, "clearance_mm": pilot - bolt, "files": ["needle_mount.stl"]})
        bore = pin_hole_diameter_mm(spec.needle.outer_diameter, spec.machine.printer, spec.needle.fit)
        rows.append({"id": "needle", "fit": f"needle in its bore ({spec.needle.fit})", "hole_mm": bore,
                     "pin_mm": spec.needle.outer_diameter, "clearance_mm": bore - spec.needle.outer_diameter,
                     "files": ["needle_mount.step"]})
    return rows


SHEET_FILE = "sheet_{sheet}.dxf"
"""Every part cut from one acrylic sheet, nested (:mod:`matcad.export.sheets`)."""
SCALE_FILE = "sheets_1to1.pdf"
"""The sheets at 1:1 on paper, to check the scale before cutting (:mod:`matcad.export.pdf`)."""


def _drill_text(rows: list[dict]) -> str:
    if len(rows) == 1:
        r = rows[0]
        return f"Drill the neck pilot ({r['pilot_mm']:g} mm as cut) to {r['drill_mm']:g} mm"
    holes = "; ".join(f"{r['taxel']} {r['pilot_mm']:g} → {r['drill_mm']:g} mm" for r in rows)
    return (f"Drill each neck pilot to its own finished size, engraved beside it (\"t1 Ø…\"): {holes} — one drill "
            "per size (bill of materials); check each hole with the drill's shank before the next size")


def steps(spec: Spec, caliper: list[dict], print_files: list[str] = ()) -> list[dict]:
    """The kit made and assembled in order: each step with what to do, on which sheet or machine, which files;
    ``caliper`` is :func:`sheets_to_caliper` of the laser parts, ``print_files`` the 3MF print jobs written. A
    board's steps name its taxels as the parts are engraved."""
    from matcad.parts.features import SHEETS, sheet_kerf_mm, sheet_thickness_mm
    from matcad.parts.neck_plate import drill_plan
    from matcad.spec import taxels

    o, out = spec.outputs, []
    board = len(taxels(spec)) > 1
    riser = _riser_words(spec) if spec.riser is not None and o.neck_plate else None

    def step(where: str, files: list[str], do: str) -> None:
        out.append({"where": where, "files": files, "do": do})

    unmeasured = [c for c in caliper if c["status"] != "measured"]
    step("calipers", [], "Caliper every sheet (table above) in several places; enter the values (neck.length, "
         + ("riser.thickness, " if spec.riser is not None else "")
         + "guide.thickness, spacer.height), set *_measured = true (and *_example = false) and rebuild"
         + (" — still to caliper: " + ", ".join(f"{c['sheet_mm']:g} mm ({c['status']})" for c in unmeasured)
            if unmeasured else ""))
    step("laser + printer", ["matcad coupon"], "Cut one coupon per sheet (coupon_<sheet>.dxf) and print "
         "coupon_printed.stl; set each sheet's laser_kerf from the hole that fits its pin, and the needle/dowel "
         "fits from the printed bores; rebuild")
    cuts: dict[str, list[str]] = {}
    for part in wanted(spec, Kind.LASER):
        cuts.setdefault(part.sheet, []).append(f"{part.name}.dxf")
    for sheet, files in cuts.items():
        t, _ = sheet_thickness_mm(spec, sheet)
        step(f"laser, {t:g} mm acrylic", [SHEET_FILE.format(sheet=sheet), *files],
             f"Check the scale first ({SCALE_FILE} printed at 100 %: its 10 mm square measures 10.0 mm), then cut "
             f"the {SHEETS[sheet]} from the {t:g} mm sheet, all nested in {SHEET_FILE.format(sheet=sheet)}, kerf "
             f"{sheet_kerf_mm(spec, sheet):g} mm (already compensated in the file: cut on the line; engrave first, "
             "then the inner cuts, the outlines last)")
    if riser:
        step("bench", ["neck_plate.dxf", "riser.dxf"], riser["bond"])
    drills = drill_plan(spec)
    if drills:
        step("drill", ["neck_plate.dxf", *(["riser.dxf"] if riser else [])], _drill_text(drills)
             + (riser["drill"] if riser else "") + " (drill press, plate clamped flat, backed with scrap)")
    printed = [part for part in wanted(spec, Kind.PRINTED)]
    if printed:
        jobs = list(print_files) or [PRINT_FILE.format(printer=spec.machine.printer)]
        step(f"printer ({spec.machine.printer})", [*jobs, *(f"{part.name}.stl" for part in printed)],
             _print_text(spec, [part.name for part in printed], jobs))
    if o.end_cap_mold:
        step("bench", ["end_cap_mold_base.stl", "end_cap_mold_lid.stl"], "Cast the caps: follow the casting guide"
             + (riser["cast"] if riser else ""))
    if o.needle_mount:
        step("bench", ["needle_mount.stl"], "Fix the mount by its ears (4 x M3) to the bench or robot; press the "
             "dowels into it; slide " + ("each needle up the bore labelled with its taxel on the mount's top face "
                                         if board else "the needle up the bore ")
             + "until its tip stands out of the top face as the BOM states; fix the hub")
    stack = "spacers (spacer.dxf) over the bolt holes, " if spec.spacer.style == "laser" else ""
    seat = ("seat each cap in the locator hole engraved with its taxel, base face down on the plate"
            if board else "seat the cap in the locator, base face down on the plate")
    plate = "the neck plate"
    if riser:
        plate, seat = "the neck plate with the riser bonded on it", riser["seat"]
    step("bench", ["neck_plate.dxf", *(["riser.dxf"] if riser else []), "guide_locator.dxf", "guide_clamp.dxf"],
         f"Stack on the mount: {stack}{plate}, the locator guide; {seat}; lay the clamp guide over the flange"
         f"{'s' if board else ''}; {spec.fasteners.bolt} bolts through all layers into the mount, tightened "
         "evenly until the clamp sits on the locator (that closes the flange squeeze)")
    step("bench", ["report.md"], "Blow air through the needle and record: the tone should sit in the predicted "
         "band; calibrate with `matcad calibrate`")
    return out


def _riser_words(spec: Spec) -> dict[str, str]:
    """What the [riser] adds to the steps (mm): ``bond`` (a step of its own: the riser solvent-bonded on the plate
    on the dowels, before any neck is drilled), ``drill`` (each neck that runs on through it drilled through both
    sheets in one pass), ``cast`` (the pocketed caps' thicker flanges) and ``seat`` (where each cap sits)."""
    from matcad.spec import cap_flange_thickness_mm, taxels

    board = taxels(spec)
    through = [t for t in board if t.neck.riser]
    pocketed = [t for t in board if not t.neck.riser]

    def names(group) -> str:
        return ", ".join(t.name for t in group)

    cut = ("holes are undersize pilots in both sheets, drilled through both after bonding" if spec.plate.neck_pilot
           else "holes are cut to size in both sheets: before the cement sets, push a pin or drill shank of each "
           "neck's size through riser and plate together to check they line up")
    bond = (f"Bond the {spec.riser.thickness:g} mm riser (riser.dxf) on the neck plate before any neck is drilled: "
            "both on the two dowels through their dowel holes (they go together one way only), engraving up, "
            "pressed flat; run acrylic solvent cement (water-thin, e.g. Weld-On 4) into the joint along the outline "
            "with a needle applicator and let it wick between the sheets, keeping it out of the pockets' and necks' "
            f"edges (it crazes a cut edge); pull the dowels once it grips, let it cure 24 h. The through-neck "
            f"{cut}" + (f" ({names(through)})" if through else " (none: no neck runs through this riser)"))
    drill = (f"; {names(through)}: {'their necks run' if len(through) > 1 else 'its neck runs'} on through the "
             "bonded riser: drill through riser and plate in one pass from the riser's side, so the two holes "
             "cannot be offset" if through else "")
    drill += (f"; {names(pocketed)}: down through the plate at the bottom of {'their' if len(pocketed) > 1 else 'its'}"
              " riser pocket" if pocketed else "")
    cast = "".join(f"; {names(g)}: flange{'s' if len(g) > 1 else ''} cast {cap_flange_thickness_mm(spec, g[0]):g} "
                   f"mm thick ({what})" for g, what in ((pocketed, f"in the riser's pockets: {spec.riser.thickness:g}"
                                                         " mm thicker, down to the plate"), (through, "on the riser"))
                   if g)
    seat = ("seat each cap in the locator hole engraved with its taxel, base face down"
            + (f"; {names(pocketed)} down through the riser's pockets onto the plate" if pocketed else "")
            + (f"; {names(through)} on the riser" if through else ""))
    return {"bond": bond, "drill": drill, "cast": cast, "seat": seat}


def _print_text(spec: Spec, names: list[str], jobs: list[str]) -> str:
    """The print step: the 3MF job(s) with each part's settings, the captive nuts, the STL fallback."""
    from matcad.parts.mold_layout import layout
    from matcad.parts.print_profile import profile

    printer = spec.machine.printer
    parts = "; ".join(f"{n}: {p.layer_mm:g} mm layers, " + (f"{p.walls} walls, {p.infill_pct:g} % infill"
                                                            if p.walls else "solid")
                      for n in names for p in [profile(printer, n)])
    text = (f"Open {' then '.join(jobs)} in the slicer ({'one bed load each' if len(jobs) > 1 else 'one bed'}): "
            f"each part lies on its bed face, with its settings ({parts}; {profile(printer, names[0]).material})")
    if spec.outputs.end_cap_mold:
        lay = layout(spec)
        c = lay.clamp
        text += (f"; the mold base pauses when its layers reach {c.pocket_top_z + lay.base_height:.2f} mm: drop an "
                 f"{c.bolt} nut into each of its {len(lay.bolts)} hex pockets and resume (the next layer closes "
                 "them over the nuts)" if not c.open_below else
                 f"; after printing {lay.nut_insert}")
    return text + ". No supports: the STLs are the same parts in the same poses"


def fabrication(spec: Spec, flats: list[Flat], job: dict | None = None) -> dict:
    """The report's fabrication section for the laser parts ``flats`` and the print ``job`` written (its 3MF
    files): sheets to caliper, the seal, the fits, the ordered steps."""
    caliper = sheets_to_caliper(flats)
    return {"caliper": caliper, "seal": seal(spec), "fits": fits(spec, flats),
            "steps": steps(spec, caliper, [f["file"] for f in (job or {}).get("files", ())])}
