"""The report's known sections as Markdown (one text: report.md, and report.html through it), and the helpers the
page shares: table-cell escaping and the link from a finding to the picture of the part it concerns."""

from __future__ import annotations

RULE_PARTS = {"needle.": "needle_mount", "fit.dowel_printed": "needle_mount", "mold.": "end_cap_mold_base",
              "print.": "end_cap_mold_base", "cap.": "end_cap", "silicone.": "end_cap", "acoustic.": "prediction"}
"""Rule id prefix → the part (picture) it concerns, for findings whose message does not start with a part."""


def cell(text) -> str:
    """Free text made safe for a Markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def part_anchor(part: str) -> str:
    """HTML id of a part's picture."""
    return f"part-{part}"


def finding_part(finding: dict, r: dict) -> str | None:
    """The pictured part a finding concerns: the part its message starts with, else by its rule id."""
    pictured = {f["part"] for f in r.get("figures", ())}
    head = finding["message"].split(":", 1)[0].strip()
    if head in pictured:
        return head
    for prefix, part in RULE_PARTS.items():
        if finding["id"].startswith(prefix) and part in pictured:
            return part
    return None


def _part_link(finding: dict, r: dict) -> str:
    """The part a finding concerns, linked to its preview in the report ('–' when it names none)."""
    part = finding_part(finding, r)
    return f"[{part}](#{part_anchor(part)})" if part else "–"


def _fabrication_markdown(f: dict | None) -> list[str]:
    if not f:
        return []
    s = f["seal"]
    lines = ["", "## Fabrication", "", "Caliper these sheets before cutting — the guide sheet before printing the mold:",
             "", "| sheet [mm] | first part | tolerance [mm] | measured | why |", "|---:|---|---:|---|---|"]
    status = {"measured": "yes", "example": "**no** (example value)", "nominal": "**no**"}
    lines += [f"| {c['sheet_mm']:g} | {c['part']} | ±{c['tolerance_mm']:.2f} | {status[c['status']]} | "
              f"{cell(c['why'])} |" for c in f["caliper"]]
    for c in s.get("caps", [s]):
        lines += ["", _seal_markdown(c)]
    lines += ["", "Steps, in order:", ""]
    lines += [f"{i}. **{cell(s['where'])}** — {cell(s['do'])}" + (f" (`{'`, `'.join(s['files'])}`)" if s["files"] else "")
              for i, s in enumerate(f["steps"], 1)]
    if f["fits"]:
        lines += ["", "| fit | hole [mm] | part in it [mm] | clearance [mm] |", "|---|---:|---:|---:|"]
        lines += [f"| {cell(x['fit'])} | {x['hole_mm']:.3f} | {x['pin_mm']:.3f} | {x['clearance_mm']:+.3f} |"
                  for x in f["fits"]]
    return lines


def _seal_markdown(s: dict) -> str:
    """The seal of one cap (:func:`matcad.report.fabrication.seal`), or of a [riser]'s caps on one seat."""
    pocket = s.get("seat") == "plate"
    where = "in the riser's pockets" if pocket else "on the riser"
    who = f" of {', '.join(s['taxels'])} ({where})" if "seat" in s else ""
    cast = f" + {s['riser_sheet_mm']:g}" if pocket else ""
    sheets = "guide and riser sheets'" if pocket else "guide sheet's"
    return (f"Seal{who}: the flange is cast {s['guide_sheet_mm']:g} + {s['flange_squeeze_mm']:g}{cast} mm thick; over "
            f"the {sheets} ±{s['sheet_tolerance_mm']:.2f} mm the clamp squeezes it {s['squeeze_low_mm']:+.2f} … "
            f"{s['squeeze_high_mm']:+.2f} mm ({s['guide_status']} {'guide ' if pocket else ''}sheet)"
            + (f"; **unverified**: until you caliper your own sheet it may be {s['unverified_low_mm']:+.2f} … "
               f"{s['unverified_high_mm']:+.2f} mm (nominal ±{s['nominal_tolerance_mm']:.2f} mm)."
               if s["unverified_low_mm"] is not None else "."))


def _casting_markdown(c: dict | None) -> list[str]:
    if not c:
        return []
    v = c["venting"]
    lines = ["", "## Casting guide", "",
             f"{c['caps']} cap(s) of {c['grade']} in a {c['mold_material']} mold: mix **{c['batch_g']:.1f} g** "
             f"({c['mix_ratio']}) — {c['batch_reason']}. Pot life {c['pot_life_min']:g} min; cure "
             f"{c['cure_h_room']:g} h at 23 °C or warm at most {c['max_cure_c']:g} °C.", "",
             f"Venting: every ceiling of each cavity in pour orientation reaches an escape within "
             f"{v['vent_reach_mm']:g} mm — base face {v['base_face_reach_mm']:.2f} mm ({v['base_face_vents_per_cap']} "
             f"vents + the fill port), core-pin end over the membrane {v['pin_end_reach_mm']:.2f} mm (to its rim, "
             "where the pin's side rises to the base face: no vent through the pin). Cast beyond the cap: "
             + ", ".join(f"{a['taxel']} {a['sprues']} sprues ≤ {a['sprue_mm3']:.1f} mm³ on the sealing face, "
                         f"{a['inside_cavity_mm3']:.3f} mm³ inside the cavity" for a in c["appendages"]) + ".", ""]
    if c["inhibition"]:
        lines += [f"**SLA cure inhibition:** {c['inhibition']}.", ""]
    lines += [f"{i}. {step}" for i, step in enumerate(c["steps"], 1)]
    lines += ["", "Trim:", ""] + [f"- {t}" for t in c["trim"]]
    return lines


def _stock(length) -> str:
    """A stock length (mm) as the BOM prints it; '?' when no stock length is long enough."""
    return "?" if length is None else f"{length:g}"


def _silicone_markdown(s: dict) -> list[str]:
    caps = "; ".join(f"{', '.join(c['taxels'])}: {c['cap_volume_mm3']:.1f} mm³ ({c['cap_mass_g']:.2f} g)"
                     for c in s["caps"]) if len(s["caps"]) > 1 else (
        f"{s['cap_volume_mm3']:.1f} mm³ ({s['cap_mass_g']:.2f} g) per cap")
    return [f"- silicone: {caps}; one pour of {s['caps_per_pour']} cap(s) casts {s['cast_volume_ml']:.3f} ml and "
            f"needs {s['needed_mass_g']:.2f} g with cup, sprues and vents; mix {s['batch_mass_g']:.1f} g "
            f"({s['batch_ml']:.1f} ml)"]


def _drills_markdown(drills: list[dict]) -> list[str]:
    return [f"- twist drill Ø{d['diameter_mm']:g} mm (HSS jobber, DIN 338{'' if d['standard'] else '; not a 0.1 mm step: ream'}) "
            f"for the neck pilot{'s' if len(d['taxels']) > 1 else ''} of {', '.join(d['taxels'])}" for d in drills]


def _files_to_make_markdown(sheets: list[dict] | None, job: dict | None) -> list[str]:
    """The cut files (one per sheet, nested) and the print job (one 3MF, each part with its settings)."""
    lines = []
    if sheets:
        lines += ["", "## Cut files, one per sheet", "",
                  "Each sheet's parts nested in one file (engraving, then inner cuts, outlines last); "
                  "`sheets_1to1.pdf` draws them at 1:1 to check the scale on paper first.", "",
                  "| sheet | file | parts | kerf [mm] | size [mm] | PDF page |", "|---|---|---|---:|---|---|"]
        lines += [f"| {s['thickness_mm']:g} mm | `{s['file']}` | {', '.join(s['parts'])} | {s['kerf_mm']:g} | "
                  f"{s['width_mm']:.1f} × {s['height_mm']:.1f} | {s['pdf_page']['page']} |" for s in sheets]
    if job:
        lines += ["", f"## Print job ({job['printer']})", "",
                  "| file | part | settings | material |", "|---|---|---|---|"]
        lines += [f"| `{f['file']}` | {o['name']} | {cell(', '.join(f'{k} {v}' for k, v in o['settings'].items()))} | "
                  f"{cell(o['material'])} |" for f in job["files"] for o in f["objects"]]
        lines += [f"- pause after the layer at z = {p['after_layer_z_mm']:.2f} mm ({p['part']}): {p['message']}"
                  for f in job["files"] for p in f["pauses"]]
        lines += [f"- after printing ({p['part']}): {p['message']}" for f in job["files"]
                  for p in f["after_printing"]]
    return lines


def _riser_markdown(riser: dict | None) -> list[str]:
    """The [riser] sheet's line of As built: its sheet, and each taxel's neck length, cap seat and flange (mm)."""
    if not riser:
        return []
    seat = {"riser": "cap on the riser", "plate": "cap on the plate in a pocket of the riser"}
    return [f"- riser: {riser['thickness_mm']:g} mm sheet ({riser['status']}, kerf {riser['laser_kerf_mm']:g} mm) "
            f"bonded on the plate; necks through it: {', '.join(riser['through']) or 'none'}; "
            + "; ".join(f"{t['name']} neck l {t['neck_length_mm']:g} mm, {seat[t['cap_seat']]}, flange "
                        f"{t['cap_flange_thickness_mm']:g} mm" for t in riser["taxels"])]


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


def sections(r: dict) -> str:
    """The report's known sections (:data:`matcad.report.page.KNOWN_KEYS`) as Markdown: title and verdict, as
    built, prediction, bands, design rules, BOM, fabrication, casting, taxels, files, mesh checks."""
    from matcad.render.bands import bands_markdown
    from matcad.render.plots import chosen_models_status

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
    status = chosen_models_status(r)
    lines = [f"# {r['name']} — matcad {r['matcad_version']} build report", "",
             f"**Verdict: {r['verdict']}** (design rules) · {headline}"
             + (f" · **{status}**: the f0 comes from a model outside its validity" if status else ""), "",
             f"## As built{scope}", "",
             f"- cavity: D {ab['cavity_diameter_mm']:g} × L {ab['cavity_length_mm']:g} mm, draft "
             f"{ab['draft_deg']:g}° (closed-end D {ab['cavity_tip_diameter_mm']:.3f} mm), volume "
             f"{ab['cavity_volume_mm3']:.3f} mm³",
             f"- neck: {ab['neck_diameter_finished_mm']:g} mm finished ({ab['neck_finish']}; cut at "
             f"{ab['neck_diameter_as_cut_mm']:g} mm, kerf {ab['laser_kerf_mm']:g} mm), length "
             f"{ab['neck_length_mm']:g} mm ({'measured' if ab['neck_length_measured'] else 'nominal'})",
             *_riser_markdown(ab.get("riser")),
             f"- neck area {p['neck_area_mm2']:.4f} mm², A·l/V {p['neck_air_ratio']:.3f}, c "
             f"{p['speed_of_sound_m_s']:.2f} m/s", "",
             f"## Prediction{scope}", "", "| model | f0 [Hz] | valid | failed checks |", "|---|---:|---|---|"]
    for name, m in p["models"].items():
        failed = ", ".join(k for k, ok in m["checks"].items() if not ok) or "–"
        lines.append(f"| {name}{' (chosen)' if name == p['model'] else ''} | {m['f0_hz']:.1f} | "
                     f"{'yes' if m['valid'] else 'no'} | {failed} |")
    lines += ["", f"Band {p['band_hz'][0]:.0f}–{p['band_hz'][1]:.0f} Hz, root-sum-square in ln f of:", "",
              "| source | tolerance | low [Hz] | high [Hz] |", "|---|---|---:|---:|"]
    lines += [f"| {b['source']} | {cell(b['tolerance'])} | {b['low_hz']:+.1f} | {b['high_hz']:+.1f} |"
              for b in p["budget"]]
    if p["warnings"]:  # what the physics says and where a model does not hold (e.g. the paper's measured 4.0 kHz)
        lines += ["", "Prediction notes:", ""] + [f"- {w}" for w in p["warnings"]]
    lines += bands_markdown(r.get("bands"))
    lines += ["", "## Design rules", "", "| level | rule | part | message | fix |", "|---|---|---|---|---|"]
    lines += [f"| {f['level']} | {f['id']} | {_part_link(f, r)} | {cell(f['message'])} | {cell(f['fix'])} |"
              for f in r["findings"]]
    lines += ["", "## Bill of materials", ""]
    sheet_note = {"measured": " (measured)", "example": " (example value: caliper yours)", "nominal": ""}
    lines += [f"- acrylic {sh['thickness_mm']:g} mm{sheet_note[sh['status']]}: "
              f"{', '.join(sh['parts'])} — {sh['area_mm2'] / 100:.1f} cm²" for sh in bom["sheets"]]
    lines += _silicone_markdown(bom["silicone"]) + _drills_markdown(bom["drills"])
    n, d, b = bom["needle"], bom["dowels"], bom["bolts"]
    lines += [f"- {d['count']} × dowel pin Ø{d['diameter_mm']:g} × {_stock(d['length_mm'])} mm ({d['standard']}; "
              f"the stack needs ≥ {d['min_length_mm']:.2f} mm)",
              f"- {bom['spacers']['count']} spacers: {bom['spacers']['note']}",
              f"- {b['count']} × {b['size']} × {_stock(b['length_mm'])} mm socket head screws ({b['standard']}; the "
              f"stack needs ≥ {b['min_length_mm']:.2f} mm; {b['note']}"
              + (f", {b['into_mount_mm']:.1f} mm into it)" if b["into_mount_mm"] is not None else ")"),
              f"- {n['count']} × needle Ø{n['outer_diameter_mm']:g} mm ({n['gauge']} G), {n['hub']}, "
              f"{_stock(n['length_mm'])} mm long (≥ {n['min_length_mm']:.1f} mm), at θ = {n['theta_deg']:g}°, "
              f"y = {n['y_mm']:g} mm; tip {n['protrusion_mm']:.2f} mm out of the mount's top face ({n['note']})"]
    if "mold_clamp" in bom:
        c = bom["mold_clamp"]
        lines += [f"- mold clamp: {c['count']} × {c['size']} × {_stock(c['length_mm'])} mm socket head screws "
                  f"({c['standard']}), {c['nuts']} × {c['size']} hex nuts ({c['nut_standard']}, {c['note']}), "
                  f"{c['washers']} washers", f"- release agent: {bom['release_agent']}"]
    if "mount_fixing" in bom:
        f = bom["mount_fixing"]
        lines.append(f"- mount fixing: {f['count']} × {f['size']} screws {f['note']}")
    lines += _fabrication_markdown(r.get("fabrication"))
    lines += _files_to_make_markdown(r.get("sheets"), r.get("print_job"))
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
                         f"{cell(turn + m['bed_face'])} |")
    return "\n".join(lines) + "\n"
