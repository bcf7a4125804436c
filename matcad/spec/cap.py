"""The cast silicone end cap's derived dimensions, one function each (mm): what parts, rules, the cap mechanics
and the reports all read. ``t`` is a spec or a :class:`~matcad.spec.board.Taxel` (its own cavity and cap); the
flange thickness and the neck's length need the spec (its guide, plate and riser sheets)."""

from __future__ import annotations


def cap_flange_diameter_mm(t) -> float:
    """Diameter of the end cap's base flange, which the locator guide surrounds (mm)."""
    return t.end_cap.outer_diameter + 2 * t.end_cap.flange_width


def in_pocket(spec, t=None) -> bool:
    """Whether the cap of ``t`` (a :class:`~matcad.spec.board.Taxel`; default ``spec``'s own) sits on the plate in
    a pocket cut through ``spec``'s [riser] (its neck stops at the plate), rather than on the riser."""
    return spec.riser is not None and not (spec if t is None else t).neck.riser


def cap_flange_thickness_mm(spec, t=None) -> float:
    """Flange thickness of the cap of ``t`` (default ``spec``'s own): the guide thickness plus the clamp squeeze,
    plus the riser's thickness when the cap sits in a pocket of the riser (:func:`in_pocket`; mm). The flange is the
    height of the cap's wall the stack holds: the acoustics' clamped height and the mechanics' flange."""
    pocket = spec.riser.thickness if in_pocket(spec, t) else 0.0
    return spec.guide.thickness + spec.end_cap.flange_squeeze + pocket


def neck_length_mm(spec, t=None) -> float:
    """Length of the neck of ``t`` (default ``spec``'s own): the plate's sheet (neck.length), plus the riser's where
    the neck runs on through a [riser] (neck.riser; mm)."""
    through = spec.riser is not None and not in_pocket(spec, t)
    return spec.neck.length + (spec.riser.thickness if through else 0.0)


def cap_height_mm(t) -> float:
    """End cap height from its base (on the plate) to its top: L + top thickness (mm)."""
    return t.cavity.length + t.end_cap.top_thickness
