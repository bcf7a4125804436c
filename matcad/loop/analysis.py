"""The result of analysing one band of a recording, and how it is concluded from the frames the tracker decided.

:func:`conclude` takes every frame of the band (:class:`Frames`) and gives the :class:`Analysis`, or the reason there
is none (:class:`matcad.errors.LoopError`): it keeps the taxel on its own line through hops and crossings of a second
tone (:mod:`matcad.loop.crossing`), leaves out flagged segments (mode jumps, blends), refuses a ridge that hugs the
band edge, and reports other sources — a second stable line in the band (a neighbouring taxel) with its frequency
and level; a stronger tone outside the band (hum, a harmonic), never taken. Frequencies Hz, times s, levels dB.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from matcad.listening import EDGE_BINS, WINDOW_S, window_samples
from matcad.errors import LoopError
from matcad.loop import crossing
from matcad.loop.segments import Segment
from matcad.loop.spectrum import BandBins, levels
from matcad.loop.stats import median
from matcad.loop.voicing import (MIN_RUN, MIN_RUN_HARMONIC, STABLE_BINS, STRONG_DB, STRONG_RUN, WEAK_DB,
                                 longest_run)

SECOND_SOURCE_FRACTION = 0.5


@dataclass(frozen=True)
class Source:
    """Another line in the band: median frequency (Hz), median level relative to the tracked tone (dB) and the
    fraction of voiced frames it was present in."""

    frequency_hz: float
    relative_db: float
    fraction: float


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`matcad.loop.analyze.analyze`: statistics over voiced frames, the per-frame track, segments
    and warnings."""

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
    frame_level_db: np.ndarray = field(repr=False, default=None)
    """The ridge's own level per frame (dB of power, not over the floor; the tracker's ridge, before any hop is
    undone): lets a board tell a harmonic from a taxel's own tone (:func:`matcad.loop.board.discount_harmonics`)."""
    unassigned: str = ""
    """Why the tracked line cannot be told to be the taxel's ('' when it can): a second tone of comparable level
    (within :data:`matcad.loop.crossing.COMPARABLE_DB`) in the band from the first voiced frames on, so that no
    stretch of the taxel alone anchors its identity (issue 24). ``sense`` gives no force then."""

    def to_dict(self) -> dict:
        return {"mean_hz": self.mean_hz, "median_hz": self.median_hz, "std_hz": self.std_hz,
                "snr_db": self.snr_db, "prominence_db": self.prominence_db, "tone_fraction": self.tone_fraction,
                "band_hz": list(self.band_hz), "sample_rate_hz": self.sample_rate_hz,
                "duration_s": self.duration_s, "frames": int(len(self.track_hz)),
                "voiced_frames": int(np.sum(self.voiced)), "segments": [s.to_dict() for s in self.segments],
                "other_sources": [{"frequency_hz": s.frequency_hz, "relative_db": s.relative_db,
                                   "fraction": s.fraction} for s in self.sources],
                "warnings": list(self.warnings), "unassigned": self.unassigned}

    def to_text(self, source: str) -> str:
        """What ``analyze`` prints for the recording named ``source``: the statistics, the segments, the
        warnings."""
        head = (f"{source}: mean {self.mean_hz:.2f} Hz, median {self.median_hz:.2f} Hz, sd {self.std_hz:.2f} Hz "
                f"over {int(self.voiced.sum())} voiced of {len(self.track_hz)} frames (tone "
                f"{100 * self.tone_fraction:.0f} %); line {self.snr_db:.1f} dB over the floor, prominence "
                f"{self.prominence_db:.1f} dB (band {self.band_hz[0]:.0f}-{self.band_hz[1]:.0f} Hz)")
        return "\n".join([head, *self.segments_text(), *(f"  warning: {w}" for w in self.warnings)])

    def segments_text(self, forces=None, heading: bool = True) -> list[str]:
        """Lines: how many steady segments (``heading``), then one per segment (:meth:`Segment.to_text`), with its
        force when ``forces`` (per segment: force, low, high in N) is given. More than :data:`SEGMENTS_SHOWN`
        (a long recording): the first and last :data:`SEGMENTS_END` and one summary line between them (how many
        are left out, their frequency range, durations and flags); segments.csv keeps every one."""
        segs = self.segments
        lines = [f"  {len(segs)} steady segments:"] if heading else []

        def line(i: int) -> str:
            return segs[i].to_text(None if forces is None else forces[i])

        if len(segs) <= SEGMENTS_SHOWN:
            return lines + [line(i) for i in range(len(segs))]
        hidden = segs[SEGMENTS_END:-SEGMENTS_END]
        means = [s.mean_hz for s in hidden]
        lengths = sorted(s.end_s - s.start_s for s in hidden)
        flagged = sum(bool(s.flag) for s in hidden)
        summary = (f"  ... {len(hidden)} more segments, {hidden[0].start_s:.2f}-{hidden[-1].end_s:.2f} s: mean "
                   f"{min(means):.2f}-{max(means):.2f} Hz, {lengths[len(lengths) // 2]:.2f} s long (median), "
                   f"{flagged} flagged; every segment in segments.csv")
        return (lines + [line(i) for i in range(SEGMENTS_END)] + [summary]
                + [line(i) for i in range(len(segs) - SEGMENTS_END, len(segs))])


SEGMENTS_SHOWN = 12
"""At most this many segment lines on standard output; a longer list is summarised (:meth:`segments_text`)."""
SEGMENTS_END = 5
"""Segments shown at each end of a summarised list."""


@dataclass(frozen=True)
class Frames:
    """Every frame of one band as the tracker decided it: time (s), the ridge's frequency (Hz) and excess over the
    floor (dB), voicing state (1 voiced, else 0), the strongest other line in the band (bin, excess dB, level
    relative to the ridge dB; −inf where none), and whether a harmonic sound was heard below the band
    (:mod:`matcad.loop.harmonic`)."""

    times_s: np.ndarray
    track_hz: np.ndarray
    excess_db: np.ndarray
    state: np.ndarray
    other_bin: np.ndarray
    other_excess_db: np.ndarray
    other_level_db: np.ndarray
    harmonic: np.ndarray


def _why_unvoiced(frames: Frames, fs: float) -> str:
    """Why no frame counted as the tone: a recording too short for the shortest run that can count
    (:data:`STRONG_RUN` frames); a harmonic sound below the band while no run reached :data:`MIN_RUN_HARMONIC`
    frames; or no line strong or steady enough (levels dB over the floor)."""
    excess = frames.excess_db
    hop = window_samples(fs) // 2

    def run_ms(n: int) -> float:
        return 1e3 * (window_samples(fs) + (n - 1) * hop) / fs

    best = f"best frame {np.max(excess):.1f} dB"
    if len(excess) < STRONG_RUN:
        return (f"the recording holds {len(excess)} analysis frame ({WINDOW_S * 1e3:.0f} ms), too short for a run of "
                f"{STRONG_RUN} frames ({run_ms(STRONG_RUN):.0f} ms) at >= {STRONG_DB:g} dB, the least a tone needs to "
                f"count (a lone frame is as often a noise peak; {best}): record longer")
    longest = longest_run(excess >= WEAK_DB)
    heard = int(np.count_nonzero(frames.harmonic))
    if heard and longest < MIN_RUN_HARMONIC:
        return (f"a harmonic sound (a voice, a buzz, music; or the periodic rounding error of a synthesised tone) "
                f"was heard below the band in {heard} of {len(excess)} frames, and near one a tone needs a run of "
                f"{MIN_RUN_HARMONIC} frames ({run_ms(MIN_RUN_HARMONIC):.0f} ms) to count, as a voice leaves "
                f"steady-looking lines of 2-8 frames in the band; the longest run here is {longest} frames ({best}): "
                "record longer or away from the sound")
    return (f"no run of frames holds a steady line (within ±{STABLE_BINS} bins) >= {STRONG_DB:g} dB over the local "
            f"noise floor for {STRONG_RUN} frames, nor >= {WEAK_DB:g} dB for {MIN_RUN} frames ({best})")


def conclude(frames: Frames, bins: BandBins, duration_s: float, loudest: str = "", plot=(None, None)) -> Analysis:
    """The :class:`Analysis` of the band ``bins`` of a recording ``duration_s`` (s) long. ``loudest``: the
    :func:`strongest_outside` text ('' when none); ``plot``: the pooled spectrogram (column times s, level dB
    frequency × column). Raises LoopError when no frame can be the taxel's tone or when the ridge hugs the band
    edge."""
    times, track, excess, state = frames.times_s, frames.track_hz, frames.excess_db, frames.state
    lo, hi = bins.band_hz
    band_freqs = bins.band_freqs
    hint = f"; {loudest}" if loudest else ""
    if len(track) == 0:
        raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz: the recording is shorter than one "
                        f"{WINDOW_S * 1e3:.0f} ms analysis window")
    if not np.any(state == 1):
        raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz: {_why_unvoiced(frames, bins.fs)}{hint}")
    # the taxel's line through hops and crossings of two tones
    ident = crossing.follow_taxel(times, track, state, frames.other_bin, frames.other_excess_db,
                                  frames.other_level_db, excess, band_freqs)
    track, state, segments = ident.track_hz, ident.state, list(ident.segments)
    flagged = [s for s in segments if s.flag]
    for s in flagged:
        state[(times >= s.start_s) & (times <= s.end_s) & (state == 1)] = 2
    voiced = state == 1
    if not np.any(voiced):
        raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz that can be the taxel's: every voiced frame is in a "
                        f"flagged segment ({flagged[0].flag}){hint}")
    nb = len(band_freqs)
    path = (track[voiced] - band_freqs[0]) / bins.df
    edge = np.mean((path <= EDGE_BINS) | (path >= nb - 1 - EDGE_BINS))
    if edge > 0.5:
        raise LoopError(f"the ridge hugs the band edge ({100 * edge:.0f} % of voiced frames within {EDGE_BINS} "
                        f"bins of {lo:.0f} or {hi:.0f} Hz): the tone is probably outside the band; widen "
                        f"it{hint}")
    other_excess, other_level = ident.other_excess, ident.other_level
    sources = second_sources(ident.other_bin[voiced], other_excess[voiced], other_level[voiced], band_freqs)
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
    longest = longest_run(voiced)
    if longest < MIN_RUN_HARMONIC:
        seconds = MIN_RUN_HARMONIC * (window_samples(bins.fs) // 2) / bins.fs
        warnings.append(f"no voiced stretch lasts {MIN_RUN_HARMONIC} frames ({seconds:.2f} s; the longest: "
                        f"{longest}): these may be a room's response peaks or another transient rather than a "
                        "singing taxel")
    unassigned = _unassigned(sources, other_excess[voiced], other_level[voiced])
    prom = np.where(np.isfinite(other_level[voiced]), -other_level[voiced], excess[voiced])
    plot_times, plot_db = plot
    return Analysis(mean_hz=float(np.mean(track[voiced])), median_hz=float(median(track[voiced])),
                    std_hz=float(np.std(track[voiced])), snr_db=float(median(excess[voiced])),
                    prominence_db=float(median(prom)), tone_fraction=float(np.mean(voiced)),
                    band_hz=(lo, hi), sample_rate_hz=bins.fs, duration_s=duration_s, times_s=times,
                    track_hz=track, frame_snr_db=excess, voiced=voiced, segments=tuple(segments),
                    sources=tuple(sources), plot_times_s=plot_times, plot_freqs_hz=band_freqs, plot_db=plot_db,
                    warnings=tuple(warnings), unassigned=unassigned)


def _unassigned(sources, other_excess, other_level) -> str:
    """:attr:`Analysis.unassigned` from the second sources and, per voiced frame, the strongest other line's excess
    over its floor and level relative to the ridge (dB): a comparable second source present in most of the first
    MIN_RUN_HARMONIC voiced frames."""
    close = [s for s in sources if abs(s.relative_db) <= crossing.COMPARABLE_DB]
    first = slice(0, MIN_RUN_HARMONIC)
    comparable = (other_excess[first] >= WEAK_DB) & (other_level[first] >= -crossing.COMPARABLE_DB)
    if not close or np.mean(comparable) <= 0.5:
        return ""
    return (f"two tones of comparable level in the band from the start (the other near {close[0].frequency_hz:.0f} "
            f"Hz, {close[0].relative_db:+.1f} dB): nothing tells which one is the taxel, so no force is given; "
            "listen in the taxel's own band (a board spec, or --band around its tone only)")


def second_sources(other_bin, other_excess, other_level, band_freqs) -> list[Source]:
    """A second line present (≥ WEAK_DB over its floor) in ≥ SECOND_SOURCE_FRACTION of voiced frames, clustered
    in frequency; its level relative to the tracked line (dB of power)."""
    if len(other_bin) == 0:
        return []
    present = other_excess >= WEAK_DB
    if np.mean(present) < SECOND_SOURCE_FRACTION:
        return []
    bins = other_bin[present]
    centre = median(bins)
    close = np.abs(bins - centre) <= 3 * STABLE_BINS
    if np.sum(close) < SECOND_SOURCE_FRACTION * len(other_bin):
        return []
    rel = float(median(other_level[present][close]))
    return [Source(float(band_freqs[int(round(centre))]), rel, float(np.sum(close) / len(other_bin)))]


def strongest_outside(f, mean_spectrum, bands, in_band_peak, on_harmonic=None) -> str:
    """'a stronger tone near … Hz outside the band (… dB above …)' if one exists above 20 Hz outside every band of
    ``bands`` (Hz; the first is this taxel's, the others its neighbours'), else ''. ``f``: the spectrum's bins (Hz);
    ``mean_spectrum``: its mean power; ``in_band_peak``: the band's highest mean power. A tone is a line of the mean
    spectrum (:func:`matcad.loop.spectrum.levels`: a local maximum >= LINE_DB over the running-median floor): the
    skirt of a tone inside a band, sloping out past the band's edge, is none (it named a silent board taxel's
    neighbour, 25 Hz inside its own band, as a stronger tone 10-35 Hz outside it). Nor is a bin whose mean power
    was at least half heard on a taxel's predicted harmonic (``on_harmonic``: each bin's share,
    :mod:`matcad.loop.overtones`; it named a singing taxel's 2f in every silent neighbour's reason: 46/46)."""
    df = f[1] - f[0]
    outside = f > 20.0  # below 20 Hz: drift, not a tone
    for lo, hi in bands:
        outside &= (f < lo - 2 * df) | (f > hi + 2 * df)
    outside &= np.isfinite(levels(mean_spectrum[None, :], mean_spectrum.max(keepdims=True))[2][0])
    if on_harmonic is not None:
        outside &= on_harmonic < 0.5
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
