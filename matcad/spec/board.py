"""A board of taxels: the typed value every per-taxel computation takes. Lengths in millimetres.

A spec describes one taxel at the plate centre (no [array], no [[taxel]]), a grid of identical taxels ([array]),
or taxels that differ ([[taxel]] entries, each overriding the shared [cavity], [neck], [end_cap] and [needle]
tables). :func:`taxels` turns any of them into the same tuple of :class:`Taxel` values; physics written for one
taxel is applied to each through :func:`taxel_spec`.

``spec`` is a :class:`matcad.spec.model.Spec`, taken as it is (duck-typed): the Spec's own checks go through
:func:`taxels`, so this module cannot import the Spec class.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from matcad.spec.calibration import Calibration
from matcad.spec.drawn import filled
from matcad.spec.sections import Cavity, EndCap, Neck, Needle, TaxelEntry

ENTRY_FIELDS = {
    "cavity.diameter": "cavity_diameter", "cavity.length": "cavity_length", "neck.diameter": "neck_diameter",
    "neck.riser": "neck_riser",
    "end_cap.outer_diameter": "cap_outer_diameter", "end_cap.top_thickness": "cap_top_thickness",
    "needle.theta_deg": "needle_theta_deg", "needle.y": "needle_y", "needle.flow_l_min": "needle_flow_l_min"}
"""Shared-table field → the [[taxel]] key that overrides it for one taxel."""


@dataclass(frozen=True)
class Taxel:
    """One resonator of a board: its name, where its neck axis is on the neck plate (x, y in mm, plate centre =
    origin) and its own validated geometry. ``neck.length`` is the plate's sheet, the same for every taxel;
    ``neck.riser`` whether its neck runs on through the spec's [riser] (:func:`matcad.spec.cap.neck_length_mm`).
    ``calibration``: its own Eq. 5 calibration ([taxel.calibration]), None when the spec gives it none."""

    name: str
    x: float
    y: float
    cavity: Cavity
    neck: Neck
    end_cap: EndCap
    needle: Needle
    calibration: Calibration | None = None


def _override(section, prefix: str, entry: TaxelEntry):
    values = {key.split(".")[1]: getattr(entry, attr) for key, attr in ENTRY_FIELDS.items()
              if key.startswith(prefix + ".") and getattr(entry, attr) is not None}
    return dataclasses.replace(section, **values) if values else section


def _from_entry(spec, index: int, entry: TaxelEntry) -> Taxel:
    return Taxel(name=entry.name or f"t{index}", x=entry.x, y=entry.y,
                 cavity=_override(spec.cavity, "cavity", entry), neck=_override(spec.neck, "neck", entry),
                 end_cap=_override(spec.end_cap, "end_cap", entry), needle=_override(spec.needle, "needle", entry),
                 calibration=entry.calibration)


def grid_positions_mm(columns: int, rows: int, pitch_x: float | None, pitch_y: float | None) \
        -> list[tuple[float, float]]:
    """Neck axes of a ``columns`` x ``rows`` grid centred on the origin, row by row from the top left (+y up), mm."""
    px, py = pitch_x or 0.0, pitch_y or 0.0
    return [((c - (columns - 1) / 2) * px, ((rows - 1) / 2 - r) * py) for r in range(rows) for c in range(columns)]


def taxels(spec) -> tuple[Taxel, ...]:
    """Every taxel of ``spec`` in order (names t1, t2, ... unless [[taxel]] names them); one taxel "t1" at (0, 0)
    for a spec without [array] or [[taxel]]."""
    if spec.taxel:
        return tuple(_from_entry(spec, i, entry) for i, entry in enumerate(spec.taxel, 1))
    if spec.array is not None:
        a = spec.array
        points = grid_positions_mm(a.columns, a.rows, a.pitch_x, a.pitch_y)
    else:
        points = [(0.0, 0.0)]
    return tuple(Taxel(f"t{i}", x, y, spec.cavity, spec.neck, spec.end_cap, spec.needle)
                 for i, (x, y) in enumerate(points, 1))


def is_array(spec) -> bool:
    """Whether ``spec`` describes more than one taxel."""
    return len(taxels(spec)) > 1


def field_path(spec, index: int, key: str) -> str:
    """The spec field that sets ``key`` (e.g. 'neck.diameter') for the taxel at 0-based ``index``: its [[taxel]]
    override when it has one, else the shared table's field."""
    if spec.taxel and key in ENTRY_FIELDS and getattr(spec.taxel[index], ENTRY_FIELDS[key]) is not None:
        return f"taxel[{index + 1}].{ENTRY_FIELDS[key]}"
    return key


def taxel_spec(spec, taxel: Taxel):
    """A single-taxel spec with ``taxel``'s geometry (its position dropped) and its own calibration when it has
    one (else the spec's [calibration]; a taxel's own calibration was measured on this taxel as drawn): how per-taxel
    physics (predict, wall modes, cap mechanics) is applied to one taxel of a board. The [riser] stays, so the
    taxel's neck runs through it or its cap sits in a pocket of it as on the board. A one-taxel spec's own taxel
    is the spec itself (the same tables: nothing to replace, so nothing is read or checked again)."""
    if (spec.array is None and not spec.taxel and taxel.calibration is None and taxel.cavity is spec.cavity
            and taxel.neck is spec.neck and taxel.end_cap is spec.end_cap and taxel.needle is spec.needle):
        return spec
    own = dataclasses.replace(spec, cavity=taxel.cavity, neck=taxel.neck, end_cap=taxel.end_cap,
                              needle=taxel.needle, array=None, taxel=())
    if taxel.calibration is None:
        return own
    return dataclasses.replace(own, calibration=filled(taxel.calibration, own))
