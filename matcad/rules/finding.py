"""A design rule's verdict, and the levels it may have.

Levels: ``error`` (the part will not work or cannot be made: `build` refuses without --force), ``warning``
(likely trouble; fix or accept knowingly), ``info`` (numbers worth knowing before casting).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Callable

LEVELS = ("error", "warning", "info")
"""Every finding's level, most severe first: findings are listed in this order."""


@dataclass(frozen=True)
class Finding:
    """One rule's verdict: id, level, the measured value, the limit it was held to, message and fix."""

    id: str
    level: str
    value: object
    limit: object
    message: str
    fix: str = ""

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class ArrayRule:
    """How a sweep judges one spec rule on arrays of one-taxel variants (a module's ``ARRAY_RULES``): the finding
    it gives (``id``, ``level``), the function of the spec the sweep memoises for it (``inputs``: spec → a number)
    and ``column(inputs, field, design, design_of, wall_model, physics_of)``, the rule on the variants' arrays: how
    many such findings each variant gets. ``field(dotted key)`` gives every variant's value, ``design`` their
    :class:`matcad.acoustics.design.Design` of arrays, ``design_of(rows)`` that of the variants at ``rows``,
    ``physics_of(rows)`` their f0 (Hz) by the model `predict` chooses for the wall
    (:data:`matcad.acoustics.registry.CHOSEN`) where the sweep has it, else None."""

    id: str
    level: str
    inputs: Callable
    column: Callable


def fits_bed(size, bed) -> bool:
    """Whether a box ``size`` (x, y[, z] mm) fits inside ``bed`` (the same axes, mm), turned either way round in
    the bed's plane (a slicer or the laser's software may rotate it by 90°; a diagonal placement is not tried)."""
    (x, y, *z), (bx, by, *bz) = size, bed
    return all(a <= b for a, b in zip(z, bz)) and ((x <= bx and y <= by) or (y <= bx and x <= by))


def findings_text(findings) -> str:
    """The findings as `matcad check` prints them: one line each (level, rule, message) and its fix below unless
    it is only information."""
    if not findings:
        return "  no findings"
    return "\n".join(f"  {f.level:<7} {f.id:<24} {f.message}" + (f"\n  {'':<7} {'':<24} fix: {f.fix}" if f.fix
                                                                  and f.level != "info" else "")
                     for f in findings)


def verdict_dict(findings) -> dict:
    """`matcad check --json`: every finding and the verdict ('fail' with any error, else 'pass')."""
    return {"findings": [f.to_dict() for f in findings],
            "verdict": "fail" if any(f.level == "error" for f in findings) else "pass"}
