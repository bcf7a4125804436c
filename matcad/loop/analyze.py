"""Frequency of a taxel's tone from a recording, frame by frame, in blocks (bounded memory, live streams).

The paper used MATLAB spectrogram + tfridge and a pspectrum peak in 4–5.5 kHz. Here, per frame (Hann window
~93 ms, 2× zero padding, 50 % overlap; :class:`Framer`):

1. *Strength over the local floor.* Each bin's power is divided by the running median of the power over
   ±:data:`FLOOR_BINS`/2 bins (≈ ±170 Hz) around it: the excess in dB. The median follows coloured noise (pink,
   brown, a speech or fan hump) where a band-wide mean would not. Under white or smoothly coloured noise a bin's
   power is exponential; with a *known* median the tail would be exp(−ln 2 · 10^(x/10)) per bin, but the floor is
   itself estimated from ~30 independent bins, so the measured tail is far heavier: 1.2e-4 over 12 dB (law 2e-5),
   ~8e-7 over 15 dB (law 3e-10) per bin (benchmarks/analyze.py; the order-statistic law for a median of 31–41
   bins brackets it within ×2). A lone frame whose ridge stands ≥ 15 dB came 5 times in 116 100 noise frames.
2. *Mains combs removed.* A line with lines of similar level (within :data:`COMB_LEVEL_DB`) at ±Δ and ±2Δ
   (Δ = 50, 60, 100 or 120 Hz; 3 of the 4 places) belongs to hum or buzz, not to a taxel, whose neighbours are
   not a comb: its bins are removed before tracking.
3. *Ridge with a jump allowance.* A Viterbi path through the excess: moving Δ bins costs
   :data:`JUMP_PENALTY_DB`·Δ² up to :data:`MAX_STEP_BINS`, any larger jump a flat :data:`JUMP_COST_DB` — so the
   ridge follows a slow wobble smoothly, re-acquires after a gap and follows a press that jumps 300 Hz between
   frames. Decisions are made with a fixed lag of :data:`LAG_FRAMES` frames (~1 s), which bounds memory.
4. *Voicing.* A frame is voiced (the tone is there) when it belongs to a run of frames whose ridge stays within
   ±:data:`STABLE_BINS` bins and stands ≥ :data:`WEAK_DB` over the floor, and the run is either
   ≥ :data:`MIN_RUN` frames long or ≥ :data:`STRONG_RUN` frames with one ≥ :data:`STRONG_DB` (a lone strong frame
   is not enough: see 1). A line that is one of a harmonic comb (:func:`_in_harmonic_comb`: a voice) is no
   candidate. While a harmonic sound — a voice or buzz, recognised by its resolved low harmonics below the band
   (:mod:`matcad.loop.harmonic`) — is present and no tone has been established (a run of
   :data:`MIN_RUN_HARMONIC` frames within :data:`ANCHOR_FRAMES`), a run needs MIN_RUN_HARMONIC frames (~0.46 s):
   a voice's smeared high harmonics and the room's response peaks it excites leave steady-looking lines of 2–8
   frames. A run that would have qualified otherwise is held and voiced after all if such a run starts within
   ANCHOR_FRAMES after it. Away from a voiced frame (ANCHOR_FRAMES) a weak run needs :data:`MIN_RUN_NEW` frames and
   the thresholds also adapt to the clutter
   (order-statistic CFAR): where the band's other bins, pooled over ±:data:`CLUTTER_FRAMES` frames, stand
   ≥ WEAK_DB more often than :data:`CLUTTER_TARGET` (dry noise: 0.76 %), WEAK_DB and STRONG_DB rise together until
   they do not — broadband noise through a reverberant room has a tail ~3× heavier at 8 dB, ~10× at 10 dB, from
   the room's response peaks. Design value: at most 1e-4 falsely voiced frames per frame of noise (one per ~8 min);
   measured 0 in 116 100 frames (3.2e7 frame × bins; 30 min each of white, pink and brown noise), 95 % upper
   bound 2.6e-5 per frame (benchmarks/analyze.py --noise-minutes 30). Synthetic speech alone: 0 frames voiced in
   20 seeds (was 3.4 %). Reduced, not rejected: broadband noise heard through a reverberant room (RT60 0.6 s)
   voices 0.28 % of frames over 5 seeds ("no tone" in 4; 6.5 % before the adaptive thresholds and MIN_RUN_NEW;
   room-noise case) — its lines at the room's response peaks can be as steady as a weak tone; when no voiced
   stretch lasts MIN_RUN_HARMONIC frames the analysis warns that the frames may be such peaks (every room-noise
   false alarm measured; no case with a tone).
   The threshold is a strength and a stability, never a fraction of the file: 1 s of clear tone in a 10 min file
   is found.
5. *Segments.* Voiced frames are cut into steady segments at gaps and at steps larger than :data:`STEP_HZ`
   between frames; a segment that sits more than :data:`MODE_JUMP_RATIO` above or below the one before it,
   without a ramp in between, cannot be a press (Eq. 5 spans ~+11 % from 0 to 25 N): it is flagged as a mode
   jump (overblowing) and its frames are left out of the statistics.
6. *Other sources.* A second stable line in the band (a neighbouring taxel) is reported with its frequency and
   level; a stronger tone outside the band (hum, a harmonic) is reported, never taken. When a second tone of
   similar level shares the band, :mod:`matcad.loop.crossing` keeps the taxel on its own line where the ridge
   hops to the other or the two cross (by slope, else level), and leaves out, with a warning, the frames after a
   crossing whose identity nothing decides.

Frequencies Hz, times s, levels dB.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from matcad.loop import LoopError
from matcad.loop.harmonic import harmonic_frames

WINDOW_S = 0.093
"""~4096 samples at 44.1 kHz: ~11 Hz resolution (5.4 Hz bins with 2× padding), 46 ms between frames."""
ZERO_PAD = 2
FLOOR_BINS = 63
"""Width of the running median that sets the local noise floor (≈ 340 Hz at 44.1 kHz)."""
EXCLUDE_BINS = 6
"""Bins either side of a line that belong to it (Hann main lobe is ±4 bins at 2× padding)."""
JUMP_PENALTY_DB = 1.0
MAX_STEP_BINS = 4
JUMP_COST_DB = 14.0
"""Any jump wider than MAX_STEP_BINS costs this once: a tone ≥ STRONG_DB repays it in one frame, noise does not."""
LAG_FRAMES = 20
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
guard, pooled over ±CLUTTER_FRAMES frames, the fraction ≥ WEAK_DB + s must not exceed this (dry noise: 0.76 % on average,
above 1 % in about one window in ten, which then asks 0.5 dB more of a new weak tone); s (a multiple of CLUTTER_STEP_DB, at most CLUTTER_STEPS of them) raises WEAK_DB
and STRONG_DB alike where the clutter's tail is heavier — a reverberant room's response peaks, a voice."""
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
COMB_SPACINGS_HZ = (50.0, 60.0, 100.0, 120.0)
COMB_LEVEL_DB = 10.0
COMB_GRID_FRACTION = 0.6
COMB_ZONE_BINS = 3
HARMONIC_SPACING_HZ = (80.0, 400.0)
HARMONIC_TESTS = (((-2, -1, 1, 2), 3, 2, 8.0), ((-4, -3, -2, -1, 1, 2, 3, 4), 5, 1, 6.0))
"""(multiples of Δ, how many must hold a line, within ± bins, line level dB): a line with such neighbours, Δ in
the speech pitch range HARMONIC_SPACING_HZ, is a harmonic (see :func:`_in_harmonic_comb`)."""
LINE_DB = 6.0
"""A local maximum this far over the floor counts as a line in the comb and second-source tests."""
STEP_HZ = 12.0
"""Frame-to-frame change that ends a steady segment (a ±20 Hz wobble over 2.5 s moves ≤ 2.5 Hz per frame; a
2→12 N press ramped in 0.2 s moves ~60 Hz per frame)."""
MIN_SEGMENT_FRAMES = 3
MAX_GAP_FRAMES = 1
MODE_JUMP_RATIO = 1.11
JUMP_GAP_FRAMES = 8
"""A jump across at most this many frames (~0.37 s) with no voiced frame between the two levels is abrupt."""
SECOND_SOURCE_FRACTION = 0.5
EDGE_BINS = 2
PLOT_COLUMNS = 1200


@dataclass(frozen=True)
class Segment:
    """A steady stretch of the tone: start and end (s), frames, mean/median/sd of frequency (Hz), and a flag
    ('' or why its frames are not the taxel's load-bearing tone)."""

    start_s: float
    end_s: float
    frames: int
    mean_hz: float
    median_hz: float
    std_hz: float
    flag: str = ""

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Source:
    """Another line in the band: median frequency (Hz), median level relative to the tracked tone (dB) and the
    fraction of voiced frames it was present in."""

    frequency_hz: float
    relative_db: float
    fraction: float


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`analyze`: statistics over voiced frames, the per-frame track, segments and warnings."""

    mean_hz: float
    median_hz: float
    std_hz: float
    snr_db: float
    prominence_db: float
    tone_fraction: float
    band_hz: tuple[float, float]
    sample_rate_hz: float
    duration_s: float
    times_s: np.ndarray = field(repr=False)
    track_hz: np.ndarray = field(repr=False)
    frame_snr_db: np.ndarray = field(repr=False)
    voiced: np.ndarray = field(repr=False)
    """True where the tone is present and is the taxel's (not a flagged mode jump)."""
    segments: tuple[Segment, ...] = ()
    sources: tuple[Source, ...] = ()
    plot_times_s: np.ndarray = field(repr=False, default=None)
    plot_freqs_hz: np.ndarray = field(repr=False, default=None)
    plot_db: np.ndarray = field(repr=False, default=None)  # frequency × column, max-pooled in time
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return {"mean_hz": self.mean_hz, "median_hz": self.median_hz, "std_hz": self.std_hz,
                "snr_db": self.snr_db, "prominence_db": self.prominence_db, "tone_fraction": self.tone_fraction,
                "band_hz": list(self.band_hz), "sample_rate_hz": self.sample_rate_hz,
                "duration_s": self.duration_s, "frames": int(len(self.track_hz)),
                "voiced_frames": int(np.sum(self.voiced)), "segments": [s.to_dict() for s in self.segments],
                "other_sources": [{"frequency_hz": s.frequency_hz, "relative_db": s.relative_db,
                                   "fraction": s.fraction} for s in self.sources],
                "warnings": list(self.warnings)}


def window_samples(fs: float) -> int:
    """Window length (samples): the power of two nearest WINDOW_S."""
    return max(64, int(2 ** round(np.log2(WINDOW_S * fs))))


class Framer:
    """Blocks of samples in, Hann-windowed power spectra (frames × frequency, one-sided PSD) out.

    Frame k covers samples [k·hop, k·hop + n); its time is its centre. Only frames lying wholly inside the input
    are produced. Keeps at most one window of samples between calls.
    """

    def __init__(self, fs: float, n: int | None = None):
        self.fs = float(fs)
        self.n = n or window_samples(fs)
        self.hop = self.n // 2
        self.mfft = ZERO_PAD * self.n
        self.window = np.hanning(self.n + 1)[:-1]
        self.scale = 2.0 / (self.fs * np.sum(self.window**2))
        self.freqs = np.fft.rfftfreq(self.mfft, 1.0 / self.fs)
        self._carry = np.zeros(0)
        self.frames = 0  # frames produced so far

    def feed(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(frame times s, power frames × bins) for every frame completed by ``x``."""
        buf = np.concatenate([self._carry, np.asarray(x, dtype=float)])
        count = 0 if len(buf) < self.n else (len(buf) - self.n) // self.hop + 1
        if count == 0:
            self._carry = buf
            return np.zeros(0), np.zeros((0, len(self.freqs)))
        frames = np.lib.stride_tricks.sliding_window_view(buf, self.n)[: count * self.hop: self.hop]
        power = np.abs(np.fft.rfft(frames * self.window, n=self.mfft, axis=1)) ** 2 * self.scale
        times = ((self.frames + np.arange(count)) * self.hop + self.n / 2) / self.fs
        self.frames += count
        self._carry = buf[count * self.hop:]
        return times, power


class BandTracker:
    """One taxel's tone in one band, block by block: floor, comb removal, ridge, voicing, segments.

    ``push(times, power)`` takes frames from a :class:`Framer`; ``finish()`` returns the :class:`Analysis`.
    Everything but the Viterbi recursion (one vector step per frame) and the voicing state machine (a few scalar
    operations per frame) works on whole blocks of frames: the floor is one running median over the block's rows
    laid end to end, the fixed-lag decisions of a block are one vectorised backtrack, peak refinement and the
    harmonic test act on all decided frames at once. Frames whose bin is not yet decided (≤ LAG_FRAMES) are kept;
    the arrays kept grow by eight numbers per frame (~0.1 MB per minute of audio); the plot is max-pooled to at
    most 2·PLOT_COLUMNS columns. ``on_frame`` (optional) is called with (time s, frequency Hz or NaN, excess dB)
    as each frame's voicing becomes final, for live output.
    """

    def __init__(self, freqs: np.ndarray, fs: float, band_hz: tuple[float, float], on_frame=None):
        nyquist = fs / 2
        lo, hi = max(0.0, band_hz[0]), min(band_hz[1], nyquist)
        if not lo < hi:
            raise ValueError(f"band {band_hz[0]:g}-{band_hz[1]:g} Hz invalid for a {fs:g} Hz recording "
                             f"(must lie below {nyquist:g} Hz)")
        self.fs, self.band = fs, (lo, hi)
        self.df = float(freqs[1] - freqs[0])
        self.in_band = np.flatnonzero((freqs >= lo) & (freqs <= hi))
        if len(self.in_band) < 2 * EXCLUDE_BINS + 3:
            raise ValueError(f"band {lo:g}-{hi:g} Hz is narrower than the analysis needs "
                             f"({(2 * EXCLUDE_BINS + 3) * self.df:.0f} Hz)")
        margin = max(FLOOR_BINS // 2, int(np.ceil(2 * max(COMB_SPACINGS_HZ) / self.df)) + 2)
        self.slab = np.arange(max(0, self.in_band[0] - margin), min(len(freqs), self.in_band[-1] + margin + 1))
        self.offset = int(self.in_band[0] - self.slab[0])
        self.freqs = freqs
        self.on_frame = on_frame
        nb = len(self.in_band)
        steps = np.arange(-MAX_STEP_BINS, MAX_STEP_BINS + 1)
        src = np.arange(nb)[None, :] - steps[:, None]  # bin a state comes from, per step
        self._src = np.clip(src, 0, nb - 1)
        self._cost = np.where((src >= 0) & (src < nb), JUMP_PENALTY_DB * steps[:, None].astype(float) ** 2, np.inf)
        self._score = None
        # frames not yet decided: time, band log power, band excess, band lines, slab lines, back pointers and the
        # best state of each frame's score
        self._p_times = np.zeros(0)
        self._p_log = np.zeros((0, nb))
        self._p_excess = np.zeros((0, nb))
        self._p_lines = np.zeros((0, nb))
        self._p_slab_lines = np.zeros((0, len(self.slab)))
        self._p_back = np.zeros((0, nb), dtype=np.intp)
        self._p_best = np.zeros(0, dtype=np.intp)
        self.times, self.track, self.excess, self.state, self.other_bin, self.other_excess = [], [], [], [], [], []
        self.other_level, self.harmonic = [], []
        self._run_start, self._run_max, self._marked = -1, -np.inf, 0  # current candidate run (none: start −1)
        self._harmonic_sound: list[bool] = []  # per frame pushed: a harmonic sound below the band
        self._clutter = np.zeros((0, CLUTTER_STEPS + 1))  # per recent frame: clutter bins >= WEAK_DB + k*step
        self._clutter_bins = np.zeros(0)
        self._clutter_first = 0  # frame index of the first row kept
        self._anchor_end = -np.inf  # last frame of the latest run of MIN_RUN_HARMONIC frames
        self._run_lenient = False  # the current run would qualify near an established tone
        self._run_firm, self._run_max_shifted = 0, -np.inf  # its frames over the shifted WEAK_DB; its best, shifted
        self._voiced_end = -np.inf  # the latest voiced frame
        self._held: list[tuple[int, int]] = []  # such runs (first, last frame) not voiced, awaiting a tone
        self._voice_done = 0  # frames whose voicing is final
        self._plot_cols: list[np.ndarray] = []
        self._plot_times: list[float] = []
        self._pool = 1
        self._pool_acc: list[np.ndarray] = []
        self.band_peak_power = np.zeros(nb)

    # --- per block --------------------------------------------------------------------------------------------
    def push(self, times: np.ndarray, power: np.ndarray) -> None:
        if len(times) == 0:
            return
        from scipy.ndimage import maximum_filter1d

        tiny = np.finfo(float).tiny
        slab = power[:, self.slab]
        floor = _running_median_rows(slab, FLOOR_BINS)
        excess_slab = 10 * np.log10((slab + tiny) / (floor + tiny))
        log_slab = 10 * np.log10(slab + tiny)
        nb = len(self.in_band)
        band = slice(self.offset, self.offset + nb)
        # lines: local maxima LINE_DB over the floor
        is_max = (excess_slab >= maximum_filter1d(excess_slab, 3, axis=1)) & (excess_slab >= LINE_DB)
        lines = np.where(is_max, excess_slab, -np.inf)
        comb_zone = maximum_filter1d(self._mains_comb(lines).astype(np.uint8), 2 * COMB_ZONE_BINS + 1,
                                     axis=1).astype(bool)
        emit = np.where(comb_zone[:, band], 0.0, np.clip(excess_slab[:, band], 0.0, None))
        band_lines = np.where(comb_zone[:, band], -np.inf, lines[:, band])
        self.band_peak_power += slab[:, band].sum(axis=0)
        self._harmonic_sound.extend(harmonic_frames(power, self.freqs, self.band[0]).tolist())
        counts, bins = _clutter_counts(excess_slab[:, band])
        self._clutter = np.concatenate([self._clutter, counts])
        self._clutter_bins = np.concatenate([self._clutter_bins, bins])
        self._plot(times, log_slab[:, band])
        back, best = self._forward(emit)
        self._p_times = np.concatenate([self._p_times, times])
        self._p_log = np.concatenate([self._p_log, log_slab[:, band]])
        self._p_excess = np.concatenate([self._p_excess, excess_slab[:, band]])
        self._p_lines = np.concatenate([self._p_lines, band_lines])
        self._p_slab_lines = np.concatenate([self._p_slab_lines, lines])
        self._p_back = np.concatenate([self._p_back, back])
        self._p_best = np.concatenate([self._p_best, best])
        ready = len(self._p_times) - LAG_FRAMES  # pending frame j is decided once frame j + LAG_FRAMES is in
        if ready > 0:
            # fixed lag: frame j's bin is the best path ending at frame j + LAG, traced back LAG steps
            states = self._p_best[LAG_FRAMES:LAG_FRAMES + ready].copy()
            rows = np.arange(ready)
            for s in range(LAG_FRAMES, 0, -1):
                states = self._p_back[rows + s, states]
            self._decide(ready, states)
        drop = max(0, self._voice_done - CLUTTER_FRAMES - 1 - self._clutter_first)  # rows no frame will pool again
        self._clutter, self._clutter_bins = self._clutter[drop:], self._clutter_bins[drop:]
        self._clutter_first += drop

    def _forward(self, emit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Viterbi recursion over a block's emissions (frames × bins, dB): back pointers and each frame's best
        state. Moving Δ ≤ MAX_STEP_BINS bins costs JUMP_PENALTY_DB·Δ², any jump JUMP_COST_DB from the best state;
        the score is renormalised to a maximum of 0 every frame."""
        n, nb = emit.shape
        back = np.empty((n, nb), dtype=np.intp)
        best = np.empty(n, dtype=np.intp)
        cols = np.arange(nb)
        score = self._score
        for i in range(n):
            if score is None:
                score = emit[i].copy()
                back[i] = cols
            else:
                cand = score[self._src] - self._cost
                pick = np.argmax(cand, axis=0)
                local = cand[pick, cols]
                jump_from = int(np.argmax(score))
                far = score[jump_from] - JUMP_COST_DB
                back[i] = np.where(local >= far, self._src[pick, cols], jump_from)
                score = np.maximum(local, far) + emit[i]
                score -= score.max()
            best[i] = np.argmax(score)
        self._score = score
        return back, best

    def _mains_comb(self, lines: np.ndarray) -> np.ndarray:
        """Lines (frames × slab bins) that sit on a mains grid m·S (S = 50, 60, 100, 120 Hz) which hosts lines at
        ≥ COMB_GRID_FRACTION of its places in the frame, unless COMB_LEVEL_DB above the grid's median line."""
        from scipy.ndimage import maximum_filter1d

        near = maximum_filter1d(lines, 3, axis=1)
        f0 = self.freqs[self.slab[0]]
        members = np.zeros(lines.shape, dtype=bool)
        for spacing in COMB_SPACINGS_HZ:
            m = np.arange(np.ceil(f0 / spacing), np.floor(self.freqs[self.slab[-1]] / spacing) + 1)
            grid = np.round((m * spacing - f0) / self.df).astype(int)
            grid = grid[(grid >= 1) & (grid < lines.shape[1] - 1)]
            if len(grid) < 8:
                continue
            hosted = near[:, grid]
            ok = np.isfinite(hosted)
            comb = np.mean(ok, axis=1) >= COMB_GRID_FRACTION
            if not np.any(comb):
                continue
            level = np.nanmedian(np.where(ok, hosted, np.nan)[comb], axis=1)
            on_grid = np.zeros(lines.shape[1], dtype=bool)
            on_grid[np.concatenate([grid - 1, grid, grid + 1])] = True
            members[comb] |= on_grid[None, :] & np.isfinite(lines[comb]) & (lines[comb] < level[:, None] + COMB_LEVEL_DB)
        return members

    def _plot(self, times, log_band):
        for t, row in zip(times, log_band):
            self._pool_acc.append(row.astype(np.float32))
            if len(self._pool_acc) == self._pool:
                self._plot_cols.append(np.max(self._pool_acc, axis=0))
                self._plot_times.append(t)
                self._pool_acc = []
                if len(self._plot_cols) >= 2 * PLOT_COLUMNS:
                    self._plot_cols = [np.maximum(a, b) for a, b in zip(self._plot_cols[::2], self._plot_cols[1::2])]
                    self._plot_times = self._plot_times[1::2]
                    self._pool *= 2

    def _decide(self, count: int, states: np.ndarray) -> None:
        """The oldest ``count`` pending frames' ridge bins are ``states``: refine each to the highest of its ±1
        bins with a parabolic peak (dB), note the strongest other line, test harmonicity, pass them to voicing."""
        nb = self._p_log.shape[1]
        rows = np.arange(count)
        log = self._p_log[:count]
        near = states[:, None] + np.arange(-1, 2)[None, :]
        level = np.where((near >= 0) & (near < nb), log[rows[:, None], np.clip(near, 0, nb - 1)], -np.inf)
        peak = np.clip(near[rows, np.argmax(level, axis=1)], 1, nb - 2)
        l, m, r = log[rows, peak - 1], log[rows, peak], log[rows, peak + 1]
        denom = l - 2 * m + r
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(denom < 0, np.clip(0.5 * (l - r) / denom, -0.5, 0.5), 0.0)
        freq = self.freqs[self.in_band[0]] + (peak + delta) * self.df
        masked = np.where(np.abs(np.arange(nb)[None, :] - peak[:, None]) <= EXCLUDE_BINS, -np.inf,
                          self._p_lines[:count])
        other = np.argmax(masked, axis=1)
        other_excess = masked[rows, other]
        other_level = np.where(np.isfinite(other_excess), log[rows, other] - m, -np.inf)
        harmonic = _in_harmonic_comb(self._p_slab_lines[:count], peak + self.offset, self.df)
        excess = self._p_excess[rows, peak]
        first = len(self.track)
        self.times.extend(self._p_times[:count].tolist())
        self.track.extend(freq.tolist())
        self.excess.extend(excess.tolist())
        self.state.extend([0] * count)
        self.other_bin.extend(other.tolist())
        self.other_excess.extend(other_excess.tolist())
        self.other_level.extend(other_level.tolist())
        self.harmonic.extend(harmonic.tolist())
        for name in ("_p_times", "_p_log", "_p_excess", "_p_lines", "_p_slab_lines", "_p_back", "_p_best"):
            setattr(self, name, getattr(self, name)[count:])
        for i in range(first, first + count):
            self._voice(i)

    def _voice(self, i):
        """Voicing state machine: candidate runs (frames ≥ WEAK_DB on a stable line; a frame whose line is one of a
        harmonic comb is none) qualify by length (MIN_RUN) or strength (STRONG_RUN frames, one ≥ STRONG_DB). Away from
        an established tone (a run of MIN_RUN_HARMONIC frames within ANCHOR_FRAMES before it) a run must do more:
        near a harmonic sound it needs MIN_RUN_HARMONIC frames; elsewhere, with no voiced frame within ANCHOR_FRAMES
        before it, it needs MIN_RUN_NEW frames (or the strength shortcut) over both thresholds raised by the
        clutter's shift (:meth:`_threshold_shift`). A run that would have qualified otherwise is held, and voiced
        after all when an established tone starts within ANCHOR_FRAMES after it (a tone that begins while someone
        speaks or a fan blows in a reverberant room)."""
        e = -np.inf if self.harmonic[i] else self.excess[i]
        shifted = e - self._threshold_shift(i)
        start = self._run_start
        stable = start >= 0 and abs(self._bin_of(i) - self._bin_of(i - 1)) <= STABLE_BINS
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
        self._emit_until(min([stop] + [h[0] for h in self._held]))

    def _threshold_shift(self, i):
        """dB by which the clutter around frame ``i`` raises WEAK_DB and STRONG_DB (CLUTTER_TARGET)."""
        lo, hi = max(0, i - CLUTTER_FRAMES - self._clutter_first), i + CLUTTER_FRAMES + 1 - self._clutter_first
        fraction = self._clutter[lo:hi].sum(axis=0) / max(1.0, self._clutter_bins[lo:hi].sum())
        return CLUTTER_STEP_DB * int(np.argmax(np.append(fraction, 0.0) <= CLUTTER_TARGET))

    def _mark(self, first, last):
        for j in range(first, last + 1):
            self.state[j] = 1

    def _bin_of(self, i):
        return (self.track[i] - self.freqs[self.in_band[0]]) / self.df

    def _emit_until(self, stop):
        if self.on_frame is not None:
            for j in range(self._voice_done, stop):
                self.on_frame(self.times[j], self.track[j] if self.state[j] else float("nan"), self.excess[j])
        self._voice_done = max(self._voice_done, stop)

    # --- end of input ---------------------------------------------------------------------------------------
    def finish(self, duration_s: float, full_mean_power: np.ndarray | None = None, others=()) -> Analysis:
        """The :class:`Analysis` of everything pushed. ``full_mean_power`` (the whole spectrum's mean) lets a
        stronger tone outside the band be reported; one inside another taxel's band (``others``, Hz) is that
        taxel's, not reported here."""
        count = len(self._p_times)
        if count:  # the rest: one backtrack from the best final state
            states = np.empty(count, dtype=np.intp)
            states[-1] = self._p_best[-1]
            for j in range(count - 1, 0, -1):
                states[j - 1] = self._p_back[j, states[j]]
            self._decide(count, states)
        self._run_start = -1
        self._emit_until(len(self.track))
        if self._pool_acc:
            self._plot_cols.append(np.max(self._pool_acc, axis=0))
            self._plot_times.append(self.times[-1] if self.times else 0.0)
        times, track = np.array(self.times), np.array(self.track)
        excess, state = np.array(self.excess), np.array(self.state, dtype=int)
        lo, hi = self.band
        loudest = ""
        if full_mean_power is not None and len(times):
            loudest = _strongest_outside(self.freqs, full_mean_power, [(lo, hi), *others],
                                         float(self.band_peak_power.max() / len(times)))
        hint = f"; {loudest}" if loudest else ""
        if len(track) == 0:
            raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz: the recording is shorter than one "
                            f"{WINDOW_S * 1e3:.0f} ms analysis window")
        if not np.any(state == 1):
            raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz: no frame has a line >= {STRONG_DB:g} dB over the "
                            f"local noise floor, nor >= {WEAK_DB:g} dB steady for {MIN_RUN} frames (best frame "
                            f"{np.max(excess):.1f} dB){hint}")
        from matcad.loop.crossing import follow_taxel  # the taxel's line through hops and crossings of two tones

        ident = follow_taxel(times, track, state, np.array(self.other_bin), np.array(self.other_excess),
                             np.array(self.other_level), excess, self.freqs[self.in_band])
        track, state, segments = ident.track_hz, ident.state, list(ident.segments)
        flagged = [s for s in segments if s.flag]
        for s in flagged:
            state[(times >= s.start_s) & (times <= s.end_s) & (state == 1)] = 2
        voiced = state == 1
        if not np.any(voiced):
            raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz that can be the taxel's: every voiced frame is in a "
                            f"flagged segment ({flagged[0].flag}){hint}")
        nb = len(self.in_band)
        path = (track[voiced] - self.freqs[self.in_band[0]]) / self.df
        edge = np.mean((path <= EDGE_BINS) | (path >= nb - 1 - EDGE_BINS))
        if edge > 0.5:
            raise LoopError(f"the ridge hugs the band edge ({100 * edge:.0f} % of voiced frames within {EDGE_BINS} "
                            f"bins of {lo:.0f} or {hi:.0f} Hz): the tone is probably outside the band; widen "
                            f"it{hint}")
        other_excess, other_level = ident.other_excess, ident.other_level
        sources = _second_sources(ident.other_bin[voiced], other_excess[voiced], other_level[voiced],
                                  self.freqs[self.in_band])
        warnings = list(ident.warnings)
        if loudest:
            warnings.append(f"{loudest} was ignored: hum, a harmonic or another source")
        for s in sources:
            which = "stronger than" if s.relative_db > 0 else "weaker than"
            warnings.append(f"a second tone near {s.frequency_hz:.0f} Hz in {100 * s.fraction:.0f} % of voiced "
                            f"frames, {abs(s.relative_db):.1f} dB {which} the tracked one: another taxel or an "
                            "overtone; if it is the taxel, narrow the band with --band")
        for s in flagged:
            warnings.append(f"{s.start_s:.2f}-{s.end_s:.2f} s at {s.mean_hz:.0f} Hz: {s.flag}; left out")
        longest = _longest_run(voiced)
        if longest < MIN_RUN_HARMONIC:
            seconds = MIN_RUN_HARMONIC * (window_samples(self.fs) // 2) / self.fs
            warnings.append(f"no voiced stretch lasts {MIN_RUN_HARMONIC} frames ({seconds:.2f} s; the longest: "
                            f"{longest}): these may be a room's response peaks or another transient rather than a "
                            "singing taxel")
        prom = np.where(np.isfinite(other_level[voiced]), -other_level[voiced], excess[voiced])
        return Analysis(mean_hz=float(np.mean(track[voiced])), median_hz=float(np.median(track[voiced])),
                        std_hz=float(np.std(track[voiced])), snr_db=float(np.median(excess[voiced])),
                        prominence_db=float(np.median(prom)), tone_fraction=float(np.mean(voiced)),
                        band_hz=(lo, hi), sample_rate_hz=self.fs, duration_s=duration_s, times_s=times,
                        track_hz=track, frame_snr_db=excess, voiced=voiced, segments=tuple(segments),
                        sources=tuple(sources), plot_times_s=np.array(self._plot_times),
                        plot_freqs_hz=self.freqs[self.in_band], plot_db=np.array(self._plot_cols).T,
                        warnings=tuple(warnings))


def _segments(times, track, state, df) -> list[Segment]:
    """Steady segments of voiced frames. A segment reached by an abrupt jump (no ramp frames) of more than
    MODE_JUMP_RATIO whose mean also lies that far from the median of all voiced frames is flagged as a mode
    jump."""
    runs, cur = [], []
    for i in np.flatnonzero(state >= 1):
        if cur and (i - cur[-1] > MAX_GAP_FRAMES + 1 or abs(track[i] - track[cur[-1]]) > STEP_HZ):
            runs.append(cur)
            cur = []
        cur.append(int(i))
    if cur:
        runs.append(cur)
    reference = float(np.median(track[state >= 1]))
    out, last = [], None
    for run in runs:
        if len(run) < MIN_SEGMENT_FRAMES:
            continue
        f = track[run]
        mean = float(np.mean(f))
        flag = ""
        between = track[last[1] + 1:run[0]][state[last[1] + 1:run[0]] >= 1] if last is not None else []
        abrupt = (last is not None and run[0] - last[1] <= JUMP_GAP_FRAMES
                  and not np.any((between - last[0]) * (between - mean) < 0))  # no ramp frame in between
        ratio = mean / reference
        far = max(ratio, 1 / ratio) > MODE_JUMP_RATIO
        if far and abrupt and max(mean / last[0], last[0] / mean) > MODE_JUMP_RATIO:
            flag = (f"abrupt jump x{mean / last[0]:.3f} from {last[0]:.0f} Hz, x{ratio:.3f} from the recording's "
                    f"median, more than a press can give (Eq. 5: x{MODE_JUMP_RATIO:g} over 0-25 N): a mode jump "
                    "(overblowing)")
        elif far and last is not None and last[2] and max(mean / last[0], last[0] / mean) <= MODE_JUMP_RATIO:
            flag = last[2]  # the same jumped mode, after a dropout
        last = (mean, run[-1], flag)
        out.append(Segment(float(times[run[0]]), float(times[run[-1]]), len(run), mean, float(np.median(f)),
                           float(np.std(f)), flag))
    return out


def _longest_run(flags: np.ndarray) -> int:
    """Length of the longest stretch of consecutive True values."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return int(np.max(np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1), initial=0))


def _running_median_rows(rows: np.ndarray, width: int) -> np.ndarray:
    """Median over ``width`` (odd) neighbouring columns of each row, edges continued by their end values (the
    same numbers as scipy's median_filter(size=(1, width), mode='nearest')). The rows are laid end to end, each
    padded by its own edge values, and filtered in one 1-D pass: ~15× faster than the 2-D filter."""
    from scipy.ndimage import median_filter

    half = width // 2
    padded = np.pad(rows, ((0, 0), (half, half)), mode="edge")
    return median_filter(padded.ravel(), size=width, mode="nearest").reshape(padded.shape)[:, half:-half]


def _clutter_counts(excess: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame (rows of band excess, dB): how many bins outside CLUTTER_GUARD_BINS of the strongest stand
    ≥ WEAK_DB + k·CLUTTER_STEP_DB (k = 0 … CLUTTER_STEPS), and how many bins were counted."""
    cols = np.arange(excess.shape[1])
    outside = np.abs(cols[None, :] - np.argmax(excess, axis=1)[:, None]) > CLUTTER_GUARD_BINS
    levels = WEAK_DB + CLUTTER_STEP_DB * np.arange(CLUTTER_STEPS + 1)
    counts = ((excess[:, :, None] >= levels[None, None, :]) & outside[:, :, None]).sum(axis=1)
    return counts.astype(float), outside.sum(axis=1).astype(float)


def _in_harmonic_comb(lines: np.ndarray, p: np.ndarray, df: float) -> np.ndarray:
    """Per frame (rows of ``lines``, dB over the floor, −inf where no line): True when the line at bin ``p`` is one
    of a harmonic comb of spacing Δ in HARMONIC_SPACING_HZ (a voice, or any periodic sound), not a taxel. Two
    tests (:data:`HARMONIC_TESTS`): lines ≥ 8 dB within ±2 bins at 3 of ±Δ, ±2Δ (resolved harmonics), or lines
    ≥ 6 dB within ±1 bin at 5 of ±Δ … ±4Δ (a wider comb of weaker, partly smeared harmonics). Each neighbour must
    also be within COMB_LEVEL_DB of the line. A taxel's own skirt (jet noise through the resonator, ~±100 Hz)
    reaches ±Δ, not ±3Δ."""
    from scipy.ndimage import maximum_filter1d

    k, n = lines.shape
    rows = np.arange(k)
    level = lines[rows, p]
    d = np.arange(int(HARMONIC_SPACING_HZ[0] / df), int(HARMONIC_SPACING_HZ[1] / df) + 1)
    found = np.zeros(k, dtype=bool)
    for orders, hits, tolerance, line_db in HARMONIC_TESTS:
        need = np.maximum(line_db, level - COMB_LEVEL_DB)
        near = maximum_filter1d((lines >= need[:, None]).astype(np.uint8), 2 * tolerance + 1, axis=1,
                                mode="constant") > 0
        at = p[:, None, None] + np.array(orders)[None, :, None] * d[None, None, :]
        hit = near[rows[:, None, None], np.clip(at, 0, n - 1)] & (at >= 0) & (at < n)
        found |= np.any(hit.sum(axis=1) >= hits, axis=1)
    return np.isfinite(level) & found


def _second_sources(other_bin, other_excess, other_level, band_freqs) -> list[Source]:
    """A second line present (≥ WEAK_DB over its floor) in ≥ SECOND_SOURCE_FRACTION of voiced frames, clustered
    in frequency; its level relative to the tracked line (dB of power)."""
    if len(other_bin) == 0:
        return []
    present = other_excess >= WEAK_DB
    if np.mean(present) < SECOND_SOURCE_FRACTION:
        return []
    bins = other_bin[present]
    centre = np.median(bins)
    close = np.abs(bins - centre) <= 3 * STABLE_BINS
    if np.sum(close) < SECOND_SOURCE_FRACTION * len(other_bin):
        return []
    rel = float(np.median(other_level[present][close]))
    return [Source(float(band_freqs[int(round(centre))]), rel, float(np.sum(close) / len(other_bin)))]


def _strongest_outside(f, mean_spectrum, bands, in_band_peak) -> str:
    """'a stronger tone near … Hz outside the band (… dB above …)' if one exists above 20 Hz outside every band of
    ``bands`` (Hz; the first is this taxel's, the others its neighbours'), else ''."""
    df = f[1] - f[0]
    outside = f > 20.0  # below 20 Hz: drift, not a tone
    for lo, hi in bands:
        outside &= (f < lo - 2 * df) | (f > hi + 2 * df)
    if not np.any(outside):
        return ""
    i = int(np.argmax(np.where(outside, mean_spectrum, 0.0)))
    if mean_spectrum[i] <= in_band_peak:
        return ""
    i = int(np.clip(i, 1, len(f) - 2))
    a, b, c = 10 * np.log10(mean_spectrum[i - 1:i + 2] + np.finfo(float).tiny)
    delta = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
    where = f[i] + float(np.clip(delta, -0.5, 0.5)) * df
    return (f"a stronger tone near {where:.0f} Hz outside the band{'s of every taxel' if len(bands) > 1 else ''} "
            f"({10 * np.log10(mean_spectrum[i] / in_band_peak):.1f} dB above the in-band peak)")


def band_from_prediction(band_hz: tuple[float, float]) -> tuple[float, float]:
    """Analysis band for a taxel: its predicted unloaded band, −10 % / +25 % (load raises f: +11 % at 25 N on
    the paper's Eq. 5 fit)."""
    return band_hz[0] * 0.9, band_hz[1] * 1.25


def run_trackers(blocks, fs: float, bands, on_frame=None) -> tuple[list[BandTracker], float, np.ndarray]:
    """Feed an iterable of sample blocks at ``fs`` (Hz) to one :class:`BandTracker` per band (Hz), in one pass:
    (trackers, duration s, mean power spectrum). ``on_frame`` is called as (band index, time s, frequency Hz or
    NaN, excess dB) as frames become final."""
    framer = Framer(fs)
    trackers = [BandTracker(framer.freqs, fs, band,
                            None if on_frame is None else (lambda *a, k=k: on_frame(k, *a)))
                for k, band in enumerate(bands)]
    total = np.zeros(len(framer.freqs))
    samples = 0
    for block in blocks:
        samples += len(block)
        times, power = framer.feed(block)
        if len(times):
            total += power.sum(axis=0)
            for tr in trackers:
                tr.push(times, power)
    return trackers, samples / fs, total / max(1, framer.frames)


def analyze_stream(blocks, fs: float, bands, on_frame=None) -> list[Analysis]:
    """One :class:`Analysis` per band (Hz) from an iterable of sample blocks at ``fs`` (Hz), in one pass
    (:func:`run_trackers`); raises LoopError when any band has no tone. A board of taxels whose silent members
    must not stop the others is :func:`matcad.loop.board.analyze_board`."""
    trackers, duration, mean_power = run_trackers(blocks, fs, bands, on_frame)
    return [tr.finish(duration, mean_power, [b for j, b in enumerate(bands) if j != k])
            for k, tr in enumerate(trackers)]


def analyze(x: np.ndarray, fs: float, band_hz: tuple[float, float]) -> Analysis:
    """The tone's frequency track inside ``band_hz`` (Hz) of samples ``x`` at ``fs`` (Hz).

    Raises LoopError (with the reason) when no frame holds the tone or when the ridge hugs a band edge.
    """
    step = 1 << 16
    return analyze_stream((x[i:i + step] for i in range(0, max(len(x), 1), step)), fs, [band_hz])[0]


def write_track_csv(analysis: Analysis, path) -> None:
    """Per-frame time (s), frequency (Hz, empty where unvoiced), ridge excess over the floor (dB) and voicing."""
    rows = ["time_s,frequency_hz,snr_db,voiced"] + [
        f"{t:.6f},{f'{f:.4f}' if v else ''},{s:.2f},{int(v)}"
        for t, f, s, v in zip(analysis.times_s, analysis.track_hz, analysis.frame_snr_db, analysis.voiced)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def write_segments_csv(analysis: Analysis, path, forces=None) -> None:
    """Per segment: start, end (s), frames, mean/median/sd frequency (Hz), flag; and force with its 95 % interval
    (N) when ``forces`` (one (force, low, high) per segment) is given."""
    head = "start_s,end_s,frames,mean_hz,median_hz,std_hz"
    head += ",force_n,force_low_n,force_high_n" if forces is not None else ""
    rows = [head + ",flag"]
    for i, s in enumerate(analysis.segments):
        row = f"{s.start_s:.3f},{s.end_s:.3f},{s.frames},{s.mean_hz:.3f},{s.median_hz:.3f},{s.std_hz:.3f}"
        if forces is not None:
            row += "," + ",".join("" if not np.isfinite(v) else f"{v:.4f}" for v in forces[i])
        rows.append(row + "," + s.flag.replace(",", ";"))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def plot(analysis: Analysis, path, forces=None) -> None:
    """Spectrogram of the band (dB, max-pooled in time) with the voiced track and segments; with ``forces``
    (per frame: force, low, high in N) a second panel of force against time. PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = 2 if forces is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 3.2 * rows + 0.8), sharex=True, squeeze=False)
    ax = axes[0, 0]
    db = analysis.plot_db
    ax.pcolormesh(analysis.plot_times_s, analysis.plot_freqs_hz, db, shading="nearest", cmap="magma",
                  vmin=np.percentile(db, 5), vmax=db.max())
    ax.plot(analysis.times_s, np.where(analysis.voiced, analysis.track_hz, np.nan), color="cyan", lw=1,
            label="voiced track")
    segs = analysis.segments
    if segs:  # one call for all segments: a 60 min file has thousands
        ax.hlines([s.mean_hz for s in segs], [s.start_s for s in segs], [s.end_s for s in segs],
                  colors=["red" if s.flag else "white" for s in segs], lw=2)
    ax.set(ylabel="frequency [Hz]",
           title=f"mean {analysis.mean_hz:.2f} Hz over {100 * analysis.tone_fraction:.0f} % of frames (voiced), "
                 f"{len(analysis.segments)} segments")
    ax.legend(loc="upper right", fontsize=8)
    if forces is not None:
        force, low, high = forces
        bx = axes[1, 0]
        bx.fill_between(analysis.times_s, low, high, alpha=0.3, label="95 % interval")
        bx.plot(analysis.times_s, force, "k.", ms=2, label="force per voiced frame")
        bx.set(ylabel="force [N]")
        bx.legend(loc="upper right", fontsize=8)
    save_time_figure(fig, axes, path)


def save_time_figure(fig, axes, path) -> None:
    """Label the shared time axis (s) of a column of panels and write the figure as PNG (100 dpi)."""
    import matplotlib.pyplot as plt

    axes[-1, 0].set(xlabel="time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
