"""What to measure, make and assemble, in order: the fabrication plan the report renders (pure data, mm).

Sheets first (they decide the flange the mold casts), then cutting, printing, casting, assembly. Every step
names its sheet or file, so report.md/report.html read as a checklist. Read from the laser parts the build cut
(``flats``), not made again.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from matcad.acoustics.uncertainty import sheet_tolerance_mm
from matcad.parts.registry import Kind, wanted
from matcad.parts.stack import squeeze_range_mm

if TYPE_CHECKING:
    from matcad.parts.flat import Flat
    from matcad.spec import Spec

WHY_CALIPER = {
    "neck_plate": "its thickness is the neck length l, which sets f",
    "guide_locator": "the cap's flange is cast to this thickness + the squeeze: measure BEFORE printing the mold",
    "guide_clamp": "same sheet as the locator",
    "spacer": "sets the gap under the neck mouth (the jet path)",
}


def sheets_to_caliper(flats: list[Flat]) -> list[dict]:
    """Each sheet of the laser parts ``flats`` once: thickness, tolerance (mm), whether it is marked measured, and
    why it matters."""
    rows, seen = [], set()
    for flat in flats:
        if flat.thickness in seen:  # parts listed plate, guides, spacer: a shared sheet keeps its first use
            continue
        seen.add(flat.thickness)
        rows.append({"sheet_mm": flat.thickness, "part": flat.name, "measured": flat.thickness_measured,
                     "tolerance_mm": sheet_tolerance_mm(flat.thickness, flat.thickness_measured),
                     "before_mold": flat.name.startswith("guide"), "why": WHY_CALIPER.get(flat.name, "")})
    return rows


def seal(spec: Spec) -> dict:
    """Flange squeeze over the guide sheet's tolerance (mm), as the rule ``seal.squeeze`` judges it."""
    lo, hi, tol = squeeze_range_mm(spec)
    return {"flange_squeeze_mm": spec.end_cap.flange_squeeze, "guide_sheet_mm": spec.guide.thickness,
            "guide_measured": spec.guide.thickness_measured, "sheet_tolerance_mm": tol,
            "squeeze_low_mm": lo, "squeeze_high_mm": hi}


def fits(spec: Spec, flats: list[Flat]) -> list[dict]:
    """The fits the kit relies on, as designed (mm): hole, what goes in it, and the clearance claimed (diametral;
    negative = interference), the locator's hole read from the laser parts ``flats``. Each names the files a check
    reads it back from."""
    from matcad.parts.features import SELF_TAP_PILOT_MM, bolt_nominal_mm, pin_hole_diameter_mm
    from matcad.spec import cap_flange_diameter_mm

    rows = []
    if spec.outputs.end_cap_mold:
        k = spec.mold.key_diameter
        rows.append({"id": "key", "fit": "mold key in lid socket (at the parting plane)",
                     "hole_mm": k + 2 * spec.machine.key_clearance, "pin_mm": k, "clearance_mm": 2 * spec.machine.key_clearance,
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


def steps(spec: Spec, caliper: list[dict]) -> list[dict]:
    """The kit made and assembled in order: each step with what to do, on which sheet or machine, which files;
    ``caliper`` is :func:`sheets_to_caliper` of the laser parts."""
    from matcad.parts.features import SHEETS, sheet_kerf_mm, sheet_thickness_mm

    o, out = spec.outputs, []

    def step(where: str, files: list[str], do: str) -> None:
        out.append({"where": where, "files": files, "do": do})

    unmeasured = [c for c in caliper if not c["measured"]]
    step("calipers", [], "Caliper every sheet (table above) in several places; enter the values (neck.length, "
         "guide.thickness, spacer.height), set *_measured = true and rebuild"
         + (f" — still nominal: {', '.join(str(c['sheet_mm']) + ' mm' for c in unmeasured)}" if unmeasured else ""))
    step("laser + printer", ["matcad coupon"], "Cut one coupon per sheet (coupon_<sheet>.dxf) and print "
         "coupon_printed.stl; set each sheet's laser_kerf from the hole that fits its pin, and the needle/dowel "
         "fits from the printed bores; rebuild")
    cuts: dict[str, list[str]] = {}
    for part in wanted(spec, Kind.LASER):
        cuts.setdefault(part.sheet, []).append(f"{part.name}.dxf")
    for sheet, files in cuts.items():
        t, _ = sheet_thickness_mm(spec, sheet)
        step(f"laser, {t:g} mm acrylic", files, f"Cut the {SHEETS[sheet]} from the {t:g} mm sheet, kerf "
             f"{sheet_kerf_mm(spec, sheet):g} mm (already compensated in the file: cut on the line; inner "
             "cuts first, engraving as score)")
    if o.neck_plate and spec.plate.neck_pilot:
        step("drill", ["neck_plate.dxf"], f"Drill the neck pilot to {spec.neck.diameter:g} mm (drill press, "
             "plate clamped flat, back it with scrap)")
    printed = [f"{part.name}.stl" for part in wanted(spec, Kind.PRINTED)]
    if printed:
        step(f"printer ({spec.machine.printer})", printed, "Print each part as exported (flat face down, no "
             "supports; the report's mesh table gives each part's bed face)")
    if o.end_cap_mold:
        step("bench", ["end_cap_mold_base.stl", "end_cap_mold_lid.stl"], "Cast the caps: follow the casting guide")
    if o.needle_mount:
        step("bench", ["needle_mount.stl"], "Fix the mount by its ears (4 x M3) to the bench or robot; press the "
             f"dowels into it; slide the needle up the bore until its tip stands out of the top face as the BOM "
             "states; fix the hub")
    stack = "spacers (spacer.dxf) over the bolt holes, " if spec.spacer.style == "laser" else ""
    step("bench", ["neck_plate.dxf", "guide_locator.dxf", "guide_clamp.dxf"], f"Stack on the mount: {stack}"
         "the neck plate, the locator guide; seat the cap in the locator, base face down on the plate; lay the "
         f"clamp guide over its flange; {spec.fasteners.bolt} bolts through all layers into the mount, tightened "
         "evenly until the clamp sits on the locator (that closes the flange squeeze)")
    step("bench", ["report.md"], "Blow air through the needle and record: the tone should sit in the predicted "
         "band; calibrate with `matcad calibrate`")
    return out


def fabrication(spec: Spec, flats: list[Flat]) -> dict:
    """The report's fabrication section for the laser parts ``flats``: sheets to caliper, the seal, the fits, the
    ordered steps."""
    caliper = sheets_to_caliper(flats)
    return {"caliper": caliper, "seal": seal(spec), "fits": fits(spec, flats), "steps": steps(spec, caliper)}
