"""One taxel's prediction under load: the unloaded acoustics composed with Eq. 5 (a calibration) and the cap
mechanics. Forces N, frequencies Hz, lengths mm.

:func:`predict` is what `matcad predict` prints: the acoustic ladder's unloaded f0 and band
(:func:`matcad.acoustics.predict.predict`) and, at the asked forces, f(F) from the spec's [calibration] (paper
Eq. 5) and from the cap pressed by a plate (:mod:`matcad.mechanics`, FElupe, seconds), each point naming its
source. The cap's curve is computed once per distinct cap in a process (:func:`cap_curve`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from matcad.acoustics import design as adapt
from matcad.acoustics.eq5 import MAT_PAPER_2024
from matcad.acoustics.predict import LoadPoint, Prediction
from matcad.acoustics.predict import predict as predict_unloaded
from matcad.acoustics.registry import ModelResult
from matcad.prediction.anchor import ANCHORS, anchor
from matcad.prediction.curves import cap_curve

def load_model_of(spec, model: str, progress=None):
    """(design, cap curve) that f(F) of the single-taxel ``spec`` is computed on: the drawn design and the grade's
    curve, or, when its prediction is ``as_built``, the design built in the inferred lab state and the curve of its
    silicone (:mod:`matcad.prediction.asbuilt`)."""
    from matcad.mechanics.case import cap_case

    d = adapt.design(spec)
    curve = cap_curve(cap_case(spec), progress)
    if model != "as_built":
        return d, curve
    from matcad.prediction import asbuilt
    from matcad.prediction.inference import infer

    state = infer(spec).state
    return asbuilt.built(d, state), asbuilt.built_curve(curve, state)


def _anchored(spec, p: Prediction, name: str | None) -> Prediction:
    """``p`` with its headline f0 and band anchored to the spec's measurements (:mod:`matcad.prediction.anchor`):
    the anchor's result joins the models, the physics-only numbers stay in ``physics_*``."""
    a = anchor(spec, name)
    if a is None:
        return p
    result = a.anchored(spec)
    models = dict(p.models) | {a.name: ModelResult(result.f0_hz, {}, result.note)}
    return dataclasses.replace(p, models=models, model=a.name, f0_hz=result.f0_hz, band_hz=result.band_hz,
                               budget=result.lines)


def predict(spec, forces_n=(), model: str | None = None, fem_level: int | None = None,
            mechanics: bool = True, progress=None) -> Prediction:
    """Predict the unloaded resonance of the single-taxel ``spec`` with every model, and f at ``forces_n`` (N) from
    the cap mechanics (imported only then; ``mechanics=False`` skips it) and, if calibrated, from Eq. 5 too.

    ``model`` overrides the automatic choice: a registered model that serves the spec's wall, or 'relative'
    (ValueError otherwise); ``fem_level`` sets the FEM's elements across the neck radius (default
    :data:`matcad.acoustics.fem.DEFAULT_LEVEL`); ``progress(done, total)`` (:mod:`matcad.progress`) is told the
    cap's load steps as they converge and the FEM's deformed outlines as they are solved.
    """
    if spec.taxel or spec.array is not None:
        from matcad.spec import SpecError, taxel_spec, taxels

        board = taxels(spec)
        if len(board) > 1:  # a board is predicted taxel by taxel (matcad.prediction.bands)
            raise SpecError("taxel", f"{len(board)} taxels", "predict answers for one taxel so far")
        spec = taxel_spec(spec, board[0])
    d = adapt.design(spec)
    anchored = model in ANCHORS
    if anchored:
        anchor(spec, model)  # refuses, naming what the spec lacks
    p = predict_unloaded(d, adapt.reference(spec), None if anchored else model, fem_level)
    if model is None or anchored:
        p = _anchored(spec, p, model)
    cal = adapt.calibration(spec, d)
    warnings = list(p.warnings)
    curve: tuple[LoadPoint, ...] = ()
    load_model = None
    if len(forces_n):
        if cal is not None:
            f_at = cal.frequency_hz(np.asarray(forces_n, dtype=float))
            curve = tuple(LoadPoint(float(force), None if np.isnan(f) else float(f), cal.invalid_reason(force),
                                    source=f"calibration {cal.name} (Eq. 5)") for force, f in zip(forces_n, f_at))
            if cal.area_convention == MAT_PAPER_2024.area_convention:
                warnings.append("load curve uses the paper's A = d^2/4 convention with its fitted V0 (see docs/paper.md); "
                                "its volumes are not physical cavity volumes")
    if len(forces_n) and mechanics:
        from matcad.acoustics.fem import DEFAULT_LEVEL
        from matcad.mechanics.frequency import load_points

        # the FEM route on the deformed outlines when the FEM is the chosen model; as built, when inferred
        built, cap = load_model_of(spec, p.model, progress)
        rows, load_model = load_points(built, cap, forces_n, p.f0_hz,
                                       (fem_level or DEFAULT_LEVEL) if p.model == "fem" else None, progress)
        curve += tuple(LoadPoint(**row) for row in rows)
        if load_model["message"]:
            warnings.append(f"cap mechanics: {load_model['message']}")
    return dataclasses.replace(p, warnings=tuple(warnings), load_curve=curve, load_model=load_model,
                               calibration=None if cal is None else f"{cal.name} ({cal.area_convention})")
