"""A 3MF print job per printer (print_fdm.3mf, print_sla.3mf): every printed part of the kit as exported (its
print pose, on its bed face), laid out on the bed, each with its own slicer settings — layer height, walls,
infill, solid layers — and the material, and for the mold base how its captive nuts go in (on FDM a pause, on
SLA a note to press them in after printing). Parts that do not fit one bed go to further plates
(print_sla_1.3mf, print_sla_2.3mf, ...), each a job of its own.

3MF Core 2015/02 (mm) with PrusaSlicer's metadata, which PrusaSlicer, SuperSlicer and OrcaSlicer read:
``Metadata/Slic3r_PE.config`` (the project's printer technology, material and defaults),
``Metadata/Slic3r_PE_model.config`` (per-object settings and names) and
``Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml`` (a pause at a print height, with its message).
``Metadata/matcad_print_notes.txt`` says the same in words for any other slicer. Byte-for-byte reproducible:
fixed zip dates, no UUIDs, no creation time. Lengths in mm.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

GAP_MM = 8.0
"""Between parts on the bed."""
CONTENT_TYPES = ('<?xml version="1.0" encoding="UTF-8"?>\n'
                 '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">\n'
                 ' <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>\n'
                 ' <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>\n'
                 ' <Default Extension="config" ContentType="text/plain"/>\n'
                 ' <Default Extension="xml" ContentType="application/xml"/>\n'
                 ' <Default Extension="txt" ContentType="text/plain"/>\n'
                 '</Types>\n')
RELS = ('<?xml version="1.0" encoding="UTF-8"?>\n'
        '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">\n'
        ' <Relationship Target="/3D/3dmodel.model" Id="rel0" '
        'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>\n'
        '</Relationships>\n')
PAUSE = 1
"""PrusaSlicer's custom G-code type of a pause (CustomGCode::PausePrint)."""


@dataclass(frozen=True)
class PrintPart:
    """One part of the job: its name, its mesh in the print pose (vertices mm, triangles), its print profile
    (:class:`matcad.parts.print_profile.PrintProfile`), for an FDM mold base a pause: (print height of the last
    layer before it, message), and what to do to the part once printed (an SLA mold base's nuts)."""

    name: str
    vertices: object
    faces: object
    profile: object
    pause: tuple[float, str] | None = None
    after: str | None = None


def _footprint(part: PrintPart) -> tuple[float, float]:
    import numpy as np

    w, d = np.ptp(np.asarray(part.vertices)[:, :2], axis=0)
    return float(w), float(d)


def _rows(sizes: list[tuple[float, float]], bed_w: float) -> list[list[int]]:
    """Indices of ``sizes`` in rows left to right, each row at most ``bed_w`` wide (a part wider stands alone)."""
    rows, row, width = [], [], 0.0
    for i, (w, _) in enumerate(sizes):
        if row and width + GAP_MM + w > bed_w:
            rows.append(row)
            row, width = [], 0.0
        width += (GAP_MM if row else 0.0) + w
        row.append(i)
    return rows + [row]


def bed_mm(spec) -> tuple[float, float]:
    """The bed the parts are laid out on: the printer's build volume in x and y (``machine.print_volume_x``,
    ``print_volume_y``; mm)."""
    return spec.machine.print_volume_x, spec.machine.print_volume_y


def plates(parts: list[PrintPart], bed: tuple[float, float]) -> list[list[PrintPart]]:
    """The parts split into loads of the ``bed`` (x, y mm; :func:`bed_mm`): rows of parts :data:`GAP_MM` apart, a
    new plate when the next row would not fit (an SLA display holds the mold halves, not the mount beside them)."""
    bed_w, bed_h = bed
    sizes = [_footprint(p) for p in parts]
    out, plate, depth = [], [], 0.0
    for row in _rows(sizes, bed_w):
        h = max(sizes[i][1] for i in row)
        if plate and depth + GAP_MM + h > bed_h:
            out.append(plate)
            plate, depth = [], 0.0
        depth += (GAP_MM if plate else 0.0) + h
        plate += [parts[i] for i in row]
    return out + [plate]


def layout_mm(parts: list[PrintPart], bed: tuple[float, float]) -> list[tuple[float, float]]:
    """Where each part's footprint centre goes on the ``bed`` (x, y mm): rows left to right, :data:`GAP_MM` apart,
    the whole block centred on the bed (mm)."""
    bed_w, bed_h = bed
    sizes = [_footprint(p) for p in parts]
    rows = _rows(sizes, bed_w)
    heights = [max(sizes[i][1] for i in r) for r in rows]
    y = (sum(heights) + GAP_MM * (len(rows) - 1)) / 2 + bed_h / 2
    out = [(0.0, 0.0)] * len(parts)
    for r, h in zip(rows, heights):
        x = bed_w / 2 - (sum(sizes[i][0] for i in r) + GAP_MM * (len(r) - 1)) / 2
        for i in r:
            out[i] = (x + sizes[i][0] / 2, y - h / 2)
            x += sizes[i][0] + GAP_MM
        y -= h + GAP_MM
    return out


def _object_xml(i: int, part: PrintPart) -> str:
    import numpy as np

    v = np.asarray(part.vertices, dtype=float)
    centre = (v[:, :2].min(axis=0) + v[:, :2].max(axis=0)) / 2
    v = v - [centre[0], centre[1], v[:, 2].min()]
    verts = "\n".join(f'     <vertex x="{x:.6f}" y="{y:.6f}" z="{z:.6f}"/>' for x, y, z in v)
    tris = "\n".join(f'     <triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in np.asarray(part.faces))
    return (f'  <object id="{i}" type="model" name={quoteattr(part.name)}>\n   <mesh>\n    <vertices>\n{verts}\n'
            f'    </vertices>\n    <triangles>\n{tris}\n    </triangles>\n   </mesh>\n  </object>')


def object_settings(part: PrintPart, printer: str) -> dict[str, str]:
    """The slicer settings one object carries (PrusaSlicer keys and value syntax)."""
    p = part.profile
    if printer == "sla":
        return {"layer_height": f"{p.layer_mm:g}", "supports_enable": "0", "pad_enable": "0"}
    return {"layer_height": f"{p.layer_mm:g}", "first_layer_height": f"{p.first_layer_mm:g}",
            "perimeters": str(p.walls), "fill_density": f"{p.infill_pct:g}%",
            "top_solid_layers": str(p.solid_layers), "bottom_solid_layers": str(p.solid_layers)}


def project_config(parts: list[PrintPart], printer: str) -> str:
    """Metadata/Slic3r_PE.config: the printer technology, the material, no supports, the pause G-code."""
    p = parts[0].profile
    if printer == "sla":
        lines = {"printer_technology": "SLA", "layer_height": f"{p.layer_mm:g}", "initial_layer_height":
                 f"{p.first_layer_mm:g}", "supports_enable": "0", "pad_enable": "0", "material_notes": p.material}
    else:
        lines = {"printer_technology": "FFF", "layer_height": f"{p.layer_mm:g}",
                 "first_layer_height": f"{p.first_layer_mm:g}", "filament_type": p.material.split(",")[0],
                 "filament_notes": p.material, "support_material": "0", "pause_print_gcode": "M601"}
    return "; generated by matcad\n" + "".join(f"; {k} = {v}\n" for k, v in sorted(lines.items()))


def model_config(parts: list[PrintPart], printer: str) -> str:
    """Metadata/Slic3r_PE_model.config: each object's name and settings, its one volume's triangle range."""
    out = ['<?xml version="1.0" encoding="UTF-8"?>', "<config>"]
    for i, part in enumerate(parts, 1):
        out.append(f' <object id="{i}" instances_count="1">')
        out.append(f'  <metadata type="object" key="name" value={quoteattr(part.name)}/>')
        out += [f'  <metadata type="object" key="{k}" value={quoteattr(v)}/>'
                for k, v in object_settings(part, printer).items()]
        out.append(f'  <volume firstid="0" lastid="{len(part.faces) - 1}">')
        out.append(f'   <metadata type="volume" key="name" value={quoteattr(part.name)}/>')
        out.append('   <metadata type="volume" key="volume_type" value="ModelPart"/>')
        out += ["  </volume>", " </object>"]
    return "\n".join(out + ["</config>"]) + "\n"


def pauses_xml(parts: list[PrintPart]) -> str | None:
    """Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml: a pause before the first layer above each part's pause
    height (half a layer above its last layer, so it lands on the next layer whatever the other parts' layers)."""
    codes = [(part.pause[0] + part.profile.layer_mm / 2, part.pause[1]) for part in parts if part.pause]
    if not codes:
        return None
    rows = [f'<code print_z="{z:.6g}" type="{PAUSE}" extruder="1" color="" extra={quoteattr(message)} '
            'gcode="M601"/>' for z, message in sorted(codes)]
    return ('<?xml version="1.0" encoding="utf-8"?>\n<custom_gcodes_per_print_z>\n' + "\n".join(rows)
            + '\n<mode value="SingleExtruder"/>\n</custom_gcodes_per_print_z>\n')


def notes(parts: list[PrintPart], printer: str) -> str:
    """The same job in words, for a slicer that reads only the meshes."""
    lines = [f"matcad print job ({printer}): each part is exported lying on its bed face; print it as it lies, no "
             "supports.", ""]
    for part in parts:
        p = part.profile
        settings = (f"{p.layer_mm:g} mm layers, {p.walls} walls, {p.infill_pct:g} % infill, "
                    f"{p.solid_layers} solid top/bottom layers" if p.walls else f"{p.layer_mm:g} mm layers, solid")
        lines.append(f"{part.name}: {settings}; {p.material}. {p.why}.")
        if part.pause:
            lines.append(f"  PAUSE after the layer at z = {part.pause[0]:.2f} mm: {part.pause[1]}")
        if part.after:
            lines.append(f"  AFTER PRINTING: {part.after}")
    return "\n".join(lines) + "\n"


def write_3mf(parts: list[PrintPart], printer: str, bed: tuple[float, float], path: Path) -> dict:
    """Write the print job for ``printer`` laid out on ``bed`` (x, y mm); returns what it holds: each object's name,
    bed position and settings, and the pauses (mm)."""
    places = layout_mm(parts, bed)
    objects = "\n".join(_object_xml(i, part) for i, part in enumerate(parts, 1))
    items = "\n".join(f'  <item objectid="{i}" transform="1 0 0 0 1 0 0 0 1 {x:.4f} {y:.4f} 0" printable="1"/>'
                      for i, (x, y) in enumerate(places, 1))
    model = ('<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xml:lang="en-US" '
             'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" '
             'xmlns:slic3rpe="http://schemas.slic3r.org/3mf/2017/06">\n'
             ' <metadata name="slic3rpe:Version3mf">1</metadata>\n <metadata name="Application">matcad</metadata>\n'
             f' <resources>\n{objects}\n </resources>\n <build>\n{items}\n </build>\n</model>\n')
    files = {"[Content_Types].xml": CONTENT_TYPES, "_rels/.rels": RELS, "3D/3dmodel.model": model,
             "Metadata/Slic3r_PE.config": project_config(parts, printer),
             "Metadata/Slic3r_PE_model.config": model_config(parts, printer),
             "Metadata/matcad_print_notes.txt": notes(parts, printer)}
    pauses = pauses_xml(parts)
    if pauses:
        files["Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml"] = pauses
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name, text in files.items():
            info = zipfile.ZipInfo(name, date_time=(2000, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, text.encode("utf-8"))
    return {"file": path.name, "printer": printer,
            "objects": [{"name": p.name, "x_mm": x, "y_mm": y, "settings": object_settings(p, printer),
                         "material": p.profile.material} for p, (x, y) in zip(parts, places)],
            "pauses": [{"part": p.name, "after_layer_z_mm": p.pause[0], "message": p.pause[1]}
                       for p in parts if p.pause],
            "after_printing": [{"part": p.name, "message": p.after} for p in parts if p.after]}
