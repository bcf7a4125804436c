"""f(F) before casting: the acoustic ladder on the deformed cavity of a :class:`~matcad.mechanics.solver.CapCurve`.

Per load state (unloaded first): the transmission line (Selamet et al. 1997, as in the unloaded ladder) on the
equivalent cylinder of the deformed cavity, same volume V and length L_eq = area-weighted mean height of the
deformed closed end, so that D_eq = sqrt(4V/(π L_eq)); optionally the axisymmetric FEM on the deformed outline
itself (:func:`matcad.acoustics.fem.deform_cavity`, rigid walls). The curve's ``f_hz`` is the unloaded ladder's
chosen f0 times the route's ratio f(F)/f(0), so it carries the same model choice as f0 (soft wall, band) and
only the *shift* comes from the deformed geometry. Lengths mm, volumes mm³, F in N, f in Hz.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from matcad.acoustics import geometry, models, registry
from matcad.acoustics.design import Design
from matcad.acoustics.eq5 import Eq5, frequency_constant_mm3_hz2
from matcad.acoustics.resonator import Resonator, resonator
from matcad.mechanics.solver import CapCurve


@dataclass(frozen=True)
class ForceState:
    """One load state: F (N), plate travel x (mm), cavity volume V (mm³), equivalent length (mm), the
    transmission-line and (if run) FEM frequencies on the deformed cavity and the reported ``f_hz`` (Hz)."""

    force_n: float
    displacement_mm: float
    cavity_volume_mm3: float
    equivalent_length_mm: float
    f_tl_hz: float
    f_fem_hz: float | None
    f_hz: float


@dataclass(frozen=True)
class ForceCurve:
    """f(F) along a cap curve: the states, df/dF (Hz/N) at each (:func:`tangent_hz_per_n`; NaN when no step
    converged), the force where f stops rising (None when it
    rises to the end), Eq. 5 constants fitted to (F, f) under the physical πd²/4 and the paper's d²/4 convention
    (None with ``fit_note`` saying why), which route set the shift (``route``) and, when the FEM was asked for but
    could not mesh a deformed outline, ``fem_note``."""

    states: tuple[ForceState, ...]
    sensitivity_hz_per_n: tuple[float, ...]
    turn_force_n: float | None
    eq5: Eq5 | None
    eq5_paper_convention: Eq5 | None
    fit_note: str
    route: str
    fem_note: str
    mechanics: CapCurve


def equivalent_length_mm(end_rz) -> float:
    """Area-weighted mean height of a closed end (r, z) from its corner to the axis: ∫ z d(r²) / r_corner² (mm)."""
    p = np.asarray(end_rz, dtype=float)
    r2, z = p[:, 0] ** 2, p[:, 1]
    return float(np.sum(0.5 * (z[1:] + z[:-1]) * (r2[:-1] - r2[1:])) / r2[0])


def tangent_hz_per_n(forces_n, f_hz) -> np.ndarray:
    """df/dF (Hz/N) at each load state: second-order differences of the curve, one-sided at its ends (the tangent
    at 0 N is that of the parabola through the first three states, so its error falls with the square of the step,
    not linearly like a one-step difference: paper cap 57.2/56.9/57.0 Hz/N at 3/4/10 steps to 2 mm, against 57.01
    from states 0.01 mm apart); a secant with two states, NaN with one (no step converged). With 1 or 2 steps the
    first states are 1-2 mm apart and the tangent is coarse (45.0 and 48.8 Hz/N): ask for >= 3 steps."""
    forces_n, f_hz = np.asarray(forces_n, dtype=float), np.asarray(f_hz, dtype=float)
    if len(f_hz) < 2:
        return np.full(len(f_hz), np.nan)
    return np.gradient(f_hz, forces_n, edge_order=2 if len(f_hz) > 2 else 1)


def deformed_resonator(res: Resonator, volume_mm3: float, length_mm: float, neck_diameter_mm: float) -> Resonator:
    """``res`` with its cavity replaced by the cylinder of volume ``volume_mm3`` and length ``length_mm``."""
    d = float(geometry.equivalent_diameter_mm(volume_mm3, length_mm))
    return dataclasses.replace(
        res, volume=volume_mm3, cavity_diameter=d, cavity_length=length_mm,
        cavity_area=float(geometry.circle_area_mm2(d)),
        inner_ingard=float(models.ingard_end_correction_mm(neck_diameter_mm, d)),
        inner_step=float(models.step_end_correction_mm(neck_diameter_mm, d)))


def force_curve(d: Design, curve: CapCurve, f0_hz: float | None = None, fem_level: int | None = None,
                progress=None) -> ForceCurve:
    """f(F) of design ``d`` along ``curve``; ``f0_hz`` the unloaded ladder's chosen f0 (default: the transmission
    line's); ``fem_level`` runs the FEM on every deformed outline and makes it the route of the shift
    (``progress(outlines done, outlines)`` told as each is solved)."""
    from matcad.acoustics.eq5fit import fit
    from matcad.errors import LoopError

    res = resonator(d)
    line = registry.model("transmission_line")
    outlines = [curve.unloaded_outline] + [s.cavity_outline for s in curve.steps]
    forces, xs, vols = curve.column("force_n"), curve.column("displacement_mm"), curve.column("cavity_volume_mm3")
    lengths = [equivalent_length_mm(curve.split(o)[1]) for o in outlines]
    f_tl = np.array([float(line.f0_hz(deformed_resonator(res, v, le, d.neck_diameter)))
                     for v, le in zip(vols, lengths)])
    f_fem, fem_note = None, ""
    if fem_level is not None:
        from matcad.acoustics import fem

        g = fem.geometry(d)
        f_fem = np.full(len(f_tl), np.nan)
        for i, (f_guess, o) in enumerate(zip(f_tl, outlines)):
            try:
                f_fem[i] = fem.solve(g, 2 * np.pi * f_guess / (res.c_m_s * models.MM_PER_M), fem_level, res.c_m_s,
                                     cavity_outline=curve.split(o)).f0_hz
            except ValueError as exc:
                fem_note = (f"FEM on the deformed outline unavailable from x = {xs[i]:.3g} mm ({exc}); the shift "
                            "comes from the transmission line")
                break
            if progress is not None:
                progress(i + 1, len(outlines))
    route = f_tl if f_fem is None or fem_note else f_fem
    f = (route[0] if f0_hz is None else f0_hz) * route / route[0]
    slope = tangent_hz_per_n(forces, f)
    falling = np.flatnonzero(np.diff(f) <= 0)
    turn = float(forces[falling[0]]) if len(falling) else None
    k = float(frequency_constant_mm3_hz2(res.c_m_s, d.neck_diameter, d.neck_length))
    eq5 = eq5_paper = None
    note = ""
    try:
        cal = fit(forces, f, k).law
        eq5 = Eq5(cal.v0_mm3, cal.a, cal.b, area_convention="pi_d2/4", name="mechanics")
        # A = d²/4 is A(πd²/4)/π: every volume of the fit scales by 1/π
        eq5_paper = Eq5(cal.v0_mm3 / np.pi, cal.a / np.pi, cal.b / np.pi, area_convention="d2/4", name="mechanics")
    except (LoopError, np.linalg.LinAlgError) as exc:  # a curve Eq. 5 cannot follow (e.g. a crushed tiny cavity)
        note = f"no Eq. 5 fit: {exc}"
    states = tuple(ForceState(float(F), float(x), float(v), float(le), float(a),
                              None if f_fem is None or np.isnan(f_fem[i]) else float(f_fem[i]), float(b))
                   for i, (F, x, v, le, a, b) in enumerate(zip(forces, xs, vols, lengths, f_tl, f)))
    return ForceCurve(states, tuple(float(s) for s in slope), turn, eq5, eq5_paper, note,
                      "transmission line on the equivalent cylinder" if route is f_tl
                      else f"axisymmetric FEM on the deformed outline, level {fem_level}", fem_note, curve)


def at_forces(fc: ForceCurve, forces_n) -> list[tuple[float, float | None, float | None, float | None, str]]:
    """(F, f_hz, x_mm, V_mm3, reason) at each requested force by linear interpolation between load states; None
    and a reason outside the computed curve."""
    force = np.array([s.force_n for s in fc.states])
    cols = {name: np.array([getattr(s, name) for s in fc.states])
            for name in ("f_hz", "displacement_mm", "cavity_volume_mm3")}
    out = []
    for F in np.asarray(forces_n, dtype=float):
        if not np.isfinite(F) or F < 0:
            out.append((float(F), None, None, None, "the cap model is for compressive forces F >= 0"))
        elif F > force[-1]:
            why = fc.mechanics.message or "raise [mechanics] displacement_mm to extend it"
            out.append((float(F), None, None, None,
                        f"F = {F:g} N is beyond the computed curve (max {force[-1]:.3g} N: {why})"))
        else:
            out.append((float(F), *(float(np.interp(F, force, cols[c])) for c in
                                    ("f_hz", "displacement_mm", "cavity_volume_mm3")), ""))
    return out


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def load_points(d: Design, curve: CapCurve, forces_n, f0_hz: float,
                fem_level: int | None = None, progress=None) -> tuple[list[dict], dict]:
    """The cap model's answer to ``matcad predict --force``: one row per force (force_n, f_hz, displacement_mm,
    cavity_volume_mm3, reason, source) and a summary (material, contact, run, df/dF, turn force, Eq. 5 fit, the
    whole computed curve with each state's deformed cavity outline as [r, z] mm from the wall's foot to the axis) for
    design ``d`` along the cap's ``curve``. ``f0_hz`` is the unloaded ladder's chosen f0 (Hz); see
    :func:`force_curve`."""
    fc = force_curve(d, curve, f0_hz, fem_level, progress)
    source = f"cap mechanics ({curve.material.model}, {curve.contact}, G = {curve.material.shear_modulus_mpa:.3g} MPa)"
    rows = [{"force_n": F, "f_hz": f, "displacement_mm": x, "cavity_volume_mm3": v, "reason": why, "source": source}
            for F, f, x, v, why in at_forces(fc, forces_n)]

    def constants(cal):
        return None if cal is None else {"v0_mm3": cal.v0_mm3, "a": cal.a, "b": cal.b,
                                         "area_convention": cal.area_convention}

    summary = {
        "source": source, "material": curve.material.note, "contact": curve.contact,
        "shear_modulus_mpa": curve.material.shear_modulus_mpa, "complete": curve.complete,
        "message": curve.message, "route": fc.route, "fem_note": fc.fem_note, "seconds": curve.seconds,
        "nodes": curve.nodes, "cells": curve.cells, "element_size_mm": curve.element_size_mm,
        "sensitivity_hz_per_n_at_0": _finite(fc.sensitivity_hz_per_n[0]), "max_force_n": fc.states[-1].force_n,
        "turn_force_n": fc.turn_force_n, "eq5": constants(fc.eq5), "eq5_paper_convention":
            constants(fc.eq5_paper_convention), "fit_note": fc.fit_note,
        "curve": [dataclasses.asdict(s) | {"sensitivity_hz_per_n": _finite(d), "peak_strain": p,
                                            "cavity_outline_mm": np.round(o, 5).tolist()}
                  for s, d, p, o in zip(fc.states, fc.sensitivity_hz_per_n, curve.column("peak_strain"),
                                        [curve.unloaded_outline] + [st.cavity_outline for st in curve.steps])],
    }
    return rows, summary
