"""``--vary`` axes → the full grid of variants (plain data: each variant is the user's spec data with one value
set per varied field, validated like a spec file).

Units are the spec's own (``matcad schema``): lengths mm, angles deg, temperatures °C.
"""

from __future__ import annotations

import difflib
import itertools
import math
from dataclasses import dataclass

import numpy as np

MAX_POINTS = 200
"""Most values one ``--vary`` axis may take."""
MAX_VARIANTS = 20_000
"""Most variants a per-variant sweep may have (fem, relative, a board, --cad: each variant runs predict and the
rules on its own, and its rows are held in memory)."""
MAX_GRID = 10_000_000
"""Most variants any sweep may have (the product of its axes): a sweep on arrays streams its table to disk chunk
by chunk, so its memory does not grow with the grid."""
VARIABLE_KINDS = ("number", "integer")
"""Only numeric spec fields can be swept; choices (wall.model, neck.mouth) are set with ``--set``."""


@dataclass(frozen=True)
class Axis:
    """One varied spec field: its dotted key, unit and values (in the field's unit; ints for an integer field)."""

    field: str
    unit: str
    values: tuple[float, ...]
    integer: bool = False

    @property
    def section(self) -> str:
        return self.field.split(".", 1)[0]

    @property
    def name(self) -> str:
        return self.field.split(".", 1)[1]


def _fields() -> dict[str, dict]:
    """Every numeric field of the shared tables: its schema row (allowed text, lo, hi, lo_open, unit); [[taxel]]
    entries are not swept."""
    from matcad.spec import schema

    return {row["key"]: row for row in schema() if row["kind"] in VARIABLE_KINDS and "[]" not in row["key"]}


def _error(field: str, value, allowed: str):
    from matcad.spec import SpecError

    return SpecError(f"--vary {field}", value, allowed)


def _number(field: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise _error(field, text, "each value must be a finite number")
    return value


def _in_range(field: str, value: float, row: dict) -> None:
    lo, hi = row["lo"], row["hi"]
    lo_ok = value > lo if row["lo_open"] else value >= lo
    whole = row["kind"] == "integer" and value.is_integer() and abs(value) < 2 ** 53  # exact in a float
    shown = int(value) if whole else value  # a count as typed: 0, not 0.0
    if not (lo_ok and value <= hi):
        raise _error(field, shown, f"outside the field's range: {row['allowed']}")
    if row["kind"] == "integer" and value != int(value):
        raise _error(field, shown, f"must be whole numbers: {row['allowed']}")


def parse_axis(text: str) -> Axis:
    """``FIELD=LO:HI:N`` (N evenly spaced values, both ends included) or ``FIELD=a,b,c`` → an :class:`Axis`.

    Raises SpecError naming the field, the value and what is allowed: an unknown or non-numeric field (with a
    did-you-mean), N < 1 or > :data:`MAX_POINTS`, LO > HI, a value outside the field's range (``matcad schema``),
    a fraction for an integer field.
    """
    field, sep, raw = text.partition("=")
    field, raw = field.strip(), raw.strip()
    if not sep or not raw:
        raise _error(field or text, text, "must be FIELD=LO:HI:N or FIELD=a,b,c (e.g. cavity.length=3:6:7)")
    known = _fields()
    if field not in known:
        close = difflib.get_close_matches(field, list(known), n=1, cutoff=0.6)
        hint = f"did you mean '{close[0]}'? " if close else ""
        raise _error(field, raw, f"unknown or not a numeric spec field; {hint}allowed: {', '.join(known)}")
    row = known[field]
    if ":" in raw:
        parts = raw.split(":")
        if len(parts) != 3:
            raise _error(field, raw, "must be LO:HI:N")
        lo, hi = _number(field, parts[0]), _number(field, parts[1])
        try:
            n = int(parts[2])
        except ValueError:
            raise _error(field, raw, f"N = {parts[2]!r} must be a whole number, 1 <= N <= {MAX_POINTS}") from None
        if not 1 <= n <= MAX_POINTS:
            raise _error(field, raw, f"N = {n} must be 1 <= N <= {MAX_POINTS}")
        if lo > hi:
            raise _error(field, raw, f"LO = {lo:g} must be <= HI = {hi:g}")
        if n == 1 and lo != hi:
            raise _error(field, raw, "N = 1 needs LO = HI (or give the one value as FIELD=a)")
        values = tuple(float(v) for v in np.linspace(lo, hi, n))
        if row["kind"] == "integer" and any(v != round(v) for v in values):
            raise _error(field, raw, f"{n} values from {lo:g} to {hi:g} are not all whole numbers, which the field "
                                     f"takes ({row['allowed']}): choose N with (HI - LO) / (N - 1) whole")
    else:
        values = tuple(_number(field, v) for v in raw.split(","))
        if len(values) > MAX_POINTS:
            raise _error(field, raw, f"{len(values)} values: at most {MAX_POINTS}")
        if len(set(values)) != len(values):
            raise _error(field, raw, "each value at most once")
    for v in values:
        _in_range(field, v, row)
    integer = row["kind"] == "integer"
    return Axis(field, row["unit"], tuple(int(v) for v in values) if integer else values, integer)


def parse_axes(texts) -> tuple[Axis, ...]:
    """Every ``--vary``; a field at most once, and at most :data:`MAX_GRID` variants in all (a per-variant sweep
    refuses more than :data:`MAX_VARIANTS` when its model is known)."""
    axes = tuple(parse_axis(t) for t in texts)
    seen = [a.field for a in axes]
    for a in axes:
        if seen.count(a.field) > 1:
            raise _error(a.field, "twice", "vary each field at most once")
    size = math.prod(len(a.values) for a in axes)
    if size > MAX_GRID:
        raise _error(" ".join(seen), size, f"the grid has {size} variants, at most {MAX_GRID} are allowed")
    return axes


def grid(axes: tuple[Axis, ...], start: int = 0, stop: int | None = None) -> list[tuple[float, ...]]:
    """The combinations ``start:stop`` of the axes' values (all by default), the first axis varying slowest
    (row-major: reshape to the axes' lengths)."""
    return list(itertools.islice(itertools.product(*(a.values for a in axes)), start, stop))


def variant_data(data: dict, axes: tuple[Axis, ...], values: tuple[float, ...]) -> dict:
    """A copy of the raw spec ``data`` with each axis's field set to its value (integers stay integers). The copy
    is deep (a pickle round trip: parsed TOML is plain data; ~2.5x faster than copy.deepcopy)."""
    import pickle

    out = pickle.loads(pickle.dumps(data, protocol=pickle.HIGHEST_PROTOCOL))
    for axis, value in zip(axes, values):
        section = out.get(axis.section)
        if not isinstance(section, dict):
            section = out[axis.section] = {}
        section[axis.name] = int(value) if axis.integer else value
    return out
