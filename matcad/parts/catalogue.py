"""Which parts a spec asks for. Laser parts are plain data; 3-D parts load build123d only when asked."""

from __future__ import annotations

from matcad.parts.flat import Flat
from matcad.parts.guide import ROLES, guide
from matcad.parts.neck_plate import neck_plate
from matcad.parts.spacer import spacer


def laser_parts(spec) -> list[Flat]:
    """Every laser part ``[outputs]`` asks for (design intent, finished sizes)."""
    parts = []
    if spec.outputs.neck_plate:
        parts.append(neck_plate(spec))
    if spec.outputs.guides:
        parts += [guide(spec, role) for role in ROLES]
    if spec.outputs.spacers and spec.spacer.style == "laser":
        parts.append(spacer(spec))
    return parts


def printed_parts(spec) -> dict[str, object]:
    """Name → build123d solid for every printed part ``[outputs]`` asks for (imports the CAD kernel)."""
    parts = {}
    if spec.outputs.end_cap_mold:
        from matcad.parts.end_cap import end_cap
        from matcad.parts.end_cap_mold import mold_base, mold_lid

        parts["end_cap"] = end_cap(spec)
        parts["end_cap_mold_base"] = mold_base(spec)
        parts["end_cap_mold_lid"] = mold_lid(spec)
    if spec.outputs.needle_mount:
        from matcad.parts.needle_mount import needle_mount

        parts["needle_mount"] = needle_mount(spec)
    return parts


def needs_cad_kernel(spec) -> bool:
    """Whether building ``spec`` needs build123d (any STL/STEP output)."""
    o = spec.outputs
    return o.end_cap_mold or o.needle_mount or o.assembly
