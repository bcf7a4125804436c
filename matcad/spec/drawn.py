"""The drawing of a taxel that was built and measured — a [reference], a [[measured]] entry, a [calibration] — and
the spec of that drawing. Lengths in mm.

Each of those sections may give the geometry the measured taxel was drawn with; what it leaves out is filled from
the spec as loaded (:func:`filled`), so that it stays the taxel that was built when a design search, a sweep or an
uncertainty budget varies the spec.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from matcad.spec.fields import LENGTH_MAX_MM, length_mm, param

AS_LOADED = "of the measured taxel's drawing; default this spec's as loaded"


def _drawn(what: str):
    """One length of the measured taxel's drawing (mm; None: the spec's as loaded)."""
    return length_mm(f"{what} {AS_LOADED}", None)


@dataclass(frozen=True, kw_only=True)
class Drawn:
    """A measured taxel's drawing: its geometry and how it was built where that moves its pitch (the cap's draft,
    the mount gap and the plate that bounds it, the clamp on the cap's flange) (mm, deg; None: this spec's as
    loaded)."""

    cavity_diameter: float | None = _drawn("cavity diameter")
    cavity_length: float | None = _drawn("cavity length")
    neck_diameter: float | None = _drawn("neck diameter")
    neck_length: float | None = _drawn("neck length (sheet)")
    cap_outer_diameter: float | None = _drawn("end-cap outer diameter")
    cap_top_thickness: float | None = _drawn("end-cap top thickness")
    mold_draft_deg: float | None = param(f"core-pin draft {AS_LOADED}", "deg", None, lo=0.0, hi=10.0,
                                         lo_open=False)
    spacer_height: float | None = _drawn("mount gap (spacer height)")
    plate_width: float | None = _drawn("neck plate width")
    plate_depth: float | None = _drawn("neck plate depth")
    guide_thickness: float | None = _drawn("guide sheet thickness (it clamps the cap's flange)")
    flange_squeeze: float | None = param(f"end-cap flange squeeze {AS_LOADED}", "mm", None, lo=0.0, hi=LENGTH_MAX_MM,
                                         lo_open=False)


DRAWN = {"cavity_diameter": ("cavity", "diameter"), "cavity_length": ("cavity", "length"),
         "neck_diameter": ("neck", "diameter"), "neck_length": ("neck", "length"),
         "cap_outer_diameter": ("end_cap", "outer_diameter"), "cap_top_thickness": ("end_cap", "top_thickness"),
         "mold_draft_deg": ("mold", "draft_deg"), "spacer_height": ("spacer", "height"),
         "plate_width": ("plate", "width"), "plate_depth": ("plate", "depth"),
         "guide_thickness": ("guide", "thickness"), "flange_squeeze": ("end_cap", "flange_squeeze")}
"""Each :class:`Drawn` field → the table and field of the spec it stands for: every field of one taxel that the
closed-form models read (:data:`matcad.sweep.fast.FIELDS`) but the air and the silicone, which an anchor treats
on its own (the air's temperature) or takes as the calibrated taxel's (the silicone)."""


def filled(entry, spec):
    """``entry`` (a :class:`Drawn` section) with the geometry it leaves out taken from ``spec``."""
    return dataclasses.replace(entry, **{key: getattr(getattr(spec, table), name)
                                         for key, (table, name) in DRAWN.items() if getattr(entry, key) is None})


def drawn_spec(spec, entry, **changes):
    """``spec`` with ``entry``'s drawn geometry (fields it leaves out stay ``spec``'s) and ``changes`` (other
    top-level fields of the spec, e.g. ``reference=None``); validated like any replace; ``spec`` itself when it
    draws the entry already and nothing changes."""
    tables: dict = {}
    for key, (table, name) in DRAWN.items():
        value = getattr(entry, key)
        if value is not None and value != getattr(getattr(spec, table), name):
            tables.setdefault(table, {})[name] = value
    if not tables and not changes:
        return spec  # the spec draws it already
    return dataclasses.replace(spec, **{t: dataclasses.replace(getattr(spec, t), **v) for t, v in tables.items()},
                               **changes)


def pinned(data: dict, spec) -> dict:
    """Raw spec ``data`` whose [calibration], [reference] and [[measured]] tables name the drawing they were
    measured on, taken from ``spec`` (``data`` as loaded): a variant made by editing the data (a sweep's) then keeps
    them on the taxel that was built, as ``dataclasses.replace`` does. The data are not changed."""
    out = dict(data)
    for key in ("calibration", "reference"):
        entry = getattr(spec, key)
        if entry is not None and isinstance(data.get(key), dict):
            out[key] = {k: getattr(entry, k) for k in DRAWN} | data[key]
    if spec.measured and isinstance(data.get("measured"), list):
        out["measured"] = [{k: getattr(entry, k) for k in DRAWN} | raw if isinstance(raw, dict) else raw
                           for entry, raw in zip(spec.measured, data["measured"])]
    return out

