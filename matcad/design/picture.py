"""The pictures `matcad design` writes next to the spec it designed: for one taxel the target, f0 along the varied
field and the section as it was and as solved (:mod:`matcad.render.design`); for an array every taxel's band on
the band chart the build report uses (:func:`matcad.render.bands.band_chart`)."""

from __future__ import annotations

import numpy as np

CURVE_POINTS = 41
"""Points of the f0 curve along the varied field (closed-form models: milliseconds each)."""


def solution_plot(start, result, folder) -> str:
    """``plot_design.png`` of a :class:`matcad.design.solve.Solution` solved from the spec ``start``."""
    from matcad.design.solve import chosen_model, get_field, model_f0, with_fields
    from matcad.render.design import DESIGN_PNG, design_plot
    from matcad.spec import SpecError

    geometry = ("cavity.diameter", "cavity.length", "neck.diameter", "neck.length")
    field = next(iter(result.fields))
    a, b = result.fields[field]
    lo, hi = min(a, b), max(a, b)
    pad = max(0.25 * (hi - lo), 0.05 * hi)
    model, base = chosen_model(result.spec)
    curve = []
    for x in np.linspace(max(lo - pad, 1e-3), hi + pad, CURVE_POINTS):
        try:
            curve.append([float(x), model_f0(with_fields(result.spec, {field: x}), model, base)])
        except (SpecError, ValueError, ArithmeticError):  # an impossible geometry there: a gap in the curve
            continue
    data = {"name": result.spec.name, "field": field, "model": result.model, "target_hz": result.target_hz,
            "f0_hz": result.f0_hz, "error": result.error, "curve": curve,
            "start_f0_hz": model_f0(start, model, base) if curve else result.f0_hz,
            "start": {k: float(get_field(start, k)) for k in geometry},
            "solved": {k: float(get_field(result.spec, k)) for k in geometry}}
    return design_plot(data, folder / DESIGN_PNG)["file"]


def allocation_chart(result, folder) -> str:
    """``plot_taxel_bands.png`` of an :class:`matcad.design.allocate.Allocation`: every taxel's band."""
    from matcad.prediction.bands import summary
    from matcad.render.bands import BANDS_PNG, band_chart

    band_chart(summary(result.spec, list(result.bands)), folder / BANDS_PNG)
    return BANDS_PNG
