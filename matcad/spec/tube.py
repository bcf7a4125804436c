"""The [tube] table of a ``kind = "tube"`` spec: an AcousTac fipple-tube taxel (Li et al. 2022; the MAT paper's
Fig. 1a), a printed closed-open tube with a fipple (windway and edge) at its open end and the cast silicone end cap
on its closed end. Lengths in millimetres, angles in degrees.

The tube reuses the MAT taxel's cast cap: the cap's cavity continues the bore (diameter = bore_diameter, depth =
cap_depth), so the cap mold, the cap mechanics and the wall model read it as the cavity of a MAT cap. Which other
tables a tube spec may carry is :data:`TUBE_TABLES` (the rest describe the MAT neck plate stack and are refused).
Sources of the defaults and ranges: docs/tube.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from matcad.spec.fields import LENGTH_MAX_MM, Section, SpecError, length_mm, param

EDGE_LAND_MM = 0.1
"""The labium's tip sits this far outside the bore's wall line: a plane through the wall line would touch the bore
at one point (no valid solid), and no printer makes a sharper edge than this anyway."""
SEAT_CONE_DEG = 30.0
"""The cones of the printed tube (the bore's floor on the block, the needle seat's ceiling, the cap seat's
underside, the labium's inner bevel), from vertical: the FDM overhang limit of :mod:`matcad.rules.printing`."""
KINDS = ("mat", "tube")
"""Taxel kinds: 'mat' the Helmholtz taxel of the MAT paper (default), 'tube' the AcousTac fipple tube."""
TUBE_TABLES = ("tube", "end_cap", "mold", "machine", "outputs", "air", "wall", "microphone", "silicone",
               "mechanics", "needle")
"""The tables a tube spec may carry besides its name and kind; the others (cavity, neck, plate, guide, spacer,
fasteners, mount, calibration, reference, array, taxel, measured) describe the MAT stack and are refused."""


@dataclass(frozen=True)
class Tube(Section):
    """The printed fipple tube (docs/tube.md): a bore of diameter ``bore_diameter`` running ``length`` from the
    fipple's mouth (the edge) to the cap's seat, a windway of ``windway_height`` x ``windway_width`` through the
    block, the edge ``edge_distance`` downstream of the windway exit, bevelled at ``edge_angle``."""

    table: ClassVar[str] = "tube"

    bore_diameter: float = param("inner diameter of the printed tube (and of the cap's cavity); AcousTac-scale "
                                 "tubes 4-10 mm", "mm", lo=0.5, hi=50.0, lo_open=False)
    length: float = param("bore length from the mouth's edge to the cap's seat (the air column without the cap's "
                          "cavity); a quarter wave at 3-5.5 kHz needs about 12-26 mm", "mm", lo=2.0, hi=1000.0,
                          lo_open=False)
    cap_depth: float | None = param("depth of the cap's cavity, which continues the bore (default = "
                                    "bore_diameter); pressing the cap shortens the air column by its volume change",
                                    "mm", None, lo=0.5, hi=LENGTH_MAX_MM, lo_open=False)
    mouth: str = param("the open end: 'fipple' (a windway blowing at an edge through a window in the tube wall, "
                       "Rayleigh's aperture conductance) or 'unflanged' / 'flanged' (an edge-blown open end, "
                       "Levine & Schwinger 1948 / Norris & Sheng 1989)", default="fipple", kind="choice",
                       choices=("fipple", "unflanged", "flanged"))
    windway_height: float = param("windway (flue) height h, the jet's thickness; recorders 0.5-1.5 mm",
                                  "mm", 1.0, lo=0.1, hi=20.0, lo_open=False)
    windway_width: float = param("windway width B across the jet = the mouth's width; at most the bore "
                                 "diameter", "mm", 4.0, lo=0.3, hi=50.0, lo_open=False)
    edge_distance: float = param("distance W from the windway exit to the edge (the mouth's height); "
                                 "recorders W ~ 4 h", "mm", 3.0, lo=0.3, hi=50.0, lo_open=False)
    edge_angle: float = param("angle of the edge's bevel (labium) to the jet; recorders 10-30 deg", "deg", 20.0,
                              lo=5.0, hi=60.0, lo_open=False)
    wall: float = length_mm("printed tube wall thickness (>= 2 extrusion widths on FDM)", 1.2)
    supply_flow_l_min: float = param("air flow into the windway (the MAT paper blew about 1.5 L/min through a "
                                     "1-10 L/min meter); sets the jet speed U = Q / (h B) the edge-tone rule "
                                     "checks", "L/min", 1.5, lo=0.01, hi=100.0, lo_open=False)
    block_length: float = param("length of the block the windway runs through, from the supply needle's seat "
                                "to the windway exit", "mm", 8.0, lo=1.0, hi=100.0, lo_open=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.windway_width > self.bore_diameter:
            raise SpecError("tube.windway_width", self.windway_width,
                            f"must be <= tube.bore_diameter = {self.bore_diameter:g} mm (the mouth is a window in "
                            "the bore's wall)")
        if self.windway_height >= self.bore_diameter / 2:
            raise SpecError("tube.windway_height", self.windway_height,
                            f"must be < tube.bore_diameter / 2 = {self.bore_diameter / 2:g} mm (the windway runs "
                            "through the block beside the bore's axis)")

    @property
    def cap_cavity_depth(self) -> float:
        """The cap's cavity depth (mm): ``cap_depth``, default the bore diameter."""
        return self.bore_diameter if self.cap_depth is None else self.cap_depth
