"""The whole spec: the :class:`Spec` of every table, and a parsed TOML document to a resolved Spec and back.

:func:`from_dict` validates each table, runs the cross-field checks (:mod:`matcad.spec.checks`) and fills the
defaults that depend on other fields (the cap body proportional to the cavity, the key clearance by printer,
silicone values from its grade); :func:`to_dict` gives the resolved spec as plain data. Lengths in mm.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

from matcad.materials import GRADES
from matcad.spec.calibration import Calibration
from matcad.spec.checks import cross_checks
from matcad.spec.drawn import filled
from matcad.spec.fields import MISSING, SpecError, convert, declarations, did_you_mean, param, read_section
from matcad.spec.measured import Measured
from matcad.spec.tube import KINDS, TUBE_TABLES, Tube
from matcad.spec.sections import (CAP_OUTER_PER_D, CAP_TOP_PER_D, MAX_TAXELS, Air, Array, Cavity, EndCap,
                                  Fasteners, Guide, Machine, Mechanics, Microphone, Mold, Mount, Neck, Needle,
                                  Outputs, Plate, Reference, Riser, Silicone, Spacer, TaxelEntry, Wall)


def _default(cls: type):
    """A Spec field whose default is the table ``cls()``, made once and shared: tables are frozen, so a spec's tables
    left to their defaults are validated once per process, not once per spec (a sweep makes one per variant)."""
    return field(default_factory=functools.cache(cls))


@dataclass(frozen=True)
class Spec:
    """A whole taxel design. Lengths in mm."""

    name: str = param("design name; the build folder is out/<name>", kind="name")
    cavity: Cavity = field(default=None)  # type: ignore[assignment]
    neck: Neck = field(default=None)  # type: ignore[assignment]
    plate: Plate = _default(Plate)
    riser: Riser | None = None
    guide: Guide = _default(Guide)
    spacer: Spacer = _default(Spacer)
    end_cap: EndCap = _default(EndCap)
    fasteners: Fasteners = _default(Fasteners)
    needle: Needle = _default(Needle)
    mount: Mount = _default(Mount)
    mold: Mold = _default(Mold)
    machine: Machine = _default(Machine)
    outputs: Outputs = _default(Outputs)
    air: Air = _default(Air)
    wall: Wall = _default(Wall)
    microphone: Microphone = _default(Microphone)
    silicone: Silicone = _default(Silicone)
    calibration: Calibration | None = None
    mechanics: Mechanics = _default(Mechanics)
    reference: Reference | None = None
    array: Array | None = None
    taxel: tuple[TaxelEntry, ...] = ()
    measured: tuple[Measured, ...] = ()
    tube: Tube | None = None
    kind: str = param("taxel kind: 'mat' (the MAT paper's Helmholtz taxel) or 'tube' (an AcousTac fipple tube, "
                      "the [tube] table; docs/tube.md)", default="mat", kind="choice", choices=KINDS)

    def __post_init__(self) -> None:
        object.__setattr__(self, "name", convert("name", self.name, _meta("name")))
        object.__setattr__(self, "kind", convert("kind", self.kind, _meta("kind")))
        for section, cls in SECTIONS.items():
            value = getattr(self, section)
            if value is None and section in required_sections(self.kind):
                raise SpecError(section, MISSING, f"is required: add a [{section}] table")
            if value is not None and not isinstance(value, cls):
                raise SpecError(section, value, f"must be a {cls.__name__} section")
        for key, cls in ARRAY_TABLES.items():
            object.__setattr__(self, key, tuple(getattr(self, key)))
            if not all(isinstance(entry, cls) for entry in getattr(self, key)):
                raise SpecError(key, getattr(self, key), f"must be [[{key}]] entries")
        cross_checks(self)


SECTIONS: dict[str, type] = {
    "cavity": Cavity, "neck": Neck, "plate": Plate, "riser": Riser, "guide": Guide, "spacer": Spacer, "end_cap": EndCap,
    "fasteners": Fasteners, "needle": Needle, "mount": Mount, "mold": Mold, "machine": Machine,
    "outputs": Outputs, "air": Air, "wall": Wall, "microphone": Microphone, "silicone": Silicone,
    "calibration": Calibration, "mechanics": Mechanics, "reference": Reference, "array": Array, "tube": Tube}
REQUIRED_SECTIONS = ("cavity", "neck")
TUBE_REQUIRED = ("tube", "cavity")
"""A tube spec's required tables (its cavity, the cap's, is filled from [tube] by :func:`from_dict`)."""


def required_sections(kind: str) -> tuple[str, ...]:
    """The tables a spec of taxel ``kind`` must have."""
    return TUBE_REQUIRED if kind == "tube" else REQUIRED_SECTIONS


def _meta(name: str) -> dict:
    """The declaration of the Spec's own field ``name`` ('name' or 'kind')."""
    return declarations(Spec)[name][1]


ARRAY_TABLES: dict[str, type] = {"taxel": TaxelEntry, "measured": Measured}
"""Arrays of tables ([[taxel]], [[measured]]): key → the Section class of one entry."""


def from_dict(data: dict) -> Spec:
    """Validate a parsed TOML document into a :class:`Spec` (lengths in mm). Raises SpecError."""
    known = ["name", "kind", *SECTIONS, *ARRAY_TABLES]
    for key in data:
        if key not in known:
            raise SpecError(key, data[key], did_you_mean(key, known))
    if "name" not in data:
        raise SpecError("name", MISSING, f"is required ({_meta('name')['doc']})")
    values: dict[str, Any] = {"name": convert("name", data["name"], _meta("name"))}
    kind = values["kind"] = convert("kind", data.get("kind", "mat"), _meta("kind"))
    if kind == "tube":
        data = _tube_data(data)
    elif "tube" in data and data["tube"] is not None:
        raise SpecError("tube", data["tube"], "applies only to kind = 'tube' (add kind = \"tube\", or remove [tube])")
    for section, cls in SECTIONS.items():
        if section in data and data[section] is None and section not in required_sections(kind):
            continue
        if section in data:
            values[section] = read_section(cls, section, data[section])
        elif section in required_sections(kind):
            raise SpecError(section, MISSING, f"is required: add a [{section}] table")
    for key, cls in ARRAY_TABLES.items():
        if key in data:
            values[key] = _entries(key, cls, data[key])
    return _resolve_defaults(Spec(**values))  # Spec.__post_init__ runs the cross-field checks


def _tube_data(data: dict) -> dict:
    """A tube spec's document with its cap's cavity filled from [tube] (diameter = bore, length = cap depth). Raises
    SpecError for a table that does not apply to a tube (the MAT neck-plate stack) or a missing [tube]."""
    for key, value in data.items():
        if key not in ("name", "kind", *TUBE_TABLES) and value is not None and value != []:
            raise SpecError(key, value, f"does not apply to kind = 'tube' (a tube spec takes name, kind and "
                                        f"{', '.join(f'[{t}]' for t in TUBE_TABLES)})")
    if data.get("tube") is None:
        raise SpecError("tube", MISSING, "is required for kind = 'tube': add a [tube] table (bore_diameter, length)")
    tube = read_section(Tube, "tube", data["tube"])
    return {**data, "cavity": {"diameter": tube.bore_diameter, "length": tube.cap_cavity_depth}}


def _entries(key: str, cls: type, data: Any) -> tuple:
    """The [[key]] tables of ``data`` as ``cls`` sections, 1 to :data:`MAX_TAXELS` of them."""
    if not isinstance(data, (list, tuple)) or not all(isinstance(item, dict) for item in data):
        raise SpecError(key, data, f"must be [[{key}]] tables, one per taxel")
    if not 1 <= len(data) <= MAX_TAXELS:
        raise SpecError(key, f"{len(data)} entries", f"must be 1 to {MAX_TAXELS} [[{key}]] entries")
    return tuple(read_section(cls, f"{key}[{i}]", item) for i, item in enumerate(data, 1))


PROPORTIONAL_DEFAULTS = {"end_cap.outer_diameter": CAP_OUTER_PER_D, "end_cap.top_thickness": CAP_TOP_PER_D}
"""The fields whose default follows cavity.diameter (this factor times it) when the spec leaves them out."""
KEY_CLEARANCE_MM = {"fdm": 0.2, "sla": 0.1}
"""Registration-key clearance per side by printer process (docs/physics.md, shop practice)."""
PRINT_VOLUME_MM = {"fdm": (250.0, 210.0, 220.0), "sla": (120.0, 68.0, 150.0)}
"""Default build volume (x, y, z mm) by printer process: a Prusa MK4 (FDM) and a Prusa SL1 (SLA display), from
Prusa Research's specifications (``machine.print_volume_*`` override it)."""


def _resolve_defaults(spec: Spec) -> Spec:
    """Fill defaults that depend on other fields (cap body proportional to the cavity; key clearance and build
    volume by printer; silicone values from its grade), then the measured taxels' drawings from the spec so
    resolved: each table remade once, where something of it was left to a default, and the spec once."""
    cap = spec.end_cap
    d = spec.cavity.diameter
    changes: dict[str, Any] = {}
    if spec.taxel:
        changes["taxel"] = tuple(dataclasses.replace(
            e, cap_outer_diameter=_proportional(e.cap_outer_diameter, cap.outer_diameter, CAP_OUTER_PER_D,
                                                e.cavity_diameter or d),
            cap_top_thickness=_proportional(e.cap_top_thickness, cap.top_thickness, CAP_TOP_PER_D,
                                            e.cavity_diameter or d)) for e in spec.taxel)
    per_d = {key.split(".")[1]: factor for key, factor in PROPORTIONAL_DEFAULTS.items()}
    _remade(changes, "end_cap", cap, {name: factor * d for name, factor in per_d.items()
                                      if getattr(cap, name) is None})
    machine = spec.machine
    given = (machine.print_volume_x, machine.print_volume_y, machine.print_volume_z)
    _remade(changes, "machine", machine,
            {**({"key_clearance": KEY_CLEARANCE_MM[machine.printer]} if machine.key_clearance is None else {}),
             **{name: default for name, v, default in zip(("print_volume_x", "print_volume_y", "print_volume_z"),
                                                          given, PRINT_VOLUME_MM[machine.printer])
                if None in given and v is None}})
    grade = GRADES[spec.silicone.grade]
    _remade(changes, "silicone", spec.silicone,
            {"density_g_cm3": grade.density_kg_m3 / 1000.0} if spec.silicone.density_g_cm3 is None else {})
    _remade(changes, "wall", spec.wall, {name: getattr(grade, name) for name in ("shear_modulus_mpa", "loss_factor",
                                                                                 "khz_modulus_factor")
                                         if getattr(spec.wall, name) is None})
    resolved = SimpleNamespace(**{**{key: getattr(spec, key) for key in SECTIONS}, **changes})
    if spec.reference is not None:
        changes["reference"] = filled(spec.reference, resolved)
    if spec.calibration is not None:
        changes["calibration"] = filled(spec.calibration, resolved)
    if spec.measured:
        changes["measured"] = tuple(filled(e, resolved) for e in spec.measured)
    return dataclasses.replace(spec, **changes) if changes else spec


def _remade(changes: dict, key: str, section, values: dict) -> None:
    """``changes[key]``: ``section`` with ``values`` set (remade, so validated, once), when there are any."""
    if values:
        changes[key] = dataclasses.replace(section, **values)


def _proportional(own: float | None, shared: float | None, per_d: float, cavity_diameter: float) -> float:
    """A taxel's cap size: its own, else the shared [end_cap] value the user gave, else ``per_d`` x its D (mm)."""
    if own is not None:
        return own
    return shared if shared is not None else per_d * cavity_diameter


def to_dict(spec: Spec) -> dict:
    """The resolved spec (defaults filled in) as plain TOML-like data; an array of tables only when it has
    entries."""
    data = dataclasses.asdict(spec)
    for key in ARRAY_TABLES:
        entries = data.pop(key)
        if entries:
            data[key] = list(entries)
    if spec.kind == "mat":  # a MAT spec reads back as it always did
        del data["kind"], data["tube"]
        return data
    return {key: value for key, value in data.items() if key in ("name", "kind", *TUBE_TABLES)}
