"""Live output of ``sense --live``: one line per frame as soon as its voicing is final, with the force heard.

One taxel: ``   12.345 s    5123.45 Hz  F = 3.210 +- 0.456 N`` (or "outside the calibrated range", or "no tone").
A board: ``   12.345 s  t1 5123.45 Hz F=3.210+-0.456 N | t2 no tone | ...``, one row per frame once every taxel has
decided it (:class:`matcad.loop.board.LiveFrames`). Times s, frequencies Hz, forces N with the half-width of their
95 % interval.
"""

from __future__ import annotations

import numpy as np

from matcad.loop.board import LiveFrames
from matcad.loop.sense import force_interval


def taxel_line(cal, temperature_c, time_s: float, freq: float) -> str:
    """One frame of one taxel heard at ``freq`` (Hz, NaN: no tone) through calibration ``cal``
    (:class:`matcad.acoustics.eq5.Eq5`) at ``temperature_c`` (°C)."""
    if freq != freq:
        return f"{time_s:9.3f} s  no tone"
    force, half, _ = force_interval(cal, [freq], temperature_c)
    text = f"F = {force[0]:.3f} +- {half[0]:.3f} N" if np.isfinite(force[0]) else "outside the calibrated range"
    return f"{time_s:9.3f} s  {freq:9.2f} Hz  {text}"


def taxel_printer(cal, temperature_c, emit):
    """The ``on_frame`` callback of :func:`matcad.loop.analyze.analyze_stream` that hands each frame's
    :func:`taxel_line` to ``emit``."""
    def on_frame(_, time_s, freq, _excess):
        emit(taxel_line(cal, temperature_c, time_s, freq))
    return on_frame


def board_line(names, cals, temperature_c, time_s: float, values) -> str:
    """One frame of a board: per taxel of ``names`` its frequency (Hz) and, with a calibration in ``cals``
    ({name: Eq5}), its force at ``temperature_c`` (°C); ``values``: (frequency Hz or NaN, excess dB)
    per taxel."""
    def taxel_text(taxel, freq):
        if freq != freq:
            return f"{taxel} no tone"
        text = f"{taxel} {freq:.2f} Hz"
        if taxel in cals:
            force, half, _ = force_interval(cals[taxel], [freq], temperature_c)
            text += (f" F={force[0]:.3f}+-{half[0]:.3f} N" if np.isfinite(force[0])
                     else " outside the calibrated range")
        return text

    return f"{time_s:9.3f} s  " + " | ".join(taxel_text(taxel, freq) for taxel, (freq, _) in zip(names, values))


def board_printer(names, cals, temperature_c, emit) -> LiveFrames:
    """The ``on_frame`` callback of :func:`matcad.loop.board.analyze_board` that hands each frame's
    :func:`board_line` to ``emit`` once every taxel has decided it (call its ``flush()`` at the end)."""
    return LiveFrames(len(names), lambda time_s, values: emit(board_line(names, cals, temperature_c, time_s,
                                                                         values)))
