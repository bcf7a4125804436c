"""Geometry spec: TOML → validated, frozen dataclasses. All lengths in millimetres.

Each field is declared once, with its unit, default, allowed range and meaning; the same declaration
validates input, prints ``matcad schema`` and documents the template. Validation rejects only what is not
physical (non-positive or non-finite lengths, wrong types, a neck wider than its cavity); what is merely hard
to fabricate is a design rule, not an input error.

Dimension names follow the paper (mat-paper.md, Fig. 2): D, L the silicone cavity; d, l the acrylic neck.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from matcad.inputs import CALIBRATION_MAX_BYTES, SPEC_MAX_BYTES
from matcad.materials import DEFAULT_GRADE, GRADES

LENGTH_MIN_MM = 1e-3
LENGTH_MAX_MM = 1e5
CAP_OUTER_PER_D = 2.5
CAP_TOP_PER_D = 0.6


class SpecError(ValueError):
    """Bad spec input. ``field`` is the dotted spec key, ``value`` what was given, ``allowed`` the rule."""

    def __init__(self, field_name: str, value: Any, allowed: str):
        self.field = field_name
        self.value = value
        self.allowed = allowed
        from matcad.errors import shorten

        super().__init__(f"{field_name} = {shorten(value)}: {allowed}")


def _param(doc: str, unit: str = "", default: Any = dataclasses.MISSING, *, kind: str = "number",
           lo: float | None = None, hi: float | None = None, lo_open: bool = True,
           choices: tuple[str, ...] = (), section: type | None = None) -> Any:
    """Declare one spec field. ``kind`` is number | integer | bool | text | range | choice | name | section (a
    sub-table validated as the Section class ``section``)."""
    meta = {"doc": doc, "unit": unit, "kind": kind, "lo": lo, "hi": hi, "lo_open": lo_open,
            "choices": choices, "section": section}
    return field(default=default, metadata=meta)


def _length(doc: str, default: Any = dataclasses.MISSING) -> Any:
    return _param(doc, "mm", default, lo=LENGTH_MIN_MM, hi=LENGTH_MAX_MM, lo_open=False)


class Section:
    """Base of every spec section: each field is validated on construction by the same per-field converter that
    reads TOML, so ``dataclasses.replace`` (or a direct call) cannot make an invalid section. ``None`` is
    accepted where the field's default is ``None`` (resolved later or optional)."""

    def __post_init__(self) -> None:
        path = SECTION_NAMES.get(type(self), type(self).__name__.lower())
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None and f.default is None:
                continue
            if value is None and f.default is dataclasses.MISSING:
                raise SpecError(f"{path}.{f.name}", None, f"is required ({f.metadata['doc']})")
            object.__setattr__(self, f.name, _convert(f"{path}.{f.name}", value, dict(f.metadata)))


@dataclass(frozen=True)
class Cavity(Section):
    """The silicone end cap's cylindrical channel (paper: D, L)."""

    diameter: float = _length("cavity diameter D, cast in the silicone end cap")
    length: float = _length("cavity length L, from the plate face to the closed end")


@dataclass(frozen=True)
class Neck(Section):
    """The through-hole in the acrylic neck plate (paper: d, l)."""

    diameter: float = _length("neck diameter d (the through-hole as designed)")
    length: float = _length("neck length l = neck plate thickness")
    mouth: str = _param("outer end of the neck: 'baffled' (flat infinite flange), 'unflanged' "
                        "(thin tube end), or 'mount' (flange with the air-supply mount a spacer height "
                        "below, as in the paper)", default="mount", kind="choice",
                        choices=("baffled", "unflanged", "mount"))


@dataclass(frozen=True)
class Plate(Section):
    """The laser-cut neck plate outline; the mount gap under it vents at its edges."""

    width: float = _length("neck plate width (x), neck at its centre", 24.0)
    depth: float = _length("neck plate depth (y), neck at its centre", 24.0)
    thickness_measured: bool = _param("true if neck.length is the measured sheet thickness (cast acrylic "
                                      "varies +-(0.4 + 0.1 t) mm, ISO 7823-1)", default=False, kind="bool")
    label: str = _param("text engraved on the neck plate ('' for none)", default="", kind="text")
    neck_pilot: bool = _param("cut the neck as an undersize pilot, to be drilled to neck.diameter "
                              "(avoids the laser's taper in thick sheet)", default=False, kind="bool")
    pilot_undersize: float = _param("pilot hole is this much smaller than the neck", "mm", 0.3, lo=0.0,
                                    hi=LENGTH_MAX_MM)
    bolt_inset: float = _param("bolt and dowel centres inset from the plate edges", "mm", 2.5, lo=0.0,
                               hi=LENGTH_MAX_MM)
    laser_kerf: float | None = _param("full kerf in the neck plate sheet; default machine.laser_kerf (kerf "
                                      "grows with sheet thickness: measure each sheet with `matcad coupon`)",
                                      "mm", None, lo=0.0, hi=5.0, lo_open=False)


@dataclass(frozen=True)
class Guide(Section):
    """Laser-cut guides over the plate: a locator around the cap's flange and a clamp over it (paper Sec. II)."""

    thickness: float = _length("guide sheet thickness (paper: 1.5 mm acrylic)", 1.5)
    thickness_measured: bool = _param("true if guide.thickness is a measured value", default=False,
                                      kind="bool")
    laser_kerf: float | None = _param("full kerf in the guide sheet; default machine.laser_kerf (kerf "
                                      "grows with sheet thickness: measure each sheet with `matcad coupon`)",
                                      "mm", None, lo=0.0, hi=5.0, lo_open=False)


@dataclass(frozen=True)
class Spacer(Section):
    """Spacers between the neck plate and the air-supply mount (paper: 1.59 mm, for ventilation)."""

    height: float = _length("gap between neck plate and mount; the 'mount' mouth's gap height", 1.59)
    style: str = _param("'laser' (square spacers cut from a sheet of this thickness) or 'standoff' "
                        "(printed on the needle mount)", default="laser", kind="choice",
                        choices=("laser", "standoff"))
    size: float = _length("spacer square side / standoff diameter", 5.0)
    thickness_measured: bool = _param("true if spacer.height is a measured sheet thickness", default=False,
                                      kind="bool")
    laser_kerf: float | None = _param("full kerf in the spacer sheet; default machine.laser_kerf (kerf "
                                      "grows with sheet thickness: measure each sheet with `matcad coupon`)",
                                      "mm", None, lo=0.0, hi=5.0, lo_open=False)


@dataclass(frozen=True)
class Fasteners(Section):
    """Bolts clamping guide, plate, spacers and mount; dowel pins aligning them."""

    bolt: str = _param("metric bolt size", default="M2", kind="choice", choices=("M2", "M2.5", "M3"))
    bolt_fit: str = _param("ISO 273 clearance class", default="normal", kind="choice",
                           choices=("close", "normal", "loose"))
    dowel_diameter: float = _length("dowel pin diameter", 1.5)
    dowel_fit_laser: str = _param("dowel fit in laser-cut parts (press fits are not achievable in "
                                  "laser-cut acrylic)", default="slip", kind="choice",
                                  choices=("clearance", "slip", "press"))
    dowel_fit_printed: str = _param("dowel fit in the printed needle mount", default="press", kind="choice",
                                    choices=("clearance", "slip", "press"))


@dataclass(frozen=True)
class Needle(Section):
    """The air-supply needle (paper: 1.52 mm, theta = 75 deg)."""

    outer_diameter: float = _length("needle outer diameter", 1.52)
    theta_deg: float = _param("needle axis angle to the plate surface", "deg", 75.0, lo=0.0, hi=90.0)
    y: float = _param("distance, in the plane of the plate's underside, from the point where the needle "
                      "axis meets that plane to the nearest edge of the neck opening", "mm", 1.0,
                      lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)
    tip_clearance: float = _param("gap between the needle's end face and the plate underside", "mm", 0.3,
                                  lo=0.0, hi=LENGTH_MAX_MM, lo_open=False)
    length: float = _length("exposed needle length modelled for collision checks", 25.0)
    fit: str = _param("needle fit in the printed bore", default="slip", kind="choice",
                      choices=("clearance", "slip", "press"))


@dataclass(frozen=True)
class Mount(Section):
    """The printed air-supply (needle) mount under the plate."""

    thickness: float = _length("mount block thickness", 8.0)


@dataclass(frozen=True)
class Mold(Section):
    """Two-part printed mold for the silicone end cap (base + lid carrying the core pin)."""

    draft_deg: float = _param("core-pin draft; narrows the cavity toward its closed end (reported)", "deg",
                              0.0, lo=0.0, hi=10.0, lo_open=False)
    wall: float = _length("mold wall around each cap and between caps", 4.0)
    floor: float = _length("mold floor under the cap top", 2.0)
    lid_thickness: float = _length("lid plate thickness", 3.0)
    count: int = _param("caps per mold", default=1, kind="integer", lo=1, hi=50)
    fill_port: float = _length("fill port diameter (>= 2 mm for syringe filling)", 2.0)
    vent: float = _length("vent diameter", 1.0)
    vent_reach: float = _length("farthest any point of a cavity ceiling in pour orientation may be from the edge "
                                "of a vent or the fill port; vents are added until it holds", 2.0)
    bolt: str = _param("mold clamp bolt size", default="M3", kind="choice", choices=("M2", "M2.5", "M3"))
    key_height: float = _length("registration key (truncated cone) height", 2.0)
    key_diameter: float = _length("registration key base diameter", 4.0)


@dataclass(frozen=True)
class Machine(Section):
    """The user's laser cutter and printer; fits and compensation come from here."""

    laser_kerf: float = _param("full kerf width of the laser (measure with `matcad coupon`)", "mm", 0.2,
                               lo=0.0, hi=5.0, lo_open=False)
    laser_min_feature: float = _length("smallest laser-cut feature or web that survives", 1.0)
    printer: str = _param("printer process for the mold and mount", default="fdm", kind="choice",
                          choices=("fdm", "sla"))
    nozzle: float = _length("FDM nozzle diameter (walls >= 2 nozzles)", 0.4)
    key_clearance: float | None = _param("registration-key clearance per side; default by printer "
                                         "(fdm 0.2, sla 0.1)", "mm", None, lo=0.0, hi=5.0)
    stl_tolerance: float = _param("STL chordal deviation; floored at 1e-4 x each part's size (the report "
                                  "gives the one used)", "mm", 0.01, lo=1e-5, hi=10.0)
    stl_angular_tolerance: float = _param("STL angular deviation (0.1 rad keeps STL volume within 0.05 % "
                                          "of the solid on the paper taxel; below 0.02 rad the triangle "
                                          "count, time and memory grow as its inverse square)", "rad", 0.1,
                                          lo=0.02, hi=1.0, lo_open=False)


@dataclass(frozen=True)
class Outputs(Section):
    """What `matcad build` writes; only what is asked for is built."""

    end_cap_mold: bool = _param("STL + STEP mold base and lid", default=True, kind="bool")
    neck_plate: bool = _param("DXF + SVG neck plate", default=True, kind="bool")
    guides: bool = _param("DXF + SVG locator and clamp guides", default=True, kind="bool")
    spacers: bool = _param("DXF + SVG spacers (when spacer.style = 'laser')", default=True, kind="bool")
    needle_mount: bool = _param("STL + STEP needle mount", default=True, kind="bool")
    assembly: bool = _param("assembly.step and section.svg", default=True, kind="bool")
    reference_square: bool = _param("10 mm reference square on its own layer in every DXF/SVG",
                                    default=True, kind="bool")


@dataclass(frozen=True)
class Microphone(Section):
    """The recording chain."""

    sample_rate_hz: float = _param("microphone sample rate (band must stay < 0.45 x this)", "Hz", 44100.0,
                                   lo=0.0, hi=1e7)
    floor_hz: float = _param("lowest frequency worth designing for (room noise, hum)", "Hz", 1000.0,
                             lo=0.0, hi=1e7, lo_open=False)


@dataclass(frozen=True)
class Silicone(Section):
    """Cast silicone: a grade from :mod:`matcad.materials` supplies the defaults of every material value."""

    grade: str = _param("cast silicone grade (see docs/materials.md for the sourced values)",
                        default=DEFAULT_GRADE, kind="choice", choices=tuple(GRADES))
    density_g_cm3: float | None = _param("density of the cured silicone; default from the grade", "g/cm^3",
                                         None, lo=0.0, hi=30.0)
    waste_factor: float = _param("batch volume / cast volume (cups, sprues, vents)", "", 1.3, lo=1.0,
                                 hi=100.0, lo_open=False)


@dataclass(frozen=True)
class EndCap(Section):
    """Outer body of the cast silicone end cap (the paper does not give it; defaults are matcad's)."""

    outer_diameter: float | None = _length(
        f"outer diameter of the silicone end cap body; default {CAP_OUTER_PER_D} x cavity.diameter", None)
    top_thickness: float | None = _length(
        f"silicone thickness above the cavity's closed end; default {CAP_TOP_PER_D} x cavity.diameter", None)
    flange_width: float = _length("width of the base flange the clamp guide holds, beyond the body", 2.0)
    flange_squeeze: float = _param("flange is this much thicker than the guide, so the clamp seals it",
                                   "mm", 0.1, lo=0.0, hi=LENGTH_MAX_MM, lo_open=False)


@dataclass(frozen=True)
class Air(Section):
    """The air in and around the taxel."""

    temperature_c: float = _param("air temperature; sets the speed of sound", "degC", 20.0,
                                  lo=-273.15, hi=1000.0)
    speed_of_sound: float | None = _param("speed of sound; overrides temperature_c when given (at least "
                                          "50 m/s: slower than any gas in use, e.g. SF6 at -50 C ~ 120 m/s)",
                                          "m/s", None, lo=50.0, hi=1e4, lo_open=False)


@dataclass(frozen=True)
class Wall(Section):
    """Cavity wall mechanics."""

    model: str = _param("'rigid' (ideal walls) or 'silicone' (elastic cap with inertia and loss)",
                        default="rigid", kind="choice", choices=("rigid", "silicone"))
    shear_modulus_mpa: tuple[float, float] | None = _param(
        "[low, high] static shear modulus of the cured silicone; default from silicone.grade "
        "(Dragon Skin 30: 0.2-0.6 MPa)", "MPa", None, kind="range", lo=0.0, hi=1e6)
    loss_factor: tuple[float, float] | None = _param(
        "[low, high] loss factor eta of the silicone at kHz (G* = G(1 + i eta)); default from silicone.grade "
        "(Dragon Skin 30: 0.1-0.2)", "", None, kind="range", lo=0.0, hi=10.0, lo_open=False)
    khz_modulus_factor: tuple[float, float] | None = _param(
        "[low, high] storage modulus at kHz over the static shear_modulus_mpa; default from silicone.grade "
        "(Dragon Skin 30: 1.0-1.6, an assumption, see docs/materials.md)", "", None, kind="range", lo=0.0,
        hi=1e3)


@dataclass(frozen=True)
class Mechanics(Section):
    """Cap mechanics for f(F) before casting: the cap pressed by a rigid flat plate (matcad.mechanics)."""

    material: str = _param("hyperelastic law with the grade's sourced constants (docs/materials.md)",
                           default="ogden", kind="choice", choices=("neo_hookean", "yeoh", "ogden"))
    contact: str = _param("plate on the cap's top: 'sticking' (no slip) or 'frictionless'", default="sticking",
                          kind="choice", choices=("sticking", "frictionless"))
    shear_modulus_mpa: float | None = _param("initial shear modulus the law is scaled to; default the grade's "
                                             "preset (Dragon Skin 30 Ogden: 0.31 MPa)", "MPa", None, lo=0.0,
                                             hi=1e3)
    displacement_mm: float = _param("plate travel of the predicted curve", "mm", 2.0, lo=0.0, hi=LENGTH_MAX_MM)
    steps: int = _param("load steps over that travel", default=10, kind="integer", lo=1, hi=200)
    element_size_mm: float | None = _param("mesh element size; default from the cap's thinnest part", "mm", None,
                                           lo=LENGTH_MIN_MM, hi=LENGTH_MAX_MM)
    max_force_n: float = _param("largest normal force a taxel must sense: the top of its loaded band (the paper "
                                "loads its taxel to ~20-25 N, Fig. 7; its Eq. 5 fit turns back at 26.9 N)", "N", 20.0,
                                lo=0.0, hi=1e4)


@dataclass(frozen=True)
class Calibration(Section):
    """Paper Eq. 5 constants: V_eff = v0_mm3 - a F^2 - b F (F in N)."""

    v0_mm3: float = _param("effective unloaded cavity volume V_ci (at least the smallest cavity a spec allows, "
                           "(1e-3 mm)^3)", "mm^3", lo=LENGTH_MIN_MM ** 3, hi=1e18, lo_open=False)
    a: float = _param("quadratic deflection coefficient a (paper: -0.0086)", "mm^3/N^2",
                      lo=-1e12, hi=1e12, lo_open=False)
    b: float = _param("linear deflection coefficient b (paper: 0.4626)", "mm^3/N",
                      lo=-1e12, hi=1e12, lo_open=False)
    area_convention: str = _param(
        "neck area used with v0: 'pi_d2/4' (physical, A = pi d^2/4) or 'd2/4' (the paper's fit, "
        "see docs/paper.md)", default="pi_d2/4", kind="choice", choices=("pi_d2/4", "d2/4"))
    k_mm3_hz2: float | None = _param("K = c^2 A / (4 pi^2 l) the fit used; when given it replaces the one "
                                     "computed from the neck and area_convention (written by `matcad calibrate`)",
                                     "mm^3 Hz^2", None, lo=0.0, hi=1e30)
    force_range_n: tuple[float, float] | None = _param(
        "[low, high] forces the calibration was measured over; `sense` gives no force outside it", "N", None,
        kind="range", lo=-1e6, hi=1e6, lo_open=False)
    covariance: tuple[float, ...] | None = _param(
        "covariance of (v0_mm3, b, a), 9 numbers row by row (written by `matcad calibrate`)", "", None,
        kind="vector9", lo=-1e30, hi=1e30, lo_open=False)
    residual_std_mm3: float | None = _param("standard deviation of the fit's residuals in K/f^2", "mm^3", None,
                                            lo=0.0, hi=1e30, lo_open=False)
    dof: int | None = _param("degrees of freedom of the fit (points - 3)", default=None, kind="integer",
                             lo=1, hi=10**9)
    cycle_std_mm3: float | None = _param(
        "between-cycle (hysteresis) standard deviation in K/f^2, estimated from several load cycles or assumed "
        "from the paper (written by `matcad calibrate`); added to every force interval", "mm^3", None,
        lo=0.0, hi=1e30, lo_open=False)
    temperature_c: float | None = _param("air temperature during calibration; `sense --temperature-c` scales "
                                         "frequencies by sqrt(T/T_cal) (f follows c)", "degC", None,
                                         lo=-273.15, hi=1000.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_calibration(self)


@dataclass(frozen=True)
class Reference(Section):
    """A taxel you built and recorded: matcad then predicts this design as the measured f0 times the physics
    ratio (this design / the reference), which cancels most of what the models miss. Geometry fields left out
    are this design's own; everything else (plate, mouth, silicone, air) is shared."""

    f0_hz: float = _param("measured unloaded resonance of the reference taxel", "Hz", lo=0.0, hi=1e7)
    f0_tolerance_hz: float = _param("+- uncertainty of that measurement", "Hz", 20.0, lo=0.0, hi=1e7,
                                    lo_open=False)
    cavity_diameter: float | None = _length("reference cavity diameter; default this design's", None)
    cavity_length: float | None = _length("reference cavity length; default this design's", None)
    neck_diameter: float | None = _length("reference neck diameter; default this design's", None)
    neck_length: float | None = _length("reference neck length (sheet thickness); default this design's", None)
    cap_outer_diameter: float | None = _length("reference end-cap outer diameter; default this design's", None)
    cap_top_thickness: float | None = _length("reference end-cap top thickness; default this design's", None)


MAX_TAXELS = 64
"""Most taxels one spec may describe (one microphone hears a handful; 64 bounds the work per input)."""


@dataclass(frozen=True)
class Array(Section):
    """Grid helper for a board of identical taxels: ``columns`` x ``rows`` taxels centred on the neck plate, named
    t1, t2, ... row by row from the top left (+y up). Use [[taxel]] entries instead for taxels that differ."""

    columns: int = _param("taxels along x", default=1, kind="integer", lo=1, hi=MAX_TAXELS)
    rows: int = _param("taxels along y", default=1, kind="integer", lo=1, hi=MAX_TAXELS)
    pitch_x: float | None = _length("distance between neighbouring neck axes along x (required for columns > 1)",
                                    None)
    pitch_y: float | None = _length("distance between neighbouring neck axes along y (required for rows > 1)",
                                    None)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.columns * self.rows > MAX_TAXELS:
            raise SpecError("array.rows", self.rows, f"must keep columns x rows <= {MAX_TAXELS} taxels "
                                                     f"(columns = {self.columns})")
        for count, pitch in (("columns", "pitch_x"), ("rows", "pitch_y")):
            if getattr(self, count) > 1 and getattr(self, pitch) is None:
                raise SpecError(f"array.{pitch}", None, f"is required when array.{count} > 1 (mm between neck "
                                                        "axes)")


def _position(doc: str) -> Any:
    return _param(doc, "mm", lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)


@dataclass(frozen=True)
class TaxelEntry(Section):
    """One [[taxel]] of an array spec: where its neck is on the plate and how its geometry differs from the shared
    [cavity], [neck], [end_cap] and [needle] tables (a field left out is the shared value). The neck length is the
    plate's sheet and the mouth is the plate's, so neither is per taxel."""

    x: float = _position("neck axis x on the neck plate, plate centre = 0")
    y: float = _position("neck axis y on the neck plate, plate centre = 0")
    name: str | None = _param("taxel name in reports and loop outputs; default t<i> (1-based, in file order)",
                              default=None, kind="name")
    cavity_diameter: float | None = _length("this taxel's cavity diameter D; default [cavity]", None)
    cavity_length: float | None = _length("this taxel's cavity length L; default [cavity]", None)
    neck_diameter: float | None = _length("this taxel's neck diameter d; default [neck]", None)
    cap_outer_diameter: float | None = _length(
        f"this taxel's end-cap outer diameter; default [end_cap] if given there, else {CAP_OUTER_PER_D} x its D",
        None)
    cap_top_thickness: float | None = _length(
        f"this taxel's end-cap top thickness; default [end_cap] if given there, else {CAP_TOP_PER_D} x its D", None)
    needle_theta_deg: float | None = _param("this taxel's needle angle to the plate; default [needle]", "deg",
                                            None, lo=0.0, hi=90.0)
    needle_y: float | None = _param("this taxel's needle offset y (see needle.y); default [needle]", "mm", None,
                                    lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)
    calibration: Calibration | None = _param(
        "this taxel's Eq. 5 calibration as a [taxel.calibration] sub-table, the fields of [calibration] (`matcad "
        "calibrate --taxel NAME` writes it); `sense --spec` uses it, `--calibration NAME=FILE` overrides it",
        default=None, kind="section", section=Calibration)


@dataclass(frozen=True)
class Spec:
    """A whole taxel design. Lengths in mm."""

    name: str = _param("design name; the build folder is out/<name>", kind="name")
    cavity: Cavity = field(default=None)  # type: ignore[assignment]
    neck: Neck = field(default=None)  # type: ignore[assignment]
    plate: Plate = field(default_factory=Plate)
    guide: Guide = field(default_factory=Guide)
    spacer: Spacer = field(default_factory=Spacer)
    end_cap: EndCap = field(default_factory=EndCap)
    fasteners: Fasteners = field(default_factory=Fasteners)
    needle: Needle = field(default_factory=Needle)
    mount: Mount = field(default_factory=Mount)
    mold: Mold = field(default_factory=Mold)
    machine: Machine = field(default_factory=Machine)
    outputs: Outputs = field(default_factory=Outputs)
    air: Air = field(default_factory=Air)
    wall: Wall = field(default_factory=Wall)
    microphone: Microphone = field(default_factory=Microphone)
    silicone: Silicone = field(default_factory=Silicone)
    calibration: Calibration | None = None
    mechanics: Mechanics = field(default_factory=Mechanics)
    reference: Reference | None = None
    array: Array | None = None
    taxel: tuple[TaxelEntry, ...] = ()

    def __post_init__(self) -> None:
        name_meta = dict(dataclasses.fields(Spec)[0].metadata)
        object.__setattr__(self, "name", _convert("name", self.name, name_meta))
        for section, cls in SECTIONS.items():
            value = getattr(self, section)
            if value is None and section in REQUIRED_SECTIONS:
                raise SpecError(section, None, f"is required: add a [{section}] table")
            if value is not None and not isinstance(value, cls):
                raise SpecError(section, value, f"must be a {cls.__name__} section")
        object.__setattr__(self, "taxel", tuple(self.taxel))
        if not all(isinstance(entry, TaxelEntry) for entry in self.taxel):
            raise SpecError("taxel", self.taxel, "must be [[taxel]] entries")
        _cross_checks(self)


SECTIONS: dict[str, type] = {
    "cavity": Cavity, "neck": Neck, "plate": Plate, "guide": Guide, "spacer": Spacer, "end_cap": EndCap,
    "fasteners": Fasteners, "needle": Needle, "mount": Mount, "mold": Mold, "machine": Machine,
    "outputs": Outputs, "air": Air, "wall": Wall, "microphone": Microphone, "silicone": Silicone,
    "calibration": Calibration, "mechanics": Mechanics, "reference": Reference, "array": Array}
SECTION_NAMES: dict[type, str] = {cls: name for name, cls in SECTIONS.items()} | {TaxelEntry: "taxel"}
REQUIRED_SECTIONS = ("cavity", "neck")
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")
"""Matched with fullmatch: ``$`` would accept a final newline."""
MAX_NESTING = 32
"""Deepest TOML nesting a spec document may have (a spec needs 2); deeper is refused before Python recursion."""


def _did_you_mean(key: str, known: list[str]) -> str:
    import difflib

    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return f"unknown key{hint} allowed: {', '.join(known)}"


def _range_text(meta: dict) -> str:
    lo, hi, unit = meta["lo"], meta["hi"], f" {meta['unit']}" if meta["unit"] else ""
    op = "<" if meta["lo_open"] else "<="
    return f"a finite number, {lo:g} {op} value <= {hi:g}{unit}"


def _allowed_text(meta: dict) -> str:
    kind = meta["kind"]
    if kind == "choice":
        return " | ".join(meta["choices"])
    if kind == "range":
        return "[low, high], each " + _range_text(meta)
    if kind == "integer":
        return f"a whole number, {meta['lo']:g} <= value <= {meta['hi']:g}"
    if kind == "bool":
        return "true | false"
    if kind == "text":
        return "at most 40 printable ASCII characters"
    if kind == "vector9":
        return "9 finite numbers"
    if kind == "name":
        return "A-Z a-z 0-9 . _ - (1-64)"
    return _range_text(meta)


def _number(path: str, value: Any, meta: dict) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SpecError(path, value, f"must be {_range_text(meta)}")
    try:
        x = float(value)
    except OverflowError:  # an integer of >= 309 digits
        raise SpecError(path, value, f"must be {_range_text(meta)}") from None
    if x != 0 and abs(x) < sys.float_info.min:  # subnormal: no physical value, and 1/x overflows
        raise SpecError(path, value, f"must be {_range_text(meta)}, not a subnormal number")
    lo_ok = x > meta["lo"] if meta["lo_open"] else x >= meta["lo"]
    if not (math.isfinite(x) and lo_ok and x <= meta["hi"]):
        raise SpecError(path, value, f"must be {_range_text(meta)}")
    return x


def _convert(path: str, value: Any, meta: dict) -> Any:
    kind = meta["kind"]
    if kind == "number":
        return _number(path, value, meta)
    if kind == "integer":
        if isinstance(value, bool) or not isinstance(value, int) or not meta["lo"] <= value <= meta["hi"]:
            raise SpecError(path, value, f"must be a whole number, {meta['lo']:g} <= value <= {meta['hi']:g}")
        return value
    if kind == "vector9":
        if not isinstance(value, (list, tuple)) or len(value) != 9:
            raise SpecError(path, value, "must be a list of 9 finite numbers (a 3 x 3 matrix, row by row)")
        return tuple(_number(path, v, meta) for v in value)
    if kind == "bool":
        if not isinstance(value, bool):
            raise SpecError(path, value, "must be true or false")
        return value
    if kind == "text":
        if not isinstance(value, str) or len(value) > 40 or not all(32 <= ord(ch) < 127 for ch in value):
            raise SpecError(path, value, "must be at most 40 printable ASCII characters")
        return value
    if kind == "choice":
        if value not in meta["choices"]:
            raise SpecError(path, value, f"must be one of {', '.join(map(repr, meta['choices']))}")
        return value
    if kind == "range":
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise SpecError(path, value, f"must be [low, high], each {_range_text(meta)}")
        lo, hi = (_number(path, v, meta) for v in value)
        if lo > hi:
            raise SpecError(path, value, "must be [low, high] with low <= high")
        return (lo, hi)
    if kind == "section":
        return value if isinstance(value, meta["section"]) else _section(meta["section"], path, value)
    if kind == "name":
        if not isinstance(value, str) or not _NAME_RE.fullmatch(value) or value in (".", ".."):
            raise SpecError(path, value, "must be 1-64 characters of A-Z a-z 0-9 . _ - "
                                         "starting with a letter or digit (it names a folder)")
        return value
    raise AssertionError(kind)


def _section(cls: type, path: str, data: Any) -> Any:
    if not isinstance(data, dict):
        raise SpecError(path, data, "must be a table, e.g. [" + path + "]")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            raise SpecError(f"{path}.{key}", data[key], _did_you_mean(key, list(fields)))
    values = {}
    for name, f in fields.items():
        if name in data and data[name] is None and f.default is None:  # to_dict's unset optional field
            continue
        if name in data:
            values[name] = _convert(f"{path}.{name}", data[name], dict(f.metadata))
        elif f.default is dataclasses.MISSING:
            raise SpecError(f"{path}.{name}", None, f"is required ({f.metadata['doc']})")
    own = SECTION_NAMES.get(cls, "")
    try:
        return cls(**values)
    except SpecError as err:  # a cross-field check names the table by its own name: name it where it sits
        if path == own or not err.field.startswith(own + "."):
            raise
        raise SpecError(path + err.field[len(own):], err.value, err.allowed) from None


def _cross_checks(spec: Spec) -> None:
    if spec.reference is not None and not spec.reference.f0_tolerance_hz < spec.reference.f0_hz:
        raise SpecError("reference.f0_tolerance_hz", spec.reference.f0_tolerance_hz,
                        f"must be < reference.f0_hz = {spec.reference.f0_hz:g} Hz (a band in ln f needs f0 - tol > 0)")
    if spec.reference is not None:
        try:
            reference_spec(spec)
        except SpecError as err:
            raise SpecError(f"reference ({err.field})", err.value, err.allowed) from None
    if spec.array is not None and spec.taxel:
        raise SpecError("array", "[array] and [[taxel]]", "give either an [array] grid or [[taxel]] entries, not both")
    names = [entry.name for entry in spec.taxel]
    for i, name in enumerate(names, 1):
        if name is not None and name in names[:i - 1]:
            raise SpecError(f"taxel[{i}].name", name, "must be unique among the [[taxel]] entries")
    from matcad.taxel import field_path, taxels

    for index, t in enumerate(taxels(spec)):
        _geometry_checks(t, lambda key, i=index: field_path(spec, i, key), spec.mold.draft_deg)


def _geometry_checks(t, path, draft_deg: float) -> None:
    """What makes one taxel's geometry impossible (``t`` a :class:`matcad.taxel.Taxel`; ``path(key)`` names the
    spec field that sets ``key``, e.g. 'neck.diameter' or 'taxel[2].neck_diameter')."""
    if t.neck.diameter > t.cavity.diameter:
        raise SpecError(path("neck.diameter"), t.neck.diameter,
                        f"must be <= {path('cavity.diameter')} = {t.cavity.diameter:g} mm (a neck cannot be "
                        "wider than its cavity)")
    tip = t.cavity.diameter - 2 * t.cavity.length * math.tan(math.radians(draft_deg))
    if tip <= 0:
        raise SpecError("mold.draft_deg", draft_deg,
                        f"must leave the cavity open: draft closes a {t.cavity.diameter:g} mm cavity within "
                        f"its {t.cavity.length:g} mm length ({path('cavity.length')})")
    if t.end_cap.outer_diameter is not None and t.end_cap.outer_diameter <= t.cavity.diameter:
        raise SpecError(path("end_cap.outer_diameter"), t.end_cap.outer_diameter,
                        f"must be > {path('cavity.diameter')} = {t.cavity.diameter:g} mm")


def from_dict(data: dict) -> Spec:
    """Validate a parsed TOML document into a :class:`Spec` (lengths in mm). Raises SpecError."""
    known = ["name", *SECTIONS, "taxel"]
    for key in data:
        if key not in known:
            raise SpecError(key, data[key], _did_you_mean(key, known))
    name_meta = dict(dataclasses.fields(Spec)[0].metadata)
    if "name" not in data:
        raise SpecError("name", None, f"is required ({name_meta['doc']})")
    values: dict[str, Any] = {"name": _convert("name", data["name"], name_meta)}
    for section, cls in SECTIONS.items():
        if section in data and data[section] is None and section not in REQUIRED_SECTIONS:
            continue
        if section in data:
            values[section] = _section(cls, section, data[section])
        elif section in REQUIRED_SECTIONS:
            raise SpecError(section, None, f"is required: add a [{section}] table")
    if "taxel" in data:
        values["taxel"] = _taxel_entries(data["taxel"])
    return _resolve_defaults(Spec(**values))  # Spec.__post_init__ runs the cross-field checks


def _taxel_entries(data: Any) -> tuple[TaxelEntry, ...]:
    if not isinstance(data, (list, tuple)) or not all(isinstance(item, dict) for item in data):
        raise SpecError("taxel", data, "must be [[taxel]] tables, one per taxel")
    if not 1 <= len(data) <= MAX_TAXELS:
        raise SpecError("taxel", f"{len(data)} entries", f"must be 1 to {MAX_TAXELS} [[taxel]] entries")
    return tuple(_section(TaxelEntry, f"taxel[{i}]", item) for i, item in enumerate(data, 1))


KEY_CLEARANCE_MM = {"fdm": 0.2, "sla": 0.1}
"""Registration-key clearance per side by printer process (docs/physics.md, shop practice)."""


def _resolve_defaults(spec: Spec) -> Spec:
    """Fill defaults that depend on other fields (cap body proportional to the cavity; key clearance; silicone
    values from its grade)."""
    cap = spec.end_cap
    entries = tuple(dataclasses.replace(
        e, cap_outer_diameter=_proportional(e.cap_outer_diameter, cap.outer_diameter, CAP_OUTER_PER_D,
                                            e.cavity_diameter or spec.cavity.diameter),
        cap_top_thickness=_proportional(e.cap_top_thickness, cap.top_thickness, CAP_TOP_PER_D,
                                        e.cavity_diameter or spec.cavity.diameter)) for e in spec.taxel)
    d = spec.cavity.diameter
    cap = dataclasses.replace(
        cap, outer_diameter=cap.outer_diameter if cap.outer_diameter is not None else CAP_OUTER_PER_D * d,
        top_thickness=cap.top_thickness if cap.top_thickness is not None else CAP_TOP_PER_D * d)
    machine = spec.machine
    if machine.key_clearance is None:
        machine = dataclasses.replace(machine, key_clearance=KEY_CLEARANCE_MM[machine.printer])
    grade = GRADES[spec.silicone.grade]
    silicone = spec.silicone
    if silicone.density_g_cm3 is None:
        silicone = dataclasses.replace(silicone, density_g_cm3=grade.density_kg_m3 / 1000.0)
    wall = spec.wall
    if wall.shear_modulus_mpa is None:
        wall = dataclasses.replace(wall, shear_modulus_mpa=grade.shear_modulus_mpa)
    if wall.loss_factor is None:
        wall = dataclasses.replace(wall, loss_factor=grade.loss_factor)
    if wall.khz_modulus_factor is None:
        wall = dataclasses.replace(wall, khz_modulus_factor=grade.khz_modulus_factor)
    return dataclasses.replace(spec, end_cap=cap, machine=machine, silicone=silicone, wall=wall, taxel=entries)


def _proportional(own: float | None, shared: float | None, per_d: float, cavity_diameter: float) -> float:
    """A taxel's cap size: its own, else the shared [end_cap] value the user gave, else ``per_d`` x its D (mm)."""
    if own is not None:
        return own
    return shared if shared is not None else per_d * cavity_diameter


def reference_spec(spec: Spec) -> Spec:
    """The reference taxel of ``spec``'s [reference] as a whole spec: this design with the reference's geometry."""
    ref = spec.reference

    def pick(value, own):
        return own if value is None else value

    return dataclasses.replace(
        spec, reference=None,
        cavity=dataclasses.replace(spec.cavity, diameter=pick(ref.cavity_diameter, spec.cavity.diameter),
                                   length=pick(ref.cavity_length, spec.cavity.length)),
        neck=dataclasses.replace(spec.neck, diameter=pick(ref.neck_diameter, spec.neck.diameter),
                                 length=pick(ref.neck_length, spec.neck.length)),
        end_cap=dataclasses.replace(spec.end_cap,
                                    outer_diameter=pick(ref.cap_outer_diameter, spec.end_cap.outer_diameter),
                                    top_thickness=pick(ref.cap_top_thickness, spec.end_cap.top_thickness)))


def variant(spec: Spec, section: str, **values: Any) -> Spec:
    """A model variant of a validated spec (uncertainty budgets, sweeps): ``values`` set in ``section`` without
    input validation, because a perturbation may step past what a user may write (a 1 µm neck less its sheet
    tolerance, 10.5° of draft). Never use it for user input; ``dataclasses.replace`` validates."""
    part = getattr(spec, section)
    names = {f.name for f in dataclasses.fields(part)}
    unknown = set(values) - names
    if unknown:
        raise TypeError(f"{section} has no field {', '.join(sorted(unknown))}")
    part = copy.copy(part)
    for name, value in values.items():
        object.__setattr__(part, name, value)
    out = copy.copy(spec)
    object.__setattr__(out, section, part)
    return out


def load(path: str | Path) -> Spec:
    """Read and validate a spec TOML file. Raises SpecError naming the field on bad input."""
    return from_dict(_read_toml(path, "spec file", SPEC_MAX_BYTES))


def _depth(value: Any, limit: int) -> int:
    """Nesting depth of parsed TOML data, stopping once it passes ``limit``."""
    if limit < 0 or not isinstance(value, (dict, list)):
        return 0
    items = value.values() if isinstance(value, dict) else value
    return 1 + max((_depth(v, limit - 1) for v in items), default=0)


def _read_toml(path: str | Path, what: str, limit: int) -> dict:
    """A size-limited regular file parsed as TOML; any failure is a SpecError naming the file."""
    from matcad.errors import InputError
    from matcad.inputs import read_text

    p = Path(path)
    try:
        text = read_text(p, what, limit)
    except InputError as exc:
        raise SpecError(what, str(p), str(exc).split(": ", 1)[-1]) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(what, str(p), f"must be valid TOML ({exc})") from None
    except (RecursionError, ValueError, MemoryError) as exc:  # nesting or integer digits beyond the parser's limits
        raise SpecError(what, str(p), f"must be valid TOML within the parser's limits ({exc.__class__.__name__})") \
            from None
    if _depth(data, MAX_NESTING) > MAX_NESTING:
        raise SpecError(what, str(p), f"nests tables or arrays deeper than {MAX_NESTING} levels")
    return data


def load_calibration(path: str | Path) -> Calibration:
    """The [calibration] table of a calibration file or of a whole spec, validated like a spec's."""
    p = Path(path)
    data = _read_toml(p, "calibration file", CALIBRATION_MAX_BYTES)
    if "cavity" in data:
        cal = from_dict(data).calibration
        if cal is None:
            raise SpecError("calibration", None, f"is required: {p} has no [calibration] table")
        return cal
    if "calibration" not in data:
        raise SpecError("calibration", None, f"is required: {p} has no [calibration] table")
    return _section(Calibration, "calibration", data["calibration"])


def _check_calibration(cal: Calibration) -> None:
    """What sensing needs of a calibration beyond each field's range: a covariance that is one (symmetric,
    variances >= 0, no negative eigenvalue beyond rounding), and V_eff = v0 - bF - aF^2 > 0 over its force range
    (else f = sqrt(K/V_eff) is not real there)."""
    if cal.covariance is not None:
        import numpy as np

        cov = np.array(cal.covariance, dtype=float).reshape(3, 3)
        scale = float(np.max(np.abs(cov))) or 1.0
        if np.any(np.diag(cov) < 0) or not np.allclose(cov, cov.T, rtol=1e-9, atol=1e-12 * scale) \
                or float(np.min(np.linalg.eigvalsh((cov + cov.T) / 2))) < -1e-9 * scale:
            raise SpecError("calibration.covariance", list(cal.covariance),
                            "must be a covariance matrix: symmetric, variances >= 0, positive semi-definite")
    if cal.force_range_n is not None:
        for force in cal.force_range_n:
            if not cal.v0_mm3 - cal.b * force - cal.a * force * force > 0:
                raise SpecError("calibration.force_range_n", list(cal.force_range_n),
                                f"must keep V_eff = v0 - bF - aF^2 > 0 mm^3 (at F = {force:g} N it is not)")


def schema() -> list[dict]:
    """Every spec field: key, unit, default, allowed values (as text, and as kind, choices, lo, hi) and meaning."""
    rows = []
    name_meta = dataclasses.fields(Spec)[0].metadata
    rows.append({"key": "name", "unit": "", "default": None, "allowed": "A-Z a-z 0-9 . _ - (1-64)",
                 "required": True, "doc": name_meta["doc"], "kind": "name", "choices": [], "lo": None,
                 "hi": None, "lo_open": True, "required_in_table": True})
    tables = [*SECTIONS.items(), ("taxel[]", TaxelEntry)]
    tables += [(f"{name}.{f.name}", f.metadata["section"]) for name, cls in tables for f in dataclasses.fields(cls)
               if f.metadata["kind"] == "section"]  # sub-tables, e.g. taxel[].calibration
    for section, cls in tables:
        for f in dataclasses.fields(cls):
            meta = f.metadata
            if meta["kind"] == "section":
                continue
            allowed = _allowed_text(dict(meta))
            default = None if f.default is dataclasses.MISSING else f.default
            required = f.default is dataclasses.MISSING and section in REQUIRED_SECTIONS
            rows.append({"key": f"{section}.{f.name}", "unit": meta["unit"],
                         "default": list(default) if isinstance(default, tuple) else default,
                         "allowed": allowed, "required": required, "doc": meta["doc"], "kind": meta["kind"],
                         "choices": list(meta["choices"]), "lo": meta["lo"], "hi": meta["hi"],
                         "lo_open": meta["lo_open"], "required_in_table": f.default is dataclasses.MISSING})
    return rows


def to_dict(spec: Spec) -> dict:
    """The resolved spec (defaults filled in) as plain TOML-like data; ``taxel`` only when it has entries."""
    data = dataclasses.asdict(spec)
    entries = data.pop("taxel")
    return data | ({"taxel": list(entries)} if entries else {})
