"""Spec → every model's f0, the chosen f0 and band, validity flags and warnings (one result object).

Frequencies in Hz, lengths mm. The default model is the transmission line (rigid wall) or, for
``wall.model = "silicone"``, the transmission line coupled to the cap's wall modes (``elastic_wall``: the wall's
mass, stiffness and loss; it moves f up when the cap's modes lie below f, down when they lie well above).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from matcad.acoustics import models, registry
from matcad.acoustics.air import VISCOUS_REGIME_EPS, boundary_layer_drop, boundary_layer_shift
from matcad.acoustics.load import MAT_PAPER_2024, LoadCalibration, frequency_at_force_hz, invalid_reason
from matcad.acoustics import wall as wall_model
from matcad.acoustics.resonator import cap_shape as cap_shape_of
from matcad.acoustics.resonator import (dynamic_moduli_pa, evaluate, loss_factors, resonator, shear_moduli_pa,
                                        wall_arguments, wall_modes)
from matcad.acoustics.uncertainty import BudgetLine, budget, total

PLANE_WAVE_CUTOFF_KA = 1.8412
"""First non-planar (1,1) mode of a circular duct cuts on at k·a = 1.8412 (zero of J1')."""
PANCAKE_L_OVER_D = 0.3
LUMPED_NECK_AIR_RATIO = 0.1
BOUNDARY_LAYER_WARN = 0.05
LUMPED_END_CORRECTION_RATIO = 0.1
"""Uncorrected Eq. 1 needs the neck's end corrections ≪ its length (they are 24 % of it on the paper taxel)."""
PAPER_TAXEL_MM = (3.18, 4.76, 2.10, 6.35)
"""Cavity D, L and neck d, l of the source paper's taxel (templates/mat-paper.toml)."""
PAPER_MEASURED_HZ = 4000.0
"""The one published measurement of that taxel: ~4.0 kHz unloaded (MAT paper, Sec. VI)."""


@dataclass(frozen=True)
class ModelResult:
    """One rung of the ladder: f0 (Hz), its validity checks (name → passed) and its source."""

    f0_hz: float
    checks: dict[str, bool]
    source: str

    @property
    def valid(self) -> bool:
        return all(self.checks.values())


@dataclass(frozen=True)
class LoadPoint:
    """f at one force (N, Hz) from ``source`` (Eq. 5 with a calibration, or the cap mechanics, which also gives the
    plate travel (mm) and the cavity volume (mm³)): f_hz is None and reason says why when it has no answer there."""

    force_n: float
    f_hz: float | None
    reason: str = ""
    displacement_mm: float | None = None
    cavity_volume_mm3: float | None = None
    source: str = ""


@dataclass(frozen=True)
class Prediction:
    cavity_volume_mm3: float
    neck_area_mm2: float
    cavity_area_mm2: float
    neck_air_ratio: float
    diameter_ratio: float
    speed_of_sound_m_s: float
    outer_end_correction_mm: float
    inner_end_correction_mm: float
    models: dict[str, ModelResult]
    model: str
    f0_hz: float
    band_hz: tuple[float, float]
    budget: tuple[BudgetLine, ...]
    warnings: tuple[str, ...]
    calibration: str | None = None
    load_curve: tuple[LoadPoint, ...] = ()
    load_model: dict | None = None

    def to_dict(self) -> dict:
        d = asdict(self)
        for name, result in self.models.items():
            d["models"][name]["valid"] = result.valid
        d["band_hz"] = list(self.band_hz)
        return d


def spec_calibration(spec) -> LoadCalibration | None:
    """The spec's [calibration] as a LoadCalibration, or None."""
    cal = spec.calibration
    if cal is None:
        return None
    values = (cal.v0_mm3, cal.a, cal.b, cal.area_convention)
    paper = MAT_PAPER_2024
    if values == (paper.v0_mm3, paper.a, paper.b, paper.area_convention) and cal.k_mm3_hz2 is None:
        return paper
    return LoadCalibration(*values, name="spec", k_mm3_hz2=cal.k_mm3_hz2)


def _checks_plane_wave(f_hz, c_m_s, cavity_diameter_mm, cavity_length_mm) -> dict[str, bool]:
    k = 2 * np.pi * f_hz / (c_m_s * models.MM_PER_M)
    return {"plane_waves_in_cavity": bool(k * cavity_diameter_mm / 2 < PLANE_WAVE_CUTOFF_KA),
            "not_pancake": bool(cavity_length_mm / cavity_diameter_mm >= PANCAKE_L_OVER_D)}


def _model_warnings(name: str, result: ModelResult, diameter_ratio: float) -> list[str]:
    text = {
        "neck_air_ratio_small": f"{name}: neck holds much air relative to the cavity (A*l/V >= "
                                f"{LUMPED_NECK_AIR_RATIO}); lumped neck assumption fails",
        "end_corrections_small": f"{name}: the neck's end corrections are >= {LUMPED_END_CORRECTION_RATIO:g} x its "
                                 "length; uncorrected Eq. 1 overestimates f",
        "ingard_xi_below_0.4": f"{name}: Ingard's inner correction used at xi = {diameter_ratio:.3g}, outside "
                               f"its stated xi < {models.INGARD_XI_LIMIT}",
        "plane_waves_in_cavity": f"{name}: cavity wider than the plane-wave limit at f0 (k*D/2 >= "
                                 f"{PLANE_WAVE_CUTOFF_KA}); 1-D model unreliable",
        "not_pancake": f"{name}: flat cavity (L/D < {PANCAKE_L_OVER_D}); radial modes add a few percent error",
        "quasi_static_wall": f"{name}: the cap's wall modes lie below {wall_model.QUASI_STATIC_RATIO:g} x f0, where "
                             "a quasi-static (massless) wall is invalid: it ignores the wall's inertia, which "
                             "moves f up when the modes lie below f; use elastic_wall or --model fem",
        "wall_shape_in_table": f"{name}: the cap's shape lies outside the wall-mode table (clamped to its edge); "
                               "check with --model fem",
        "no_wall_mode_near_f": f"{name}: a cap wall mode with volume coupling lies within "
                               f"{100 * wall_model.HYBRID_BAND:.0f} % of f0: cavity and wall hybridise, two "
                               "resonances can compete, and this fast model's measured error is larger there (the "
                               "band carries it); check with --model fem",
    }
    return [text[check] for check, ok in result.checks.items() if not ok]


def fem_result(spec, c_m_s: float, f_guess_hz: float, level: int) -> ModelResult:
    """The FEM reference for this spec: rigid walls (acoustic eigenmode), or the elastic silicone cap coupled to
    the air (forced-response peak) at the middle of the spec's kHz modulus and loss ranges."""
    from matcad.acoustics import fem

    if spec.wall.model == "silicone":
        from matcad.acoustics import fsi

        shear, loss = dynamic_moduli_pa(spec)[1], loss_factors(spec)[1]
        run = fsi.solve(fem.geometry_from_spec(spec), fsi.cap_from_spec(spec, shear, loss), f_guess_hz, level,
                        c_m_s)
        modes = ", ".join(f"{f:.0f}" for f in run.wall_modes_hz)
        return ModelResult(run.f0_hz, {"fundamental_found": run.q > fem.MIN_Q},
                           f"coupled elastic cap + air FEM (scikit-fem, Taylor-Hood P2/P1 cap, P2 air), level "
                           f"{run.level}, {run.dofs} dofs, G = {shear / 1e6:.3g} MPa, eta = {loss:.2g}: peak of "
                           f"the driven response, Q = {run.q:.1f}; cap modes in vacuo {modes} Hz; "
                           f"{run.seconds:.2f} s")
    k_guess = 2 * np.pi * f_guess_hz / (c_m_s * models.MM_PER_M)
    run = fem.solve(fem.geometry_from_spec(spec), k_guess, level, speed_of_sound_m_s=c_m_s)
    checks = {"mode_in_cavity": run.cavity_energy_fraction > 0.3, "fundamental_found": run.q > fem.MIN_Q}
    return ModelResult(run.f0_hz, checks, f"axisymmetric P2 FEM (scikit-fem), level {run.level}, {run.dofs} "
                                          f"dofs, Q = {run.q:.1f}, {run.seconds:.2f} s")


def _relative(spec, model: str, this: ModelResult) -> ModelResult:
    """This design as the reference taxel's measured f0 times ``model``'s ratio (this design / reference); it
    carries ``this`` design's checks of that model."""
    from matcad.spec import reference_spec

    ref = reference_spec(spec)
    f_ref = float(evaluate(resonator(ref), model, *wall_arguments(ref, model)))
    f_model_hz = this.f0_hz
    ratio = f_model_hz / f_ref
    return ModelResult(spec.reference.f0_hz * ratio, dict(this.checks),
                       f"measured reference {spec.reference.f0_hz:g} Hz x {model} ratio {ratio:.4f} "
                       f"(this design {f_model_hz:.0f} Hz / reference {f_ref:.0f} Hz by the same model)")


def _paper_anchor(spec, chosen: str, f0_hz: float, band_low_hz: float) -> list[str]:
    """For the paper's taxel with a silicone cap: what physics predicts against the one published measurement."""
    dims = (spec.cavity.diameter, spec.cavity.length, spec.neck.diameter, spec.neck.length)
    if spec.wall.model != "silicone" or not np.allclose(dims, PAPER_TAXEL_MM, rtol=1e-6):
        return []
    gap = 100 * (1 - PAPER_MEASURED_HZ / f0_hz)
    where = "below the band" if PAPER_MEASURED_HZ < band_low_hz else "inside the band's low tail"
    return [f"{chosen}: physics predicts {f0_hz:.0f} Hz for the paper's taxel; its one published measurement "
            f"(~{PAPER_MEASURED_HZ / 1000:.1f} kHz unloaded) lies {gap:.0f} % lower, {where}. That gap is not "
            "explained by the wall (the Dragon Skin cap's wall modes lie below f, which moves f up, not down); open "
            "candidates: jet and mount flow effects, the real sheet thickness, the real cap shape. Build and record "
            "one taxel and predict new designs relative to it."]


def _wall_results(spec, res) -> dict[str, ModelResult]:
    """The two silicone-wall rungs: the quasi-static wall (valid only with every coupled wall mode ≥ 3 f) and
    the elastic wall with its modes, mass and loss (the chosen one)."""
    c = res.c_m_s
    static = shear_moduli_pa(spec)[1]
    f_static = float(evaluate(res, "soft_wall", static))
    dynamic, loss = dynamic_moduli_pa(spec)[1], loss_factors(spec)[1]
    f_elastic = float(evaluate(res, "elastic_wall", dynamic, loss))
    modes = wall_modes(res, dynamic)
    in_table = {"wall_shape_in_table": not wall_model.shape_outside_table(cap_shape_of(res)),
                "no_wall_mode_near_f": wall_model.mode_near(modes, f_elastic) is None}
    coupled = ", ".join(f"{f:.0f}" for f in modes.coupled_hz()[:4])
    return {
        "soft_wall": ModelResult(
            f_static, _checks_plane_wave(f_static, c, res.cavity_diameter, res.cavity_length)
            | {"quasi_static_wall": wall_model.quasi_static_valid(wall_modes(res, static), f_static)},
            f"transmission line with a quasi-static (massless) silicone wall (Lame cylinder + half-space end) at "
            f"G = {static / 1e6:.3g} MPa static; valid only when the cap's wall modes lie >= "
            f"{wall_model.QUASI_STATIC_RATIO:g} x f"),
        "elastic_wall": ModelResult(
            f_elastic, _checks_plane_wave(f_elastic, c, res.cavity_diameter, res.cavity_length) | in_table,
            f"transmission line coupled to the cap's wall modes (from the coupled FEM's elastic operator, "
            f"wall_modes.json) at G = {dynamic / 1e6:.3g} MPa (kHz), eta = {loss:.2g}; coupled wall modes "
            f"{coupled} Hz; peak of the driven response"),
    }


def predict(spec, forces_n=(), model: str | None = None, fem_level: int | None = None,
            mechanics: bool = True) -> Prediction:
    """Predict the unloaded resonance of ``spec`` with every model; f at ``forces_n`` (N) from the cap mechanics
    (:mod:`matcad.mechanics`, imported only then; ``mechanics=False`` skips it) and, if calibrated, from Eq. 5 too.

    ``model`` overrides the automatic choice: one of the returned ``models`` keys, or ``fem`` (elements
    across the neck radius ``fem_level``, default :data:`matcad.acoustics.fem.DEFAULT_LEVEL`).
    """
    if spec.taxel or spec.array is not None:
        from matcad.spec import SpecError, taxel_spec, taxels

        board = taxels(spec)
        if len(board) > 1:  # per-taxel predictions land with the band allocation; refuse rather than answer for one
            raise SpecError("taxel", f"{len(board)} taxels", "predict answers for one taxel so far")
        spec = taxel_spec(spec, board[0])
    neck = spec.neck
    res = resonator(spec)
    c, xi, air_ratio = res.c_m_s, res.diameter_ratio, res.neck_air_ratio
    lumped_ok = air_ratio < LUMPED_NECK_AIR_RATIO
    corrections_small = (res.outer_correction + res.inner_step) / res.neck_length < LUMPED_END_CORRECTION_RATIO
    results: dict[str, ModelResult] = {
        "lumped": ModelResult(float(evaluate(res, "lumped")),
                              {"neck_air_ratio_small": lumped_ok, "end_corrections_small": corrections_small},
                              registry.model("lumped").source),
        "end_corrected": ModelResult(
            float(evaluate(res, "end_corrected")),
            {"neck_air_ratio_small": lumped_ok, "ingard_xi_below_0.4": xi < models.INGARD_XI_LIMIT},
            f"Eq. 1 with l + {neck.mouth} outer correction + Ingard 1953 inner correction"),
    }
    f_tl = float(evaluate(res, "transmission_line"))
    results["transmission_line"] = ModelResult(
        f_tl, _checks_plane_wave(f_tl, c, res.cavity_diameter, res.cavity_length),
        registry.model("transmission_line").source)
    chosen = "transmission_line"
    if spec.wall.model == "silicone":
        results.update(_wall_results(spec, res))
        chosen = "elastic_wall"
    solver = next((m for m in registry.MODELS if m.name == model and m.needs_skfem), None)
    if solver is not None:
        from matcad.acoustics.fem import DEFAULT_LEVEL

        results[model] = solver.function()(spec, c, results[chosen].f0_hz, fem_level or DEFAULT_LEVEL)
    if spec.reference is not None:
        results["relative"] = _relative(spec, chosen, results[chosen])
        if model is None:
            chosen = "relative"
    if model is not None:
        if model not in results:
            raise ValueError(f"model {model!r} invalid, must be one of {sorted(results) + ['fem']}")
        chosen = model
    lines = budget(spec, res, chosen, results[chosen].f0_hz, results[chosen].valid)
    low, high = total(lines, results[chosen].f0_hz)

    warnings = _model_warnings(chosen, results[chosen], xi)
    eps = float(boundary_layer_shift(results[chosen].f0_hz, neck.diameter / 2))
    if eps > VISCOUS_REGIME_EPS:
        warnings.append(f"{chosen}: the {neck.diameter:g} mm neck is so narrow that boundary layers fill it "
                        f"(Kirchhoff eps = {eps:.2f}): viscous flow, heavy damping, it may not sing at all")
    elif eps > BOUNDARY_LAYER_WARN:
        warnings.append(f"{chosen}: viscous/thermal boundary layers in this {neck.diameter:g} mm neck lower f by "
                        f"~{100 * boundary_layer_drop(results[chosen].f0_hz, neck.diameter / 2):.1f} %, which the "
                        "lossless models leave out (the band includes it)")
    if spec.reference is None:
        warnings += _paper_anchor(spec, chosen, results[chosen].f0_hz, results[chosen].f0_hz + low)
    cal = spec_calibration(spec)
    curve: tuple[LoadPoint, ...] = ()
    load_model = None
    if len(forces_n):
        if cal is not None:
            f_at = frequency_at_force_hz(cal, np.asarray(forces_n, dtype=float), c, neck.diameter, neck.length)
            curve = tuple(LoadPoint(float(force), None if np.isnan(f) else float(f), invalid_reason(cal, force),
                                    source=f"calibration {cal.name} (Eq. 5)") for force, f in zip(forces_n, f_at))
            if cal.area_convention == MAT_PAPER_2024.area_convention:
                warnings.append("load curve uses the paper's A = d^2/4 convention with its fitted V0 (see docs/paper.md); "
                                "its volumes are not physical cavity volumes")
    if len(forces_n) and mechanics:
        from matcad.mechanics.frequency import load_points

        # the FEM route on the deformed outlines when the FEM is the chosen model (DEFAULT_LEVEL imported above)
        rows, load_model = load_points(spec, forces_n, results[chosen].f0_hz,
                                       (fem_level or DEFAULT_LEVEL) if chosen == "fem" else None)
        curve += tuple(LoadPoint(**row) for row in rows)
        if load_model["message"]:
            warnings.append(f"cap mechanics: {load_model['message']}")
    f0 = results[chosen].f0_hz
    return Prediction(
        cavity_volume_mm3=res.volume, neck_area_mm2=res.neck_area, cavity_area_mm2=res.cavity_area,
        neck_air_ratio=air_ratio, diameter_ratio=xi, speed_of_sound_m_s=c,
        outer_end_correction_mm=res.outer_correction, inner_end_correction_mm=res.inner_step, models=results,
        model=chosen, f0_hz=f0, band_hz=(f0 + low, f0 + high), budget=tuple(lines), warnings=tuple(warnings),
        calibration=None if cal is None else f"{cal.name} ({cal.area_convention})", load_curve=curve,
        load_model=load_model)
