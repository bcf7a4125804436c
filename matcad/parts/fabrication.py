"""What to measure, make and assemble, in order: the fabrication plan the report renders (pure data, mm).

Sheets first (they decide the flange the mold casts), then cutting, printing, casting, assembly. Every step
names its sheet or file, so report.md/report.html read as a checklist.
"""

from __future__ import annotations

from matcad.acoustics.uncertainty import sheet_tolerance_mm
from matcad.parts.catalogue import laser_parts

WHY_CALIPER = {
    "neck_plate": "its thickness is the neck length l, which sets f",
    "guide_locator": "the cap's flange is cast to this thickness + the squeeze: measure BEFORE printing the mold",
    "guide_clamp": "same sheet as the locator",
    "spacer": "sets the gap under the neck mouth (the jet path)",
}


def sheets_to_caliper(spec) -> list[dict]:
    """Each laser sheet once: thickness, tolerance (mm), whether it is marked measured, and why it matters."""
    rows, seen = [], set()
    for flat in laser_parts(spec):
        if flat.thickness in seen:  # parts listed plate, guides, spacer: a shared sheet keeps its first use
            continue
        seen.add(flat.thickness)
        rows.append({"sheet_mm": flat.thickness, "part": flat.name, "measured": flat.thickness_measured,
                     "tolerance_mm": sheet_tolerance_mm(flat.thickness, flat.thickness_measured),
                     "before_mold": flat.name.startswith("guide"), "why": WHY_CALIPER.get(flat.name, "")})
    return rows


def seal(spec) -> dict:
    """Flange squeeze over the guide sheet's tolerance (mm), as the rule ``seal.squeeze`` judges it."""
    from matcad.rules.stack import squeeze_range_mm

    lo, hi, tol = squeeze_range_mm(spec)
    return {"flange_squeeze_mm": spec.end_cap.flange_squeeze, "guide_sheet_mm": spec.guide.thickness,
            "guide_measured": spec.guide.thickness_measured, "sheet_tolerance_mm": tol,
            "squeeze_low_mm": lo, "squeeze_high_mm": hi}


def fits(spec) -> list[dict]:
    """The fits the kit relies on, as designed (mm): hole, what goes in it, and the clearance claimed (diametral;
    negative = interference). Each names the files a check reads it back from."""
    from matcad.parts.features import (SELF_TAP_PILOT_MM, bolt_nominal_mm, cap_flange_diameter_mm,
                                       pin_hole_diameter_mm)
    from matcad.parts.guide import guide

    rows = []
    if spec.outputs.end_cap_mold:
        k = spec.mold.key_diameter
        rows.append({"id": "key", "fit": "mold key in lid socket (at the parting plane)",
                     "hole_mm": k + 2 * spec.machine.key_clearance, "pin_mm": k, "clearance_mm": 2 * spec.machine.key_clearance,
                     "files": ["end_cap_mold_lid.stl", "end_cap_mold_base.stl"]})
    if spec.outputs.guides:
        hole = next(h for h in guide(spec, "locator").holes if h.purpose == "cap").diameter
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


def fabrication(spec) -> dict:
    """The report's fabrication section: sheets to caliper, the seal, the fits."""
    return {"caliper": sheets_to_caliper(spec), "seal": seal(spec), "fits": fits(spec)}
