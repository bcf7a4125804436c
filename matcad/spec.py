"""Geometry spec: TOML → validated, frozen dataclasses. All lengths in millimetres.

Each field is declared once, with its unit, default, allowed range and meaning; the same declaration
validates input, prints ``matcad schema`` and documents the template. Validation rejects only what is not
physical (non-positive or non-finite lengths, wrong types, a neck wider than its cavity); what is merely hard
to fabricate is a design rule, not an input error.

Dimension names follow the paper (mat-paper.md, Fig. 2): D, L the silicone cavity; d, l the acrylic neck.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

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
        super().__init__(f"{field_name} = {value!r}: {allowed}")


def _param(doc: str, unit: str = "", default: Any = dataclasses.MISSING, *, kind: str = "number",
           lo: float | None = None, hi: float | None = None, lo_open: bool = True,
           choices: tuple[str, ...] = ()) -> Any:
    """Declare one spec field. ``kind`` is number | range | choice | name."""
    meta = {"doc": doc, "unit": unit, "kind": kind, "lo": lo, "hi": hi, "lo_open": lo_open,
            "choices": choices}
    return field(default=default, metadata=meta)


def _length(doc: str, default: Any = dataclasses.MISSING) -> Any:
    return _param(doc, "mm", default, lo=LENGTH_MIN_MM, hi=LENGTH_MAX_MM, lo_open=False)


@dataclass(frozen=True)
class Cavity:
    """The silicone end cap's cylindrical channel (paper: D, L)."""

    diameter: float = _length("cavity diameter D, cast in the silicone end cap")
    length: float = _length("cavity length L, from the plate face to the closed end")


@dataclass(frozen=True)
class Neck:
    """The through-hole in the acrylic neck plate (paper: d, l)."""

    diameter: float = _length("neck diameter d (the through-hole as designed)")
    length: float = _length("neck length l = neck plate thickness")
    mouth: str = _param("outer end of the neck: 'baffled' (flat infinite flange), 'unflanged' "
                        "(thin tube end), or 'mount' (flange with the air-supply mount a spacer height "
                        "below, as in the paper)", default="mount", kind="choice",
                        choices=("baffled", "unflanged", "mount"))


@dataclass(frozen=True)
class Plate:
    """The laser-cut neck plate outline; the mount gap under it vents at its edges."""

    width: float = _length("neck plate width (x), neck at its centre", 20.0)
    depth: float = _length("neck plate depth (y), neck at its centre", 20.0)


@dataclass(frozen=True)
class Spacer:
    """Spacers between the neck plate and the air-supply mount (paper: 1.59 mm, for ventilation)."""

    height: float = _length("gap between neck plate and mount; the 'mount' mouth's gap height", 1.59)


@dataclass(frozen=True)
class EndCap:
    """Outer body of the cast silicone end cap (the paper does not give it; defaults are matcad's)."""

    outer_diameter: float | None = _length(
        f"outer diameter of the silicone end cap body; default {CAP_OUTER_PER_D} x cavity.diameter", None)
    top_thickness: float | None = _length(
        f"silicone thickness above the cavity's closed end; default {CAP_TOP_PER_D} x cavity.diameter", None)


@dataclass(frozen=True)
class Air:
    """The air in and around the taxel."""

    temperature_c: float = _param("air temperature; sets the speed of sound", "degC", 20.0,
                                  lo=-273.15, hi=1000.0)
    speed_of_sound: float | None = _param("speed of sound; overrides temperature_c when given", "m/s",
                                          None, lo=0.0, hi=1e4)


@dataclass(frozen=True)
class Wall:
    """Cavity wall mechanics."""

    model: str = _param("'rigid' (ideal walls) or 'silicone' (quasi-static wall compliance band)",
                        default="rigid", kind="choice", choices=("rigid", "silicone"))
    shear_modulus_mpa: tuple[float, float] = _param(
        "[low, high] shear modulus of the cured silicone; Dragon Skin 30 ~0.31 MPa, uncertain ~2x",
        "MPa", (0.2, 0.6), kind="range", lo=0.0, hi=1e6)


@dataclass(frozen=True)
class Calibration:
    """Paper Eq. 5 constants: V_eff = v0_mm3 - a F^2 - b F (F in N)."""

    v0_mm3: float = _param("effective unloaded cavity volume V_ci", "mm^3", lo=0.0, hi=1e18)
    a: float = _param("quadratic deflection coefficient a (paper: -0.0086)", "mm^3/N^2",
                      lo=-1e12, hi=1e12, lo_open=False)
    b: float = _param("linear deflection coefficient b (paper: 0.4626)", "mm^3/N",
                      lo=-1e12, hi=1e12, lo_open=False)
    area_convention: str = _param(
        "neck area used with v0: 'pi_d2/4' (physical, A = pi d^2/4) or 'd2/4' (the paper's fit, "
        "see DIGEST)", default="pi_d2/4", kind="choice", choices=("pi_d2/4", "d2/4"))


@dataclass(frozen=True)
class Spec:
    """A whole taxel design. Lengths in mm."""

    name: str = _param("design name; the build folder is out/<name>", kind="name")
    cavity: Cavity = field(default=None)  # type: ignore[assignment]
    neck: Neck = field(default=None)  # type: ignore[assignment]
    plate: Plate = field(default_factory=Plate)
    spacer: Spacer = field(default_factory=Spacer)
    end_cap: EndCap = field(default_factory=EndCap)
    air: Air = field(default_factory=Air)
    wall: Wall = field(default_factory=Wall)
    calibration: Calibration | None = None


SECTIONS: dict[str, type] = {"cavity": Cavity, "neck": Neck, "plate": Plate, "spacer": Spacer,
                             "end_cap": EndCap, "air": Air, "wall": Wall, "calibration": Calibration}
REQUIRED_SECTIONS = ("cavity", "neck")
_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")


def _did_you_mean(key: str, known: list[str]) -> str:
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return f"unknown key{hint} allowed: {', '.join(known)}"


def _range_text(meta: dict) -> str:
    lo, hi, unit = meta["lo"], meta["hi"], f" {meta['unit']}" if meta["unit"] else ""
    op = "<" if meta["lo_open"] else "<="
    return f"a finite number, {lo:g} {op} value <= {hi:g}{unit}"


def _number(path: str, value: Any, meta: dict) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SpecError(path, value, f"must be {_range_text(meta)}")
    x = float(value)
    lo_ok = x > meta["lo"] if meta["lo_open"] else x >= meta["lo"]
    if not (math.isfinite(x) and lo_ok and x <= meta["hi"]):
        raise SpecError(path, value, f"must be {_range_text(meta)}")
    return x


def _convert(path: str, value: Any, meta: dict) -> Any:
    kind = meta["kind"]
    if kind == "number":
        return _number(path, value, meta)
    if kind == "choice":
        if value not in meta["choices"]:
            raise SpecError(path, value, f"must be one of {', '.join(map(repr, meta['choices']))}")
        return value
    if kind == "range":
        if not isinstance(value, list) or len(value) != 2:
            raise SpecError(path, value, f"must be [low, high], each {_range_text(meta)}")
        lo, hi = (_number(path, v, meta) for v in value)
        if lo > hi:
            raise SpecError(path, value, "must be [low, high] with low <= high")
        return (lo, hi)
    if kind == "name":
        if not isinstance(value, str) or not _NAME_RE.match(value) or value in (".", ".."):
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
        if name in data:
            values[name] = _convert(f"{path}.{name}", data[name], dict(f.metadata))
        elif f.default is dataclasses.MISSING:
            raise SpecError(f"{path}.{name}", None, f"is required ({f.metadata['doc']})")
    return cls(**values)


def _cross_checks(spec: Spec) -> None:
    if spec.neck.diameter > spec.cavity.diameter:
        raise SpecError("neck.diameter", spec.neck.diameter,
                        f"must be <= cavity.diameter = {spec.cavity.diameter:g} mm (a neck cannot be "
                        "wider than its cavity)")
    if spec.end_cap.outer_diameter <= spec.cavity.diameter:
        raise SpecError("end_cap.outer_diameter", spec.end_cap.outer_diameter,
                        f"must be > cavity.diameter = {spec.cavity.diameter:g} mm")


def from_dict(data: dict) -> Spec:
    """Validate a parsed TOML document into a :class:`Spec` (lengths in mm). Raises SpecError."""
    known = ["name", *SECTIONS]
    for key in data:
        if key not in known:
            raise SpecError(key, data[key], _did_you_mean(key, known))
    name_meta = dict(dataclasses.fields(Spec)[0].metadata)
    if "name" not in data:
        raise SpecError("name", None, f"is required ({name_meta['doc']})")
    values: dict[str, Any] = {"name": _convert("name", data["name"], name_meta)}
    for section, cls in SECTIONS.items():
        if section in data:
            values[section] = _section(cls, section, data[section])
        elif section in REQUIRED_SECTIONS:
            raise SpecError(section, None, f"is required: add a [{section}] table")
    spec = Spec(**values)
    spec = _resolve_defaults(spec)
    _cross_checks(spec)
    return spec


def _resolve_defaults(spec: Spec) -> Spec:
    """Fill defaults that scale with the design (cap body proportional to the cavity)."""
    cap = spec.end_cap
    d = spec.cavity.diameter
    cap = dataclasses.replace(
        cap, outer_diameter=cap.outer_diameter if cap.outer_diameter is not None else CAP_OUTER_PER_D * d,
        top_thickness=cap.top_thickness if cap.top_thickness is not None else CAP_TOP_PER_D * d)
    return dataclasses.replace(spec, end_cap=cap)


def load(path: str | Path) -> Spec:
    """Read and validate a spec TOML file. Raises SpecError naming the field on bad input."""
    p = Path(path)
    try:
        text = p.read_bytes().decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError("spec file", str(p), f"must be a readable UTF-8 TOML file ({exc.__class__.__name__})")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError("spec file", str(p), f"must be valid TOML ({exc})")
    return from_dict(data)


def schema() -> list[dict]:
    """Every spec field: key, unit, default, allowed values and meaning."""
    rows = []
    name_meta = dataclasses.fields(Spec)[0].metadata
    rows.append({"key": "name", "unit": "", "default": None, "allowed": "A-Z a-z 0-9 . _ - (1-64)",
                 "required": True, "doc": name_meta["doc"]})
    for section, cls in SECTIONS.items():
        for f in dataclasses.fields(cls):
            meta = f.metadata
            if meta["kind"] == "choice":
                allowed = " | ".join(meta["choices"])
            elif meta["kind"] == "range":
                allowed = "[low, high], each " + _range_text(dict(meta))
            else:
                allowed = _range_text(dict(meta))
            default = None if f.default is dataclasses.MISSING else f.default
            required = f.default is dataclasses.MISSING and section in REQUIRED_SECTIONS
            rows.append({"key": f"{section}.{f.name}", "unit": meta["unit"],
                         "default": list(default) if isinstance(default, tuple) else default,
                         "allowed": allowed, "required": required, "doc": meta["doc"]})
    return rows


def to_dict(spec: Spec) -> dict:
    """The resolved spec (defaults filled in) as plain TOML-like data."""
    return dataclasses.asdict(spec)
