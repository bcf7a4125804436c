"""Measured beats modelled: a taxel's headline f0 and band anchored to what was measured, wherever something was.
Frequencies Hz, lengths mm.

Anchors, in the order they win (docs/inference.md):

- ``calibration`` — the taxel's own [calibration] (a board taxel's [taxel.calibration]): its Eq. 5 f(0) at the
  air's temperature, with the fit's uncertainty; a design varied from the calibrated one moves by the physics
  ratio (this design / the calibrated one);
- ``as_built`` — the lab state inferred from [[measured]] taxels (and a [reference]) by
  :mod:`matcad.prediction.inference`: the physics on this design built in that state, with the inference's
  uncertainty;
- ``relative`` — a [reference] alone: its measured f0 times the physics ratio
  (:mod:`matcad.acoustics.predict`, where it is one of the ladder's results).

An anchor is made once from the spec as loaded (:func:`anchor`) and then answers for that spec and for designs
varied from it (a design search, a sweep) with :meth:`Anchor.f0_hz` (the number alone, milliseconds) or
:meth:`Anchor.anchored` (with its band and budget lines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

from matcad.acoustics.uncertainty import TEMPERATURE_TOL_C, BudgetLine, total
from matcad.spec import calibrated_spec

CALIBRATION_F0_SD = 0.01
"""Relative sd of a calibration's f(0) that carries no covariance (the paper's constants: it reports "~4.0 kHz")."""
Z95 = 1.959963984540054
"""Standard normal quantile of a 95 % two-sided band."""


@dataclass(frozen=True)
class Anchored:
    """A design's anchored f0 (Hz), its band (Hz) and budget lines, the anchor's name and what it rests on."""

    name: str
    f0_hz: float
    band_hz: tuple[float, float]
    lines: tuple[BudgetLine, ...]
    note: str


def _physics_hz(spec) -> float:
    """f0 (Hz) of the single-taxel ``spec`` by the registry's chosen closed-form model for its wall."""
    from matcad.acoustics import registry
    from matcad.acoustics.design import design
    from matcad.acoustics.resonator import resonator

    d = design(spec)
    return float(registry.model(registry.CHOSEN[d.wall.model]).f0_hz(resonator(d), d.wall))


def _temperature_line(spec, f0_hz: float) -> list[BudgetLine]:
    """The air temperature of use, ±:data:`TEMPERATURE_TOL_C` (f ∝ sqrt(T)), unless the speed of sound is given."""
    if spec.air.speed_of_sound is not None:
        return []
    kelvin = spec.air.temperature_c + 273.15
    low, high = (f0_hz * (math.sqrt(max(kelvin + s * TEMPERATURE_TOL_C, 0.0) / kelvin) - 1) for s in (-1, 1))
    return [BudgetLine("air temperature", f"{spec.air.temperature_c:g} +-{TEMPERATURE_TOL_C:g} C", low, high)]


class CalibrationAnchor:
    """The calibrated taxel's Eq. 5 f(0) (:func:`matcad.acoustics.design.calibration`) at the spec's air."""

    name = "calibration"

    def __init__(self, spec):
        from matcad.acoustics.design import calibration, design

        self.spec = spec
        measured = calibrated_spec(spec)  # the same for every design varied from the calibrated spec
        d = design(measured)
        cal = calibration(measured, d)
        self.cal = cal
        f = float(cal.frequency_hz(0.0))
        if not math.isfinite(f):  # an Eq. 5 with no unloaded state cannot anchor anything
            from matcad.spec import SpecError

            raise SpecError("calibration", f"v0_mm3 = {cal.v0_mm3:g}, a = {cal.a:g}, b = {cal.b:g}",
                            f"gives no f(0) to anchor the prediction to: {cal.invalid_reason(0.0) or 'f(0) undefined'}")
        if spec.calibration.k_mm3_hz2 is not None and cal.temperature_c is not None:
            f *= math.sqrt((d.air.temperature_c + 273.15) / (cal.temperature_c + 273.15))
        self.f_cal = f
        variance = (cal.cov[0, 0] if cal.covariance is not None else 0.0) + (cal.residual_std_mm3 or 0.0) ** 2 \
            + cal.cycle_std_mm3 ** 2
        self.sd = 0.5 * math.sqrt(variance) / cal.v0_mm3 if variance > 0 else CALIBRATION_F0_SD
        self.calibrated = measured  # the calibrated taxel's own spec

    @cached_property
    def physics(self) -> float:
        """The calibrated taxel's physics f0 (Hz), computed for the first design varied from it: the calibrated
        taxel itself has a ratio of exactly 1 and needs none."""
        return _physics_hz(self.calibrated)

    def ratio(self, spec) -> float:
        """This design's physics f0 over the calibrated taxel's (1 exactly when ``spec`` draws the calibrated
        taxel)."""
        return 1.0 if self.same(spec) else _physics_hz(spec) / self.physics

    def same(self, spec) -> bool:
        """Whether ``spec`` draws the calibrated taxel (its geometry equals the calibration's drawing)."""
        return calibrated_spec(spec) == spec

    def f0_hz(self, spec) -> float:
        return self.f_cal * self.ratio(spec)

    def anchored(self, spec) -> Anchored:
        f0 = self.f0_hz(spec)
        half = Z95 * self.sd * f0
        lines = [BudgetLine("calibration f(0)", f"{self.cal.name}: Eq. 5 at F = 0, {100 * self.sd:.2g} % (1 sd)"
                                                + ("" if self.cal.covariance is not None else ", no covariance given"),
                            -half, half)]
        if not self.same(spec):
            lines.append(_ratio_line(spec, f0))
        lines += _temperature_line(spec, f0)
        low, high = total(lines, f0)
        return Anchored(self.name, f0, (f0 + low, f0 + high), tuple(lines),
                        f"[calibration] {self.cal.name}: Eq. 5 f(0) = {self.f_cal:.0f} Hz"
                        + ("" if self.same(spec) else f" x physics ratio {f0 / self.f_cal:.4f}"))


def ratio_share(spec) -> float:
    """The chosen model's largest relative error on a ratio between two designs (benchmarks/error_vs_runtime.py)."""
    from matcad.acoustics.registry import CHOSEN, model_errors

    error = model_errors()[CHOSEN[spec.wall.model]]
    return error.get("ratio_max_abs", error["max_abs"])


def _ratio_line(spec, f0_hz: float) -> BudgetLine:
    """The chosen model's error on a ratio between two designs, as a budget line (Hz)."""
    from matcad.acoustics.registry import CHOSEN

    share = ratio_share(spec)
    return BudgetLine("model ratio", f"{CHOSEN[spec.wall.model]}: max |error| of new/calibrated {100 * share:.2f} %",
                      -share * f0_hz, share * f0_hz)


class AsBuiltAnchor:
    """The lab state inferred from the measured taxels (:func:`matcad.prediction.inference.infer`)."""

    name = "as_built"

    def __init__(self, spec):
        from matcad.prediction.inference import infer

        self.inference = infer(spec)
        self.level = float(self.inference.level_factors([self.inference.z])[0])

    def f0_hz(self, spec) -> float:
        """The model on ``spec`` built in the most probable state times that state's level factor (Hz;
        milliseconds): what a design search solves with; :meth:`anchored` gives the posterior median, the same to a
        fraction of its band away from a doublet."""
        from matcad.acoustics.design import design
        from matcad.prediction.measurements import f0_hz

        return f0_hz(design(spec), self.inference.state, self.inference.model) * self.level

    def anchored(self, spec) -> Anchored:
        p = self.inference.predict(spec)
        f0 = p.f0_hz
        names = ", ".join(t.name for t in self.inference.taxels)
        state = (BudgetLine("measured", f"this drawing was measured ({', '.join(p.measured)}): its f0 +-1.96 sd",
                            p.state_low_hz, p.state_high_hz) if p.measured else
                 BudgetLine("as-built state", f"inferred from {len(self.inference.taxels)} measured taxel(s) "
                                              f"({names}), {self.inference.data_count} data: 95 % of its states",
                            p.state_low_hz, p.state_high_hz))
        lines = [state,
                 BudgetLine("part to part", "one laser's neck holes +-0.03 mm (1 sd)", -Z95 * p.part_sd_hz,
                            Z95 * p.part_sd_hz)]
        if p.model_sd_hz > 0:  # none for a drawing that was measured
            lines.insert(1, BudgetLine("model", f"{p.model} on the built design: max |error| vs FEM as 2 sd"
                                                + (f" (failing {', '.join(p.failed_checks)})" if p.failed_checks
                                                   else ""), -Z95 * p.model_sd_hz, Z95 * p.model_sd_hz))
        if p.doublet_hz is not None:
            gap = p.doublet_hz - f0
            lines.append(BudgetLine("doublet", f"a cap mode near f: the cavity also peaks at {p.doublet_hz:.0f} Hz "
                                               "(>= -6 dB); it may sing there", min(gap, 0.0), max(gap, 0.0)))
        lines += _temperature_line(spec, f0)
        low, high = total(lines, f0)
        s = self.inference.state
        return Anchored(self.name, f0, (f0 + low, f0 + high), tuple(lines),
                        f"as built by the lab of [[measured]] {names}: neck {s.neck_offset_mm:+.3g} mm, joined air "
                        f"{s.side_volume_mm3:.3g} mm^3, sheet {s.sheet_offset_mm:+.3g} mm (`matcad infer`)")


ANCHORS = {"calibration": (lambda spec: spec.calibration is not None, CalibrationAnchor),
           "as_built": (lambda spec: bool(spec.measured), AsBuiltAnchor)}
"""The anchors this module makes, in the order they win (a [reference] alone is the ladder's 'relative')."""


def anchor(spec, name: str | None = None):
    """The anchor of ``spec`` as loaded: the first of :data:`ANCHORS` whose data it has, or the one ``name``d
    (ValueError when the spec lacks its data); None when it has none."""
    if name is not None:
        applies, make = ANCHORS[name]
        if not applies(spec):
            need = {"calibration": "a [calibration]", "as_built": "[[measured]] taxels"}[name]
            raise ValueError(f"model {name!r} needs {need} in the spec")
        return make(spec)
    for applies, make in ANCHORS.values():
        if applies(spec):
            return make(spec)
    return None


def available(spec) -> list[str]:
    """The anchors ``spec`` has data for, in the order they win."""
    return [name for name, (applies, _) in ANCHORS.items() if applies(spec)]
