"""Uncertainty budget of a prediction: one line per source, combined root-sum-square into the band (Hz).

Sources: the chosen model's own error (measured against the converged FEM by benchmarks/error_vs_runtime.py, stored
in model_errors.json; an FEM whose checks fail reaches the cheap model it refines), fabrication (neck diameter as
cut or drilled, sheet thickness per ISO 7823-1 unless measured, printed cavity diameter, core-pin draft), air
temperature, viscous/thermal boundary layers (one-sided: every model here is lossless) and the silicone's kHz
modulus (static range × kHz factor) and loss factor. Each line re-evaluates the chosen model (or, for the FEM, the
cheap model it refines) with that one input moved to the ends of its tolerance; the silicone line samples the whole
modulus × loss rectangle, because f is not monotonic in G when wall modes cross f. Lines are independent, so lows
and highs add in quadrature separately, in ln f (relative shifts), which keeps a wide band above zero.

The budget works on a :class:`~matcad.acoustics.design.Design` of floats (one prediction, with its lines' words)
or of numpy arrays (a sweep's variants, every closed-form rung: the same numbers per variant, no words). Each
line's variants are evaluated together (the ten tolerance ends in one call, the wall's modulus samples in another):
each entry is the same arithmetic as its variant alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matcad.acoustics import registry
from matcad.acoustics.air import boundary_layer_shift
from matcad.acoustics.resonator import resonator

NECK_DIAMETER_TOL_MM = {"laser": 0.1, "drilled": 0.02}
"""Laser-cut acrylic holds ±0.1 mm (docs/physics.md); a pilot drilled to size ±0.02 mm."""
MEASURED_SHEET_TOL_MM = 0.05
"""A calipered sheet."""
CAVITY_DIAMETER_TOL_MM = {"fdm": 0.1, "sla": 0.05}
DRAFT_TOL_DEG = 0.25
TEMPERATURE_TOL_C = 3.0
"""A lab's day-to-day swing; an explicit speed of sound is taken as exact."""
MODULUS_SAMPLES = 13
"""Log-spaced moduli across the silicone's range (each at the low and the high loss factor)."""
TOLERANCES = {"neck.diameter": "neck_diameter", "neck.length": "neck_length", "cavity.diameter": "cavity_diameter",
              "mold.draft_deg": "draft_deg", "air.temperature_c": "air_temperature_c"}
"""Spec field of each fabrication and air tolerance → the :class:`Design` field it moves."""


@dataclass(frozen=True)
class BudgetLine:
    """One source: what varies, by how much, and the f shift at each end (Hz, low ≤ 0 ≤ high; arrays of variants
    in a sweep, where ``tolerance`` is empty)."""

    source: str
    tolerance: str
    low_hz: float
    high_hz: float


def sheet_tolerance_mm(thickness_mm, measured: bool):
    """± thickness tolerance of an acrylic sheet (mm): a calipered sheet :data:`MEASURED_SHEET_TOL_MM`, else cast
    sheet per ISO 7823-1, ±(0.4 + 0.1 t)."""
    return MEASURED_SHEET_TOL_MM if measured else 0.4 + 0.1 * thickness_mm


def fabrication_tolerances(making, neck_length_mm) -> tuple:
    """(neck diameter, sheet thickness, cavity diameter) tolerances (± mm) of how a taxel is made
    (:class:`~matcad.acoustics.design.Making`; its fields may be arrays of variants, each its own). A neck through
    the plate and a riser (``making.riser_mm`` of it) has both sheets' tolerances added: sheets of one batch may err
    the same way."""
    if np.ndim(making.neck_drilled) == 0:
        riser = sheet_tolerance_mm(making.riser_mm, making.riser_measured) if making.riser_mm else 0.0
        return (NECK_DIAMETER_TOL_MM["drilled" if making.neck_drilled else "laser"],
                sheet_tolerance_mm(neck_length_mm - making.riser_mm, making.sheet_measured) + riser,
                CAVITY_DIAMETER_TOL_MM[making.printer])
    return (np.where(making.neck_drilled, NECK_DIAMETER_TOL_MM["drilled"], NECK_DIAMETER_TOL_MM["laser"]),
            np.where(making.sheet_measured, MEASURED_SHEET_TOL_MM, sheet_tolerance_mm(neck_length_mm, False)),
            np.array([CAVITY_DIAMETER_TOL_MM[p] for p in making.printer]))


def tolerance_ends(neck_diameter, neck_length, cavity_diameter, cavity_length, draft_deg, temperature_c,
                   neck_diameter_tol, sheet_tol, cavity_diameter_tol) -> dict[str, tuple]:
    """The two ends of each fabrication and air tolerance, clamped to stay physical (mm, deg, °C; scalars or
    arrays of variants): {dotted field: (low end, high end)}. A neck smaller than its tolerance is a
    design-rule matter, so here it may at most halve; a sheet keeps 5 % of its thickness; the cavity stays at
    least the neck; draft stays within [0, 99 % of what closes the cavity]; air stays above -273 °C."""
    d, t, big_d = neck_diameter, neck_length, cavity_diameter
    max_draft = np.degrees(np.arctan(big_d / (2 * cavity_length))) * 0.99
    return {
        "neck.diameter": (np.maximum(d - neck_diameter_tol, d / 2), np.minimum(d + neck_diameter_tol, big_d)),
        "neck.length": (np.maximum(t - sheet_tol, 0.05 * t), t + sheet_tol),
        "cavity.diameter": (np.maximum(big_d - cavity_diameter_tol, d), big_d + cavity_diameter_tol),
        "mold.draft_deg": (np.maximum(draft_deg - DRAFT_TOL_DEG, 0.0), np.minimum(draft_deg + DRAFT_TOL_DEG,
                                                                                  max_draft)),
        "air.temperature_c": (np.maximum(temperature_c - TEMPERATURE_TOL_C, -273.0),
                              temperature_c + TEMPERATURE_TOL_C),
    }


def model_error_share(error: dict, valid):
    """The model's relative error for the band: its max |error| over the benchmark geometries where its checks
    pass, or over all of them where ``valid`` (bool or array) is False."""
    return np.where(valid, error["max_abs"], error.get("max_abs_all", error["max_abs"]))


def _ends(shifts, array: bool):
    """(low, high) of the shifts of one line, 0 included (Hz)."""
    if array:
        return _fold(list(shifts) + [0.0], np.less), _fold(list(shifts) + [0.0], np.greater)
    return min(shifts + [0.0]), max(shifts + [0.0])


def _fold(values, better):
    """Python's ``min`` (``better`` np.less) or ``max`` (np.greater) of ``values`` entry by entry on arrays: the
    first value replaced by each later one that is better, so a NaN is kept only where it comes first (a tolerance
    end outside the model's domain drops out exactly as in one prediction)."""
    out = np.asarray(values[0], dtype=float)
    for value in values[1:]:
        out = np.where(better(value, out), value, out)
    return out


def budget(d, res, model: str, f0_hz, valid=True, reference=None) -> list[BudgetLine]:
    """Every source's contribution for ``model`` at ``f0_hz`` (Hz) on design ``d`` (``res`` its resonator);
    ``valid`` False (the model's own checks fail) takes its error over every benchmark case, not only the valid
    ones, and for the FEM (a failed check: the mode it solved may not be the taxel's) reaches the cheap rung's f0;
    ``reference`` is the measured :class:`~matcad.acoustics.design.Reference` of the 'relative' model."""
    array = np.ndim(f0_hz) > 0
    cheap = registry.model(model if model in registry.cheap_models() else registry.CHOSEN[d.wall.model])
    relative = model == "relative"
    shear, loss = cheap.wall_arguments(d.wall)
    # the cheap model's sensitivities, applied to the chosen f0 (the same model: a factor of exactly 1)
    scale = 1.0 if cheap.name == model else f0_hz / float(cheap.f0_hz(res, shear_modulus_pa=shear, loss_factor=loss))

    def shifts(fs):
        return _ends([(f if array else float(f)) * scale - f0_hz for f in fs], array)

    def words(text) -> str:
        return "" if array else text()

    lines = []
    error = registry.model_errors().get(cheap.name if relative else model)
    if relative:
        share = error["ratio_max_abs"] if valid else error.get("ratio_max_abs_all", error["ratio_max_abs"])
        lines.append(BudgetLine("model ratio", f"{cheap.name}: max |error| of new/reference {100 * share:.2f} % vs "
                                               f"FEM over designs near the paper taxel"
                                               f"{'' if valid else ', checks failing included'}",
                                -share * f0_hz, share * f0_hz))
        ref = reference
        lines.append(BudgetLine("reference measurement", f"{ref.f0_hz:g} +-{ref.f0_tolerance_hz:g} Hz",
                                -ref.f0_tolerance_hz / ref.f0_hz * f0_hz, ref.f0_tolerance_hz / ref.f0_hz * f0_hz))
    elif error is None:  # only before benchmarks/error_vs_runtime.py has measured a new rung
        lines.append(BudgetLine("model", f"{model}: error not measured yet (run benchmarks/error_vs_runtime.py)",
                                0.0, 0.0))
    else:
        share = model_error_share(error, valid)
        worst = share if array else float(share)
        cases, where = error["cases"], "geometries where its checks pass"
        if not array and not valid and "max_abs_all" in error:
            cases, where = error["of"], "geometries, checks failing included"
        low, high = -worst * f0_hz, worst * f0_hz
        told = words(lambda: f"{model}: max |error| {100 * worst:.2f} % vs FEM over {cases} {where}")
        if not array and not valid and cheap.name != model:  # a mesh rung's failed check: maybe not the taxel's mode
            f_cheap = f0_hz / scale
            low, high = min(low, f_cheap - f0_hz), max(high, f_cheap - f0_hz)
            told = (f"{model}: its checks fail, so the mode it solved may not be the taxel's: the band reaches "
                    f"{cheap.name}'s {f_cheap:.0f} Hz")
        lines.append(BudgetLine("model", told, low, high))
    making = d.making
    drilled = making.neck_drilled
    d_tol, sheet_tol, cav_tol = fabrication_tolerances(making, d.neck_length)
    ends = tolerance_ends(d.neck_diameter, d.neck_length, d.cavity_diameter, d.cavity_length, d.draft_deg,
                          d.air.temperature_c, d_tol, sheet_tol, cav_tol)

    moved_f0 = _moved_f0(cheap, d, ends, shear, loss)

    def moved(field):
        return shifts(moved_f0[field])

    what = "" if array else "measured" if making.sheet_measured else "ISO 7823-1 cast sheet"
    if not array and making.riser_mm:
        riser = "measured" if making.riser_measured else "ISO 7823-1 cast sheet"
        what = f"plate {what} + {making.riser_mm:g} mm riser {riser}"
    lines += [BudgetLine("neck diameter", words(lambda: f"+-{d_tol:g} mm ({'drilled' if drilled else 'laser cut'})"),
                         *moved("neck.diameter")),
              BudgetLine("neck length (sheet)", words(lambda: f"+-{sheet_tol:.3g} mm ({what})"), *moved("neck.length")),
              BudgetLine("cavity diameter (core pin)", words(lambda: f"+-{cav_tol:g} mm ({making.printer})"),
                         *moved("cavity.diameter")),
              BudgetLine("core-pin draft", words(lambda: f"{d.draft_deg:g} +-{DRAFT_TOL_DEG:g} deg"),
                         *moved("mold.draft_deg"))]
    given = d.air.speed_of_sound_m_s
    if array:  # a variant with an explicit speed of sound has no temperature line
        by_temperature = np.isnan(np.asarray(np.nan if given is None else given, dtype=float))
        low, high = moved("air.temperature_c")
        lines.append(BudgetLine("air temperature", "", np.where(by_temperature, low, 0.0),
                                np.where(by_temperature, high, 0.0)))
    elif given is None:
        lines.append(BudgetLine("air temperature", f"{d.air.temperature_c:g} +-{TEMPERATURE_TOL_C:g} C",
                                *moved("air.temperature_c")))
    eps = boundary_layer_shift(f0_hz, d.neck_diameter / 2)
    eps = eps if array else float(eps)
    drop = eps / (1.0 + eps)
    lines.append(BudgetLine("boundary layers", words(lambda: f"viscous + thermal, not in the lossless models: "
                                                             f"-{100 * drop:.1f} %"), -drop * f0_hz, 0.0))
    if cheap.name == "soft_wall":
        g_lo, _, g_hi = d.wall.static_moduli_pa()
        fs = _sampled_f0(cheap, res, np.array([g_lo, g_hi]), np.zeros(2), array) * scale - f0_hz
        lines.append(BudgetLine("silicone shear modulus", words(lambda: f"{g_lo / 1e6:g}-{g_hi / 1e6:g} MPa static"),
                                *_sample_ends(fs, array)))
    elif cheap.name == "elastic_wall":
        g_lo, _, g_hi = d.wall.dynamic_moduli_pa()
        eta_lo, _, eta_hi = d.wall.loss_factors()
        moduli = np.repeat(np.geomspace(g_lo, g_hi, MODULUS_SAMPLES), 2)
        losses = np.tile([eta_lo, eta_hi], MODULUS_SAMPLES)
        static, factor = d.wall.shear_modulus_mpa, d.wall.khz_modulus_factor
        what = "" if not relative else " on the ratio to the reference (one silicone for both)"
        if relative:  # the reference was measured at the true modulus: what varies is the ratio (one design)
            ref_res = resonator(reference.design)
            ratios = (_sampled_f0(cheap, res, moduli, losses, array)
                      / _sampled_f0(cheap, ref_res, moduli, losses, array))
            fs = ratios * f0_hz / (float(cheap.f0_hz(res, shear_modulus_pa=shear, loss_factor=loss))
                                   / float(cheap.f0_hz(ref_res, shear_modulus_pa=shear, loss_factor=loss))) - f0_hz
        else:
            fs = _sampled_f0(cheap, res, moduli, losses, array) * scale - f0_hz
        lines.append(BudgetLine("silicone modulus and loss",
                                words(lambda: f"G {g_lo / 1e6:.3g}-{g_hi / 1e6:.3g} MPa at kHz (static {static[0]:g}-"
                                              f"{static[1]:g} x {factor[0]:g}-{factor[1]:g}), eta {eta_lo:g}-{eta_hi:g}"
                                              f"{what}"),
                                *_sample_ends(fs, array)))
        if relative:
            lines += reference_doublet(reference, cheap, f0_hz)
    return lines


def reference_doublet(reference, cheap, f0_hz: float) -> list[BudgetLine]:
    """When the reference taxel's own cavity peaks twice (a cap mode near its f: a doublet, >= -6 dB), its measured
    tone may be either peak: the ratio to the other one as a budget line (Hz), else nothing."""
    from matcad.acoustics.resonator import elastic_wall_doublet_hz

    ref = reference.design
    shear, loss = cheap.wall_arguments(ref.wall)
    res = resonator(ref)
    other = elastic_wall_doublet_hz(res, shear, loss)
    if other is None:
        return []
    f_ref = float(cheap.f0_hz(res, shear_modulus_pa=shear, loss_factor=loss))
    shift = f0_hz * (f_ref / other - 1.0)
    return [BudgetLine("reference doublet", f"the reference's cavity also peaks at {other:.0f} Hz (its model f "
                                            f"{f_ref:.0f} Hz): its measured tone may be that peak",
                       min(shift, 0.0), max(shift, 0.0))]


def _moved_f0(cheap, d, ends: dict, shear, loss) -> dict:
    """f0 (Hz) of ``cheap`` with each tolerance at each of its ends, all in one evaluation of the model: a design
    whose moved fields carry a leading axis of 2 × 5 variants (each row the same arithmetic as that variant
    alone). {dotted field: (f at the low end, f at the high end)}, floats or arrays of the design's variants."""
    count = 2 * len(TOLERANCES)
    base = {name: getattr(d, name) for name in TOLERANCES.values() if name != "air_temperature_c"}
    base["air_temperature_c"] = d.air.temperature_c
    columns = {name: np.array(np.broadcast_to(value, (count,) + np.shape(value)), dtype=float)
               for name, value in base.items()}
    for j, (field, name) in enumerate(TOLERANCES.items()):
        for end, value in enumerate(ends[field]):
            columns[name][2 * j + end] = value
    f = cheap.f0_hz(resonator(d.replace(**columns)), shear_modulus_pa=shear, loss_factor=loss)
    return {field: (f[2 * j], f[2 * j + 1]) for j, field in enumerate(TOLERANCES)}


def _sampled_f0(cheap, res, moduli, losses, array: bool) -> np.ndarray:
    """f0 (Hz) of a wall model at each (modulus Pa, loss factor) sample: (samples,) for one design, (samples,
    variants) for a sweep's, in one evaluation (the samples a leading axis: the rigid peak and the transmission
    line, which do not depend on them, computed once)."""
    from matcad.acoustics.wall import SELECT_LOSS

    if np.min(losses) >= SELECT_LOSS:
        shape = (-1, 1) if array else (-1,)
        return np.asarray(cheap.f0_hz(res, shear_modulus_pa=np.reshape(moduli, shape),
                                      loss_factor=np.reshape(losses, shape)), dtype=float)
    # a loss below SELECT_LOSS (one design: its Helmholtz branch is followed down the losses)
    return np.array([cheap.f0_hz(res, shear_modulus_pa=float(g), loss_factor=float(eta)) if not array else
                     cheap.f0_hz(res, shear_modulus_pa=g, loss_factor=eta) for g, eta in zip(moduli, losses)])


def _sample_ends(shifts: np.ndarray, array: bool) -> tuple:
    """(low, high) of a line sampled over the silicone's range, 0 included (Hz): floats, or arrays of variants."""
    low, high = _fold(list(shifts) + [0.0], np.less), _fold(list(shifts) + [0.0], np.greater)
    return (low, high) if array else (float(low), float(high))


def total(lines: list[BudgetLine], f0_hz: float) -> tuple[float, float]:
    """Lows and highs combined root-sum-square in ln f, as offsets from ``f0_hz`` (Hz): the same as a plain
    root-sum-square of small shifts, and never below zero frequency when shifts are large."""
    low, high = combine([x.low_hz for x in lines], [x.high_hz for x in lines], f0_hz)
    return float(low), float(high)


def combine(lows, highs, f0_hz):
    """:func:`total` on shifts that may be arrays of variants (Hz): (low, high) offsets from ``f0_hz``."""
    def rss(shifts):  # a shift of -f0 (a band reaching 0 Hz) is ln 0 = -inf: the band's low end is then 0 Hz
        with np.errstate(divide="ignore"):
            return np.sqrt(sum(np.log1p(np.asarray(x) / f0_hz) ** 2 for x in shifts))

    return f0_hz * np.expm1(-rss(lows)), f0_hz * np.expm1(rss(highs))
