"""A board's prediction: every taxel's f0, unloaded and loaded band, and the bands' conflicts, as one result.
Frequencies Hz, lengths mm, forces N."""

from __future__ import annotations

from dataclasses import dataclass

from matcad.acoustics.predict import Prediction
from matcad.prediction.bands import TaxelBand


@dataclass(frozen=True)
class BoardPrediction:
    """The spec's ``name``, each taxel's band (:class:`~matcad.prediction.bands.TaxelBand`) and whole prediction,
    and the bands' summary (:func:`matcad.prediction.bands.summary`: guard, max force, conflicts)."""

    name: str
    bands: tuple[TaxelBand, ...]
    predictions: dict[str, Prediction]
    summary: dict

    def to_dict(self) -> dict:
        return {"name": self.name, **self.summary,
                "predictions": {k: p.to_dict() for k, p in self.predictions.items()}}

    def to_text(self) -> str:
        """One row per taxel (position mm, f0, model, unloaded and loaded band Hz, rise), where each rise comes
        from, the conflicts, and each taxel's warnings and load curve."""
        data = self.summary
        lines = [f"{self.name}: {len(self.bands)} taxels; loaded band = predicted band + rise to "
                 f"{data['max_force_n']:g} N; guard {data['guard_hz']:.0f} Hz",
                 f"  {'taxel':<8} {'x, y [mm]':>14} {'f0 [Hz]':>8}  {'model':<18} {'unloaded [Hz]':>13} "
                 f"{'loaded [Hz]':>13} {'rise':>7}"]
        for b in self.bands:
            lines.append(f"  {b.name:<8} {f'{b.x_mm:g}, {b.y_mm:g}':>14} {b.f0_hz:8.0f}  {b.model:<18} "
                         f"{f'{b.unloaded_hz[0]:.0f}-{b.unloaded_hz[1]:.0f}':>13} "
                         f"{f'{b.loaded_hz[0]:.0f}-{b.loaded_hz[1]:.0f}':>13} {100 * (b.rise - 1):+6.1f}%")
        lines += [f"  rise from {source}" for source in dict.fromkeys(b.rise_source for b in self.bands)]
        lines += [f"  conflict: {c['message']}" for c in data["conflicts"]] or \
            ["  bands disjoint (guard and 2f/3f rule)"]
        for name, p in self.predictions.items():
            lines += [f"  {name} warning: {w}" for w in p.warnings]
            if p.load_curve:
                lines += [f"  {name}:"] + p.load_curve_text()
        return "\n".join(lines)


def predict_board(spec, forces_n=(), model: str | None = None, fem_level: int | None = None,
                  progress=None, mechanics: bool = True) -> BoardPrediction:
    """Every taxel of ``spec`` predicted (:func:`matcad.prediction.taxel.predict`, at ``forces_n`` N) with its band
    (:func:`matcad.prediction.bands.taxel_band`), and the board's summary; ``progress(taxels done, taxels)`` is told
    as each taxel is done. ``mechanics=False`` leaves out the cap mechanics' rise under load (a FElupe run per
    cap not yet in :mod:`matcad.mechanics.store`: seconds to minutes): each loaded band is then the unloaded one
    unless a calibration gives the rise."""
    from matcad.prediction.bands import summary, taxel_band
    from matcad.prediction.taxel import predict
    from matcad.spec import taxel_spec, taxels

    bands, predictions = [], {}
    board = taxels(spec)
    for t in board:
        one = taxel_spec(spec, t)
        p = predict(one, forces_n=forces_n, model=model, fem_level=fem_level)
        bands.append(taxel_band(one, t.name, t.x, t.y, mechanics, prediction=p))
        predictions[t.name] = p
        if progress is not None:
            progress(len(predictions), len(board))
    return BoardPrediction(spec.name, tuple(bands), predictions, summary(spec, bands))
