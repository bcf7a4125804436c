"""What PrusaSlicer adds as support to the printed tube in its print pose (docs/tube.md, the kit).

Slices the template's fipple tube, its block alone (the tube cut at the windway's exit: needle seat, its cone, the
windway) and the template with a transverse mouth (``tube.mouth = "transverse"``) with automatic supports on, as
tests/test_real_clients.py slices the MAT parts, and prints the support's volume (mm³), the highest layer it reaches
(mm), the steepest downward face (deg from vertical) and the edges where material starts in mid-air
(tests/readback.py). Needs prusa-slicer on PATH.
Run: .venv/bin/python benchmarks/tube_supports.py
"""

import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from build123d import Box, Pos  # noqa: E402

import numpy as np  # noqa: E402
import trimesh  # noqa: E402

from matcad.export.mesh import write_stl  # noqa: E402
from matcad.parts.tube import fipple_tube, heights_mm, tube_solid  # noqa: E402
from matcad.spec import from_dict, load, to_dict  # noqa: E402
from tests.readback import hanging_edge_length_mm  # noqa: E402
from tests.test_real_clients import support_volume_mm3  # noqa: E402

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "acoustac-tube.toml"


def sliced(solid, spec, folder: Path, name: str) -> tuple[float, float, float]:
    """(support mm³, highest support layer mm, part volume mm³) of ``solid`` sliced with automatic supports."""
    stl, gcode = folder / f"{name}.stl", folder / f"{name}.gcode"
    write_stl(solid, stl, spec.machine.stl_tolerance, spec.machine.stl_angular_tolerance)
    subprocess.run(["prusa-slicer", "--export-gcode", "--support-material", "--support-material-auto", "--output",
                    str(gcode), str(stl)], capture_output=True, text=True, check=True, timeout=600)
    text = gcode.read_text()
    z, kind, top = 0.0, "", 0.0
    for line in text.splitlines():
        if line.startswith(";Z:"):
            z = float(line[3:])
        elif line.startswith(";TYPE:"):
            kind = line[6:]
        elif kind.startswith("Support") and re.match(r"G1 .*E", line):
            top = max(top, z)
    return support_volume_mm3(text), top, float(solid.volume)


def main():
    spec = load(TEMPLATE)
    data = to_dict(spec)
    data["tube"]["mouth"] = "transverse"
    transverse = from_dict(data)
    tube = fipple_tube(spec)
    block = tube & (Pos(0, 0, spec.tube.block_length / 2) * Box(50, 50, spec.tube.block_length))
    print(f"labium's edge at z = {heights_mm(spec)['edge']:g} mm, windway exit at z = {spec.tube.block_length:g} mm")
    with tempfile.TemporaryDirectory() as tmp:
        for name, solid in (("tube", tube), ("block", block), ("transverse", tube_solid(transverse))):
            support, top, volume = sliced(solid, spec, Path(tmp), name)
            mesh = trimesh.load_mesh(Path(tmp) / f"{name}.stl")
            down = (mesh.face_normals[:, 2] < 0) & (mesh.triangles_center[:, 2] > 1e-3)
            steepest = float(np.degrees(np.arcsin(np.clip(-mesh.face_normals[down, 2], 0, 1))).max())
            print(f"{name:10s} part {volume:7.1f} mm^3  support {support:6.1f} mm^3  highest support layer "
                  f"{top:5.2f} mm  steepest downward face {steepest:4.1f} deg  edges in mid-air (z: mm) "
                  f"{ {float(k): round(v, 3) for k, v in hanging_edge_length_mm(mesh).items()} }")


if __name__ == "__main__":
    main()
