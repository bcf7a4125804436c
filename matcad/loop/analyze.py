"""Frequency of a taxel's tone from a recording, frame by frame, in blocks (bounded memory, live streams).

The paper used MATLAB spectrogram + tfridge and a pspectrum peak in 4–5.5 kHz. Here, per frame (Hann window
~93 ms, 2× zero padding, 50 % overlap; :mod:`matcad.listening`), one module per step:

1. *Strength over the local floor* (:mod:`matcad.loop.spectrum`): each bin's power over the running median of its
   neighbours, in dB — it follows coloured noise where a band-wide mean would not.
2. *Combs removed* (:mod:`matcad.loop.combs`): lines of mains hum or buzz are removed before tracking; a line that
   is one of a harmonic comb (a voice) is no candidate for voicing.
3. *Ridge with a jump allowance* (:mod:`matcad.loop.ridge`): a Viterbi path through the excess that follows a
   wobble smoothly and a press that jumps 300 Hz between frames, decided with a fixed lag of ~1 s.
4. *Voicing* (:mod:`matcad.loop.voicing`): a frame is voiced when it belongs to a steady run of frames over the
   floor, long or strong enough; stricter near a harmonic sound (:mod:`matcad.loop.harmonic`) and away from an
   established tone, with thresholds raised by the clutter. A strength and a stability, never a fraction of the
   file: 1 s of clear tone in a 10 min file is found; at most 1e-4 falsely voiced frames per frame of noise.
5. *Segments* (:mod:`matcad.loop.segments`): steady segments at gaps and steps; a mode jump (overblowing) is
   flagged and left out of the statistics.
6. *Other sources* (:mod:`matcad.loop.analysis`, :mod:`matcad.loop.crossing`): a second stable line in the band
   and a stronger tone outside it are reported, never taken; where a second tone of similar level shares the band
   the taxel is kept on its own line through hops and crossings (by slope, else level), and frames after a
   crossing whose identity nothing decides are left out with a warning.

:class:`matcad.loop.tracker.BandTracker` wires them together for one band; :func:`run_trackers` feeds one spectrum
to several bands in one pass. Frequencies Hz, times s, levels dB.
"""

from __future__ import annotations

import numpy as np

from matcad.loop.analysis import Analysis
from matcad.loop.overtones import Overtones
from matcad.loop.spectrum import Framer
from matcad.loop.tracker import BandTracker


def run_trackers(blocks, fs: float, bands,
                 on_frame=None) -> tuple[list[BandTracker], float, np.ndarray, np.ndarray]:
    """Feed an iterable of sample blocks at ``fs`` (Hz) to one :class:`BandTracker` per band (Hz), in one pass:
    (trackers, duration s, mean power spectrum, each bin's share of that power heard on a predicted harmonic).
    With several bands, each frame's bins on a band's predicted harmonics (:mod:`matcad.loop.overtones`) are
    discounted in the others. ``on_frame`` is called as (band index, time s, frequency Hz or NaN, excess dB) as
    frames become final."""
    framer = Framer(fs)
    trackers = [BandTracker(framer.freqs, fs, band,
                            None if on_frame is None else (lambda *a, k=k: on_frame(k, *a)))
                for k, band in enumerate(bands)]
    overtones = Overtones(framer.freqs, bands) if len(bands) > 1 else None
    total = np.zeros(len(framer.freqs))
    on_harmonic = np.zeros(len(framer.freqs))
    samples = 0
    for block in blocks:
        samples += len(block)
        times, power = framer.feed(block)
        if len(times):
            total += power.sum(axis=0)
            discount = overtones.mask(power) if overtones is not None else None
            if discount is not None:
                on_harmonic += np.where(discount, power, 0.0).sum(axis=0)
            for tr in trackers:
                tr.push(times, power, discount)
    tiny = np.finfo(float).tiny
    return trackers, samples / fs, total / max(1, framer.frames), on_harmonic / np.maximum(total, tiny)


def analyze_stream(blocks, fs: float, bands, on_frame=None) -> list[Analysis]:
    """One :class:`matcad.loop.analysis.Analysis` per band (Hz) from an iterable of sample blocks at ``fs`` (Hz),
    in one pass (:func:`run_trackers`); raises LoopError when any band has no tone. A board of taxels whose silent
    members must not stop the others is :func:`matcad.loop.board.analyze_board`."""
    trackers, duration, mean_power, on_harmonic = run_trackers(blocks, fs, bands, on_frame)
    return [tr.finish(duration, mean_power, [b for j, b in enumerate(bands) if j != k], on_harmonic)
            for k, tr in enumerate(trackers)]


def analyze(x: np.ndarray, fs: float, band_hz: tuple[float, float]) -> Analysis:
    """The tone's frequency track inside ``band_hz`` (Hz) of samples ``x`` at ``fs`` (Hz).

    Raises LoopError (with the reason) when no frame holds the tone or when the ridge hugs a band edge.
    """
    step = 1 << 16
    return analyze_stream((x[i:i + step] for i in range(0, max(len(x), 1), step)), fs, [band_hz])[0]
