"""`matcad build` of a ``kind = "tube"`` spec: the printed fipple tube, the MAT cap and its mold (the registry's
parts, made on the tube's cap), previews, and report.json / report.md (with a MAT taxel at the same pitch beside it,
:mod:`matcad.design.tube_vs_mat`), written atomically into one folder. Lengths mm. docs/tube.md.
"""

from __future__ import annotations

from pathlib import Path

from matcad.output import staged_output

CAP_PARTS = ("end_cap", "end_cap_mold_base", "end_cap_mold_lid")
"""The MAT path's registered parts the tube kit reuses: the cast cap (reference shape) and its two-part mold."""
POSES = {
    "block": ("the block's face (needle seat); bore vertical",
              "Print tube.stl as exported (block on the bed, bore vertical; the labium starts as a bridge across the "
              "window: see the report's support note); check the windway with a {h:g} mm feeler and the bore with a "
              "{d:g} mm gauge pin.", "in the block"),
    "transverse": ("the tube's foot and the windway's boss; bore vertical",
                   "Print tube.stl as exported (its foot and the windway's boss on the bed, bore vertical; no support: "
                   "nothing overhangs more than 30° from vertical); check the windway with a {h:g} mm feeler and the "
                   "bore with a {d:g} mm gauge pin.", "at the boss's end (horizontal)"),
}
"""Per printed tube (:func:`matcad.parts.tube.tube_solid`: the transverse mouth's, else the block's): its face on
the bed, the print step, where the needle's seat is."""
STEPS = (
    "Print end_cap_mold_base.stl and end_cap_mold_lid.stl; cast the cap in {grade} (report: silicone.batch).",
    "Glue the cap's flange on the tube's seat (silicone adhesive), the cap's cavity over the bore.",
    "Push the supply needle ({needle:g} mm) into its seat {seat}; blow {flow:g} L/min (the edge-tone rule's "
    "window is in the report).",
)
"""The steps after the print step (:data:`POSES`)."""


def _pose(spec) -> tuple[str, str, str]:
    return POSES["transverse" if spec.tube.mouth == "transverse" else "block"]


def _tube_files(spec, folder: Path) -> dict:
    """tube.stl/.step in its print pose and its read-back checks (mm, mm³)."""
    from matcad.export.mesh import mesh_checks, write_step, write_stl
    from matcad.parts.tube import tube_solid

    solid = tube_solid(spec)
    stl = folder / "tube.stl"
    tolerance = write_stl(solid, stl, spec.machine.stl_tolerance, spec.machine.stl_angular_tolerance)
    write_step(solid, folder / "tube.step")
    return mesh_checks(stl) | {"brep_volume_mm3": float(solid.volume), "printed": True,
                               "bed_face": _pose(spec)[0], "rotation_x_deg": 0.0,
                               "chordal_tolerance_mm": tolerance}


def build_tube(spec, out_dir: Path | None = None, force: bool = False):
    """Build a tube spec into ``out_dir`` (default out/<name>); raises DesignRuleFailure on rule errors unless
    ``force``. Returns (folder, report data)."""
    from matcad.build import DesignRuleFailure, default_out_dir, write_archive, write_printed_part
    from matcad.design.tube_vs_mat import compare
    from matcad.parts.registry import part
    from matcad.prediction.tube import predict_tube
    from matcad.render.previews import preview_name, printed_preview
    from matcad.report import KIT_ARCHIVE
    from matcad.rules import check
    from matcad.spec import to_dict

    prediction = predict_tube(spec)
    findings = check(spec, prediction)
    failure = DesignRuleFailure(findings, forced=force)
    if failure.blocking:
        raise failure
    target = Path(out_dir) if out_dir is not None else default_out_dir(spec)
    t = spec.tube
    _, printing, seat = _pose(spec)
    steps = [s.format(h=t.windway_height, d=t.bore_diameter, grade=spec.silicone.grade, seat=seat,
                      needle=spec.needle.outer_diameter, flow=t.supply_flow_l_min) for s in (printing, *STEPS)]
    comparison = compare(spec, prediction.f0_hz, steps)
    with staged_output(target) as tmp:
        meshes = {"tube.stl": _tube_files(spec, tmp)}
        for name in CAP_PARTS:
            meshes[f"{name}.stl"] = write_printed_part(name, part(name).make(spec), spec, tmp)
        figures = [printed_preview(Path(name).stem, tmp / name, tmp / preview_name(Path(name).stem))
                   for name in meshes]
        report = {"name": spec.name, "kind": "tube", "spec": to_dict(spec), "prediction": prediction.to_dict(),
                  "findings": [f.to_dict() for f in findings], "meshes": meshes, "figures": figures,
                  "fabrication": steps, "beside_mat": comparison.to_dict()}
        _write_report(report, prediction, comparison, tmp)
        write_archive(tmp, KIT_ARCHIVE)
    return target, report


def _write_report(report: dict, prediction, comparison, folder: Path) -> None:
    """report.json and report.md of a tube kit (``comparison``: :class:`matcad.design.tube_vs_mat.Comparison`)."""
    import json

    (folder / "report.json").write_text(json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    lines = [f"# {report['name']} — tube taxel, {prediction.mouth} mouth (matcad)", "", "## Prediction", "", "```",
             prediction.to_text(), "```", "", "## Design rules", ""]
    lines += [f"- **{f['level']}** `{f['id']}`: {f['message']}" for f in report["findings"]] or ["- none"]
    lines += ["", "## Parts", "", "| file | volume (mm³) | watertight | print pose |", "|---|---|---|---|"]
    lines += [f"| {name} | {m['volume_mm3']:.1f} | {m['watertight']} | {m['bed_face']} |"
              for name, m in report["meshes"].items()]
    lines += ["", "## Steps", ""] + [f"{i}. {s}" for i, s in enumerate(report["fabrication"], 1)]
    lines += ["", "## Beside a MAT taxel", ""] + comparison.to_markdown()
    lines += [""] + [f"![{f['caption']}]({f['file']})" for f in report["figures"]]
    (folder / "report.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
