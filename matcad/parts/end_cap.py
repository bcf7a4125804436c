"""The cast silicone end cap (paper: Dragon Skin 30): cavity D x L open toward the neck, a body, a base flange.

Own frame: base on z = 0 (it sits on the neck plate), axis along +z, cavity open at z = 0.
"""

import math

from matcad.parts.registry import Kind, Part, PrintPose
from matcad.spec import cap_flange_diameter_mm, cap_flange_thickness_mm, cap_height_mm


def cavity_tip_radius_mm(spec) -> float:
    """Cavity radius at its closed end: D/2 narrowed by the core pin's draft over L (mm)."""
    return spec.cavity.diameter / 2 - spec.cavity.length * math.tan(math.radians(spec.mold.draft_deg))


def cap_envelope(spec):
    """The cap's outer shape (flange + body), cavity not removed (mm)."""
    from matcad.parts.solid import cylinder_up

    flange = cylinder_up(cap_flange_diameter_mm(spec) / 2, cap_flange_thickness_mm(spec))
    body = cylinder_up(spec.end_cap.outer_diameter / 2, cap_height_mm(spec))
    return flange + body


def core_pin(spec):
    """The cavity's shape: a frustum from D at z = 0 to the drafted tip at z = L (mm)."""
    from matcad.parts.solid import frustum_up

    return frustum_up(spec.cavity.diameter / 2, cavity_tip_radius_mm(spec), spec.cavity.length)


def end_cap(spec):
    """The silicone end cap solid; its volume is the cast volume (mm³)."""
    return cap_envelope(spec) - core_pin(spec)


def board_caps(spec):
    """The board's distinct end caps (one per group of identical caps), side by side along x with the mold's
    spacing; a single taxel's cap at the origin (mm). The reference shape of what the mold casts."""
    from build123d import Compound, Pos

    from matcad.parts.mold_layout import cap_x_mm, cap_groups
    from matcad.spec import taxel_spec, taxels

    caps = [taxel_spec(spec, g[0]) for g in cap_groups(taxels(spec))]
    if len(caps) == 1:
        return end_cap(caps[0])
    xs = cap_x_mm([cap_flange_diameter_mm(c) for c in caps], spec.mold.wall)
    return Compound([Pos(x, 0, 0) * end_cap(c) for x, c in zip(xs, caps)])


PARTS = (Part("end_cap", Kind.CAST, flag="end_cap_mold", make=board_caps, order=50, colour="#f0a050",
              pose=PrintPose(0.0, "base (the sealing face), cavity opening down: cast, not printed", printed=False),
              view=("section through its axis: cavity, membrane, flange", -90.0, -90.0), label="silicone end cap",
              section="axis"),)
