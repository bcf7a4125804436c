"""Spec → every model's f0, the chosen f0 and band, validity flags and warnings (one result object).

Frequencies in Hz, lengths mm. The default model is the transmission line (rigid wall) or the transmission
line with the quasi-static silicone wall (``wall.model = "silicone"``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from matcad.acoustics import models
from matcad.acoustics.air import VISCOUS_REGIME_EPS, boundary_layer_drop, boundary_layer_shift
from matcad.acoustics.load import MAT_PAPER_2024, LoadCalibration, frequency_at_force_hz, invalid_reason
from matcad.acoustics.resonator import evaluate, resonator, shear_moduli_pa
from matcad.acoustics.uncertainty import BudgetLine, budget, total

PLANE_WAVE_CUTOFF_KA = 1.8412
"""First non-planar (1,1) mode of a circular duct cuts on at k·a = 1.8412 (zero of J1')."""
PANCAKE_L_OVER_D = 0.3
LUMPED_NECK_AIR_RATIO = 0.1
BOUNDARY_LAYER_WARN = 0.05
LUMPED_END_CORRECTION_RATIO = 0.1
"""Uncorrected Eq. 1 needs the neck's end corrections ≪ its length (they are 24 % of it on the paper taxel)."""


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
    """Eq. 5 at one force: f_hz is None and reason says why when the model has no meaning there."""

    force_n: float
    f_hz: float | None
    reason: str = ""


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
        "quasi_static_wall": f"{name}: f0 is above the silicone wall's breathing resonance; wall inertia "
                             "is not modelled and the true f may lie between the band and the rigid value",
    }
    return [text[check] for check, ok in result.checks.items() if not ok]


def _fem(spec, c_m_s: float, f_guess_hz: float, level: int, wall_checks: dict) -> ModelResult:
    """The FEM reference for this spec (rigid walls, or the silicone wall at the geometric-mean modulus, which
    shares the soft-wall model's quasi-static assumption and so its ``wall_checks``)."""
    from matcad.acoustics import fem

    k_guess = 2 * np.pi * f_guess_hz / (c_m_s * models.MM_PER_M)
    shear = shear_moduli_pa(spec)[1] if spec.wall.model == "silicone" else None
    run = fem.solve(fem.geometry_from_spec(spec, shear), k_guess, level, speed_of_sound_m_s=c_m_s)
    checks = {"mode_in_cavity": run.cavity_energy_fraction > 0.3, "fundamental_found": run.q > fem.MIN_Q,
              **wall_checks}
    return ModelResult(run.f0_hz, checks, f"axisymmetric P2 FEM (scikit-fem), level {run.level}, {run.dofs} "
                                          f"dofs, Q = {run.q:.1f}, {run.seconds:.2f} s")


def predict(spec, forces_n=(), model: str | None = None, fem_level: int | None = None) -> Prediction:
    """Predict the unloaded resonance of ``spec`` with every model; Eq. 5 at ``forces_n`` (N) if calibrated.

    ``model`` overrides the automatic choice: one of the returned ``models`` keys, or ``fem`` (elements
    across the neck radius ``fem_level``, default :data:`matcad.acoustics.fem.DEFAULT_LEVEL`).
    """
    neck = spec.neck
    res = resonator(spec)
    c, xi, air_ratio = res.c_m_s, res.diameter_ratio, res.neck_air_ratio
    lumped_ok = air_ratio < LUMPED_NECK_AIR_RATIO
    corrections_small = (res.outer_correction + res.inner_step) / res.neck_length < LUMPED_END_CORRECTION_RATIO
    results: dict[str, ModelResult] = {
        "lumped": ModelResult(float(evaluate(res, "lumped")),
                              {"neck_air_ratio_small": lumped_ok, "end_corrections_small": corrections_small},
                              "paper Eq. 1 with c_f = 0 (Helmholtz/Rayleigh)"),
        "end_corrected": ModelResult(
            float(evaluate(res, "end_corrected")),
            {"neck_air_ratio_small": lumped_ok, "ingard_xi_below_0.4": xi < models.INGARD_XI_LIMIT},
            f"Eq. 1 with l + {neck.mouth} outer correction + Ingard 1953 inner correction"),
    }
    f_tl = float(evaluate(res, "transmission_line"))
    results["transmission_line"] = ModelResult(
        f_tl, _checks_plane_wave(f_tl, c, res.cavity_diameter, res.cavity_length),
        "Selamet et al. 1997 transmission line, Kergomard & Garcia 1987 step correction")
    chosen = "transmission_line"
    if spec.wall.model == "silicone":
        shear = shear_moduli_pa(spec)[1]
        f_mid = float(evaluate(res, "soft_wall", shear))
        density = spec.silicone.density_g_cm3 * 1000.0
        breathing = float(models.wall_breathing_hz(shear, density, res.cavity_diameter, res.cap_outer_diameter))
        checks = (_checks_plane_wave(f_mid, c, res.cavity_diameter, res.cavity_length)
                  | {"quasi_static_wall": bool(f_mid < breathing)})
        results["soft_wall"] = ModelResult(
            f_mid, checks, f"transmission line with quasi-static silicone wall (Lame cylinder + half-space end) "
                           f"at G = {shear / 1e6:.3g} MPa, geometric mean of the spec's range")
        chosen = "soft_wall"
    if model == "fem":
        from matcad.acoustics.fem import DEFAULT_LEVEL

        wall_checks = {k: v for k, v in results[chosen].checks.items() if k == "quasi_static_wall"}
        results["fem"] = _fem(spec, c, results[chosen].f0_hz, fem_level or DEFAULT_LEVEL, wall_checks)
    if model is not None:
        if model not in results:
            raise ValueError(f"model {model!r} invalid, must be one of {sorted(results) + ['fem']}")
        chosen = model
    lines = budget(spec, res, chosen, results[chosen].f0_hz)
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
    cal = spec_calibration(spec)
    curve: tuple[LoadPoint, ...] = ()
    if len(forces_n):
        if cal is None:
            raise ValueError("--force needs a [calibration] table in the spec (paper Eq. 5 constants)")
        f_at = frequency_at_force_hz(cal, np.asarray(forces_n, dtype=float), c, neck.diameter, neck.length)
        curve = tuple(LoadPoint(float(force), None if np.isnan(f) else float(f), invalid_reason(cal, force))
                      for force, f in zip(forces_n, f_at))
        if cal.area_convention == MAT_PAPER_2024.area_convention:
            warnings.append("load curve uses the paper's A = d^2/4 convention with its fitted V0 (see docs/paper.md); "
                            "its volumes are not physical cavity volumes")
    f0 = results[chosen].f0_hz
    return Prediction(
        cavity_volume_mm3=res.volume, neck_area_mm2=res.neck_area, cavity_area_mm2=res.cavity_area,
        neck_air_ratio=air_ratio, diameter_ratio=xi, speed_of_sound_m_s=c,
        outer_end_correction_mm=res.outer_correction, inner_end_correction_mm=res.inner_step, models=results,
        model=chosen, f0_hz=f0, band_hz=(f0 + low, f0 + high), budget=tuple(lines), warnings=tuple(warnings),
        calibration=None if cal is None else f"{cal.name} ({cal.area_convention})", load_curve=curve)
