"""The tables of a spec: one frozen dataclass per TOML table, validated on construction. Lengths in millimetres.

Validation rejects only what is not physical (non-positive or non-finite lengths, wrong types); what is merely
hard to fabricate is a design rule, not an input error. Dimension names follow the paper (mat-paper.md, Fig. 2):
D, L the silicone cavity; d, l the acrylic neck. The [calibration] table, also read on its own, is in
:mod:`matcad.spec.calibration`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from matcad.materials import DEFAULT_GRADE, GRADES
from matcad.spec.calibration import Calibration
from matcad.spec.drawn import Drawn
from matcad.spec.fields import (LENGTH_MAX_MM, LENGTH_MIN_MM, MISSING, Section, SpecError, length_mm,
                               param)

CAP_OUTER_PER_D = 2.5
CAP_TOP_PER_D = 0.6


def _example_sheet(thickness: str) -> Any:
    """A sheet's ``thickness_example`` field, whose thickness is the field ``thickness`` ('neck.length')."""
    return param(f"true if {thickness} (with thickness_measured = true) is an example value, a template's stand-in "
                 "for a calipered sheet: predictions use it as measured, `check` reports it unverified until you "
                 "enter yours and set this false", default=False, kind="bool")


def _sheet_kerf(sheet: str) -> Any:
    """A laser-cut sheet's ``laser_kerf`` field (mm; None: machine.laser_kerf)."""
    return param(f"full kerf in the {sheet} sheet; default machine.laser_kerf (kerf grows with sheet thickness: "
                 "measure each sheet with `matcad coupon`)", "mm", None, lo=0.0, hi=5.0, lo_open=False)


@dataclass(frozen=True)
class Cavity(Section):
    """The silicone end cap's cylindrical channel (paper: D, L)."""

    table: ClassVar[str] = "cavity"

    diameter: float = length_mm("cavity diameter D, cast in the silicone end cap")
    length: float = length_mm("cavity length L, from the plate face to the closed end")


@dataclass(frozen=True)
class Neck(Section):
    """The through-hole in the acrylic neck plate (paper: d, l)."""

    table: ClassVar[str] = "neck"

    diameter: float = length_mm("neck diameter d (the through-hole as designed)")
    length: float = length_mm("neck length l = neck plate thickness")
    mouth: str = param("outer end of the neck: 'baffled' (flat infinite flange), 'unflanged' "
                       "(thin tube end), or 'mount' (flange with the air-supply mount a spacer height "
                       "below, as in the paper)", default="mount", kind="choice",
                       choices=("baffled", "unflanged", "mount"))
    riser: bool = param("the neck runs on through the [riser] sheet stacked on the plate: it is neck.length + "
                        "riser.thickness long and the cap sits on the riser; false: where there is a [riser] the cap "
                        "sits on the plate in a pocket cut through the riser, its flange riser.thickness thicker",
                        default=False, kind="bool")


@dataclass(frozen=True)
class Riser(Section):
    """A second laser-cut sheet stacked on the neck plate, under the caps, that gives a board two neck lengths
    (docs/arrays.md): a taxel whose neck runs on through it (``neck.riser``, ``[[taxel]] neck_riser``) has a neck
    neck.length + riser.thickness long and its cap on the riser; every other cap sits on the plate in a pocket cut
    through the riser, its flange riser.thickness thicker, so every flange meets the clamp at one height."""

    table: ClassVar[str] = "riser"

    thickness: float = length_mm("riser sheet thickness (a stock acrylic sheet)")
    thickness_measured: bool = param("true if riser.thickness is a measured value", default=False, kind="bool")
    thickness_example: bool = _example_sheet("riser.thickness")
    laser_kerf: float | None = _sheet_kerf("riser")


@dataclass(frozen=True)
class Plate(Section):
    """The laser-cut neck plate outline; the mount gap under it vents at its edges."""

    table: ClassVar[str] = "plate"

    width: float = length_mm("neck plate width (x), neck at its centre", 24.0)
    depth: float = length_mm("neck plate depth (y), neck at its centre", 24.0)
    thickness_measured: bool = param("true if neck.length is the measured sheet thickness (cast acrylic "
                                     "varies +-(0.4 + 0.1 t) mm, ISO 7823-1)", default=False, kind="bool")
    thickness_example: bool = _example_sheet("neck.length")
    label: str = param("text engraved on the neck plate ('' for none)", default="", kind="text")
    neck_pilot: bool = param("cut the neck as an undersize pilot, to be drilled to neck.diameter "
                             "(avoids the laser's taper in thick sheet)", default=False, kind="bool")
    pilot_undersize: float = param("pilot hole is this much smaller than the neck", "mm", 0.3, lo=0.0,
                                   hi=LENGTH_MAX_MM)
    bolt_inset: float = param("bolt and dowel centres inset from the plate edges", "mm", 2.5, lo=0.0,
                              hi=LENGTH_MAX_MM)
    laser_kerf: float | None = _sheet_kerf("neck plate")
    support_posts: bool = param("print support posts on the needle mount under the plate, on the centre line "
                                "between a board's two columns (matcad.parts.features.plate_post_positions_mm): "
                                "they carry a pressed taxel's force so a long thin plate stays flat "
                                "(plate.bending); `design --taxels` sets it when the board would bend",
                                default=False, kind="bool")
    post_diameter: float = length_mm("support post diameter: >= 2 FDM nozzle widths (print.wall), small enough "
                                     "to stay 3 mount gaps from the mouths of the 12-taxel capacity board "
                                     "(docs/arrays.md)", 1.5)


@dataclass(frozen=True)
class Guide(Section):
    """Laser-cut guides over the plate: a locator around the cap's flange and a clamp over it (paper Sec. II)."""

    table: ClassVar[str] = "guide"

    thickness: float = length_mm("guide sheet thickness (paper: 1.5 mm acrylic)", 1.5)
    thickness_measured: bool = param("true if guide.thickness is a measured value", default=False,
                                     kind="bool")
    thickness_example: bool = _example_sheet("guide.thickness")
    laser_kerf: float | None = _sheet_kerf("guide")


@dataclass(frozen=True)
class Spacer(Section):
    """Spacers between the neck plate and the air-supply mount (paper: 1.59 mm, for ventilation)."""

    table: ClassVar[str] = "spacer"

    height: float = length_mm("gap between neck plate and mount; the 'mount' mouth's gap height", 1.59)
    style: str = param("'laser' (square spacers cut from a sheet of this thickness) or 'standoff' "
                       "(printed on the needle mount)", default="laser", kind="choice",
                       choices=("laser", "standoff"))
    size: float = length_mm("spacer square side / standoff diameter", 5.0)
    thickness_measured: bool = param("true if spacer.height is a measured sheet thickness", default=False,
                                     kind="bool")
    thickness_example: bool = _example_sheet("spacer.height")
    laser_kerf: float | None = _sheet_kerf("spacer")


@dataclass(frozen=True)
class Fasteners(Section):
    """Bolts clamping guide, plate, spacers and mount; dowel pins aligning them."""

    table: ClassVar[str] = "fasteners"

    bolt: str = param("metric bolt size", default="M2", kind="choice", choices=("M2", "M2.5", "M3"))
    bolt_fit: str = param("ISO 273 clearance class", default="normal", kind="choice",
                          choices=("close", "normal", "loose"))
    dowel_diameter: float = length_mm("dowel pin diameter", 1.5)
    dowel_fit_laser: str = param("dowel fit in laser-cut parts (press fits are not achievable in "
                                 "laser-cut acrylic)", default="slip", kind="choice",
                                 choices=("clearance", "slip", "press"))
    dowel_fit_printed: str = param("dowel fit in the printed needle mount", default="press", kind="choice",
                                   choices=("clearance", "slip", "press"))


@dataclass(frozen=True)
class Needle(Section):
    """The air-supply needle (paper: 1.52 mm, theta = 75 deg)."""

    table: ClassVar[str] = "needle"

    outer_diameter: float = length_mm("needle outer diameter", 1.52)
    theta_deg: float = param("needle axis angle to the plate surface", "deg", 75.0, lo=0.0, hi=90.0)
    y: float = param("distance, in the plane of the plate's underside, from the point where the needle "
                     "axis meets that plane to the nearest edge of the neck opening", "mm", 1.0,
                     lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)
    tip_clearance: float = param("gap between the needle's end face and the plate underside", "mm", 0.3,
                                 lo=0.0, hi=LENGTH_MAX_MM, lo_open=False)
    length: float = length_mm("exposed needle length modelled for collision checks", 25.0)
    fit: str = param("needle fit in the printed bore", default="slip", kind="choice",
                     choices=("clearance", "slip", "press"))
    flow_l_min: float = param("air flow through the needle (the paper blew about 1.5 L/min, read on a 1-10 L/min "
                              "meter); sets the jet speed the jet.strouhal rule checks against the paper's "
                              "operating point", "L/min", 1.5, lo=0.01, hi=100.0, lo_open=False)


@dataclass(frozen=True)
class Mount(Section):
    """The printed air-supply (needle) mount under the plate."""

    table: ClassVar[str] = "mount"

    thickness: float = length_mm("mount block thickness", 8.0)


@dataclass(frozen=True)
class Mold(Section):
    """Two-part printed mold for the silicone end cap (base + lid carrying the core pin)."""

    table: ClassVar[str] = "mold"

    draft_deg: float = param("core-pin draft; narrows the cavity toward its closed end (reported)", "deg",
                             0.0, lo=0.0, hi=10.0, lo_open=False)
    wall: float = length_mm("mold wall around each cap and between caps", 4.0)
    floor: float = length_mm("mold floor under the cap top", 2.0)
    lid_thickness: float = length_mm("lid plate thickness", 3.0)
    count: int = param("caps per mold", default=1, kind="integer", lo=1, hi=50)
    fill_port: float = length_mm("fill port diameter (>= 2 mm for syringe filling)", 2.0)
    vent: float = length_mm("vent diameter", 1.0)
    vent_reach: float = length_mm("farthest any point of a cavity ceiling in pour orientation may be from the edge "
                                  "of a vent or the fill port; vents are added until it holds", 2.0)
    bolt: str = param("mold clamp bolt size", default="M3", kind="choice", choices=("M2", "M2.5", "M3"))
    key_height: float = length_mm("registration key (truncated cone) height", 2.0)
    key_diameter: float = length_mm("registration key base diameter", 4.0)


@dataclass(frozen=True)
class Machine(Section):
    """The user's laser cutter and printer; fits and compensation come from here."""

    table: ClassVar[str] = "machine"

    laser_kerf: float = param("full kerf width of the laser (measure with `matcad coupon`)", "mm", 0.2,
                              lo=0.0, hi=5.0, lo_open=False)
    laser_min_feature: float = length_mm("smallest laser-cut feature or web that survives", 1.0)
    printer: str = param("printer process for the mold and mount", default="fdm", kind="choice",
                         choices=("fdm", "sla"))
    nozzle: float = length_mm("FDM nozzle diameter (walls >= 2 nozzles)", 0.4)
    key_clearance: float | None = param("registration-key clearance per side; default by printer "
                                        "(fdm 0.2, sla 0.1)", "mm", None, lo=0.0, hi=5.0)
    print_volume_x: float | None = length_mm(
        "printer's build volume along x (the bed's width); default by printer: fdm 250 (a Prusa MK4, 250 x 210 x "
        "220 mm, Prusa Research's specifications), sla 120 (a Prusa SL1, 120 x 68 x 150 mm, the same source)", None)
    print_volume_y: float | None = length_mm("printer's build volume along y (the bed's depth); default by printer: "
                                             "fdm 210 (Prusa MK4), sla 68 (Prusa SL1)", None)
    print_volume_z: float | None = length_mm("printer's build height; default by printer: fdm 220 (Prusa MK4), sla "
                                             "150 (Prusa SL1)", None)
    laser_bed_x: float = length_mm("laser cutter's work area along x; default a K40-class CO2 laser's 300 x 200 mm "
                                   "bed, the common hobby laser (a 10 mm margin is kept at every edge)", 300.0)
    laser_bed_y: float = length_mm("laser cutter's work area along y; default the K40-class 200 mm", 200.0)
    stl_tolerance: float = param("STL chordal deviation; floored at 1e-4 x each part's size (the report "
                                 "gives the one used)", "mm", 0.01, lo=1e-5, hi=10.0)
    stl_angular_tolerance: float = param("STL angular deviation (0.1 rad keeps STL volume within 0.05 % "
                                         "of the solid on the paper taxel; below 0.02 rad the triangle "
                                         "count, time and memory grow as its inverse square)", "rad", 0.1,
                                         lo=0.02, hi=1.0, lo_open=False)


@dataclass(frozen=True)
class Outputs(Section):
    """What `matcad build` writes; only what is asked for is built."""

    table: ClassVar[str] = "outputs"

    end_cap_mold: bool = param("STL + STEP mold base and lid", default=True, kind="bool")
    neck_plate: bool = param("DXF + SVG neck plate, and the [riser] bonded on it when there is one", default=True,
                             kind="bool")
    guides: bool = param("DXF + SVG locator and clamp guides", default=True, kind="bool")
    spacers: bool = param("DXF + SVG spacers (when spacer.style = 'laser')", default=True, kind="bool")
    needle_mount: bool = param("STL + STEP needle mount", default=True, kind="bool")
    assembly: bool = param("assembly.step and section.svg", default=True, kind="bool")
    reference_square: bool = param("10 mm reference square on its own layer in every DXF/SVG",
                                   default=True, kind="bool")


@dataclass(frozen=True)
class Microphone(Section):
    """The recording chain."""

    table: ClassVar[str] = "microphone"

    sample_rate_hz: float = param("microphone sample rate (band must stay < 0.45 x this)", "Hz", 44100.0,
                                  lo=0.0, hi=1e7)
    floor_hz: float = param("lowest frequency worth designing for (room noise, hum)", "Hz", 1000.0,
                            lo=0.0, hi=1e7, lo_open=False)


@dataclass(frozen=True)
class Silicone(Section):
    """Cast silicone: a grade from :mod:`matcad.materials` supplies the defaults of every material value."""

    table: ClassVar[str] = "silicone"

    grade: str = param("cast silicone grade (see docs/materials.md for the sourced values)",
                       default=DEFAULT_GRADE, kind="choice", choices=tuple(GRADES))
    density_g_cm3: float | None = param("density of the cured silicone; default from the grade", "g/cm^3",
                                        None, lo=0.0, hi=30.0)
    waste_factor: float = param("batch volume / cast volume (cups, sprues, vents)", "", 1.3, lo=1.0,
                                hi=100.0, lo_open=False)


@dataclass(frozen=True)
class EndCap(Section):
    """Outer body of the cast silicone end cap (the paper does not give it; defaults are matcad's)."""

    table: ClassVar[str] = "end_cap"

    outer_diameter: float | None = length_mm(
        f"outer diameter of the silicone end cap body; default {CAP_OUTER_PER_D} x cavity.diameter", None)
    top_thickness: float | None = length_mm(
        f"silicone thickness above the cavity's closed end; default {CAP_TOP_PER_D} x cavity.diameter", None)
    flange_width: float = length_mm("width of the base flange the clamp guide holds, beyond the body", 2.0)
    flange_squeeze: float = param("flange is this much thicker than the guide, so the clamp seals it",
                                  "mm", 0.1, lo=0.0, hi=LENGTH_MAX_MM, lo_open=False)


@dataclass(frozen=True)
class Air(Section):
    """The air in and around the taxel."""

    table: ClassVar[str] = "air"

    temperature_c: float = param("air temperature; sets the speed of sound", "degC", 20.0,
                                 lo=-273.15, hi=1000.0)
    speed_of_sound: float | None = param("speed of sound; overrides temperature_c when given (at least "
                                         "50 m/s: slower than any gas in use, e.g. SF6 at -50 C ~ 120 m/s)",
                                         "m/s", None, lo=50.0, hi=1e4, lo_open=False)


WALL_SHEAR_MIN_MPA = 1e-3
"""The softest cast silicone gels are ~1 kPa in shear; below, a wall is no solid (and G's range products
underflow)."""


@dataclass(frozen=True)
class Wall(Section):
    """Cavity wall mechanics."""

    table: ClassVar[str] = "wall"

    model: str = param("'rigid' (ideal walls) or 'silicone' (elastic cap with inertia and loss)",
                       default="rigid", kind="choice", choices=("rigid", "silicone"))
    shear_modulus_mpa: tuple[float, float] | None = param(
        "[low, high] static shear modulus of the cured silicone; default from silicone.grade "
        "(Dragon Skin 30: 0.2-0.6 MPa); at least 1 kPa, the softest cast silicone gels", "MPa", None, kind="range",
        lo=WALL_SHEAR_MIN_MPA, hi=1e6, lo_open=False)
    loss_factor: tuple[float, float] | None = param(
        "[low, high] loss factor eta of the silicone at kHz (G* = G(1 + i eta)); default from silicone.grade "
        "(Dragon Skin 30: 0.1-0.2)", "", None, kind="range", lo=0.0, hi=10.0, lo_open=False)
    khz_modulus_factor: tuple[float, float] | None = param(
        "[low, high] storage modulus at kHz over the static shear_modulus_mpa; default from silicone.grade "
        "(Dragon Skin 30: 1.0-1.6, an assumption, see docs/materials.md); at least 1: an elastomer's storage "
        "modulus never falls with frequency", "", None, kind="range", lo=1.0, hi=1e3, lo_open=False)


@dataclass(frozen=True)
class Mechanics(Section):
    """Cap mechanics for f(F) before casting: the cap pressed by a rigid flat plate (matcad.mechanics)."""

    table: ClassVar[str] = "mechanics"

    material: str = param("hyperelastic law with the grade's sourced constants (docs/materials.md)",
                          default="ogden", kind="choice", choices=("neo_hookean", "yeoh", "ogden"))
    contact: str = param("plate on the cap's top: 'sticking' (no slip) or 'frictionless'", default="sticking",
                         kind="choice", choices=("sticking", "frictionless"))
    shear_modulus_mpa: float | None = param("initial shear modulus the law is scaled to; default the grade's "
                                            "preset (Dragon Skin 30 Ogden: 0.31 MPa)", "MPa", None, lo=0.0,
                                            hi=1e3)
    displacement_mm: float = param("plate travel of the predicted curve", "mm", 2.0, lo=0.0, hi=LENGTH_MAX_MM)
    steps: int = param("load steps over that travel", default=10, kind="integer", lo=1, hi=200)
    element_size_mm: float | None = param("mesh element size; default from the cap's thinnest part", "mm", None,
                                          lo=LENGTH_MIN_MM, hi=LENGTH_MAX_MM)
    max_force_n: float = param("largest normal force a taxel must sense: the top of its loaded band (the paper "
                               "loads its taxel to ~20-25 N, Fig. 7; its Eq. 5 fit turns back at 26.9 N)", "N", 20.0,
                               lo=0.0, hi=1e4)


@dataclass(frozen=True)
class Reference(Drawn, Section):
    """A taxel you built and recorded: matcad then predicts this design as the measured f0 times the physics
    ratio (this design / the reference), which cancels most of what the models miss. Geometry fields left out
    are this design's own; everything else (plate, mouth, silicone, air) is shared."""

    table: ClassVar[str] = "reference"

    f0_hz: float = param("measured unloaded resonance of the reference taxel", "Hz", lo=0.0, hi=1e7)
    f0_tolerance_hz: float = param("+- uncertainty of that measurement", "Hz", 20.0, lo=0.0, hi=1e7,
                                   lo_open=False)


MAX_TAXELS = 64
"""Most taxels one spec may describe (one microphone hears a handful; 64 bounds the work per input)."""


@dataclass(frozen=True)
class Array(Section):
    """Grid helper for a board of identical taxels: ``columns`` x ``rows`` taxels centred on the neck plate, named
    t1, t2, ... row by row from the top left (+y up). Use [[taxel]] entries instead for taxels that differ."""

    table: ClassVar[str] = "array"

    columns: int = param("taxels along x", default=1, kind="integer", lo=1, hi=MAX_TAXELS)
    rows: int = param("taxels along y", default=1, kind="integer", lo=1, hi=MAX_TAXELS)
    pitch_x: float | None = length_mm("distance between neighbouring neck axes along x (required for columns > 1)",
                                      None)
    pitch_y: float | None = length_mm("distance between neighbouring neck axes along y (required for rows > 1)",
                                      None)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.columns * self.rows > MAX_TAXELS:
            raise SpecError("array.rows", self.rows, f"must keep columns x rows <= {MAX_TAXELS} taxels "
                                                     f"(columns = {self.columns})")
        for count, pitch in (("columns", "pitch_x"), ("rows", "pitch_y")):
            if getattr(self, count) > 1 and getattr(self, pitch) is None:
                raise SpecError(f"array.{pitch}", MISSING, f"is required when array.{count} > 1 (mm between neck "
                                                        "axes)")


def _position(doc: str) -> Any:
    return param(doc, "mm", lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)


@dataclass(frozen=True)
class TaxelEntry(Section):
    """One [[taxel]] of an array spec: where its neck is on the plate and how its geometry differs from the shared
    [cavity], [neck], [end_cap] and [needle] tables (a field left out is the shared value). The neck length is the
    plate's sheet, and the riser's with it where the neck runs on through a [riser]; the mouth is the plate's."""

    table: ClassVar[str] = "taxel"

    x: float = _position("neck axis x on the neck plate, plate centre = 0")
    y: float = _position("neck axis y on the neck plate, plate centre = 0")
    name: str | None = param("taxel name in reports and loop outputs; default t<i> (1-based, in file order)",
                             default=None, kind="name")
    cavity_diameter: float | None = length_mm("this taxel's cavity diameter D; default [cavity]", None)
    cavity_length: float | None = length_mm("this taxel's cavity length L; default [cavity]", None)
    neck_diameter: float | None = length_mm("this taxel's neck diameter d; default [neck]", None)
    neck_riser: bool | None = param("this taxel's neck runs on through the [riser] sheet (see neck.riser); default "
                                    "[neck]", default=None, kind="bool")
    cap_outer_diameter: float | None = length_mm(
        f"this taxel's end-cap outer diameter; default [end_cap] if given there, else {CAP_OUTER_PER_D} x its D",
        None)
    cap_top_thickness: float | None = length_mm(
        f"this taxel's end-cap top thickness; default [end_cap] if given there, else {CAP_TOP_PER_D} x its D", None)
    needle_theta_deg: float | None = param("this taxel's needle angle to the plate; default [needle]", "deg",
                                           None, lo=0.0, hi=90.0)
    needle_y: float | None = param("this taxel's needle offset y (see needle.y); default [needle]", "mm", None,
                                   lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)
    needle_flow_l_min: float | None = param("this taxel's needle flow (see needle.flow_l_min); default [needle]",
                                            "L/min", None, lo=0.01, hi=100.0, lo_open=False)
    calibration: Calibration | None = param(
        "this taxel's Eq. 5 calibration as a [taxel.calibration] sub-table, the fields of [calibration] (`matcad "
        "calibrate --taxel NAME` writes it); `sense --spec` uses it, `--calibration NAME=FILE` overrides it",
        default=None, kind="section", section=Calibration)
