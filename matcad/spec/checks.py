"""The cross-field checks of a whole spec: what makes a design impossible although every table is valid. Lengths mm.

They run from ``Spec.__post_init__``, so a spec changed with ``dataclasses.replace`` is checked too; the spec is
taken as it is (duck-typed), so this module needs no import of the Spec class.
"""

from __future__ import annotations

import math

from matcad.spec.board import field_path, taxels
from matcad.spec.derive import calibrated_spec, reference_spec
from matcad.spec.fields import SpecError
from matcad.spec.measured import measured_spec


def cross_checks(spec) -> None:
    """What no single table can check of a whole ``spec`` (a :class:`matcad.spec.model.Spec`): the reference's band
    and geometry, [array] or [[taxel]] but not both, unique taxel names, and every taxel's geometry. Raises
    SpecError naming the field that sets the bad value."""
    if spec.kind == "tube":  # its tables are checked by matcad.spec.tube; the MAT stack is refused by from_dict
        return
    if spec.reference is not None and not spec.reference.f0_tolerance_hz < spec.reference.f0_hz:
        raise SpecError("reference.f0_tolerance_hz", spec.reference.f0_tolerance_hz,
                        f"must be < reference.f0_hz = {spec.reference.f0_hz:g} Hz (a band in ln f needs f0 - tol > 0)")
    for key, drawing in (("reference", reference_spec), ("calibration", calibrated_spec)):
        if getattr(spec, key) is not None:  # the measured taxel's own drawing must be a possible taxel
            try:
                drawing(spec)
            except SpecError as err:
                raise SpecError(f"{key} ({err.field})", err.value, err.allowed) from None
    if spec.array is not None and spec.taxel:
        raise SpecError("array", "[array] and [[taxel]]", "give either an [array] grid or [[taxel]] entries, not both")
    for key in ("taxel", "measured"):
        names = [entry.name for entry in getattr(spec, key)]
        for i, name in enumerate(names, 1):
            if name is not None and name in names[:i - 1]:
                raise SpecError(f"{key}[{i}].name", name, f"must be unique among the [[{key}]] entries")
    for i, entry in enumerate(spec.measured, 1):
        try:
            measured_spec(spec, entry)
        except SpecError as err:
            raise SpecError(f"measured[{i}] ({err.field})", err.value, err.allowed) from None
    board = taxels(spec)
    for index, t in enumerate(board):
        _geometry_checks(t, lambda key, i=index: field_path(spec, i, key), spec.mold.draft_deg)
    _riser_checks(spec, board)


def _riser_checks(spec, board) -> None:
    """A neck that runs on through a riser needs a [riser] (a riser no neck runs through is possible, if idle: the
    ``riser.idle`` rule says so)."""
    through = [i for i, t in enumerate(board) if t.neck.riser]
    if spec.riser is None and through:
        raise SpecError(field_path(spec, through[0], "neck.riser"), True,
                        "needs a [riser] table (the sheet the neck runs on through: its thickness)")


def geometry_invalid(cavity_diameter, cavity_length, neck_diameter, draft_deg, cap_outer_diameter=None):
    """Where :func:`_geometry_checks` refuses a taxel, on numpy arrays of variants (mm, deg; ``cap_outer_diameter``
    None where the spec leaves it to its default): a bool array, True where some check fails. A sweep judges its
    grid with it; the messages come from the checks themselves."""
    import numpy as np

    neck_wider = np.asarray(neck_diameter) > np.asarray(cavity_diameter)
    tip = np.asarray(cavity_diameter) - 2 * np.asarray(cavity_length) * np.tan(np.radians(draft_deg))
    bad = neck_wider | (tip <= 0)
    if cap_outer_diameter is not None:
        bad = bad | (np.asarray(cap_outer_diameter) <= np.asarray(cavity_diameter))
    return bad


def _geometry_checks(t, path, draft_deg: float) -> None:
    """What makes one taxel's geometry impossible (``t`` a :class:`matcad.spec.board.Taxel`; ``path(key)`` names the
    spec field that sets ``key``, e.g. 'neck.diameter' or 'taxel[2].neck_diameter'). :func:`geometry_invalid` is
    the same test on arrays."""
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
