"""The [tube] table of a ``kind = "tube"`` spec: an AcousTac fipple-tube taxel (Li et al. 2022; the MAT paper's
Fig. 1a), a printed closed-open tube with a fipple (windway and edge) at its open end and the cast silicone end cap
on its closed end. Lengths in millimetres, angles in degrees.

The tube reuses the MAT taxel's cast cap: the cap's cavity continues the bore (diameter = bore_diameter, depth =
cap_depth), so the cap mold, the cap mechanics and the wall model read it as the cavity of a MAT cap. Which other
tables a tube spec may carry is :data:`TUBE_TABLES` (the rest describe the MAT neck plate stack and are refused).
Sources of the defaults and ranges: docs/tube.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from matcad.spec.fields import LENGTH_MAX_MM, Section, SpecError, length_mm, param

EDGE_LAND_MM = 0.1
"""The labium's tip sits this far outside the bore's wall line: a plane through the wall line would touch the bore
at one point (no valid solid), and no printer makes a sharper edge than this anyway."""
SEAT_CONE_DEG = 30.0
"""The cones of the printed tube (the bore's floor on the block, the needle seat's ceiling, the cap seat's
underside, the labium's inner bevel), from vertical: the FDM overhang limit of :mod:`matcad.rules.printing`."""
MOUTHS = ("fipple", "transverse", "unflanged", "flanged")
"""The tube's open ends (docs/tube.md): a fipple's window above its block, a transverse window in the side wall (the
flute's arrangement, which prints without support), a plain open end unflanged or in a flange."""
WINDOWED = ("fipple", "transverse")
"""The mouths that are a window in the tube's wall, blown by the windway."""


def transverse_window_mm(windway_height: float, windway_width: float, edge_distance: float) -> tuple[float, float]:
    """A transverse mouth's window, printed with the bore vertical (mm): the height of its straight sides (the
    windway's width B plus the rise of its pointed top, (h/2)/tan 30°, so that the windway's point does not open
    under the window's roof) and the rise of its gable roof over them, (W/2)/tan 30° (both at the FDM overhang
    limit, :data:`SEAT_CONE_DEG` from vertical)."""
    slope = math.tan(math.radians(SEAT_CONE_DEG))
    return windway_width + windway_height / 2 / slope, edge_distance / 2 / slope


def transverse_floor_mm(bore_radius: float, wall: float) -> float:
    """Height of a transverse mouth's window above the bed (mm): the bore's floor below it is a funnel at
    :data:`SEAT_CONE_DEG` from vertical (no ceiling to bridge), over the printed wall's thickness under its tip."""
    return bore_radius / math.tan(math.radians(SEAT_CONE_DEG)) + wall


def transverse_window_area_mm2(windway_height: float, windway_width: float, edge_distance: float) -> float:
    """The transverse window's area (mm²): W × its sides' height plus the gable's triangle
    (:func:`transverse_window_mm`)."""
    sides, gable = transverse_window_mm(windway_height, windway_width, edge_distance)
    return edge_distance * (sides + gable / 2)


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
    mouth: str = param("the open end: 'fipple' (a windway through the block blowing at an edge across a window in "
                       "the tube wall, Rayleigh's aperture conductance), 'transverse' (the windway across the tube's "
                       "side, its jet tangential to the bore, the window's far side the edge: prints without support "
                       "on FDM) or 'unflanged' / 'flanged' (an edge-blown open end, Levine & Schwinger 1948 / Norris "
                       "& Sheng 1989)", default="fipple", kind="choice", choices=MOUTHS)
    windway_height: float = param("windway (flue) height h, the jet's thickness; recorders 0.5-1.5 mm",
                                  "mm", 1.0, lo=0.1, hi=20.0, lo_open=False)
    windway_width: float = param("windway width B across the jet = the mouth's width (a transverse mouth: the "
                                 "window's height along the bore); at most the bore diameter for a fipple",
                                 "mm", 4.0, lo=0.3, hi=50.0, lo_open=False)
    edge_distance: float = param("distance W from the windway exit to the edge (the mouth's height; a transverse "
                                 "mouth: its width across the bore's side, < bore_diameter); recorders W ~ 4 h",
                                 "mm", 3.0, lo=0.3, hi=50.0, lo_open=False)
    edge_angle: float = param("angle of the edge's bevel (labium) to the jet; recorders 10-30 deg (a transverse "
                              "mouth's edge is the window's far side, the wall's thickness: unused)", "deg", 20.0,
                              lo=5.0, hi=60.0, lo_open=False)
    wall: float = length_mm("printed tube wall thickness (>= 2 extrusion widths on FDM)", 1.2)
    supply_flow_l_min: float = param("air flow into the windway (the MAT paper blew about 1.5 L/min through a "
                                     "1-10 L/min meter); sets the jet speed U = Q / (h B) the edge-tone rule "
                                     "checks", "L/min", 1.5, lo=0.01, hi=100.0, lo_open=False)
    block_length: float = param("length of the block the windway runs through, from the supply needle's seat "
                                "to the windway exit (a transverse mouth: the boss beside the tube, along the jet)",
                                "mm", 8.0, lo=1.0, hi=100.0, lo_open=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.mouth == "transverse" and self.edge_distance >= self.bore_diameter:
            raise SpecError("tube.edge_distance", self.edge_distance,
                            f"must be < tube.bore_diameter = {self.bore_diameter:g} mm for a transverse mouth (its "
                            "window spans W across the bore's side)")
        if self.mouth != "transverse" and self.windway_width > self.bore_diameter:
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
