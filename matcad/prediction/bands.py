"""Each taxel's frequency band: where one microphone must listen for it, unloaded and pressed. Frequencies Hz.

A taxel's band is its unloaded predicted band (:func:`matcad.prediction.taxel.predict`'s ``band_hz``: the chosen
model's f0 with the uncertainty budget, root-sum-square in ln f) widened upward by the rise of f under load up to
``mechanics.max_force_n``:

- with a ``[calibration]``: paper Eq. 5 (:mod:`matcad.acoustics.eq5`), f(F)/f(0) = sqrt(V_eff(0)/V_eff(F)); the
  ratio does not depend on the calibration's area convention or K;
- without one: the cap mechanics (:mod:`matcad.mechanics`, FElupe; docs/mechanics.md), f(F)/f(0) from the
  transmission line on the deformed cavity. One run takes seconds, so each distinct cap (cavity, end cap, flange,
  draft, silicone, [mechanics] law) is computed once per process and shared by every taxel with that cap.

The rise is a ratio r = max f(F)/f(0) over 0 <= F <= max force, so the loaded band is
(unloaded low x min(1, min ratio), unloaded high x r): the model's relative uncertainty is carried onto the loaded
end. Bands of one array must stay ``guard_hz`` apart and clear of each other's 2nd and 3rd harmonics
(:func:`conflicts`; the rules in :mod:`matcad.rules.bands` report them).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from matcad.listening import HARMONICS, guard_hz

EQ5_POINTS = 65
"""Forces sampled from 0 to the maximum force to find Eq. 5's highest f (it may turn back inside the range)."""


@dataclass(frozen=True)
class TaxelBand:
    """One taxel's bands (Hz): the unloaded prediction f0 (``model``), its predicted band ``unloaded_hz`` (model
    uncertainty) and ``loaded_hz``, that band widened by f's rise up to ``max_force_n`` (N). ``rise`` is
    max f(F)/f(0) over that force range and ``rise_source`` says where it came from; ``x_mm``, ``y_mm`` the neck
    axis on the plate."""

    name: str
    f0_hz: float
    unloaded_hz: tuple[float, float]
    loaded_hz: tuple[float, float]
    model: str
    max_force_n: float
    rise: float
    rise_source: str
    x_mm: float = 0.0
    y_mm: float = 0.0

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["unloaded_hz"], d["loaded_hz"] = list(self.unloaded_hz), list(self.loaded_hz)
        return d


@dataclass(frozen=True)
class Conflict:
    """Two taxels whose bands come closer than the guard (Hz): ``other``'s loaded band meets ``taxel``'s loaded
    band (``harmonic`` = 1) or its ``harmonic``-th multiple ``band_hz``; ``gap_hz`` is the gap between them
    (negative: they overlap by that much)."""

    taxel: str
    harmonic: int
    other: str
    band_hz: tuple[float, float]
    other_hz: tuple[float, float]
    gap_hz: float
    guard_hz: float

    def describe(self) -> str:
        what = f"{self.taxel}'s loaded band" if self.harmonic == 1 else \
            f"{self.taxel}'s harmonic {self.harmonic}f ({self.harmonic} x its loaded band)"
        how = f"overlap by {-self.gap_hz:.0f} Hz" if self.gap_hz < 0 else f"are only {self.gap_hz:.0f} Hz apart"
        return (f"{what}, {self.band_hz[0]:.0f}-{self.band_hz[1]:.0f} Hz, and {self.other}'s loaded band, "
                f"{self.other_hz[0]:.0f}-{self.other_hz[1]:.0f} Hz, {how} (guard {self.guard_hz:.0f} Hz)")


def conflicts(bands, guard: float, harmonics=HARMONICS) -> list[Conflict]:
    """Every pair whose loaded bands (Hz) come within ``guard`` (Hz) of each other, and every harmonic n·band of
    one taxel (n in ``harmonics``) that comes within ``guard`` of another's band."""
    out = []
    for i, a in enumerate(bands):
        for n in (1, *harmonics):
            lo, hi = n * a.loaded_hz[0], n * a.loaded_hz[1]
            for j, b in enumerate(bands):
                if j == i or (n == 1 and j < i):
                    continue
                gap = max(lo, b.loaded_hz[0]) - min(hi, b.loaded_hz[1])
                if gap < guard:
                    out.append(Conflict(a.name, n, b.name, (lo, hi), b.loaded_hz, gap, guard))
    return out


def eq5_rise(cal, max_force_n: float) -> tuple[float, float]:
    """(min, max) of f(F)/f(0) over 0 <= F <= ``max_force_n`` (N) by paper Eq. 5 (:meth:`matcad.acoustics.eq5.Eq5.rise`,
    f ∝ V_eff^(-1/2)); SpecError naming ``mechanics.max_force_n`` where the fit has no meaning (past its V_eff
    minimum, V_eff <= 0)."""
    from matcad.spec import SpecError

    try:
        return cal.rise(max_force_n, EQ5_POINTS)
    except ValueError as exc:
        raise SpecError("mechanics.max_force_n", max_force_n,
                        f"must stay where the calibration's Eq. 5 holds: {exc}") from None


def mechanics_rise(spec, f0_hz: float, max_force_n: float, model: str = "") -> tuple[float, float, str]:
    """(min, max) of f(F)/f(0) over 0 <= F <= ``max_force_n`` (N) from the cap mechanics of the single-taxel
    ``spec`` (its curve computed once per distinct cap: :func:`matcad.prediction.curves.cap_curve`; as built when its
    prediction's ``model`` is 'as_built'), and its source text; SpecError naming ``mechanics.max_force_n`` when the
    computed curve stops below that force."""
    from matcad.mechanics.frequency import at_forces, force_curve
    from matcad.prediction.taxel import load_model_of
    from matcad.spec import SpecError

    built, curve = load_model_of(spec, model)
    fc = force_curve(built, curve, f0_hz)
    forces = np.array([s.force_n for s in fc.states])
    f = np.array([s.f_hz for s in fc.states])
    top = at_forces(fc, [max_force_n])[0][1]
    if top is None:
        why = curve.message or "raise mechanics.displacement_mm to extend it"
        raise SpecError("mechanics.max_force_n", max_force_n,
                        f"must be <= {forces[-1]:.3g} N, the largest force the cap mechanics curve reached ({why})")
    inside = np.append(f[forces <= max_force_n], top) / f[0]
    return (float(inside.min()), float(inside.max()),
            f"cap mechanics ({curve.material.model}, {curve.contact}, G = {curve.material.shear_modulus_mpa:.3g} MPa)")


def taxel_band(spec, name: str = "t1", x_mm: float = 0.0, y_mm: float = 0.0, mechanics: bool = True,
               prediction=None, strict: bool = True) -> TaxelBand:
    """The band of the single-taxel ``spec`` (see the module docstring). ``mechanics=False`` is the cheap path:
    without a [calibration] the rise is then not computed (``rise`` 1, ``rise_source`` says so) and FElupe is not
    imported. A maximum force the rise's model does not reach raises SpecError, or with ``strict=False`` leaves the
    rise not computed and says why. ``prediction`` is ``predict(spec)`` when the caller has it."""
    from matcad.acoustics.design import calibration
    from matcad.prediction.taxel import predict
    from matcad.spec import SpecError

    p = prediction or predict(spec, mechanics=False)
    force = spec.mechanics.max_force_n
    cal = calibration(spec)
    try:
        if cal is not None:
            low, high = eq5_rise(cal, force)
            source = f"calibration {cal.name} (paper Eq. 5)"
        elif mechanics:
            low, high, source = mechanics_rise(spec, p.f0_hz, force, p.model)
        else:
            low, high = 1.0, 1.0
            source = ("not computed (no [calibration]; the cap mechanics run was skipped: `matcad predict --load` "
                      "or an array's `matcad check` runs it)")
    except SpecError as exc:
        if strict:
            raise
        low, high, source = 1.0, 1.0, f"not computed ({exc})"
    lo, hi = p.band_hz
    return TaxelBand(name, p.f0_hz, (lo, hi), (lo * min(1.0, low), hi * high), p.model, force, high, source,
                     x_mm, y_mm)


def taxel_bands(spec, mechanics: bool = True, strict: bool = True, predictions=None) -> list[TaxelBand]:
    """One :class:`TaxelBand` per taxel of ``spec``, in :func:`matcad.spec.taxels` order (Hz, mm); ``mechanics``
    and ``strict`` as for :func:`taxel_band`; ``predictions`` are the taxels' ``predict(taxel_spec(spec, t))`` in
    the same order when the caller has them."""
    from matcad.spec import taxel_spec, taxels

    board = taxels(spec)
    return [taxel_band(taxel_spec(spec, t), t.name, t.x, t.y, mechanics, prediction=p, strict=strict)
            for t, p in zip(board, predictions or [None] * len(board), strict=True)]


def summary(spec, bands) -> dict:
    """The bands of a board as plain data (report.json's ``bands``, `predict --json` of an array): the guard (Hz),
    max force (N), harmonics checked, one row per taxel and every :func:`conflicts`, with its message."""
    guard = guard_hz(spec.microphone.sample_rate_hz)
    return {"guard_hz": guard, "max_force_n": spec.mechanics.max_force_n, "harmonics": list(HARMONICS),
            "taxels": [b.to_dict() for b in bands],
            "conflicts": [{"taxel": c.taxel, "harmonic": c.harmonic, "other": c.other, "band_hz": list(c.band_hz),
                           "other_hz": list(c.other_hz), "gap_hz": c.gap_hz, "message": c.describe()}
                          for c in conflicts(bands, guard)]}


def listening_bands(spec) -> list[tuple[str, tuple[float, float]]]:
    """(taxel name, band Hz the recording loop listens in) per taxel of ``spec``, in taxels(spec) order: each
    taxel's loaded band (:func:`taxel_bands`) with the edge zone either side
    (:func:`matcad.listening.loaded_listening_band`)."""
    from matcad.listening import loaded_listening_band

    fs = spec.microphone.sample_rate_hz
    return [(b.name, loaded_listening_band(b.loaded_hz, fs)) for b in taxel_bands(spec)]
