"""One taxel's unloaded resonance by every model that serves its wall: the chosen f0, its band, validity flags and
warnings, as one result object.

Frequencies in Hz, lengths mm. The default model is the registry's choice for the wall
(:data:`matcad.acoustics.registry.CHOSEN`): the transmission line for rigid walls, or the transmission line
coupled to the cap's wall modes (``elastic_wall``: the wall's mass, stiffness and loss; it moves f up when the
cap's modes lie below f, down when they lie well above) for ``wall.model = "silicone"``. How f changes under load
is composed above this floor (:mod:`matcad.prediction`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from matcad.acoustics import checks, registry
from matcad.acoustics.air import VISCOUS_REGIME_EPS, boundary_layer_drop, boundary_layer_shift
from matcad.acoustics.design import Design, Reference
from matcad.acoustics.evaluation import Evaluation
from matcad.acoustics.registry import ModelResult
from matcad.acoustics.uncertainty import BudgetLine, budget, total

EDGE_STEPS = 3
"""Fixed-point steps of :func:`mount_edge_ratio` (its end correction depends on f): the ratio settles to 1e-4."""
BOUNDARY_LAYER_WARN = 0.05
PAPER_TAXEL_MM = (3.18, 4.76, 2.10, 6.35)
"""Cavity D, L and neck d, l of the source paper's taxel (templates/mat-paper.toml)."""
PAPER_MEASURED_HZ = 4000.0
"""The one published measurement of that taxel: ~4.0 kHz unloaded (MAT paper, Sec. VI)."""


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
    """Every model's result and the chosen one's f0 and band (Hz) with its budget and warnings; the as-built
    quantities behind them (mm, mm², mm³, m/s); and, when composed with a load (:mod:`matcad.prediction`), the
    calibration used, the f(F) points and the cap mechanics' summary."""

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
    physics_model: str = ""
    physics_f0_hz: float = float("nan")
    physics_band_hz: tuple[float, float] = (float("nan"), float("nan"))

    def to_dict(self) -> dict:
        d = asdict(self)
        for name, result in self.models.items():
            d["models"][name]["valid"] = result.valid
        d["band_hz"] = list(self.band_hz)
        d["physics_band_hz"] = list(self.physics_band_hz)
        return d

    @property
    def anchored(self) -> bool:
        """Whether the headline f0 and band rest on a measurement rather than on physics alone."""
        return self.model != self.physics_model

    def to_text(self, name: str, d: Design) -> str:
        """What `matcad predict` prints for the taxel ``name`` of design ``d``: its geometry and air, every model's
        f0 with its failed checks (the chosen one starred), the band and its budget, the load curve and the
        warnings (mm, Hz)."""
        lines = [
            f"{name}: cavity D {d.cavity_diameter:g} x L {d.cavity_length:g} mm, neck d {d.neck_diameter:g} x "
            f"l {d.neck_length:g} mm, mouth {d.mouth}, wall {d.wall.model}",
            f"  cavity volume   {self.cavity_volume_mm3:10.4f} mm^3    neck area {self.neck_area_mm2:.4f} mm^2",
            f"  A*l/V           {self.neck_air_ratio:10.4f}         xi = d/D  {self.diameter_ratio:.4f}",
            f"  speed of sound  {self.speed_of_sound_m_s:10.2f} m/s     end corrections: outer "
            f"{self.outer_end_correction_mm:.3f} mm, inner {self.inner_end_correction_mm:.3f} mm",
            "",
            f"  {'model':<18} {'f0 [Hz]':>9}  {'valid':<5}  failed checks",
        ]
        for model, r in self.models.items():
            failed = ", ".join(k for k, ok in r.checks.items() if not ok) or "-"
            mark = "*" if model == self.model else " "
            lines.append(f"{mark} {model:<18} {r.f0_hz:9.1f}  {'yes' if r.valid else 'no':<5}  {failed}")
        lines += ["", f"  f0 = {self.f0_hz:.0f} Hz ({self.model}), band {self.band_hz[0]:.0f}-{self.band_hz[1]:.0f} "
                      "Hz (root-sum-square in ln f of):"]
        lines += [f"    {b.source:<28} {b.tolerance:<52} {b.low_hz:+8.1f} {b.high_hz:+8.1f} Hz" for b in self.budget]
        if self.anchored:
            lines.append(f"  physics only: f0 = {self.physics_f0_hz:.0f} Hz ({self.physics_model}), band "
                         f"{self.physics_band_hz[0]:.0f}-{self.physics_band_hz[1]:.0f} Hz")
        if self.load_curve:
            lines += self.load_curve_text()
        if self.warnings:
            lines += ["", "  warnings:"] + [f"  - {w}" for w in self.warnings]
        return "\n".join(lines)

    def load_curve_text(self) -> list[str]:
        """The load curve by source (Eq. 5 calibration, cap mechanics) and the mechanics' summary, as lines (N, Hz,
        mm, mm³)."""
        lines = []
        for source in dict.fromkeys(pt.source for pt in self.load_curve):
            lines += ["", f"  load curve from {source}:", f"  {'F [N]':>9} {'f [Hz]':>9} {'x [mm]':>8} {'V [mm^3]':>9}"]
            for pt in (q for q in self.load_curve if q.source == source):
                if pt.f_hz is None:
                    lines.append(f"  {pt.force_n:9.3f} {'n/a':>9}  {pt.reason}")
                    continue
                x, v = (f"{q:8.3f}" if q is not None else f"{'-':>8}" for q in (pt.displacement_mm,
                                                                             pt.cavity_volume_mm3))
                lines.append(f"  {pt.force_n:9.3f} {pt.f_hz:9.1f} {x} {v:>9}")
        m = self.load_model
        if m:
            turn = f"stops rising at {m['turn_force_n']:.3g} N" if m["turn_force_n"] is not None else \
                f"still rising at the curve's end, {m['max_force_n']:.3g} N"
            slope = m["sensitivity_hz_per_n_at_0"]
            slope = "n/a (no load step converged)" if slope is None else f"{slope:.1f} Hz/N"
            lines += [f"  cap mechanics: df/dF = {slope} at 0 N; f {turn}; "
                      f"f shift by {m['route']}; {m['nodes']} nodes, {m['seconds']:.1f} s"]
            for key in ("eq5", "eq5_paper_convention"):
                if m[key]:
                    e = m[key]
                    lines.append(f"  Eq. 5 fit to it ({e['area_convention']}): V0 = {e['v0_mm3']:.4g} mm^3, "
                                 f"a = {e['a']:.4g} mm^3/N^2, b = {e['b']:.4g} mm^3/N")
            lines += [f"  {m[k]}" for k in ("fit_note", "fem_note") if m[k]]
        return lines


def _relative(ev: Evaluation, reference: Reference, model: str, this: ModelResult) -> ModelResult:
    """This design as the reference taxel's measured f0 times ``model``'s ratio (this design / reference); it
    carries ``this`` design's checks of that model."""
    ref = registry.model(model).result(Evaluation(reference.design))
    f_model_hz = this.f0_hz
    ratio = f_model_hz / ref.f0_hz
    both = dict(this.checks) | {f"{checks.REFERENCE}{name}": ok for name, ok in ref.checks.items()}
    return ModelResult(reference.f0_hz * ratio, both,
                       f"measured reference {reference.f0_hz:g} Hz x {model} ratio {ratio:.4f} "
                       f"(this design {f_model_hz:.0f} Hz / reference {ref.f0_hz:.0f} Hz by the same model)")


def is_paper_taxel(d: Design):
    """Whether ``d`` is the source paper's taxel (:data:`PAPER_TAXEL_MM` to 1e-6) with a silicone cap: a bool, or
    a bool array for a design of arrays."""
    dims = np.broadcast_arrays(d.cavity_diameter, d.cavity_length, d.neck_diameter, d.neck_length)
    paper = np.all(np.isclose(dims, np.reshape(PAPER_TAXEL_MM, (4,) + (1,) * dims[0].ndim), rtol=1e-6), axis=0)
    paper = paper & (d.wall.model == "silicone")
    return bool(paper) if np.ndim(paper) == 0 else paper


def mount_edge_ratio(d: Design, res):
    """f0 with the mount's gap radiating at its far edge over f0 with the pressure released there, as every model
    takes it (:func:`matcad.acoustics.models.mount_end_correction_mm`), by the transmission line on ``res``
    (``d``'s resonator; floats or arrays): how much of f0 hangs on the gap's edge, which no model resolves (the FEM
    takes the radiating one; docs/physics.md). 1 for another mouth."""
    from dataclasses import replace

    from matcad.acoustics.models import radiating_gap_end_correction_mm

    if d.mouth != "mount":  # a sweep's variants share one mouth
        return 1.0 if np.ndim(res.neck_area) == 0 else np.ones(np.shape(res.neck_area))

    line = registry.model("transmission_line")
    released = np.asarray(line.f0_hz(res), dtype=float)
    mouth_r = res.neck_mouth_radius
    to_mean = res.neck_area / (np.pi * mouth_r * mouth_r)  # the correction as a length of the neck's mean cylinder
    f = released
    for _ in range(EDGE_STEPS):
        k = 2.0 * np.pi * f / (1000.0 * res.c_m_s)
        delta = radiating_gap_end_correction_mm(mouth_r, d.gap_mm, k) * to_mean
        f = np.asarray(line.f0_hz(replace(res, outer_correction=delta)), dtype=float)
    ratio = f / released
    return ratio if np.ndim(ratio) else float(ratio)


def mount_edge_warned(d: Design, ratio):
    """Whether the gap's edge moves f0 by more than the chosen closed-form model's measured error (bool or array)."""
    error = registry.model(registry.CHOSEN[d.wall.model]).error["max_abs"]
    return np.abs(np.asarray(ratio) - 1.0) > error


def warning_count(d: Design, f0_hz, failed_checks, reference: Reference | None = None):
    """How many warnings :func:`predict` gives the chosen model on ``d`` (floats or arrays): its failed checks,
    the boundary layers' when they are worth a warning, the mount gap's edge when it is, and the paper anchor."""
    from matcad.acoustics.resonator import resonator

    eps = boundary_layer_shift(f0_hz, np.asarray(d.neck_diameter) / 2)
    anchor = is_paper_taxel(d) if reference is None else False
    edge = mount_edge_warned(d, mount_edge_ratio(d, resonator(d)))
    return np.asarray(failed_checks) + (eps > BOUNDARY_LAYER_WARN) + edge + np.asarray(anchor, dtype=int)


def _paper_anchor(d: Design, chosen: str, f0_hz: float, band_low_hz: float) -> list[str]:
    """For the paper's taxel with a silicone cap: what physics predicts against the one published measurement."""
    if not is_paper_taxel(d):
        return []
    gap = 100 * (1 - PAPER_MEASURED_HZ / f0_hz)
    where = "below the band" if PAPER_MEASURED_HZ < band_low_hz else "inside the band's low tail"
    return [f"{chosen}: physics predicts {f0_hz:.0f} Hz for the paper's taxel; its one published measurement "
            f"(~{PAPER_MEASURED_HZ / 1000:.1f} kHz unloaded) lies {gap:.0f} % lower, {where}, and the paper's pitch "
            "per newton is 1.5x smaller than the cap mechanics give. Fed to the as-built inference, the paper's own "
            "f0 and Eq. 5 are explained by air joined to the cavity (~35-40 mm^3: the guide's clearance, gaps in "
            "the stack), and its Fig. 8 F(x) asks for a silicone ~0.45x as stiff as the grade's; a narrower neck (the "
            "paper's 'd = 2.10 mm' may be the needle's distance y) or a thicker sheet explain the f0 alone, not the "
            "sensitivity (docs/paper.md). Record one taxel as [[measured]] and matcad predicts from it."]


def _requested(d: Design, model: str, reference: Reference | None) -> None:
    """Refuse a ``--model`` that does not apply to this design, saying why (ValueError)."""
    if model == "relative":
        if reference is None:
            raise ValueError(f"model {model!r} needs a [reference] taxel (its measured f0) in the spec")
        return
    m = registry.model(model)  # ValueError naming every model for an unknown name
    if d.wall.model not in m.walls:
        raise ValueError(f"model {model!r} serves wall.model = {' or '.join(repr(w) for w in m.walls)} only; this "
                         f"design's wall is {d.wall.model!r}")


def predict(d: Design, reference: Reference | None = None, model: str | None = None,
            fem_level: int | None = None) -> Prediction:
    """Predict the unloaded resonance of design ``d`` with every closed-form model that serves its wall, and the
    mesh model ``model`` when it names one (elements across the neck radius ``fem_level``, default
    :data:`matcad.acoustics.fem.DEFAULT_LEVEL`); with a measured ``reference`` also 'relative' (its f0 times the
    chosen model's ratio), chosen by default. ``model`` overrides the choice: a registered model that serves the
    wall, or 'relative' (ValueError otherwise, saying why)."""
    if model is not None:
        _requested(d, model, reference)
    ev = Evaluation(d)
    res = ev.res
    results: dict[str, ModelResult] = {m.name: m.result(ev) for m in registry.serving(d.wall.model) if m.cheap}
    chosen = registry.CHOSEN[d.wall.model]
    mesh = registry.model(model) if model is not None and model not in registry.DERIVED else None
    if mesh is not None and not mesh.cheap:
        from matcad.acoustics.fem import DEFAULT_LEVEL

        results[model] = mesh.result(ev, results[chosen].f0_hz, fem_level or DEFAULT_LEVEL)
    if reference is not None:
        results["relative"] = _relative(ev, reference, chosen, results[chosen])
        if model is None:
            chosen = "relative"
    if model is not None:
        chosen = model
    lines = budget(d, res, chosen, results[chosen].f0_hz, results[chosen].valid, reference)
    low, high = total(lines, results[chosen].f0_hz)
    physics = chosen if chosen not in registry.DERIVED else registry.CHOSEN[d.wall.model]
    if physics == chosen:
        physics_band = (results[chosen].f0_hz + low, results[chosen].f0_hz + high)
    else:
        f_physics = results[physics].f0_hz
        p_low, p_high = total(budget(d, res, physics, f_physics, results[physics].valid), f_physics)
        physics_band = (f_physics + p_low, f_physics + p_high)

    warnings = checks.warnings(chosen, results[chosen].checks, ev,
                               Evaluation(reference.design) if reference is not None else None)
    eps = float(boundary_layer_shift(results[chosen].f0_hz, d.neck_diameter / 2))
    if eps > VISCOUS_REGIME_EPS:
        warnings.append(f"{chosen}: the {d.neck_diameter:g} mm neck is so narrow that boundary layers fill it "
                        f"(Kirchhoff eps = {eps:.2f}): viscous flow, heavy damping, it may not sing at all")
    elif eps > BOUNDARY_LAYER_WARN:
        warnings.append(f"{chosen}: viscous/thermal boundary layers in this {d.neck_diameter:g} mm neck lower f by "
                        f"~{100 * boundary_layer_drop(results[chosen].f0_hz, d.neck_diameter / 2):.1f} %, which the "
                        "lossless models leave out (the band includes it)")
    edge = mount_edge_ratio(d, res)
    if mount_edge_warned(d, edge):
        warnings.append(f"{chosen}: the mount's {d.gap_mm:g} mm gap out to {d.gap_radius_mm:g} mm is not small beside "
                        f"the wavelength at this pitch: the models release the pressure at the plate's edge, while a "
                        f"gap radiating there (the FEM's boundary) puts f0 {100 * (edge - 1):+.1f} % away, more than "
                        "the model's measured error; which a real board has is not measured and the band does not "
                        "carry it (docs/physics.md): compare `--model fem`")
    if reference is None:
        warnings += _paper_anchor(d, chosen, results[chosen].f0_hz, results[chosen].f0_hz + low)
    f0 = results[chosen].f0_hz
    return Prediction(
        cavity_volume_mm3=res.volume, neck_area_mm2=res.neck_area, cavity_area_mm2=res.cavity_area,
        neck_air_ratio=res.neck_air_ratio, diameter_ratio=res.diameter_ratio, speed_of_sound_m_s=res.c_m_s,
        outer_end_correction_mm=res.outer_correction, inner_end_correction_mm=res.inner_step, models=results,
        model=chosen, f0_hz=f0, band_hz=(f0 + low, f0 + high), budget=tuple(lines), warnings=tuple(warnings),
        physics_model=physics, physics_f0_hz=results[physics].f0_hz, physics_band_hz=physics_band)
