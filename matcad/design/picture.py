"""The pictures `matcad design` writes next to the spec it designed: for one taxel the target, f0 along the varied
field and the section as it was and as solved (:mod:`matcad.render.design`); for an array every taxel's band on
the band chart the build report uses (:func:`matcad.render.bands.band_chart`)."""

from __future__ import annotations

import numpy as np

CURVE_POINTS = 41
"""Points of the f0 curve along the varied field (closed-form models: milliseconds each)."""


def solution_plot(start, result, folder) -> str:
    """``plot_design.png`` of a :class:`matcad.design.solve.Solution` solved from the spec ``start``: f0 along its
    first varied length (``neck.length`` the taxel's whole neck, :func:`matcad.spec.neck_length_mm`, when only the
    discrete fields vary; a neck through a riser keeps the riser's part of it)."""
    from matcad.design.solve import RISER, SHEET, chosen_model, model_f0, with_fields
    from matcad.render.design import DESIGN_PNG, design_plot
    from matcad.spec import SpecError

    field = next((k for k in result.fields if k != RISER), SHEET)
    geometry = {"start": _section(start), "solved": _section(result.spec)}
    a, b = geometry["start"][field], geometry["solved"][field]
    lo, hi = min(a, b), max(a, b)
    pad = max(0.25 * (hi - lo), 0.05 * hi)
    riser = geometry["solved"][SHEET] - result.spec.neck.length  # of the neck's length: the riser's, if through it
    model, base = chosen_model(result.spec)
    curve = []
    for x in np.linspace(max(lo - pad, 1e-3), hi + pad, CURVE_POINTS):
        try:
            at = with_fields(result.spec, {field: x - riser if field == SHEET else x})
            curve.append([float(x), model_f0(at, model, base)])
        except (SpecError, ValueError, ArithmeticError):  # an impossible geometry there: a gap in the curve
            continue
    data = {"name": result.spec.name, "field": field, "model": result.model, "target_hz": result.target_hz,
            "f0_hz": result.f0_hz, "error": result.error, "curve": curve,
            "start_f0_hz": model_f0(start, model, base) if curve else result.f0_hz, **geometry}
    return design_plot(data, folder / DESIGN_PNG)["file"]


def _section(spec) -> dict:
    """The drawn section's lengths (mm): the cavity, the neck's diameter and its whole length (through a riser)."""
    from matcad.design.solve import get_field
    from matcad.spec import neck_length_mm

    return {k: float(get_field(spec, k)) for k in ("cavity.diameter", "cavity.length", "neck.diameter")} \
        | {"neck.length": neck_length_mm(spec)}


def allocation_chart(result, folder) -> str:
    """``plot_taxel_bands.png`` of an :class:`matcad.design.allocate.Allocation`: every taxel's band."""
    from matcad.prediction.bands import summary
    from matcad.render.bands import BANDS_PNG, band_chart

    band_chart(summary(result.spec, list(result.bands)), folder / BANDS_PNG)
    return BANDS_PNG
