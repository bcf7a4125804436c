"""STL and STEP writers for solids (build123d, mm) and mesh checks (trimesh)."""

from __future__ import annotations

from pathlib import Path


def write_stl(shape, path: Path, tolerance_mm: float, angular_tolerance_rad: float, matrix=None) -> None:
    """Binary STL in mm with an explicit chordal (mm) and angular (rad) tessellation tolerance; ``matrix`` (4 x 4)
    moves the tessellated mesh (not the B-rep: shared vertices stay bit-identical, so the STL stays closed)."""
    from build123d import export_stl

    if not export_stl(shape, str(path), tolerance=tolerance_mm, angular_tolerance=angular_tolerance_rad):
        raise RuntimeError(f"STL export failed for {path.name}")
    if matrix is not None:
        import numpy as np
        import trimesh

        mesh = trimesh.load_mesh(str(path), file_type="stl", process=False)
        mesh.apply_transform(np.array(matrix))
        mesh.export(str(path), file_type="stl")


def write_step(shape, path: Path) -> None:
    """STEP AP214 in mm, byte-for-byte reproducible: a fixed timestamp, and assembly-occurrence ids numbered per
    file (OpenCASCADE numbers them from a process-wide counter, so a second export in one process differs)."""
    import itertools
    import re

    from build123d import Unit, export_step

    if not export_step(shape, str(path), unit=Unit.MM, timestamp="2000-01-01T00:00:00"):
        raise RuntimeError(f"STEP export failed for {path.name}")
    text = path.read_text(encoding="utf-8")
    count = itertools.count(1)

    def renumber(m):
        return f"NEXT_ASSEMBLY_USAGE_OCCURRENCE('{next(count)}'" + re.sub(r"\s*\n\s*", "", m.group(1)) + ";"

    fixed = re.sub(r"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('\d+'(.*?);", renumber, text, flags=re.S)
    if fixed != text:
        path.write_text(fixed, encoding="utf-8")


def mesh_checks(path: Path) -> dict:
    """Read an STL back: watertight, is_volume, bodies, volume (mm³), triangle count."""
    import trimesh

    mesh = trimesh.load_mesh(str(path), file_type="stl")
    bodies = mesh.split(only_watertight=False)
    return {"watertight": bool(mesh.is_watertight), "is_volume": bool(mesh.is_volume),
            "bodies": len(bodies), "volume_mm3": float(mesh.volume), "triangles": int(len(mesh.faces))}
