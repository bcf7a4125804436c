"""How each printed part is printed, per printer process: layer height, walls, infill, material, and why (mm, %).

One table, read by the parts that need the layer grid (the mold base's captive-nut pause lands on a layer
boundary), the 3MF exporter (per-object slicer settings, :mod:`matcad.export.threemf`) and the fabrication
steps. The numbers are shop practice for small precise parts, not measured on a particular printer: a slicer
profile of your own machine overrides them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

PRINTERS = ("fdm", "sla")
PRINT_FILE = "print_{printer}.3mf"
"""The printer's 3MF print job; ``print_{printer}_1.3mf``, ``_2``, ... when the parts take more than one bed."""
FDM_MAX_OVERHANG_DEG = 30.0
"""Steepest overhang from vertical that FDM prints without support: PrusaSlicer with automatic supports (its
default profile, 0.3 mm layers; tests/test_real_clients.py) puts support under the needle mount's bore at θ = 45°
(171 mm³) and 52.5° (110 mm³), none at 60° and above (measured), i.e. at overhangs of 30° and less. Bores, nut
funnels and every other printed ceiling keep to it."""


@dataclass(frozen=True)
class PrintProfile:
    """One part on one process: layer height and first layer (mm), walls (perimeters; 0 = solid, SLA), infill
    (%), solid top/bottom layers, the material, and why these."""

    layer_mm: float
    first_layer_mm: float
    walls: int
    infill_pct: float
    solid_layers: int
    material: str
    why: str

    def layer_top_mm(self, z: float) -> float:
        """The top of the first layer whose top lies at or above ``z`` (print frame, bed at 0; mm)."""
        if z <= self.first_layer_mm + 1e-9:
            return self.first_layer_mm
        k = math.ceil((z - self.first_layer_mm) / self.layer_mm - 1e-9)
        return round(self.first_layer_mm + k * self.layer_mm, 6)


FDM_MATERIAL = "PLA, 1.75 mm filament"
SLA_MATERIAL = "standard (or tough) photopolymer resin, fully post-cured"

PROFILES: dict[str, dict[str, PrintProfile]] = {
    "fdm": {
        "end_cap_mold_base": PrintProfile(0.15, 0.2, 3, 30.0, 5, FDM_MATERIAL,
                                          "0.15 mm layers for the pocket walls (the cap's outer face); 3 walls "
                                          "around pockets, keys and nut pockets; infill only stiffens the block"),
        "end_cap_mold_lid": PrintProfile(0.1, 0.2, 3, 30.0, 5, FDM_MATERIAL,
                                         "0.1 mm layers: the core pins are the cavities, their layer lines the "
                                         "cavity walls; the pins print as walls only"),
        "needle_mount": PrintProfile(0.15, 0.2, 4, 40.0, 5, FDM_MATERIAL,
                                     "4 walls (1.6 mm) for the self-tapping bolt pilots and press-fit dowels; "
                                     "0.15 mm layers for the inclined needle bore"),
    },
    "sla": {
        name: PrintProfile(0.05, 0.05, 0, 100.0, 0, SLA_MATERIAL,
                           "printed solid and flat on the build plate as exported (no supports, no pad); wash "
                           "and post-cure before use")
        for name in ("end_cap_mold_base", "end_cap_mold_lid", "needle_mount")},
}
"""Print profile per ``machine.printer`` and part name."""


DEFAULT_PROFILES = {
    "fdm": PrintProfile(0.2, 0.2, 3, 20.0, 4, FDM_MATERIAL, "the slicer's usual settings: a part with no profile "
                        "of its own"),
    "sla": PROFILES["sla"]["needle_mount"],
}
"""The profile of a registered printed part that :data:`PROFILES` does not name (a part added by one module)."""


def profile(printer: str, part: str) -> PrintProfile:
    """The print profile of ``part`` on ``printer`` (a :data:`PRINTERS` process); :data:`DEFAULT_PROFILES` for a
    part without one of its own."""
    if printer not in PROFILES:
        raise ValueError(f"printer {printer!r} invalid, must be one of {PRINTERS}")
    return PROFILES[printer].get(part, DEFAULT_PROFILES[printer])
