"""Spec → every model's f0, the chosen f0 and band, validity flags and warnings (one result object).

Frequencies in Hz, lengths mm. The default model is the transmission line (rigid wall) or the transmission
line with the quasi-static silicone wall (``wall.model = "silicone"``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from matcad.acoustics import geometry, models
from matcad.acoustics.air import speed_of_sound_m_s
from matcad.acoustics.load import MAT_PAPER_2024, LoadCalibration, frequency_at_force_hz, invalid_reason

MODEL_ERROR = 0.03
"""Relative model-error allowance on the chosen f0 (±3 %): the DIGEST's viscous boundary-layer shift (~−2 %)
plus the mount correction's roughness; to be replaced by the error measured against the FEM reference."""
PLANE_WAVE_CUTOFF_KA = 1.8412
"""First non-planar (1,1) mode of a circular duct cuts on at k·a = 1.8412 (zero of J1')."""
PANCAKE_L_OVER_D = 0.3
LUMPED_NECK_AIR_RATIO = 0.1


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
    if values == (paper.v0_mm3, paper.a, paper.b, paper.area_convention):
        return paper
    return LoadCalibration(*values, name="spec")


def _checks_plane_wave(f_hz, c_m_s, cavity_diameter_mm, cavity_length_mm) -> dict[str, bool]:
    k = 2 * np.pi * f_hz / (c_m_s * models.MM_PER_M)
    return {"plane_waves_in_cavity": bool(k * cavity_diameter_mm / 2 < PLANE_WAVE_CUTOFF_KA),
            "not_pancake": bool(cavity_length_mm / cavity_diameter_mm >= PANCAKE_L_OVER_D)}


def _model_warnings(name: str, result: ModelResult, diameter_ratio: float) -> list[str]:
    text = {
        "neck_air_ratio_small": f"{name}: neck holds much air relative to the cavity (A*l/V >= "
                                f"{LUMPED_NECK_AIR_RATIO}); lumped neck assumption fails",
        "ingard_xi_below_0.4": f"{name}: Ingard's inner correction used at xi = {diameter_ratio:.3g}, outside "
                               f"its stated xi < {models.INGARD_XI_LIMIT}",
        "plane_waves_in_cavity": f"{name}: cavity wider than the plane-wave limit at f0 (k*D/2 >= "
                                 f"{PLANE_WAVE_CUTOFF_KA}); 1-D model unreliable",
        "not_pancake": f"{name}: flat cavity (L/D < {PANCAKE_L_OVER_D}); radial modes add a few percent error",
        "quasi_static_wall": f"{name}: f0 is above the silicone wall's breathing resonance; wall inertia "
                             "is not modelled and the true f may lie between the band and the rigid value",
    }
    return [text[check] for check, ok in result.checks.items() if not ok]


def _fem(spec, c_m_s: float, f_guess_hz: float) -> tuple[ModelResult, tuple[float, float]]:
    """The FEM reference for this spec (rigid, or at the shear-modulus range's ends and geometric mean)."""
    from matcad.acoustics import fem

    k_guess = 2 * np.pi * f_guess_hz / (c_m_s * models.MM_PER_M)
    if spec.wall.model == "silicone":
        g_lo, g_hi = (x * 1e6 for x in spec.wall.shear_modulus_mpa)
        shears = [np.sqrt(g_lo * g_hi), g_lo, g_hi]
    else:
        shears = [None]
    runs = [fem.solve(fem.geometry_from_spec(spec, g), k_guess, speed_of_sound_m_s=c_m_s) for g in shears]
    mid = runs[0]
    checks = {"mode_in_cavity": mid.cavity_energy_fraction > 0.3, "fundamental_found": mid.q > fem.MIN_Q}
    source = (f"axisymmetric P2 FEM (scikit-fem), level {mid.level}, {mid.dofs} dofs, Q = {mid.q:.1f}, "
              f"{sum(r.seconds for r in runs):.2f} s")
    band = (runs[1].f0_hz, runs[2].f0_hz) if len(runs) == 3 else (mid.f0_hz, mid.f0_hz)
    return ModelResult(mid.f0_hz, checks, source), band


def predict(spec, forces_n=(), model: str | None = None) -> Prediction:
    """Predict the unloaded resonance of ``spec`` with every model; Eq. 5 at ``forces_n`` (N) if calibrated.

    ``model`` overrides the automatic choice (one of the returned ``models`` keys).
    """
    cav, neck = spec.cavity, spec.neck
    c = float(spec.air.speed_of_sound or speed_of_sound_m_s(spec.air.temperature_c))
    # as cast: core-pin draft narrows the cavity; the 1-D models see the equal-volume cylinder
    volume = float(geometry.drafted_cavity_volume_mm3(cav.diameter, cav.length, spec.mold.draft_deg))
    cav_diameter = float(geometry.equivalent_diameter_mm(volume, cav.length))
    area = float(geometry.neck_area_mm2(neck.diameter))
    cav_area = float(geometry.circle_area_mm2(cav_diameter))
    xi = float(geometry.diameter_ratio(neck.diameter, cav_diameter))
    air_ratio = area * neck.length / volume
    gap_radius = min(spec.plate.width, spec.plate.depth) / 2.0
    outer = float(models.mouth_end_correction_mm(neck.mouth, neck.diameter / 2, spec.spacer.height, gap_radius))
    inner_ingard = float(models.ingard_end_correction_mm(neck.diameter, cav_diameter))
    inner_step = float(models.step_end_correction_mm(neck.diameter, cav_diameter))
    neck_eff = neck.length + outer + inner_step

    lumped_ok = air_ratio < LUMPED_NECK_AIR_RATIO
    results: dict[str, ModelResult] = {
        "lumped": ModelResult(float(models.lumped_hz(c, area, volume, neck.length)),
                              {"neck_air_ratio_small": lumped_ok},
                              "paper Eq. 1 with c_f = 0 (Helmholtz/Rayleigh)"),
        "end_corrected": ModelResult(
            float(models.end_corrected_hz(c, area, volume, neck.length + outer + inner_ingard)),
            {"neck_air_ratio_small": lumped_ok, "ingard_xi_below_0.4": xi < models.INGARD_XI_LIMIT},
            f"Eq. 1 with l + {neck.mouth} outer correction + Ingard 1953 inner correction"),
    }
    f_tl = float(models.transmission_line_hz(c, area, cav_area, neck_eff, cav.length))
    results["transmission_line"] = ModelResult(
        f_tl, _checks_plane_wave(f_tl, c, cav_diameter, cav.length),
        "Selamet et al. 1997 transmission line, Kergomard & Garcia 1987 step correction")
    chosen = "transmission_line"
    band_model = (f_tl, f_tl)

    if spec.wall.model == "silicone":
        g_lo, g_hi = (x * 1e6 for x in spec.wall.shear_modulus_mpa)
        shear = np.array([g_lo, np.sqrt(g_lo * g_hi), g_hi])
        n, extra = models.soft_wall_length_scale(shear, cav_diameter, spec.end_cap.outer_diameter)
        f_lo, f_mid, f_hi = models.transmission_line_hz(c, area, cav_area, neck_eff, cav.length, n, extra)
        density = spec.silicone.density_g_cm3 * 1000.0
        breathing = float(models.wall_breathing_hz(shear[1], density, cav_diameter, spec.end_cap.outer_diameter))
        checks = (_checks_plane_wave(f_mid, c, cav_diameter, cav.length)
                  | {"quasi_static_wall": bool(f_mid < breathing)})
        results["soft_wall"] = ModelResult(
            float(f_mid), checks,
            f"transmission line with quasi-static silicone wall (Lame cylinder + half-space end) at "
            f"G = {shear[1] / 1e6:.3g} MPa, geometric mean of the spec's range")
        chosen = "soft_wall"
        band_model = (float(f_lo), float(f_hi))

    if model == "fem":
        results["fem"], band_model = _fem(spec, c, results[chosen].f0_hz)
    if model is not None:
        if model not in results:
            raise ValueError(f"model {model!r} invalid, must be one of {sorted(results) + ['fem']}")
        chosen = model
        band_model = band_model if model in ("soft_wall", "fem") else (results[model].f0_hz,) * 2

    warnings = _model_warnings(chosen, results[chosen], xi)
    cal = spec_calibration(spec)
    curve: tuple[LoadPoint, ...] = ()
    if len(forces_n):
        if cal is None:
            raise ValueError("--force needs a [calibration] table in the spec (paper Eq. 5 constants)")
        f_at = frequency_at_force_hz(cal, np.asarray(forces_n, dtype=float), c, neck.diameter, neck.length)
        curve = tuple(LoadPoint(float(force), None if np.isnan(f) else float(f), invalid_reason(cal, force))
                      for force, f in zip(forces_n, f_at))
        if cal.area_convention == MAT_PAPER_2024.area_convention:
            warnings.append("load curve uses the paper's A = d^2/4 convention with its fitted V0 (see DIGEST); "
                            "its volumes are not physical cavity volumes")
    return Prediction(
        cavity_volume_mm3=volume, neck_area_mm2=area, cavity_area_mm2=cav_area, neck_air_ratio=air_ratio,
        diameter_ratio=xi, speed_of_sound_m_s=c, outer_end_correction_mm=outer,
        inner_end_correction_mm=inner_step, models=results, model=chosen, f0_hz=results[chosen].f0_hz,
        band_hz=(band_model[0] * (1 - MODEL_ERROR), band_model[1] * (1 + MODEL_ERROR)),
        warnings=tuple(warnings), calibration=None if cal is None else f"{cal.name} ({cal.area_convention})",
        load_curve=curve)
