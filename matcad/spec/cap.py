"""The cast silicone end cap's derived dimensions, one function each (mm): what parts, rules, the cap mechanics
and the reports all read. ``t`` is a spec or a :class:`~matcad.spec.board.Taxel` (its own cavity and cap); the
flange thickness needs the spec (its guide sheet)."""

from __future__ import annotations


def cap_flange_diameter_mm(t) -> float:
    """Diameter of the end cap's base flange, which the locator guide surrounds (mm)."""
    return t.end_cap.outer_diameter + 2 * t.end_cap.flange_width


def cap_flange_thickness_mm(spec) -> float:
    """Flange thickness: the guide thickness plus the clamp squeeze (mm)."""
    return spec.guide.thickness + spec.end_cap.flange_squeeze


def cap_height_mm(t) -> float:
    """End cap height from its base (on the plate) to its top: L + top thickness (mm)."""
    return t.cavity.length + t.end_cap.top_thickness
