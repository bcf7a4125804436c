"""A calibrated spec's sweep on arrays of variants: the calibration anchor
(:class:`matcad.prediction.anchor.CalibrationAnchor`) — the calibrated taxel's Eq. 5 f(0) times each variant's
physics ratio to the calibrated drawing — with its band, each entry the arithmetic `matcad predict` does on that
variant (tested equal). The physics is the model `predict` chooses for the wall
(:data:`matcad.acoustics.registry.CHOSEN`), run on the variants and on the calibrated drawing (its geometry and
build, :data:`matcad.spec.drawn.DRAWN`) with each variant's other fields (the silicone's density moves both).
Frequencies Hz, lengths mm.
"""

from __future__ import annotations

import numpy as np

from matcad.sweep import fast

MODEL = "calibration"
FIXED_TABLES = ("calibration", "air")
"""Tables a sweep on arrays does not vary: the anchor's f(0) and its sd are made once from the spec as loaded (its
[calibration], and the air's temperature where the calibration names its own); a grid over them runs variant by
variant."""


def eligible(base, axes) -> bool:
    """Whether the calibration anchor of ``base`` runs on arrays over ``axes``."""
    return base.calibration is not None and not any(a.section in FIXED_TABLES for a in axes)




class CalibratedSweep:
    """The anchor of ``base`` (a one-taxel spec with [calibration]) for the variants ``v`` of one chunk."""

    def __init__(self, chunk, base, v: fast.Variants):
        from matcad.acoustics.registry import CHOSEN
        from matcad.prediction.anchor import CalibrationAnchor
        from matcad.spec.drawn import DRAWN

        self.anchor = CalibrationAnchor(base)
        self.physics = CHOSEN[base.wall.model]
        self.drawing = {f"{table}.{name}": float(getattr(base.calibration, key)) for key, (table, name) in DRAWN.items()}
        self.same = np.all([chunk.field(base, key) == value for key, value in self.drawing.items()], axis=0)
        """Variants that draw the calibrated taxel: the ratio is exactly 1, and the band has no model-ratio line."""
        self.base = base
        self.v = v
        self.branches = (fast.branch(v, self.physics), fast.branch(self.drawn(v), self.physics))
        """The physics peaks of the variants and of their calibrated drawings (:func:`matcad.sweep.fast.branch`)."""

    @property
    def physics_hz(self) -> tuple[np.ndarray, np.ndarray]:
        """The physics f0 of the variants and of their calibrated drawings (Hz)."""
        return self.branches[0].f0_hz, self.branches[1].f0_hz

    def drawn(self, v: fast.Variants) -> fast.Variants:
        """The variants with the calibrated drawing's fields (:data:`matcad.spec.drawn.DRAWN`; their others kept)."""
        for key, value in self.drawing.items():
            v = v.with_value(key, np.full(len(v), value))
        return v

    def anchored_hz(self, v: fast.Variants, drawing_moves: bool = True) -> np.ndarray:
        """f(0) x physics(variant) / physics(calibrated drawing) (Hz) of variants moved a little from the chunk's,
        each physics followed from the chunk's own (:attr:`branches`, :func:`matcad.sweep.fast.f0_hz`); unless
        ``drawing_moves``, the drawings are the chunk's own and so is their physics."""
        variant, drawing = self.branches
        drawn = fast.f0_hz(self.drawn(v), self.physics, drawing) if drawing_moves else drawing.f0_hz
        return self.anchor.f_cal * (fast.f0_hz(v, self.physics, variant) / drawn)

    def f0_hz(self) -> np.ndarray:
        """The chunk's anchored f0 (Hz): f(0) x the physics ratio, and f(0) itself where ``same``."""
        physics, drawn = self.physics_hz
        return np.where(self.same, self.anchor.f_cal * 1.0, self.anchor.f_cal * (physics / drawn))

    def columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(f0, band low, band high) of the variants (Hz): :meth:`CalibrationAnchor.anchored`'s lines (the
        calibration's f(0), the model ratio unless ``same``, the air temperature unless the speed of sound is
        given) combined by :func:`matcad.acoustics.uncertainty.combine`. The anchored prediction has no warnings
        of its own model (`predict`'s are the physics model's, which acoustic.model_validity does not count for
        it)."""
        import math

        from matcad.acoustics.uncertainty import TEMPERATURE_TOL_C, combine
        from matcad.prediction.anchor import Z95, ratio_share

        f0 = self.f0_hz()
        half = Z95 * self.anchor.sd * f0
        share = ratio_share(self.base)
        lows, highs = [-half, np.where(self.same, 0.0, -share * f0)], [half, np.where(self.same, 0.0, share * f0)]
        air = self.base.air
        if air.speed_of_sound is None:
            kelvin = air.temperature_c + 273.15
            low, high = (math.sqrt(max(kelvin + s * TEMPERATURE_TOL_C, 0.0) / kelvin) - 1 for s in (-1, 1))
            lows.append(f0 * low)
            highs.append(f0 * high)
        low, high = combine(lows, highs, f0)
        return f0, f0 + low, f0 + high

    def sensitivity(self, field: str, follows: dict | None = None) -> np.ndarray:
        """df0/dfield of the chunk's anchored f0 (Hz per the field's unit) by :func:`matcad.sweep.fast.sensitivity`'s
        central difference: the ratio's own derivative (a drawn field moves the variant only, the drawing's physics
        is then the chunk's own; any other field moves the calibrated drawing too), each physics followed from the
        chunk's own."""
        moves = any(key not in self.drawing for key in (field, *(follows or {})))
        return fast.sensitivity(self.v, self.physics, field, follows, f0=lambda v: self.anchored_hz(v, moves))
