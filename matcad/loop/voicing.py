"""Voicing: is the taxel's tone there in a frame? A strength and a stability, never a fraction of the file.

A frame is voiced when it belongs to a run of frames whose ridge stays within ±:data:`STABLE_BINS` bins and stands
≥ :data:`WEAK_DB` over the floor, and the run is either ≥ :data:`MIN_RUN` frames long or ≥ :data:`STRONG_RUN`
frames with one ≥ :data:`STRONG_DB` (a lone strong frame is not enough: a floor estimated from ~30 bins has a heavy
tail, :mod:`matcad.loop.spectrum`). A line that is one of a harmonic comb (:func:`matcad.loop.combs.
in_harmonic_comb`: a voice) is no candidate. While a harmonic sound — a voice or buzz, recognised by its resolved
low harmonics below the band (:mod:`matcad.loop.harmonic`) — is present and no tone has been established (a run of
:data:`MIN_RUN_HARMONIC` frames within :data:`ANCHOR_FRAMES`), a run needs MIN_RUN_HARMONIC frames (~0.46 s): a
voice's smeared high harmonics and the room's response peaks it excites leave steady-looking lines of 2–8 frames. A
run that would have qualified otherwise is held and voiced after all if such a run starts within ANCHOR_FRAMES
after it. Away from a voiced frame (ANCHOR_FRAMES) a weak run needs :data:`MIN_RUN_NEW` frames and the thresholds
also adapt to the clutter (order-statistic CFAR, :class:`Clutter`): where the band's other bins, pooled over
±:data:`CLUTTER_FRAMES` frames, stand ≥ WEAK_DB more often than :data:`CLUTTER_TARGET` (dry noise: 0.76 %), WEAK_DB
and STRONG_DB rise together until they do not — broadband noise through a reverberant room has a tail ~3× heavier
at 8 dB, ~10× at 10 dB, from the room's response peaks.

Design value: at most 1e-4 falsely voiced frames per frame of noise (one per ~8 min); measured 0 in 116 100 frames
(3.2e7 frame × bins; 30 min each of white, pink and brown noise), 95 % upper bound 2.6e-5 per frame
(benchmarks/analyze.py --noise-minutes 30). A lone frame whose ridge stands ≥ 15 dB came 5 times in those 116 100
noise frames. Synthetic speech alone: 0 frames voiced in 20 seeds (was 3.4 %). Reduced, not rejected: broadband
noise heard through a reverberant room (RT60 0.6 s) voices 0.28 % of frames over 5 seeds ("no tone" in 4; 6.5 %
before the adaptive thresholds and MIN_RUN_NEW; room-noise case) — its lines at the room's response peaks can be as
steady as a weak tone; when no voiced stretch lasts MIN_RUN_HARMONIC frames the analysis warns that the frames may
be such peaks (every room-noise false alarm measured; no case with a tone). 1 s of clear tone in a 10 min file is
found. Levels dB over the local floor, positions in bins.
"""

from __future__ import annotations

import numpy as np

STRONG_DB = 15.0
"""White noise: P(excess > 15 dB) = exp(−ln2·31.6) ≈ 3e-10 per bin, < 1e-7 per frame over ~280 bins."""
WEAK_DB = 8.0
STRONG_RUN = 2
"""A run qualifies by strength (≥ STRONG_DB) once it has this many frames: a lone strong frame is a noise or speech
peak as often as a tone (measured: benchmarks/analyze.py, voicing false alarms)."""
MIN_RUN = 5
CLUTTER_GUARD_BINS = 30
"""Bins either side of a frame's strongest line left out of its clutter (the tone and its skirt)."""
CLUTTER_FRAMES = 10
CLUTTER_STEP_DB = 0.5
CLUTTER_STEPS = 16
CLUTTER_TARGET = 0.01
"""Adaptive thresholds (order-statistic CFAR, Rohling 1983): over the band's bins outside the strongest line's
guard, pooled over ±CLUTTER_FRAMES frames, the fraction ≥ WEAK_DB + s must not exceed this (dry noise: 0.76 % on
average, above 1 % in about one window in ten, which then asks 0.5 dB more of a new weak tone); s (a multiple of
CLUTTER_STEP_DB, at most CLUTTER_STEPS of them) raises WEAK_DB and STRONG_DB alike where the clutter's tail is
heavier — a reverberant room's response peaks, a voice."""
MIN_RUN_NEW = 8
"""Away from a voiced frame (a tone starting from nothing) a weak run needs this many frames over the clutter-raised
WEAK_DB, not MIN_RUN: a reverberant room's response peaks hold 5–8 frames under broadband noise (room-noise case:
2.7 % of frames voiced with MIN_RUN, 0.28 % with 8). Once a frame is voiced, runs within ANCHOR_FRAMES need
MIN_RUN again, so a weak tone that breaks up costs only its first run."""
MIN_RUN_HARMONIC = 10
"""While a harmonic sound (voice, buzz; :mod:`matcad.loop.harmonic`) is present within HARMONIC_NEAR_FRAMES of a
run, and no run of this length ended within ANCHOR_FRAMES before it, the run needs this many frames (~0.46 s):
neither the strength shortcut nor MIN_RUN. Speech-excited lines and room-response peaks last ≤ 8 frames
(benchmarks/analyze.py)."""
HARMONIC_NEAR_FRAMES = 4
ANCHOR_FRAMES = 10
STABLE_BINS = 2


def clutter_counts(excess: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame (rows of band excess, dB): how many bins outside CLUTTER_GUARD_BINS of the strongest stand
    ≥ WEAK_DB + k·CLUTTER_STEP_DB (k = 0 … CLUTTER_STEPS), and how many bins were counted."""
    cols = np.arange(excess.shape[1])
    outside = np.abs(cols[None, :] - np.argmax(excess, axis=1)[:, None]) > CLUTTER_GUARD_BINS
    levels = WEAK_DB + CLUTTER_STEP_DB * np.arange(CLUTTER_STEPS + 1)
    counts = ((excess[:, :, None] >= levels[None, None, :]) & outside[:, :, None]).sum(axis=1)
    return counts.astype(float), outside.sum(axis=1).astype(float)


class Clutter:
    """The band's clutter frame by frame (:func:`clutter_counts`) and the threshold shift it asks for around a
    frame (:meth:`shift_db`). Keeps the rows a later frame may still pool (:meth:`forget_before`)."""

    def __init__(self):
        self._counts = np.zeros((0, CLUTTER_STEPS + 1))  # per recent frame: clutter bins >= WEAK_DB + k*step
        self._bins = np.zeros(0)
        self._first = 0  # frame index of the first row kept

    def push(self, excess: np.ndarray) -> None:
        """Count a block of frames (rows of band excess, dB)."""
        counts, bins = clutter_counts(excess)
        self._counts = np.concatenate([self._counts, counts])
        self._bins = np.concatenate([self._bins, bins])

    def shift_db(self, i: int) -> float:
        """dB by which the clutter around frame ``i`` raises WEAK_DB and STRONG_DB (CLUTTER_TARGET)."""
        lo, hi = max(0, i - CLUTTER_FRAMES - self._first), i + CLUTTER_FRAMES + 1 - self._first
        fraction = self._counts[lo:hi].sum(axis=0) / max(1.0, self._bins[lo:hi].sum())
        return CLUTTER_STEP_DB * int(np.argmax(np.append(fraction, 0.0) <= CLUTTER_TARGET))

    def forget_before(self, i: int) -> None:
        """Drop the rows no frame from ``i`` on pools again."""
        drop = max(0, i - CLUTTER_FRAMES - 1 - self._first)
        self._counts, self._bins = self._counts[drop:], self._bins[drop:]
        self._first += drop


class Voicing:
    """The voicing state machine, one frame at a time (module docstring). :meth:`step` takes each frame's ridge
    excess, position and threshold shift; :attr:`state` is 1 per voiced frame, else 0; :meth:`hear` takes whether
    a harmonic sound is present, per frame, ahead of the frames stepped."""

    def __init__(self):
        self.state: list[int] = []
        self._harmonic_sound: list[bool] = []  # per frame heard: a harmonic sound below the band
        self._position = np.nan  # the ridge's position (bins) in the frame before
        self._run_start, self._run_max, self._marked = -1, -np.inf, 0  # current candidate run (none: start −1)
        self._anchor_end = -np.inf  # last frame of the latest run of MIN_RUN_HARMONIC frames
        self._run_lenient = False  # the current run would qualify near an established tone
        self._run_firm, self._run_max_shifted = 0, -np.inf  # its frames over the shifted WEAK_DB; its best, shifted
        self._voiced_end = -np.inf  # the latest voiced frame
        self._held: list[tuple[int, int]] = []  # such runs (first, last frame) not voiced, awaiting a tone

    def hear(self, harmonic_sound) -> None:
        """Whether a harmonic sound is present (:func:`matcad.loop.harmonic.harmonic_frames`), per frame."""
        self._harmonic_sound.extend(harmonic_sound)

    @property
    def heard(self) -> np.ndarray:
        """Per frame heard so far: whether a harmonic sound was present."""
        return np.array(self._harmonic_sound, dtype=bool)

    def step(self, excess_db: float, position_bins: float, shift_db: float) -> int:
        """Voice the next frame: its ridge's ``excess_db`` over the floor (−inf when the line is one of a harmonic
        comb), its ``position_bins`` in the band and the clutter's ``shift_db`` (:meth:`Clutter.shift_db`).
        Returns how many frames' voicing is now final.

        Candidate runs (frames ≥ WEAK_DB on a stable line) qualify by length (MIN_RUN) or strength (STRONG_RUN
        frames, one ≥ STRONG_DB). Away from an established tone (a run of MIN_RUN_HARMONIC frames within
        ANCHOR_FRAMES before it) a run must do more: near a harmonic sound it needs MIN_RUN_HARMONIC frames;
        elsewhere, with no voiced frame within ANCHOR_FRAMES before it, it needs MIN_RUN_NEW frames (or the
        strength shortcut) over both thresholds raised by ``shift_db``. A run that would have qualified otherwise
        is held, and voiced after all when an established tone starts within ANCHOR_FRAMES after it (a tone that
        begins while someone speaks or a fan blows in a reverberant room)."""
        i = len(self.state)
        self.state.append(0)
        e = excess_db
        shifted = e - shift_db
        start = self._run_start
        stable = start >= 0 and abs(position_bins - self._position) <= STABLE_BINS
        self._position = position_bins
        if e >= WEAK_DB and (start < 0 or stable):
            if start < 0:
                start, self._run_max, self._run_lenient = i, e, False
                self._run_firm, self._run_max_shifted = 0, shifted
            else:
                self._run_max = max(self._run_max, e)
                self._run_max_shifted = max(self._run_max_shifted, shifted)
        else:
            if start >= 0 and self._run_lenient and self.state[start] == 0:
                self._held.append((start, i - 1))
            start = i if e >= WEAK_DB else -1
            self._run_max, self._run_lenient, self._run_firm, self._run_max_shifted = e, False, 0, shifted
        self._run_firm += start >= 0 and shifted >= WEAK_DB
        self._run_start = start
        length = i - start + 1
        if start >= 0 and length >= MIN_RUN_HARMONIC:
            self._anchor_end = i
            for first, last in self._held:
                if start - last <= ANCHOR_FRAMES:
                    self._mark(first, last)
            self._held = []
        self._held = [h for h in self._held if i - h[1] <= ANCHOR_FRAMES + MIN_RUN_HARMONIC]
        lenient = start >= 0 and (length >= MIN_RUN or (length >= STRONG_RUN and self._run_max >= STRONG_DB))
        self._run_lenient |= lenient
        if start < 0:
            qualifies = False
        elif length >= MIN_RUN_HARMONIC or start - self._anchor_end <= ANCHOR_FRAMES:
            qualifies = lenient  # MIN_RUN_HARMONIC >= MIN_RUN: a run that long is lenient
        elif any(self._harmonic_sound[max(0, start - HARMONIC_NEAR_FRAMES):i + HARMONIC_NEAR_FRAMES + 1]):
            qualifies = False
        elif start - self._voiced_end <= ANCHOR_FRAMES:
            qualifies = lenient
        else:
            qualifies = self._run_firm >= MIN_RUN_NEW or (self._run_firm >= STRONG_RUN
                                                          and self._run_max_shifted >= STRONG_DB)
        if qualifies:
            self._mark(max(start, self._marked), i)
            self._marked = i + 1
            self._voiced_end = i
        stop = i + 1 if start < 0 or self.state[start] == 1 else start
        return min([stop] + [h[0] for h in self._held])

    def _mark(self, first, last):
        for j in range(first, last + 1):
            self.state[j] = 1


def longest_run(flags: np.ndarray) -> int:
    """Length of the longest stretch of consecutive True values."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return int(np.max(np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1), initial=0))
