"""A spec field: its declaration, its converter, the text of what it allows, the error a bad value raises, and the
Section base that converts every field of a table on construction.

Each field is declared once (:func:`param`, :func:`length_mm`) with its unit, default, allowed range and meaning;
the same declaration validates input (:func:`convert`, :func:`read_section`), prints ``matcad schema``
(:func:`allowed_text`) and documents the template. Lengths are millimetres, :data:`LENGTH_MIN_MM` to
:data:`LENGTH_MAX_MM`.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
import sys
from dataclasses import field
from typing import Any, ClassVar

from matcad.errors import MISSING, SpecError  # defined at the base: the CLI catches SpecError without loading the spec

LENGTH_MIN_MM = 1e-3
LENGTH_MAX_MM = 1e5
VECTOR_MAX = 10_000
"""Most values a list field (a measured series) may hold."""


def param(doc: str, unit: str = "", default: Any = dataclasses.MISSING, *, kind: str = "number",
          lo: float | None = None, hi: float | None = None, lo_open: bool = True,
          choices: tuple[str, ...] = (), section: type | None = None) -> Any:
    """Declare one spec field. ``kind`` is number | integer | bool | text | range | vector (a list of numbers) |
    vector9 | choice | name | section (a sub-table validated as the Section class ``section``). A number's lower
    bound is open unless ``lo_open`` is False; an integer's bounds are both inclusive (``lo <= value <= hi``)."""
    meta = {"doc": doc, "unit": unit, "kind": kind, "lo": lo, "hi": hi, "lo_open": lo_open and kind != "integer",
            "choices": choices, "section": section}
    return field(default=default, metadata=meta)


def length_mm(doc: str, default: Any = dataclasses.MISSING) -> Any:
    """Declare one length field: a number in mm, :data:`LENGTH_MIN_MM` <= value <= :data:`LENGTH_MAX_MM`."""
    return param(doc, "mm", default, lo=LENGTH_MIN_MM, hi=LENGTH_MAX_MM, lo_open=False)


_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")
"""Matched with fullmatch: ``$`` would accept a final newline."""


def did_you_mean(key: str, known: list[str]) -> str:
    """The ``allowed`` text for an unknown ``key``: the closest of ``known`` when one is close, and all of them."""
    import difflib

    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return f"unknown key{hint} allowed: {', '.join(known)}"


def _range_text(meta: dict) -> str:
    lo, hi, unit = meta["lo"], meta["hi"], f" {meta['unit']}" if meta["unit"] else ""
    op = "<" if meta["lo_open"] else "<="
    return f"a finite number, {lo:g} {op} value <= {hi:g}{unit}"


def allowed_text(meta: dict) -> str:
    """What a field declared with ``meta`` allows, as ``matcad schema`` prints it."""
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
    if kind == "vector":
        return "[x1, x2, ...], 1 to 10000 values, each " + _range_text(meta)
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
    if _subnormal(x):  # no physical value, and 1/x overflows
        raise SpecError(path, value, f"must be {_range_text(meta)}, not a subnormal number")
    if not _within(x, meta):
        raise SpecError(path, value, f"must be {_range_text(meta)}")
    return x


def _subnormal(x: float) -> bool:
    return x != 0 and abs(x) < sys.float_info.min


def _within(x: float, meta: dict) -> bool:
    """Whether the finite float ``x`` lies in the declared range (the low end open where ``lo_open``); False for
    inf and NaN."""
    lo_ok = x > meta["lo"] if meta["lo_open"] else x >= meta["lo"]
    return math.isfinite(x) and lo_ok and x <= meta["hi"]


def _valid_float(value: Any, meta: dict) -> bool:
    """Whether ``value`` is already what :func:`convert` makes of a number field: a float, in range, not subnormal
    (then it is kept as it is, with no path formatted for an error that cannot come: a section remade by
    ``dataclasses.replace`` re-validates its numbers at this cost)."""
    return type(value) is float and meta["kind"] == "number" and not _subnormal(value) and _within(value, meta)


def convert(path: str, value: Any, meta: dict) -> Any:
    """``value`` of the field ``path`` (a dotted spec key) checked against its declaration ``meta`` and converted
    (numbers to float, ranges and vectors to tuples, a sub-table to its Section). Raises SpecError."""
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
    if kind == "vector":
        if not isinstance(value, (list, tuple)) or not 1 <= len(value) <= VECTOR_MAX:
            raise SpecError(path, value, f"must be a list of 1 to {VECTOR_MAX} values, each {_range_text(meta)}")
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
        return value if isinstance(value, meta["section"]) else read_section(meta["section"], path, value)
    if kind == "name":
        if not isinstance(value, str) or not _NAME_RE.fullmatch(value) or value in (".", ".."):
            raise SpecError(path, value, "must be 1-64 characters of A-Z a-z 0-9 . _ - "
                                         "starting with a letter or digit (it names a folder)")
        return value
    raise AssertionError(kind)


def read_section(cls: type, path: str, data: Any) -> Any:
    """The table ``data`` found at ``path`` (e.g. 'neck', 'taxel[2]') as the Section class ``cls``: unknown keys and
    missing required fields are refused, and an error of the section's own checks is named where the table sits."""
    if not isinstance(data, dict):
        raise SpecError(path, data, "must be a table, e.g. [" + path + "]")
    declared = declarations(cls)
    for key in data:
        if key not in declared:
            raise SpecError(f"{path}.{key}", data[key], did_you_mean(key, list(declared)))
    for name, (default, meta) in declared.items():
        if name not in data and default is dataclasses.MISSING:
            raise SpecError(f"{path}.{name}", MISSING, f"is required ({meta['doc']})")
    own = cls.table
    try:
        return cls(**data)  # its __post_init__ converts every field (None: an unset optional field, as to_dict writes)
    except SpecError as err:  # a cross-field check names the table by its own name: name it where it sits
        if path == own or not err.field.startswith(own + "."):
            raise
        raise SpecError(path + err.field[len(own):], err.value, err.allowed) from None


class Section:
    """Base of every spec section: each field is validated on construction by the same per-field converter that
    reads TOML, so ``dataclasses.replace`` (or a direct call) cannot make an invalid section. ``None`` is
    accepted where the field's default is ``None`` (resolved later or optional)."""

    table: ClassVar[str]
    """The section's TOML table name ('cavity', 'end_cap', 'taxel' for a [[taxel]] entry): errors name it."""

    def __post_init__(self) -> None:
        path = self.table
        for name, (default, meta) in declarations(type(self)).items():
            value = getattr(self, name)
            if value is None and default is None:
                continue
            if value is None and default is dataclasses.MISSING:
                raise SpecError(f"{path}.{name}", MISSING, f"is required ({meta['doc']})")
            if not _valid_float(value, meta):
                object.__setattr__(self, name, convert(f"{path}.{name}", value, meta))


@functools.cache
def declarations(cls: type) -> dict[str, tuple[Any, dict]]:
    """Each field of the Section class ``cls``: name → (default, its declaration as :func:`param` made it), in
    order (read once per class, not per section made)."""
    return {f.name: (f.default, dict(f.metadata)) for f in dataclasses.fields(cls)}
