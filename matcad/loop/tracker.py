"""One taxel's tone in one band, block by block: the components of :mod:`matcad.loop.analyze` wired together.

Per block of frames from a :class:`matcad.loop.spectrum.Framer`: levels over the floor
(:func:`matcad.loop.spectrum.levels`), mains combs removed (:mod:`matcad.loop.combs`), the clutter counted
(:class:`matcad.loop.voicing.Clutter`), the harmonic sound below the band heard (:mod:`matcad.loop.harmonic`), the
spectrogram pooled (:class:`matcad.loop.plots.PlotPool`) and the ridge pushed (:class:`matcad.loop.ridge.Ridge`).
Per frame the ridge decides: its peak refined, the strongest other line noted, the harmonic-comb test, and
voicing (:class:`matcad.loop.voicing.Voicing`). At the end: :func:`matcad.loop.analysis.conclude`. Frequencies Hz,
times s, levels dB.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from matcad.listening import EXCLUDE_BINS
from matcad.loop.analysis import Analysis, Frames, conclude, strongest_outside
from matcad.loop.combs import COMB_SPACINGS_HZ, in_harmonic_comb, mains_zone
from matcad.loop.harmonic import harmonic_frames
from matcad.loop.plots import PlotPool
from matcad.loop.ridge import Ridge
from matcad.loop.spectrum import BandBins, levels
from matcad.loop.voicing import Clutter, Voicing


class Pending:
    """Per-frame rows (arrays of equal length along axis 0) kept until the ridge decides their frames, oldest
    first."""

    def __init__(self, **empty):
        self.rows = dict(empty)

    def add(self, **block) -> None:
        for name, rows in block.items():
            self.rows[name] = np.concatenate([self.rows[name], rows])

    def take(self, count: int) -> dict:
        """The oldest ``count`` rows of each name, removed."""
        taken = {name: rows[:count] for name, rows in self.rows.items()}
        self.rows = {name: rows[count:] for name, rows in self.rows.items()}
        return taken


class BandTracker:
    """One taxel's tone in one band (Hz) of a spectrum with bins ``freqs`` (Hz) at ``fs`` (Hz).

    ``push(times, power)`` takes frames from a :class:`matcad.loop.spectrum.Framer`; ``finish()`` returns the
    :class:`matcad.loop.analysis.Analysis`. Everything but the Viterbi recursion (one vector step per frame) and the
    voicing state machine (a few scalar operations per frame) works on whole blocks of frames. Frames whose bin is
    not yet decided (≤ LAG_FRAMES) are kept; the arrays kept grow by eight numbers per frame (~0.1 MB per minute of
    audio); the plot is max-pooled to at most 2·PLOT_COLUMNS columns. ``on_frame`` (optional) is called with
    (time s, frequency Hz or NaN, excess dB) as each frame's voicing becomes final, for live output.
    """

    def __init__(self, freqs: np.ndarray, fs: float, band_hz: tuple[float, float], on_frame=None):
        self.bins = BandBins.locate(freqs, fs, band_hz, 2 * max(COMB_SPACINGS_HZ))
        self.in_band, self.slab, self.offset = self.bins.in_band, self.bins.slab, self.bins.offset
        self.on_frame = on_frame
        nb = len(self.in_band)
        self._ridge = Ridge(nb)
        self._voicing = Voicing()
        self._clutter = Clutter()
        self._plot = PlotPool()
        self._pending = Pending(times=np.zeros(0), level=np.zeros((0, nb)), excess=np.zeros((0, nb)),
                                lines=np.zeros((0, nb)), slab_lines=np.zeros((0, len(self.slab))))
        # decided frames: time, ridge frequency and excess, the strongest other line (bin, excess, level)
        self.times, self.track, self.excess, self.other_bin, self.other_excess, self.other_level = \
            [], [], [], [], [], []
        self.peak_db = []  # the ridge's own level (dB of power, not over the floor)
        self._emitted = 0  # frames whose voicing is final and reported
        self.band_peak_power = np.zeros(nb)

    def push(self, times: np.ndarray, power: np.ndarray, discount: np.ndarray | None = None) -> None:
        """Frames at ``times`` (s) with their power spectra (frames × bins). ``discount`` (frames × bins, bool):
        bins on another taxel's predicted harmonic (:mod:`matcad.loop.overtones`), treated as a mains comb's: no
        emission for the ridge, no line, no excess."""
        if len(times) == 0:
            return
        b = self.bins
        slab = power[:, self.slab]
        level, excess, lines = levels(slab, power.max(axis=1))
        band = slice(self.offset, self.offset + len(self.in_band))
        zone = mains_zone(lines, b.freqs[self.slab], b.df)
        if discount is not None:
            hidden = discount[:, self.slab][:, band]
            excess[:, band] = np.where(hidden, 0.0, excess[:, band])
            zone[:, band] |= hidden
        emit = np.where(zone[:, band], 0.0, np.clip(excess[:, band], 0.0, None))
        band_lines = np.where(zone[:, band], -np.inf, lines[:, band])
        self.band_peak_power += slab[:, band].sum(axis=0)
        self._voicing.hear(harmonic_frames(power, b.freqs, b.band_hz[0]).tolist())
        self._clutter.push(excess[:, band])
        self._plot.push(times, level[:, band])
        states = self._ridge.push(emit)
        self._pending.add(times=times, level=level[:, band], excess=excess[:, band], lines=band_lines,
                          slab_lines=lines)
        if len(states):
            self._decide(states)
        self._clutter.forget_before(self._emitted)

    def _decide(self, states: np.ndarray) -> None:
        """The oldest pending frames' ridge bins are ``states``: refine each to the highest of its ±1 bins with a
        parabolic peak (dB), note the strongest other line, test harmonicity, pass them to voicing."""
        count = len(states)
        p = self._pending.take(count)
        nb = len(self.in_band)
        rows = np.arange(count)
        log = p["level"]
        near = states[:, None] + np.arange(-1, 2)[None, :]
        level = np.where((near >= 0) & (near < nb), log[rows[:, None], np.clip(near, 0, nb - 1)], -np.inf)
        peak = np.clip(near[rows, np.argmax(level, axis=1)], 1, nb - 2)
        l, m, r = log[rows, peak - 1], log[rows, peak], log[rows, peak + 1]
        denom = l - 2 * m + r
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(denom < 0, np.clip(0.5 * (l - r) / denom, -0.5, 0.5), 0.0)
        first_hz = self.bins.freqs[self.in_band[0]]
        freq = first_hz + (peak + delta) * self.bins.df
        masked = np.where(np.abs(np.arange(nb)[None, :] - peak[:, None]) <= EXCLUDE_BINS, -np.inf, p["lines"])
        other = np.argmax(masked, axis=1)
        other_excess = masked[rows, other]
        other_level = np.where(np.isfinite(other_excess), log[rows, other] - m, -np.inf)
        harmonic = in_harmonic_comb(p["slab_lines"], peak + self.offset, self.bins.df)
        excess = p["excess"][rows, peak]
        first = len(self.track)
        self.times.extend(p["times"].tolist())
        self.track.extend(freq.tolist())
        self.excess.extend(excess.tolist())
        self.other_bin.extend(other.tolist())
        self.other_excess.extend(other_excess.tolist())
        self.other_level.extend(other_level.tolist())
        self.peak_db.extend(m.tolist())
        for i, harmonic_line, position in zip(range(first, first + count), harmonic.tolist(),
                                              ((freq - first_hz) / self.bins.df).tolist()):
            e = -np.inf if harmonic_line else self.excess[i]
            self._emit_until(self._voicing.step(e, position, self._clutter.shift_db(i)))

    def _emit_until(self, stop: int) -> None:
        """Report the frames before ``stop`` not yet reported to ``on_frame``."""
        if self.on_frame is not None:
            state = self._voicing.state
            for j in range(self._emitted, stop):
                self.on_frame(self.times[j], self.track[j] if state[j] else float("nan"), self.excess[j])
        self._emitted = max(self._emitted, stop)

    def finish(self, duration_s: float, full_mean_power: np.ndarray | None = None, others=(),
               on_harmonic: np.ndarray | None = None) -> Analysis:
        """The :class:`matcad.loop.analysis.Analysis` of everything pushed. ``full_mean_power`` (the whole
        spectrum's mean) lets a stronger tone outside the band be reported; one inside another taxel's band
        (``others``, Hz) or whose power is mostly heard on a taxel's predicted harmonic (``on_harmonic``: each
        bin's share) is that taxel's, not reported here."""
        states = self._ridge.finish()
        if len(states):
            self._decide(states)
        self._emit_until(len(self.track))
        plot = self._plot.finish(self.times[-1] if self.times else 0.0)
        loudest = ""
        if full_mean_power is not None and len(self.times):
            loudest = strongest_outside(self.bins.freqs, full_mean_power, [self.bins.band_hz, *others],
                                        float(self.band_peak_power.max() / len(self.times)), on_harmonic)
        frames = Frames(np.array(self.times), np.array(self.track), np.array(self.excess),
                        np.array(self._voicing.state, dtype=int), np.array(self.other_bin),
                        np.array(self.other_excess), np.array(self.other_level),
                        self._voicing.heard[:len(self.times)])
        return replace(conclude(frames, self.bins, duration_s, loudest, plot), frame_level_db=np.array(self.peak_db))
