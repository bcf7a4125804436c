"""report.json and report.md: resolved spec, as-built geometry, prediction, findings, BOM, file manifest."""

from __future__ import annotations

import hashlib
import json
import math
from collections import defaultdict
from pathlib import Path

from matcad import __version__
from matcad.acoustics.geometry import drafted_cavity_volume_mm3, drafted_tip_diameter_mm
from matcad.parts.catalogue import laser_parts
from matcad.parts.features import (sheet_kerf_mm, bolt_nominal_mm, cap_volume_mm3, plate_bolt_positions_mm,
                                   plate_dowel_positions_mm)
from matcad.parts.fabrication import fabrication
from matcad.parts.stack import bolt_span_mm
from matcad.spec import to_dict

KIT_ARCHIVE = "kit.zip"
"""Every file of the build in one archive, written last."""
REPORT_FILES = ("report.json", "report.md", "report.html", KIT_ARCHIVE)
"""Written after the manifest: the reports, and the archive that holds everything."""
HUB_CLEARANCE_MM = 3.0
"""Needle left below the mount's underside so the hub clears it."""
NUT_HEIGHT_PER_D = 0.8
"""ISO 4032 hex nut height ≈ 0.8 d."""
THREAD_ENGAGEMENT_PER_D = 2.0
"""Self-tapping screws into printed plastic want ~2 x diameter of engagement."""


def as_built(spec) -> dict:
    """Geometry as it will be made: drafted cavity, neck as cut and as finished (mm, mm³)."""
    cav = spec.cavity
    pilot = spec.plate.neck_pilot
    return {
        "cavity_diameter_mm": cav.diameter, "cavity_length_mm": cav.length, "draft_deg": spec.mold.draft_deg,
        "cavity_tip_diameter_mm": float(drafted_tip_diameter_mm(cav.diameter, cav.length, spec.mold.draft_deg)),
        "cavity_volume_mm3": float(drafted_cavity_volume_mm3(cav.diameter, cav.length, spec.mold.draft_deg)),
        "draft_volume_change_pct": 100 * float(drafted_cavity_volume_mm3(cav.diameter, cav.length, spec.mold.draft_deg)
                                               / drafted_cavity_volume_mm3(cav.diameter, cav.length, 0.0) - 1),
        "neck_diameter_as_cut_mm": spec.neck.diameter - spec.plate.pilot_undersize if pilot else spec.neck.diameter,
        "neck_diameter_finished_mm": spec.neck.diameter,
        "neck_finish": "drill pilot to size" if pilot else "as cut (kerf compensated)",
        "neck_length_mm": spec.neck.length, "neck_length_measured": spec.plate.thickness_measured,
        "laser_kerf_mm": sheet_kerf_mm(spec, "plate"),
        "cap_volume_mm3": cap_volume_mm3(spec),
    }


def bill_of_materials(spec) -> dict:
    """Sheets, silicone, pins, bolts and needle needed for one taxel (plus the mold's batch)."""
    sheets = defaultdict(lambda: {"parts": [], "area_mm2": 0.0, "measured": False})
    for flat in laser_parts(spec):
        s = sheets[flat.thickness]
        s["parts"].append(f"{flat.quantity} x {flat.name}")
        s["area_mm2"] += flat.area_mm2 * flat.quantity
        s["measured"] = s["measured"] or flat.thickness_measured
    from matcad.parts.casting import MIN_BATCH_G

    cap = cap_volume_mm3(spec)
    needed_g = cap * spec.mold.count * spec.silicone.waste_factor / 1000 * spec.silicone.density_g_cm3
    batch_g = max(needed_g, MIN_BATCH_G)
    stack = bolt_span_mm(spec)
    bolt_d = bolt_nominal_mm(spec.fasteners.bolt)
    engage = min(THREAD_ENGAGEMENT_PER_D * bolt_d, spec.mount.thickness)
    return {
        "sheets": [{"thickness_mm": t, **v} for t, v in sorted(sheets.items())],
        "silicone": {"cap_volume_mm3": cap, "cap_mass_g": cap / 1000 * spec.silicone.density_g_cm3,
                     "caps_per_pour": spec.mold.count, "needed_mass_g": needed_g, "batch_mass_g": batch_g,
                     "batch_ml": batch_g / spec.silicone.density_g_cm3,
                     "density_g_cm3": spec.silicone.density_g_cm3},
        "dowels": {"count": len(plate_dowel_positions_mm(spec)), "diameter_mm": spec.fasteners.dowel_diameter,
                   "min_length_mm": stack + engage},
        "bolts": {"count": len(plate_bolt_positions_mm(spec)), "size": spec.fasteners.bolt,
                  "min_length_mm": stack + engage, "note": "self-tapping into the printed mount"},
        "spacers": ({"count": len(plate_bolt_positions_mm(spec)), "style": "laser",
                     "note": f"{spec.spacer.size:g} mm squares cut from {spec.spacer.height:g} mm sheet"}
                    if spec.spacer.style == "laser" else
                    {"count": len(plate_bolt_positions_mm(spec)), "style": "standoff",
                     "note": f"printed on the needle mount, {spec.spacer.height:g} mm tall"}),
        "needle": needle_bom(spec),
        **kit_hardware(spec),
    }


def casting(spec) -> dict | None:
    """The pour guide and the mold's venting (mm, g, min, h, °C), when the mold is built."""
    if not spec.outputs.end_cap_mold:
        return None
    from matcad.parts.casting import casting_guide
    from matcad.parts.mold_layout import layout

    plan = layout(spec).plan
    out = casting_guide(spec).to_dict() | {"venting": {
        "vent_reach_mm": spec.mold.vent_reach, "base_face_reach_mm": plan.reach_base_mm,
        "pin_end_reach_mm": plan.reach_tip_mm, "base_face_vents_per_cap": len(plan.inner) + len(plan.outer),
        "pin_vents_per_cap": 1, "vent_diameter_mm": spec.mold.vent}}
    from matcad.taxel import is_array, taxels

    if is_array(spec):  # which caps each mold holds, and how many pours (or molds) one board takes
        from matcad.parts.mold_layout import pours_per_board

        out["molds"] = pours_per_board(taxels(spec), spec.mold.count)
    return out


def needle_bom(spec) -> dict:
    """The needle to buy and how deep it goes (mm); a board needs one per taxel, each on its own air line (the
    mount offers no manifold), and its per-taxel needle rows sit in report.json's ``taxels``."""
    from matcad.parts.features import nearest_needle_gauge, needle_protrusion_mm, needle_tip_mm
    from matcad.taxel import taxels

    gauge, od = nearest_needle_gauge(spec.needle.outer_diameter)
    sin_t = math.sin(math.radians(spec.needle.theta_deg))
    through = (needle_tip_mm(spec)[2] + spec.spacer.height + spec.mount.thickness) / sin_t
    count = len(taxels(spec))
    board = (f" A board takes {count} needles, one bore per taxel; the mount has no manifold: feed each needle "
             "from its own regulated air line (or a splitter with a valve per line) so every jet can be set "
             "alone" if count > 1 else "")
    return {"count": count, "outer_diameter_mm": spec.needle.outer_diameter, "theta_deg": spec.needle.theta_deg,
            "y_mm": spec.needle.y, "gauge": gauge, "gauge_od_mm": od, "hub": "Luer-lock hub, blunt (dispensing) tip",
            "min_length_mm": through + HUB_CLEARANCE_MM, "protrusion_mm": needle_protrusion_mm(spec),
            "note": f"nearest standard: {gauge} G ({od:.3f} mm, ISO 9626); measure yours and enter "
                    "needle.outer_diameter. Push it up the bore until its tip stands the stated protrusion out of "
                    "the mount's top face (along the needle; a caliper depth rod), then fix the hub" + board}


def kit_hardware(spec) -> dict:
    """Mold clamp bolts and nuts, release agent, mount fixing screws (mm)."""
    from matcad.parts.casting import RELEASE_AGENT
    from matcad.parts.features import EAR_THICKNESS_MM, FIXING_BOLT, ear_holes_mm

    out = {}
    if spec.outputs.end_cap_mold:
        from matcad.parts.mold_layout import layout

        lay = layout(spec)
        d = bolt_nominal_mm(spec.mold.bolt)
        out["mold_clamp"] = {"count": len(lay.bolts), "size": spec.mold.bolt,
                             "min_length_mm": lay.base_height + spec.mold.lid_thickness + NUT_HEIGHT_PER_D * d + 1.0,
                             "nuts": len(lay.bolts), "washers": 2 * len(lay.bolts)}
        out["release_agent"] = RELEASE_AGENT
    if spec.outputs.needle_mount:
        out["mount_fixing"] = {"count": len(ear_holes_mm(spec)), "size": FIXING_BOLT,
                               "note": f"through the mount's ears ({EAR_THICKNESS_MM:g} mm) into a bench bracket or "
                                       "robot plate, on standoffs taller than the needle's hub"}
    return out


def manifest(folder: Path) -> list[dict]:
    """Every output file (except the reports themselves) with its size and sha256."""
    rows = []
    for path in sorted(folder.iterdir()):
        if path.name in REPORT_FILES:
            continue
        data = path.read_bytes()
        rows.append({"file": path.name, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()})
    return rows


def make_report(spec, prediction, findings, holes, meshes, folder: Path) -> dict:
    return {
        "matcad_version": __version__,
        "name": spec.name,
        "spec": to_dict(spec),
        "as_built": as_built(spec) | {"laser_holes": holes},
        "prediction": prediction.to_dict(),
        "findings": [f.to_dict() for f in findings],
        "verdict": "fail" if any(f.level == "error" for f in findings) else "pass",
        "bom": bill_of_materials(spec),
        "casting": casting(spec),
        "fabrication": fabrication(spec),
        "meshes": meshes,
        "files": manifest(folder),
    }


def _cell(text) -> str:
    """Free text made safe for a Markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def _part_link(finding: dict, r: dict) -> str:
    """The part a finding concerns, linked to its preview in the report ('–' when it names none)."""
    from matcad.report_page import finding_part, part_anchor

    part = finding_part(finding, r)
    return f"[{part}](#{part_anchor(part)})" if part else "–"


def _fabrication_markdown(f: dict | None) -> list[str]:
    if not f:
        return []
    s = f["seal"]
    lines = ["", "## Fabrication", "", "Caliper these sheets before cutting — the guide sheet before printing the mold:",
             "", "| sheet [mm] | first part | tolerance [mm] | measured | why |", "|---:|---|---:|---|---|"]
    lines += [f"| {c['sheet_mm']:g} | {c['part']} | ±{c['tolerance_mm']:.2f} | {'yes' if c['measured'] else '**no**'} | "
              f"{_cell(c['why'])} |" for c in f["caliper"]]
    lines += ["", f"Seal: the flange is cast {s['guide_sheet_mm']:g} + {s['flange_squeeze_mm']:g} mm thick; over the "
              f"guide sheet's ±{s['sheet_tolerance_mm']:.2f} mm the clamp squeezes it {s['squeeze_low_mm']:+.2f} … "
              f"{s['squeeze_high_mm']:+.2f} mm ({'measured' if s['guide_measured'] else 'nominal'} sheet)."]
    lines += ["", "Steps, in order:", ""]
    lines += [f"{i}. **{_cell(s['where'])}** — {_cell(s['do'])}" + (f" (`{'`, `'.join(s['files'])}`)" if s["files"] else "")
              for i, s in enumerate(f["steps"], 1)]
    if f["fits"]:
        lines += ["", "| fit | hole [mm] | part in it [mm] | clearance [mm] |", "|---|---:|---:|---:|"]
        lines += [f"| {_cell(x['fit'])} | {x['hole_mm']:.3f} | {x['pin_mm']:.3f} | {x['clearance_mm']:+.3f} |"
                  for x in f["fits"]]
    return lines


def _casting_markdown(c: dict | None) -> list[str]:
    if not c:
        return []
    v = c["venting"]
    lines = ["", "## Casting guide", "",
             f"{c['caps']} cap(s) of {c['grade']} in a {c['mold_material']} mold: mix **{c['batch_g']:.1f} g** "
             f"({c['mix_ratio']}) — {c['batch_reason']}. Pot life {c['pot_life_min']:g} min; cure "
             f"{c['cure_h_room']:g} h at 23 °C or warm at most {c['max_cure_c']:g} °C.", "",
             f"Venting: every ceiling of each cavity in pour orientation reaches an opening within "
             f"{v['vent_reach_mm']:g} mm — base face {v['base_face_reach_mm']:.2f} mm ({v['base_face_vents_per_cap']} "
             f"vents + the fill port), core-pin end over the membrane {v['pin_end_reach_mm']:.2f} mm (a vent along "
             "the pin).", ""]
    if c["inhibition"]:
        lines += [f"**SLA cure inhibition:** {c['inhibition']}.", ""]
    lines += [f"{i}. {step}" for i, step in enumerate(c["steps"], 1)]
    lines += ["", "Trim:", ""] + [f"- {t}" for t in c["trim"]]
    return lines


def _taxels_markdown(board: list[dict] | None) -> list[str]:
    """A board's taxels: position, geometry, needle and unloaded prediction, one row each (mm, deg, Hz)."""
    if not board:
        return []
    lines = ["", "## Taxels", "",
             "| taxel | x, y [mm] | cavity D × L [mm] | neck d [mm] | cap outer / top [mm] | needle θ, y | "
             "f0 [Hz] (model) | band [Hz] |", "|---|---|---|---:|---|---|---|---|"]
    for t in board:
        c, n, e, nd, p = t["cavity"], t["neck"], t["end_cap"], t["needle"], t["prediction"]
        lines.append(f"| {t['name']} | {t['x_mm']:g}, {t['y_mm']:g} | {c['diameter']:g} × {c['length']:g} | "
                     f"{n['diameter']:g} | {e['outer_diameter']:g} / {e['top_thickness']:g} | "
                     f"{nd['theta_deg']:g}°, {nd['y']:g} mm | {p['f0_hz']:.0f} ({p['model']}) | "
                     f"{p['band_hz'][0]:.0f}–{p['band_hz'][1]:.0f} |")
    return lines


def _markdown(r: dict) -> str:
    from matcad.render.bands import bands_markdown

    p, ab, bom = r["prediction"], r["as_built"], r["bom"]
    board = r.get("taxels")
    if board:  # the top-level prediction and as-built numbers are the first taxel's: say so
        headline = f"{len(board)} taxels: " + ", ".join(
            f"{t['name']} {t['f0_hz']:.0f} Hz ({t['unloaded_hz'][0]:.0f}–{t['unloaded_hz'][1]:.0f})"
            for t in r["bands"]["taxels"])
        scope = f" of taxel {board[0]['name']} (every taxel: Taxel bands, Taxels)"
    else:
        headline = f"f0 = {p['f0_hz']:.0f} Hz ({p['model']}), band {p['band_hz'][0]:.0f}–{p['band_hz'][1]:.0f} Hz"
        scope = ""
    lines = [f"# {r['name']} — matcad {r['matcad_version']} build report", "",
             f"**Verdict: {r['verdict']}** · {headline}", "",
             f"## As built{scope}", "",
             f"- cavity: D {ab['cavity_diameter_mm']:g} × L {ab['cavity_length_mm']:g} mm, draft "
             f"{ab['draft_deg']:g}° (closed-end D {ab['cavity_tip_diameter_mm']:.3f} mm), volume "
             f"{ab['cavity_volume_mm3']:.3f} mm³",
             f"- neck: {ab['neck_diameter_finished_mm']:g} mm finished ({ab['neck_finish']}; cut at "
             f"{ab['neck_diameter_as_cut_mm']:g} mm, kerf {ab['laser_kerf_mm']:g} mm), length "
             f"{ab['neck_length_mm']:g} mm ({'measured' if ab['neck_length_measured'] else 'nominal'})",
             f"- neck area {p['neck_area_mm2']:.4f} mm², A·l/V {p['neck_air_ratio']:.3f}, c "
             f"{p['speed_of_sound_m_s']:.2f} m/s", "",
             f"## Prediction{scope}", "", "| model | f0 [Hz] | valid | failed checks |", "|---|---:|---|---|"]
    for name, m in p["models"].items():
        failed = ", ".join(k for k, ok in m["checks"].items() if not ok) or "–"
        lines.append(f"| {name}{' (chosen)' if name == p['model'] else ''} | {m['f0_hz']:.1f} | "
                     f"{'yes' if m['valid'] else 'no'} | {failed} |")
    lines += ["", f"Band {p['band_hz'][0]:.0f}–{p['band_hz'][1]:.0f} Hz, root-sum-square in ln f of:", "",
              "| source | tolerance | low [Hz] | high [Hz] |", "|---|---|---:|---:|"]
    lines += [f"| {b['source']} | {_cell(b['tolerance'])} | {b['low_hz']:+.1f} | {b['high_hz']:+.1f} |"
              for b in p["budget"]]
    if p["warnings"]:  # what the physics says and where a model does not hold (e.g. the paper's measured 4.0 kHz)
        lines += ["", "Prediction notes:", ""] + [f"- {w}" for w in p["warnings"]]
    lines += bands_markdown(r.get("bands"))
    lines += ["", "## Design rules", "", "| level | rule | part | message | fix |", "|---|---|---|---|---|"]
    lines += [f"| {f['level']} | {f['id']} | {_part_link(f, r)} | {_cell(f['message'])} | {_cell(f['fix'])} |"
              for f in r["findings"]]
    s = bom["silicone"]
    lines += ["", "## Bill of materials", ""]
    lines += [f"- acrylic {sh['thickness_mm']:g} mm{' (measured)' if sh['measured'] else ''}: "
              f"{', '.join(sh['parts'])} — {sh['area_mm2'] / 100:.1f} cm²" for sh in bom["sheets"]]
    lines += [f"- silicone: {s['cap_volume_mm3']:.1f} mm³ ({s['cap_mass_g']:.2f} g) per cap; mix "
              f"{s['batch_mass_g']:.1f} g ({s['batch_ml']:.1f} ml) for {s['caps_per_pour']} cap(s), of which "
              f"{s['needed_mass_g']:.2f} g fills caps, sprues and cup",
              f"- {bom['dowels']['count']} dowel pins Ø{bom['dowels']['diameter_mm']:g} mm, ≥ "
              f"{bom['dowels']['min_length_mm']:.1f} mm long",
              f"- {bom['spacers']['count']} spacers: {bom['spacers']['note']}",
              f"- {bom['bolts']['count']} × {bom['bolts']['size']} bolts, ≥ {bom['bolts']['min_length_mm']:.1f} mm "
              f"({bom['bolts']['note']})",
              f"- needle Ø{bom['needle']['outer_diameter_mm']:g} mm ({bom['needle']['gauge']} G), "
              f"{bom['needle']['hub']}, ≥ {bom['needle']['min_length_mm']:.1f} mm long, at θ = "
              f"{bom['needle']['theta_deg']:g}°, y = {bom['needle']['y_mm']:g} mm; tip "
              f"{bom['needle']['protrusion_mm']:.2f} mm out of the mount's top face ({bom['needle']['note']})"]
    if "mold_clamp" in bom:
        c = bom["mold_clamp"]
        lines += [f"- mold clamp: {c['count']} × {c['size']} bolts ≥ {c['min_length_mm']:.0f} mm, {c['nuts']} nuts, "
                  f"{c['washers']} washers", f"- release agent: {bom['release_agent']}"]
    if "mount_fixing" in bom:
        f = bom["mount_fixing"]
        lines.append(f"- mount fixing: {f['count']} × {f['size']} screws {f['note']}")
    lines += _fabrication_markdown(r.get("fabrication"))
    lines += _casting_markdown(r.get("casting"))
    lines += _taxels_markdown(board)
    lines += ["", "## Files", "", "| file | bytes | sha256 |", "|---|---:|---|"]
    lines += [f"| {f['file']} | {f['bytes']} | `{f['sha256'][:16]}…` |" for f in r["files"]]
    if r["meshes"]:
        lines += ["", "## Mesh checks (STL read back)", "",
                  "| file | watertight | is_volume | bodies | STL vs B-rep volume | print orientation (on the bed) |",
                  "|---|---|---|---:|---:|---|"]
        for name, m in r["meshes"].items():
            dev = m["volume_mm3"] / m["brep_volume_mm3"] - 1
            turn = f"turned {m['rotation_x_deg']:g}° about x; " if m["rotation_x_deg"] else "as modelled; "
            lines.append(f"| {name} | {m['watertight']} | {m['is_volume']} | {m['bodies']} | {dev:+.4%} | "
                         f"{_cell(turn + m['bed_face'])} |")
    return "\n".join(lines) + "\n"


def write_report(report: dict, folder: Path) -> None:
    """report.json, and report.md and report.html from one Markdown rendering of the same data."""
    from matcad.report_page import render_html, render_markdown

    (folder / "report.json").write_text(json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    text = render_markdown(report, _markdown(report))
    (folder / "report.md").write_text(text, encoding="utf-8")
    (folder / "report.html").write_text(render_html(text, f"{report['name']} — matcad report"), encoding="utf-8")
