"""The report's data (report.json): resolved spec, as-built geometry, prediction, findings, BOM, casting,
fabrication plan, file manifest. Lengths in mm, volumes in mm³, masses in g.

Built from what the build already made — the laser parts it cut, the mold's layout — rather than making them
again.
"""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING

from matcad import __version__
from matcad.acoustics.geometry import drafted_cavity_volume_mm3, drafted_tip_diameter_mm
from matcad.parts.features import (SHEET_STATUSES, bolt_nominal_mm, cap_volume_mm3, plate_bolt_positions_mm,
                                   plate_dowel_positions_mm, sheet_kerf_mm, sheet_status)
from matcad.parts.print_profile import PRINT_FILE
from matcad.parts.stack import bolt_span_mm
from matcad.report.fabrication import fabrication
from matcad.report.files import manifest
from matcad.spec import cap_flange_thickness_mm, neck_length_mm, to_dict

if TYPE_CHECKING:
    from matcad.parts.flat import Flat
    from matcad.parts.mold_layout import MoldLayout

HUB_CLEARANCE_MM = 3.0
"""Needle left below the mount's underside so the hub clears it."""
THREAD_ENGAGEMENT_PER_D = 2.0
"""Self-tapping screws into printed plastic want ~2 x diameter of engagement."""


def as_built(spec) -> dict:
    """Geometry as it will be made: drafted cavity, neck as cut and as finished, its length through the plate (and
    the riser it runs on through), and the [riser] when there is one (:func:`riser_sheet`) (mm, mm³)."""
    cav = spec.cavity
    pilot = spec.plate.neck_pilot
    riser = {"riser": riser_sheet(spec)} if spec.riser is not None else {}
    return {
        "cavity_diameter_mm": cav.diameter, "cavity_length_mm": cav.length, "draft_deg": spec.mold.draft_deg,
        "cavity_tip_diameter_mm": float(drafted_tip_diameter_mm(cav.diameter, cav.length, spec.mold.draft_deg)),
        "cavity_volume_mm3": float(drafted_cavity_volume_mm3(cav.diameter, cav.length, spec.mold.draft_deg)),
        "draft_volume_change_pct": 100 * float(drafted_cavity_volume_mm3(cav.diameter, cav.length, spec.mold.draft_deg)
                                               / drafted_cavity_volume_mm3(cav.diameter, cav.length, 0.0) - 1),
        "neck_diameter_as_cut_mm": spec.neck.diameter - spec.plate.pilot_undersize if pilot else spec.neck.diameter,
        "neck_diameter_finished_mm": spec.neck.diameter,
        "neck_finish": "drill pilot to size" if pilot else "as cut (kerf compensated)",
        "neck_length_mm": neck_length_mm(spec), "neck_length_measured": spec.plate.thickness_measured,
        "laser_kerf_mm": sheet_kerf_mm(spec, "plate"),
        "cap_volume_mm3": cap_volume_mm3(spec),
    } | riser


def taxel_stack(spec, t) -> dict:
    """Where the taxel ``t`` (a :class:`matcad.spec.Taxel`) sits in a stack with a [riser]: its neck's length (the
    plate's sheet, and the riser's where it runs on through it), the face its cap sits on ('riser' or 'plate', in a
    pocket of the riser) and its cap's flange thickness (mm)."""
    return {"neck_length_mm": neck_length_mm(spec, t), "cap_seat": "riser" if t.neck.riser else "plate",
            "cap_flange_thickness_mm": cap_flange_thickness_mm(spec, t)}


def riser_sheet(spec) -> dict:
    """The [riser] sheet as built (mm): its thickness and status, its kerf, the taxels whose necks run on through it,
    those whose caps sit in its pockets, and every taxel's place in the stack (:func:`taxel_stack`)."""
    from matcad.spec import taxels

    board = taxels(spec)
    return {"thickness_mm": spec.riser.thickness, "status": sheet_status(spec, "riser"),
            "laser_kerf_mm": sheet_kerf_mm(spec, "riser"), "through": [t.name for t in board if t.neck.riser],
            "pocketed": [t.name for t in board if not t.neck.riser],
            "taxels": [{"name": t.name} | taxel_stack(spec, t) for t in board]}


def bill_of_materials(spec, flats: list[Flat], mold: MoldLayout | None) -> dict:
    """Sheets, silicone, drills, pins, bolts and needles for the kit (the silicone as the casting guide pours it);
    ``flats`` are the laser parts the build cut, ``mold`` the mold's layout when it builds one (else None). Fasteners
    come as the stock length to buy (ISO 4762 screws, ISO 8734 dowels) with the length the stack needs."""
    from matcad.parts.features import ISO_4762_LENGTHS_MM, ISO_8734_LENGTHS_MM, stock_length_mm

    sheets = defaultdict(lambda: {"parts": [], "area_mm2": 0.0, "measured": False, "status": "measured"})
    for flat in flats:
        s = sheets[flat.thickness]
        s["parts"].append(f"{flat.quantity} x {flat.name}")
        s["area_mm2"] += flat.area_mm2 * flat.quantity
        s["measured"] = s["measured"] or flat.thickness_measured
        s["status"] = max(s["status"], flat.thickness_status, key=SHEET_STATUSES.index)
    stack = bolt_span_mm(spec)
    bolt_d = bolt_nominal_mm(spec.fasteners.bolt)
    engage = min(THREAD_ENGAGEMENT_PER_D * bolt_d, spec.mount.thickness)
    bolt_len = stock_length_mm(stack + engage, ISO_4762_LENGTHS_MM)
    dowel_len = stock_length_mm(stack + engage, ISO_8734_LENGTHS_MM)
    return {
        "sheets": [{"thickness_mm": t, **v} for t, v in sorted(sheets.items())],
        "silicone": silicone_bom(spec),
        "drills": drill_bom(spec),
        "dowels": {"count": len(plate_dowel_positions_mm(spec)), "diameter_mm": spec.fasteners.dowel_diameter,
                   "min_length_mm": stack + engage, "length_mm": dowel_len, "standard": "ISO 8734"},
        "bolts": {"count": len(plate_bolt_positions_mm(spec)), "size": spec.fasteners.bolt,
                  "min_length_mm": stack + engage, "length_mm": bolt_len, "standard": "ISO 4762",
                  "into_mount_mm": None if bolt_len is None else bolt_len - stack,
                  "note": f"self-tapping into the printed mount ({spec.mount.thickness:g} mm)"},
        "spacers": ({"count": len(plate_bolt_positions_mm(spec)), "style": "laser",
                     "note": f"{spec.spacer.size:g} mm squares cut from {spec.spacer.height:g} mm sheet"}
                    if spec.spacer.style == "laser" else
                    {"count": len(plate_bolt_positions_mm(spec)), "style": "standoff",
                     "note": f"printed on the needle mount, {spec.spacer.height:g} mm tall"}),
        "needle": needle_bom(spec),
        **kit_hardware(spec, mold),
    }


def silicone_bom(spec) -> dict:
    """The silicone to buy and mix, the same numbers the casting guide pours (g, ml, mm³): per distinct cap its
    taxels, volume and mass, then one pour of the mold (:func:`matcad.parts.casting.pour`)."""
    from matcad.parts.casting import pour
    from matcad.parts.mold_layout import cap_groups
    from matcad.spec import taxel_spec, taxels

    p = pour(spec)
    rho = spec.silicone.density_g_cm3
    caps = []
    for group in cap_groups(taxels(spec)):
        v = cap_volume_mm3(taxel_spec(spec, group[0]))
        caps.append({"taxels": [t.name for t in group], "cap_volume_mm3": v, "cap_mass_g": v / 1000 * rho})
    return {"caps": caps, "cap_volume_mm3": caps[0]["cap_volume_mm3"], "cap_mass_g": caps[0]["cap_mass_g"],
            "caps_per_pour": p.caps, "cast_volume_ml": p.cast_volume_ml, "needed_mass_g": p.needed_g,
            "batch_mass_g": p.batch_g, "batch_ml": p.batch_g / rho, "density_g_cm3": rho}


def drill_bom(spec) -> list[dict]:
    """One twist drill per finished neck size, with the taxels it drills (mm); empty when the necks are cut to
    size. Metric jobber drills (DIN 338) come in 0.1 mm steps: a size off that grid says so."""
    from matcad.parts.neck_plate import drill_plan

    sizes: dict[float, list[str]] = {}
    for row in drill_plan(spec):
        sizes.setdefault(round(row["drill_mm"], 4), []).append(row["taxel"])
    return [{"diameter_mm": d, "taxels": names, "standard": abs(d * 10 - round(d * 10)) < 1e-6}
            for d, names in sorted(sizes.items())]


def casting(spec, mold: MoldLayout | None, job: dict | None = None) -> dict | None:
    """The pour guide and the venting of the mold laid out as ``mold`` (mm, g, min, h, °C), naming the files of
    the print ``job`` that hold the mold halves; None without a mold."""
    if mold is None:
        return None
    from matcad.parts.casting import casting_guide
    from matcad.parts.mold_layout import appendages

    plan = mold.plan
    jobs = tuple(f["file"] for f in (job or {}).get("files", ())
                 if any(o["name"].startswith("end_cap_mold_") for o in f["objects"]))
    out = casting_guide(spec, jobs).to_dict() | {"venting": {
        "vent_reach_mm": spec.mold.vent_reach, "base_face_reach_mm": plan.reach_base_mm,
        "pin_end_reach_mm": plan.reach_tip_mm, "base_face_vents_per_cap": len(plan.inner) + len(plan.outer),
        "pin_vents_per_cap": 0, "vent_diameter_mm": spec.mold.vent}, "appendages": appendages(spec, mold)}
    from matcad.spec import is_array, taxels

    if is_array(spec):  # which caps each mold holds, and how many pours (or molds) one board takes
        from matcad.parts.mold_layout import pours_per_board

        out["molds"] = pours_per_board(taxels(spec), spec.mold.count)
    return out


def needle_bom(spec) -> dict:
    """The needle to buy and how deep it goes (mm); a board needs one per taxel, each on its own air line (the
    mount offers no manifold), and its per-taxel needle rows sit in report.json's ``taxels``."""
    from matcad.parts.features import nearest_needle_gauge, needle_protrusion_mm, needle_tip_mm
    from matcad.spec import taxels

    gauge, od = nearest_needle_gauge(spec.needle.outer_diameter)
    sin_t = math.sin(math.radians(spec.needle.theta_deg))
    through = (needle_tip_mm(spec)[2] + spec.spacer.height + spec.mount.thickness) / sin_t
    count = len(taxels(spec))
    board = (f" A board takes {count} needles, one bore per taxel; the mount has no manifold: feed each needle "
             "from its own regulated air line (or a splitter with a valve per line) so every jet can be set "
             "alone" if count > 1 else "")
    from matcad.parts.features import NEEDLE_LENGTHS_MM, stock_length_mm

    return {"count": count, "outer_diameter_mm": spec.needle.outer_diameter, "theta_deg": spec.needle.theta_deg,
            "y_mm": spec.needle.y, "gauge": gauge, "gauge_od_mm": od, "hub": "Luer-lock hub, blunt (dispensing) tip",
            "min_length_mm": through + HUB_CLEARANCE_MM,
            "length_mm": stock_length_mm(through + HUB_CLEARANCE_MM, NEEDLE_LENGTHS_MM),
            "protrusion_mm": needle_protrusion_mm(spec),
            "note": f"nearest standard: {gauge} G ({od:.3f} mm, ISO 9626); measure yours and enter "
                    "needle.outer_diameter. Push it up the bore until its tip stands the stated protrusion out of "
                    "the mount's top face (along the needle; a caliper depth rod), then fix the hub" + board}


def kit_hardware(spec, mold: MoldLayout | None) -> dict:
    """Mold clamp bolts and nuts (for the mold laid out as ``mold``, when there is one), release agent, mount
    fixing screws (mm)."""
    from matcad.parts.casting import RELEASE_AGENT
    from matcad.parts.features import EAR_THICKNESS_MM, FIXING_BOLT, ear_holes_mm

    out = {}
    if mold is not None:
        c = mold.clamp
        out["mold_clamp"] = {"count": len(mold.bolts), "size": spec.mold.bolt, "length_mm": c.length_mm,
                             "standard": "ISO 4762", "nuts": len(mold.bolts), "nut_standard": "ISO 4032",
                             "washers": len(mold.bolts),
                             "note": ("captive: press each nut into its hex trap under the base after printing"
                                      if c.open_below else "captive: the base print "
                                      f"({PRINT_FILE.format(printer='fdm')}) pauses when its "
                                      f"layers reach z = {c.pocket_top_z + mold.base_height:.2f} mm: drop each nut "
                                      "into its pocket, resume")}
        out["release_agent"] = RELEASE_AGENT
    if spec.outputs.needle_mount:
        out["mount_fixing"] = {"count": len(ear_holes_mm(spec)), "size": FIXING_BOLT,
                               "note": f"through the mount's ears ({EAR_THICKNESS_MM:g} mm) into a bench bracket or "
                                       "robot plate, on standoffs taller than the needle's hub"}
    return out


def make_report(spec, prediction, findings, holes, meshes, folder: Path, *, flats: list[Flat],
                mold: MoldLayout | None, job: dict | None = None) -> dict:
    """The report's data for ``spec`` built into ``folder``: ``holes`` as cut and ``meshes`` (STL read-back
    checks) from the writers, ``flats`` the laser parts cut, ``mold`` the mold's layout (None without a mold),
    ``job`` the print job written (:func:`matcad.build.write_print_job`, None without one)."""
    return {
        "matcad_version": __version__,
        "name": spec.name,
        "spec": to_dict(spec),
        "as_built": as_built(spec) | {"laser_holes": holes},
        "prediction": prediction.to_dict(),
        "findings": [f.to_dict() for f in findings],
        "verdict": "fail" if any(f.level == "error" for f in findings) else "pass",
        "bom": bill_of_materials(spec, flats, mold),
        "casting": casting(spec, mold, job),
        "fabrication": fabrication(spec, flats, job),
        "meshes": meshes,
        "files": manifest(folder),
    }
