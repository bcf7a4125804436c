"""A board of taxels heard by one microphone: every taxel's tone tracked at once, assigned to its taxel, and a
force per taxel over time. Frequencies Hz, times s, forces N.

Assignment by band. Each taxel listens in its own band, given by the caller: the loaded band of
:func:`matcad.prediction.bands.listening_bands` (its predicted unloaded band widened by the rise of f under load up
to the spec's maximum force).
The bands of a valid array are disjoint with a guard, so a tone belongs to the taxel whose band holds it, and one
:class:`matcad.loop.tracker.BandTracker` per band — all fed from the same spectra in one pass
(:func:`matcad.loop.analyze.run_trackers`) — tracks every taxel at once. A band may hold another taxel's 2f or 3f
(the allocation interleaves bands between harmonics): each frame, every taxel's harmonics are predicted from its
tone and discounted in the other bands before their ridges see them (:mod:`matcad.loop.overtones`), and
:func:`discount_harmonics` checks the tracks afterwards. Frames that hold the room's tail of the old pitch just
before a fast step are left out (:func:`room_tails`). A louder
neighbour's tone lies in the neighbour's band: it is that taxel's tone, not a distractor of this one (the
"stronger tone outside the band" report skips the other taxels' bands, and their predicted harmonics); a stronger
tone outside every band is still reported, and a second line inside a taxel's own band is reported as before. A
silent taxel does not stop the others: its track carries the reason; "no tone" (exit 1) only when no taxel has one.

Calibrations: each taxel has its own Eq. 5 calibration (``matcad calibrate --taxel NAME`` per taxel), carried in
the spec as that [[taxel]] entry's [taxel.calibration] table or given to ``sense`` as ``--calibration NAME=FILE``
(which overrides the spec's for that taxel); a taxel without one gets frequencies, no force
(:func:`board_calibrations`).

Live output (``sense --live``): each tracker reports a frame once its voicing is final, and the trackers finish
frames at different moments (a candidate run waits until it qualifies); :class:`LiveFrames` joins the reports into
one row per frame, in time order, as soon as every taxel has decided that frame.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from matcad.errors import LoopError
from matcad.listening import EDGE_BINS, HARMONICS, trackable
from matcad.loop.segments import STEP_HZ
from matcad.loop.stats import median
from matcad.loop.voicing import MIN_RUN_HARMONIC, WEAK_DB
from matcad.loop.analysis import Analysis
from matcad.loop.analyze import run_trackers
from matcad.loop.sense import sense


@dataclass(frozen=True)
class TaxelTrack:
    """One taxel's result: its name, listening band (Hz) and :class:`Analysis`, or None and the reason (no tone,
    a ridge at the band edge)."""

    name: str
    band_hz: tuple[float, float]
    analysis: Analysis | None
    reason: str = ""

    def to_dict(self) -> dict:
        body = self.analysis.to_dict() if self.analysis is not None else {"reason": self.reason}
        return {"taxel": self.name, "listening_band_hz": list(self.band_hz), **body}

    def to_text(self, reading=None, sensed: bool = False) -> str:
        """This taxel's lines of a board's summary: band, frequency statistics and, with ``reading``
        (:class:`matcad.loop.sense.Reading`), its force (``sensed`` without one: the board was sensed but this
        taxel has no calibration); its segments and warnings."""
        band = f"  {self.name} ({self.band_hz[0]:.0f}-{self.band_hz[1]:.0f} Hz): "
        if self.analysis is None:
            return band + self.reason
        a, r = self.analysis, reading
        line = (f"{band}mean {a.mean_hz:.2f} Hz, sd {a.std_hz:.2f} Hz, tone {100 * a.tone_fraction:.0f} %, "
                f"{len(a.segments)} segments")
        if r is not None and r.force_n == r.force_n:
            line += f"; F = {r.force_n:.3f} N (95 %: {r.force_interval_n[0]:.3f} .. {r.force_interval_n[1]:.3f})"
        elif r is not None:
            line += f"; {r.reason}"
        elif sensed:
            line += "; no calibration: frequency only"
        warnings = list(a.warnings) + (list(r.warnings) if r is not None else [])
        return "\n".join([line, *a.segments_text(r.segments_n if r is not None else None, heading=False),
                          *(f"    warning: {w}" for w in warnings)])


def board_text(source: str, tracks, readings=None) -> str:
    """What ``analyze`` (``readings`` None) or ``sense`` ({name: Reading}) prints for a board heard in the
    recording named ``source``: one block per taxel (:meth:`TaxelTrack.to_text`)."""
    head = (f"{source}: {len(tracks)} taxels, each in its own band" if readings is None else
            f"{source}: {len(tracks)} taxels, {len(readings)} with a calibration and a tone")
    return "\n".join([head, *(t.to_text((readings or {}).get(t.name), readings is not None) for t in tracks)])


def taxels_dict(tracks, readings=None) -> list[dict]:
    """report.json's "taxels" of a board: each :meth:`TaxelTrack.to_dict`, with its reading's ``to_dict`` under
    "reading" when ``readings`` ({name: Reading}) has one."""
    return [{**t.to_dict(), **({"reading": readings[t.name].to_dict()} if t.name in (readings or {}) else {})}
            for t in tracks]


def analyze_board(blocks, fs: float, named_bands, on_frame=None) -> list[TaxelTrack]:
    """Every taxel's track from sample blocks at ``fs`` (Hz), in one pass. ``named_bands``: (name, band Hz) per
    taxel, each widened to what the tracker needs (:func:`matcad.listening.trackable`). ``on_frame`` is called as
    (taxel index, time s, frequency Hz or NaN, excess dB). Raises LoopError when no taxel has a tone."""
    named_bands = [(name, trackable(tuple(band), fs)) for name, band in named_bands]
    bands = [band for _, band in named_bands]
    hold = None if on_frame is None else TailHold(len(bands), on_frame)
    trackers, duration, mean_power, on_harmonic = run_trackers(blocks, fs, bands, hold)
    tracks = []
    for k, ((name, band), tracker) in enumerate(zip(named_bands, trackers)):
        others = [b for j, b in enumerate(bands) if j != k]
        try:
            heard = tracker.finish(duration, mean_power, others, on_harmonic)
            analysis = room_tails(off_edge(name, heard))
            tracks.append(TaxelTrack(name, band, replace(analysis, warnings=(*analysis.warnings,
                                                                             *dropouts(name, heard)))))
        except LoopError as exc:
            tracks.append(TaxelTrack(name, band, None, str(exc)))
    if hold is not None:  # the trackers' last frames come as they finish
        hold.flush()
    tracks = discount_harmonics(tracks)
    if all(t.analysis is None for t in tracks):
        raise LoopError("no taxel's tone found: " + "; ".join(f"{t.name}: {t.reason}" for t in tracks))
    return tracks


HARMONIC_TOL_BINS = 3
"""A ridge within this many bins (~16 Hz at 44.1 kHz) of a predicted harmonic m·f of another taxel's tone in the
same frame lies on that harmonic."""


HARMONIC_WEAKER_DB = 10.0
"""...and is at least this much weaker (the ridge's own level, dB) than that taxel's tone: a harmonic is weaker than
its fundamental (a Helmholtz resonator does not amplify it: -20 dB on the synthetic board); a line about as strong
as another taxel's tone is the taxel's own, even where its pitch meets the harmonic."""


def discount_harmonics(tracks, harmonics=HARMONICS) -> list[TaxelTrack]:
    """Each taxel's frames whose ridge lies on another taxel's harmonic — m·f (m in ``harmonics``) of that taxel's
    tone in the same frame, within HARMONIC_TOL_BINS, and HARMONIC_WEAKER_DB weaker — left out, with a warning;
    segments made mostly of them are flagged. The bands of a board may hold other taxels' 2f and 3f (issue 24: the
    allocation interleaves bands between harmonics instead of forbidding them): a taxel quieter than a neighbour's
    harmonic, or silent, would otherwise be read at the harmonic's pitch; where its own, much weaker tone sits on
    the harmonic the frame cannot be told and is left out too. A taxel left with no voiced frame gets no analysis
    and the reason."""
    out = []
    for k, t in enumerate(tracks):
        a = t.analysis
        if a is None:
            out.append(t)
            continue
        tol = HARMONIC_TOL_BINS * float(a.plot_freqs_hz[1] - a.plot_freqs_hz[0])
        on = np.zeros(len(a.track_hz), dtype=bool)
        which = []
        for j, other in enumerate(tracks):
            b = other.analysis
            if j == k or b is None or len(b.track_hz) != len(a.track_hz):
                continue
            for m in harmonics:
                hit = a.voiced & b.voiced & (np.abs(a.track_hz - m * b.track_hz) <= tol)
                if a.frame_level_db is not None and b.frame_level_db is not None:
                    hit &= a.frame_level_db < b.frame_level_db - HARMONIC_WEAKER_DB
                if np.any(hit):
                    which.append(f"{other.name}'s {m}f ({int(hit.sum())} frames)")
                on |= hit
        if not np.any(on):
            out.append(t)
            continue
        voiced = a.voiced & ~on
        if not np.any(voiced):
            out.append(TaxelTrack(t.name, t.band_hz, None, f"every voiced frame lies on {', '.join(which)}: no "
                                                            "tone of its own"))
            continue
        flag = "on another taxel's harmonic"
        segments = tuple(replace(s, flag=s.flag or flag)
                         if np.mean(on[(a.times_s >= s.start_s) & (a.times_s <= s.end_s)]) > 0.5 else s
                         for s in a.segments)
        f = a.track_hz[voiced]
        warning = (f"{int(on.sum())} frames of {t.name} lie on {', '.join(which)}, predicted from that taxel's "
                   "tone: left out (a harmonic, or the taxel's own tone where the two coincide)")
        out.append(TaxelTrack(t.name, t.band_hz, replace(
            a, mean_hz=float(np.mean(f)), median_hz=float(median(f)), std_hz=float(np.std(f)),
            tone_fraction=float(np.mean(voiced)), voiced=voiced, segments=segments,
            warnings=(*a.warnings, warning))))
    return out


def off_edge(name: str, a: Analysis) -> Analysis:
    """A board taxel's analysis with the frames its ridge spent at its band's edge left out (voiced ones within
    EDGE_BINS + 1 bins of an edge, and the unvoiced run at the edge that follows them): a tone pressed out of its
    band leaves the ridge parked on the skirt at the edge, which is no reading (issue 24: 3-frame segments pinned
    41 Hz below the tone). Segments there are flagged (no force); a warning says the taxel left its band. Raises
    LoopError when no voiced frame is left."""
    df = float(a.plot_freqs_hz[1] - a.plot_freqs_hz[0])
    lo, hi = a.band_hz
    near = (EDGE_BINS + 1) * df
    at_edge = (a.track_hz - lo <= near) | (hi - a.track_hz <= near)
    left = a.voiced & at_edge
    # the ridge parked at the edge right after a voiced edge frame: the tone went on out of the band
    for i in range(1, len(left)):
        if at_edge[i] and not a.voiced[i] and left[i - 1]:
            left[i] = True
    if not np.any(left & a.voiced):
        return a
    voiced = a.voiced & ~left
    if not np.any(voiced):
        raise LoopError(f"{name}'s tone sits at its band's edge in every voiced frame: it lies outside "
                        f"{lo:.0f}-{hi:.0f} Hz")
    flag = "at the band edge: the tone left the band"
    segments = tuple(replace(s, flag=s.flag or flag) if min(s.mean_hz - lo, hi - s.mean_hz) <= near else s
                     for s in a.segments)
    times = a.times_s[left]
    side = "top" if median(a.track_hz[left]) > 0.5 * (lo + hi) else "bottom"
    warning = (f"{name}'s tone reached its band's {side} edge ({hi if side == 'top' else lo:.0f} Hz) in "
               f"{int(left.sum())} frames between {times[0]:.2f} and {times[-1]:.2f} s: it left its band (pressed "
               "beyond the band's force range, or the band is wrong); those frames are left out")
    f = a.track_hz[voiced]
    return replace(a, mean_hz=float(np.mean(f)), median_hz=float(median(f)), std_hz=float(np.std(f)),
                   tone_fraction=float(np.mean(voiced)), voiced=voiced, segments=segments,
                   warnings=(*a.warnings, warning))


TAIL_FRAMES = 4
"""Frames before a pitch step that may hold the room's tail of the old pitch (a 0.4 s RT60 decays ~15 dB a frame
of 46 ms; beyond four frames the tail is below the floor)."""
TAIL_DB = 6.0
"""A frame before a step is the room's tail when its excess is this far below the line's level before it."""


def room_tails(a: Analysis) -> Analysis:
    """A board taxel's analysis with the frames before a fast pitch step that hold the room's reverberant tail of
    the old pitch left out (:func:`tail_before`, for every pair of neighbouring voiced frames). A press ramped in
    0.15 s spreads the new pitch over many bins of a 93 ms window while the tail stays on one: the ridge keeps the
    old pitch for 2-3 frames, 40-130 Hz off on a 96 kHz board's high taxels (benchmarks/design.py
    --capacity-only). Segments are kept (the tail is at the old, steady pitch); the frame counts change. Live
    output leaves out the same frames (:class:`TailHold`)."""
    v = np.flatnonzero(a.voiced)
    if len(v) < 2:
        return a
    out = np.zeros(len(a.track_hz), dtype=bool)
    for i, j in zip(v[:-1], v[1:]):
        tail_before(a.track_hz, a.frame_snr_db, a.voiced, i, j, out)
    voiced = a.voiced & ~out
    if not np.any(out) or not np.any(voiced):
        return a
    g = a.track_hz[voiced]
    return replace(a, mean_hz=float(np.mean(g)), median_hz=float(median(g)), std_hz=float(np.std(g)),
                   tone_fraction=float(np.mean(voiced)), voiced=voiced)


def tail_before(f, e, voiced, i: int, j: int, out) -> None:
    """Mark in ``out`` the room's tail before voiced frame ``j`` (``i``: the voiced frame before it; ``f`` Hz,
    ``e`` excess dB, ``voiced`` per frame): when j comes within 3 frames and moves more than STEP_HZ, up to
    TAIL_FRAMES voiced frames from i back, at i's pitch (within STEP_HZ) and at least TAIL_DB weaker than the
    median of the voiced frames TAIL_FRAMES..2·TAIL_FRAMES + 3 before i."""
    if j - i > 3 or abs(f[j] - f[i]) <= STEP_HZ:
        return
    lo = max(0, i - 2 * TAIL_FRAMES - 3)
    ref = lo + np.flatnonzero(voiced[lo:max(lo, i - TAIL_FRAMES + 1)])
    if len(ref) < 3:
        return
    level = float(median(e[ref]))
    for k in range(i, max(-1, i - TAIL_FRAMES), -1):
        if not voiced[k] or abs(f[k] - f[i]) > STEP_HZ or e[k] > level - TAIL_DB:
            break
        out[k] = True


class TailHold:
    """Between the trackers and a live ``on_frame``: each taxel's frames are held until no later frame can make
    them the room's tail (TAIL_FRAMES + 3 frames), then passed on, a tail frame as unvoiced (NaN): live lines
    say what the final analysis says (:func:`room_tails`). Keeps 2·TAIL_FRAMES + 8 frames per taxel."""

    KEEP = 2 * TAIL_FRAMES + 8

    def __init__(self, count: int, on_frame):
        self.on_frame = on_frame
        self.frames = [[] for _ in range(count)]  # per taxel: [time s, f Hz, excess dB, tail?] of the last KEEP
        self.sent = [0] * count  # per taxel: how many of the kept frames (from the newest back) are not yet sent

    def __call__(self, k: int, time_s: float, freq: float, excess: float) -> None:
        frames = self.frames[k]
        frames.append([time_s, freq, excess, False])
        self.sent[k] += 1
        f = np.array([x[1] for x in frames])
        voiced = np.isfinite(f)
        if voiced[-1]:
            earlier = np.flatnonzero(voiced[:-1])
            if len(earlier):
                out = np.zeros(len(f), dtype=bool)
                tail_before(f, np.array([x[2] for x in frames]), voiced, int(earlier[-1]), len(f) - 1, out)
                for n in np.flatnonzero(out):
                    frames[n][3] = True
        while self.sent[k] > TAIL_FRAMES + 3:
            self._send(k, len(frames) - self.sent[k])
        del frames[:max(0, len(frames) - self.KEEP)]

    def _send(self, k: int, n: int) -> None:
        time_s, freq, excess, tail = self.frames[k][n]
        self.on_frame(k, time_s, float("nan") if tail else freq, excess)
        self.sent[k] -= 1

    def flush(self) -> None:
        """Pass on every frame still held (the recording ended)."""
        for k, frames in enumerate(self.frames):
            while self.sent[k]:
                self._send(k, len(frames) - self.sent[k])


DROPOUT_FRAMES = (5, 65)
"""A silence of this many frames (~0.23-3 s) inside a steady tone is reported by :func:`dropouts`."""


def dropouts(name: str, a: Analysis) -> list[str]:
    """Warnings for the silences of a board taxel that stops abruptly at a steady pitch and comes back at the same
    pitch (within STEP_HZ) after DROPOUT_FRAMES frames, with MIN_RUN_HARMONIC voiced frames on both sides: what an
    overblown jump out of its band (the jet driving another mode) does — or a stalled jet; a press would ramp the
    pitch first. The jumped tone itself is not looked for (the trackers see only the bands).

    The tone counts as present in a frame when the frame is voiced or its ridge holds a line (≥ WEAK_DB over the
    floor) within STEP_HZ of the last voiced pitch (:func:`_on_line`): a weak taxel whose voicing comes and goes
    still sings there, and counting only voiced frames left its jump unseen (benchmarks/wrong_answers.py,
    overblown-out seed 5: 4 voiced frames before the jump, the tone on the ridge at 10-15 dB for 9 more)."""
    out = []
    v = np.flatnonzero(_on_line(a))
    for i, j in zip(v[:-1], v[1:]):
        gap = j - i - 1
        if not DROPOUT_FRAMES[0] <= gap <= DROPOUT_FRAMES[1]:
            continue
        before, after = v[v <= i][-MIN_RUN_HARMONIC:], v[v >= j][:MIN_RUN_HARMONIC]
        if len(before) < MIN_RUN_HARMONIC or len(after) < MIN_RUN_HARMONIC or before[0] < i - 2 * MIN_RUN_HARMONIC \
                or after[-1] > j + 2 * MIN_RUN_HARMONIC:
            continue
        f0, f1 = median(a.track_hz[before]), median(a.track_hz[after])
        steady = before[a.voiced[before]]  # a press ramps the voiced pitch; a blend frame on the line may not
        if abs(f1 - f0) <= STEP_HZ and len(steady) and np.ptp(a.track_hz[steady]) <= 2 * STEP_HZ:
            out.append(f"{name}'s tone stopped abruptly at {a.times_s[i]:.2f} s from a steady {f0:.0f} Hz and came "
                       f"back at the same pitch at {a.times_s[j]:.2f} s: an overblown jump out of its band (the jet "
                       "driving another mode) or a stalled jet; no force in between")
    return out


def _on_line(a: Analysis) -> np.ndarray:
    """Per frame: voiced, or the ridge ≥ WEAK_DB over the floor within STEP_HZ of the last voiced frame's pitch (the
    first voiced frame's before it)."""
    v = np.flatnonzero(a.voiced)
    if len(v) == 0:
        return a.voiced
    last = a.track_hz[v[np.clip(np.searchsorted(v, np.arange(len(a.voiced)), side="right") - 1, 0, None)]]
    return a.voiced | ((a.frame_snr_db >= WEAK_DB) & (np.abs(a.track_hz - last) <= STEP_HZ))


def parse_calibrations(values, names) -> dict[str, str]:
    """``--calibration NAME=FILE`` values → {taxel name: file}. ValueError naming the value when NAME is not one
    of ``names`` or a taxel is given twice."""
    out = {}
    for value in values:
        name, sep, path = str(value).partition("=")
        if not sep or not path:
            raise ValueError(f"--calibration {value!r} invalid for a board of {len(names)} taxels: give one "
                             f"NAME=FILE per taxel, NAME one of {', '.join(names)}")
        if name not in names:
            raise ValueError(f"--calibration {value!r}: taxel {name!r} invalid, must be one of {', '.join(names)}")
        if name in out:
            raise ValueError(f"--calibration {value!r}: taxel {name!r} is given twice")
        out[name] = path
    return out


def board_calibrations(spec, values) -> dict:
    """{taxel name: (source text, :class:`matcad.spec.Calibration`)} for a board: each taxel's [taxel.calibration]
    from ``spec``, overridden by ``--calibration NAME=FILE`` ``values`` (:func:`parse_calibrations`). ValueError
    (exit 2) when neither gives any calibration, or naming the file or field when one is bad."""
    from matcad.spec import load_calibration, taxels

    board = taxels(spec)
    names = [t.name for t in board]
    files = parse_calibrations(values or (), names)
    out = {t.name: ("spec [taxel.calibration]", t.calibration) for t in board if t.calibration is not None}
    out |= {name: (path, load_calibration(path)) for name, path in files.items()}
    if not out:
        raise ValueError(f"--calibration is required: {spec.name} has no [taxel.calibration] table; give one per "
                         f"taxel in the spec or as --calibration NAME=FILE, NAME one of {', '.join(names)}")
    return {name: out[name] for name in names if name in out}


class LiveFrames:
    """The ``on_frame`` callback of :func:`analyze_board` for live output: collects (frequency Hz or NaN, excess
    dB) per taxel and frame index and calls ``emit(time s, [(frequency, excess) per taxel])`` once per frame, in
    frame order, as soon as every taxel has reported that frame. Each tracker reports its frames in order, so a
    frame's index is the count of that taxel's earlier reports; the rows kept are those between the slowest and
    the fastest taxel (the fixed lag plus the longest run a tracker holds back before voicing it: tens of
    frames, 25 measured on the 4-taxel board scenario): memory stays bounded."""

    def __init__(self, count: int, emit):
        self.count, self.emit = count, emit
        self.reported = [0] * count  # frames reported so far, per taxel
        self.rows: dict[int, tuple[float, list]] = {}
        self.next = 0  # the next frame to emit

    def __call__(self, k: int, time_s: float, freq: float, excess: float) -> None:
        i = self.reported[k]
        self.reported[k] += 1
        self.rows.setdefault(i, (time_s, [None] * self.count))[1][k] = (freq, excess)
        while self.next in self.rows and None not in self.rows[self.next][1]:
            self.emit(*self.rows.pop(self.next))
            self.next += 1

    def flush(self) -> None:
        """Emit the frames some taxel never reported (its tracker stopped early), a missing taxel as (NaN, NaN)."""
        for i in sorted(self.rows):
            time_s, values = self.rows.pop(i)
            self.emit(time_s, [v if v is not None else (float("nan"), float("nan")) for v in values])
        self.next = max(self.reported, default=0)


def sense_board(tracks, calibrations, temperature_c=None) -> dict:
    """{taxel name: :class:`matcad.loop.sense.Reading`} for every taxel that has a tone and a calibration
    (``calibrations``: {name: :class:`matcad.acoustics.eq5.Eq5`}); raises LoopError when none of them has a force in its
    calibrated range."""
    readings = {t.name: sense(t.analysis, calibrations[t.name], temperature_c)
                for t in tracks if t.analysis is not None and t.name in calibrations}
    if not any(np.isfinite(r.force_n) for r in readings.values()):
        why = [f"{name}: {r.reason}" for name, r in readings.items()] + \
              [f"{t.name}: {t.reason}" for t in tracks if t.analysis is None and t.name in calibrations]
        raise LoopError("no calibrated taxel has a force: " + "; ".join(why or ["no calibrated taxel has a tone"]))
    return readings
