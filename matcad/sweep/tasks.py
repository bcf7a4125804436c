"""One variant's slow work as a pure function of plain data, for any executor (local processes or Dask workers,
which need matcad installed at the same version).

A task is ``{"index", "data" (the spec as TOML-like data), "model", "fem_level", "predict", "rules", "cad"}``;
the result is a flat dict of numbers and strings. Nothing raises: a variant whose spec does not validate is
``status = "invalid"``, one whose solver or build fails is ``status = "failed"``; ``reason`` says why.
"""

from __future__ import annotations

import time


def run_variant(task: dict) -> dict:
    """Validate, predict (``model``; ``fem`` refines the cheap rung), run the design rules on that prediction
    (error and warning counts, failing rule ids) and, with ``cad``, build the silicone end cap with build123d and
    read its STL back (volume mm³ against the closed form). Frequencies Hz."""
    from matcad.spec import SpecError, from_dict

    start = time.perf_counter()
    out: dict = {"index": task["index"], "status": "ok", "reason": ""}
    try:
        spec = from_dict(task["data"])
    except SpecError as exc:
        return {**out, "status": "invalid", "reason": str(exc)}
    try:
        prediction = None
        if task.get("predict") or task.get("rules"):
            from matcad.prediction import predict

            prediction = predict(spec, model=task.get("model"), fem_level=task.get("fem_level"), mechanics=False)
        if task.get("predict"):
            out.update(f0_hz=prediction.f0_hz, band_low_hz=prediction.band_hz[0],
                       band_high_hz=prediction.band_hz[1], model_valid=prediction.models[prediction.model].valid)
        if task.get("rules"):
            out.update(rule_verdicts(spec, prediction))
        if task.get("cad"):
            out.update(cad_end_cap(spec))
    except Exception as exc:  # noqa: BLE001 - a variant's failure is a row of the table, never fatal
        out.update(status="failed", reason=f"{exc.__class__.__name__}: {exc}")
    out["seconds"] = time.perf_counter() - start
    return out


def rule_verdicts(spec, prediction) -> dict:
    """Error and warning counts of :func:`matcad.rules.check` and the ids of the rules that gave them."""
    from matcad.rules import check

    findings = check(spec, prediction)
    failing = [f for f in findings if f.level in ("error", "warning")]
    return {"rule_errors": sum(f.level == "error" for f in failing),
            "rule_warnings": sum(f.level == "warning" for f in failing),
            "failing_rules": " ".join(dict.fromkeys(f"{f.id}:{f.level}" for f in failing))}


def cad_end_cap(spec) -> dict:
    """Build the end cap (:func:`matcad.parts.end_cap.end_cap`), write its STL at the spec's tolerances and read
    it back: volume (mm³), watertight, and the closed-form cast volume (:func:`cap_volume_mm3`) it should match."""
    import tempfile
    from pathlib import Path

    from matcad.export.mesh import mesh_checks, write_stl
    from matcad.parts.end_cap import end_cap
    from matcad.parts.features import cap_volume_mm3

    with tempfile.TemporaryDirectory(prefix="matcad-sweep-") as folder:
        path = Path(folder) / "end_cap.stl"
        write_stl(end_cap(spec), path, spec.machine.stl_tolerance, spec.machine.stl_angular_tolerance)
        mesh = mesh_checks(path)
    return {"cad_stl_volume_mm3": mesh["volume_mm3"], "cad_closed_form_volume_mm3": cap_volume_mm3(spec),
            "cad_watertight": mesh["watertight"], "cad_triangles": mesh["triangles"]}


def run_chunk(tasks: list[dict]) -> list[dict]:
    """Several tasks in one call (one round trip to a worker)."""
    return [run_variant(t) for t in tasks]
