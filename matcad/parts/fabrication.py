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


def fabrication(spec) -> dict:
    """The report's fabrication section: sheets to caliper, the seal."""
    return {"caliper": sheets_to_caliper(spec), "seal": seal(spec)}
