"""The taxel's identity when two tones share one band: ridge hops and crossings.

With one analysis band (a single-taxel spec, a neighbour the spec does not know, ``--band`` by hand) a second taxel
of similar level can sit in the band, and pressing one of them can carry its pitch through the other's. The ridge
of :class:`matcad.loop.tracker.BandTracker` follows the stronger line and pays to move, so it may leave the taxel
for the other tone — at a crossing, or by a jump when the other tone starts — and report the other's frequency.
Per frame the tracker keeps the ridge and the strongest other line (its bin, excess and level); from them:

1. *The second tone.* The other line counts as a tone where it stands ≥ WEAK_DB over its floor, within
   :data:`COMPARABLE_DB` of the ridge, and moves ≤ :data:`LINE_STEP_BINS` bins a frame for ≥ MIN_RUN frames.
2. *Hops.* The ridge jumps more than :data:`HOP_BINS` bins while the second tone now sits closer to where
   the ridge was than half the jump, or the ridge lands where the second tone was: the taxel's line went on; the
   taxel stays on it (the ridge is now the other tone). Said in a warning.
3. *Crossings.* The second tone disappears into the ridge (within the main lobe, ±EXCLUDE_BINS, it is not seen)
   or comes within :data:`NEAR_BINS` of it for :data:`MIN_MEET_FRAMES` to :data:`MAX_MEET_FRAMES` frames,
   having come within :data:`APPROACH_BINS` before and leaving within it after. Which line after it is the
   taxel is decided from what tells them apart: the slopes (Theil-Sen: median of pairwise slopes, Sen 1968,
   robust to a stray line) of both lines
   over :data:`WINDOW_FRAMES` frames before and after (a line that was moving keeps moving, a steady one stays; the
   pairing whose slope mismatch is smaller by ≥ :data:`SLOPE_CLEAR_HZ_S`), else their levels (the taxel's line
   ≥ :data:`LEVEL_CLEAR_DB` louder or weaker than the other's on both sides; less is the ridge's own selection
   bias: of two equal tones the one the ridge sits on measures ~3 dB louder). The frames where the two overlap
   are a blend and are left out. When neither tells (equal levels and the pressed line stops at the meeting
   point, e.g. pressed up to the other's pitch and released) nothing is guessed: every frame after the crossing
   is left out with the flag "two tones crossed at t=… s; identity after it uncertain".

A recording with no second tone of similar level in the band is returned unchanged (every realistic case of
benchmarks/analyze.py bit-identical). Measured on equal-level crossings (synth.crossing_scenario, 10 seeds;
``benchmarks/analyze.py --crossing-only``): frames reported on the other taxel 18 / 18 / 58 % → 0 / 0 / 0 % for
pass-through / touch and return / the other pressed through; a touch is flagged, not resolved.
Frequencies Hz, times s, levels dB.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from matcad.loop.segments import Segment, steady_segments
from matcad.loop.stats import median
from matcad.loop.voicing import MIN_RUN, WEAK_DB

COMPARABLE_DB = 10.0
"""A second line counts as a tone that can take the taxel's place when it is at most this far below the ridge."""
LINE_STEP_BINS = 8
"""Largest move of a line between frames (bins, ~43 Hz: a press ramp moves ~12 Hz a frame, plus the smear of a moving
line over the 93 ms window)."""
MAX_DROP_FRAMES = 2
"""Frames a line may go unseen (weaker, or another line picked) without ending it."""
HOP_BINS = 12
"""A ridge jump larger than this (bins, ~65 Hz) may be a hop to another tone."""
HOP_LOOK_FRAMES = 10
"""After a ridge jump, the line it left may be unseen this many frames (~0.46 s) before it shows as a second tone
(a weaker taxel under a newcomer's skirt)."""
NEAR_BINS = 10
"""Lines closer than this (bins, ~54 Hz; the main lobe hides one within EXCLUDE_BINS = 6) are meeting."""
APPROACH_BINS = 20
"""A meeting is a crossing when the lines are closer than this (bins, ~110 Hz) just before and just after it."""
MIN_APART = 3
"""Frames the lines must be seen apart to end a meeting."""
MIN_MEET_FRAMES = 3
"""Shortest meeting (frames): a press through another tone keeps them within NEAR_BINS for ~0.4 s; one frame is
a dropout of the second line."""
MAX_MEET_FRAMES = 30
"""Longest disappearance (frames, ~1.4 s) still read as one tone passing through the other."""
WINDOW_FRAMES = 6
"""Frames of both lines before and after a crossing from which their slopes and levels are taken (~0.28 s)."""
SLOPE_CLEAR_HZ_S = 100.0
"""Slope evidence (Hz/s) that decides a crossing: the two pairings' total slope mismatches differ by at least this
(a press ramp moves 200-300 Hz/s; the slope of a 6-frame window of a steady line scatters by ~10-20 Hz/s)."""
LEVEL_CLEAR_DB = 6.0
"""Level evidence that decides a crossing when slopes do not: the taxel's line this much louder (or weaker) than
the other on both sides."""


@dataclass(frozen=True)
class Identity:
    """The taxel's line per frame after hops and crossings: frequency (Hz), state (0 no tone, 1 voiced, 2 left out),
    the other line (bin, excess dB, level dB relative to the taxel's line), segments (flagged where left out) and
    warnings."""

    track_hz: np.ndarray
    state: np.ndarray
    other_bin: np.ndarray
    other_excess: np.ndarray
    other_level: np.ndarray
    segments: tuple[Segment, ...]
    warnings: tuple[str, ...]


def follow_taxel(times, track, state, other_bin, other_excess, other_level, excess, band_freqs) -> Identity:
    """Keep the taxel's identity through hops and crossings (module docstring). ``times`` s, ``track`` Hz (the
    ridge), ``state`` 0/1 per frame, the strongest other line per frame (``other_bin`` into ``band_freqs`` Hz,
    ``other_excess`` dB over its floor, ``other_level`` dB relative to the ridge), ``excess`` the ridge's dB."""
    df = float(band_freqs[1] - band_freqs[0])
    state = np.asarray(state, dtype=int).copy()
    voiced = np.flatnonzero((state >= 1) | (np.asarray(excess) >= WEAK_DB))  # frames with a line on the ridge
    other_hz = band_freqs[other_bin]
    tone = _second_tone(voiced, track, other_hz, other_excess, other_level, df)
    hops = _hops(voiced, track, other_hz, tone, df)
    hopped = np.zeros(len(track), dtype=bool)  # odd number of hops so far: the ridge's old line is the other line
    for _, k, _ in hops:
        hopped[voiced[k]:] = ~hopped[voiced[k]:]
    # two continuous lines through the hops: A (the ridge's line at the start) and B, B's level minus A's
    line_a, line_b = np.where(hopped, other_hz, track), np.where(hopped, track, other_hz)
    level_ba = np.where(hopped, -other_level, other_level)
    on_b = np.zeros(len(track), dtype=bool)  # the taxel is on line B
    left_out = np.zeros(len(track), dtype=bool)
    reasons: list[tuple[int, int, str]] = []  # (first frame, last frame, flag)
    warnings = []
    for _, k0, k1 in _meetings(voiced, track, other_hz, tone, df):
        before, after = voiced[max(0, k0 - WINDOW_FRAMES):k0], voiced[k1 + 1:k1 + 1 + WINDOW_FRAMES]
        before, after = before[tone[before]], after[tone[after]]
        meet = voiced[k0:k1 + 1]
        t_meet = float(times[meet[len(meet) // 2]])
        f_meet = float(median(track[meet]))
        was_b = bool(on_b[meet[0] - 1])
        pick, why = _decide(times, line_a, line_b, level_ba, was_b, before, after)
        if pick is None:
            flag = f"two tones crossed at t={t_meet:.2f} s; identity after it uncertain"
            left_out[meet[0]:] = True
            reasons.append((meet[0], len(track) - 1, flag))
            warnings.append(f"{flag} (equal levels, and neither line's motion tells them apart): the frames after "
                            f"it ({times[meet[0]]:.2f} s on) are left out; give the other taxel its own band or "
                            "press one taxel at a time")
            break
        on_b[meet[0]:] = pick
        left_out[meet] = True
        reasons.append((meet[0], meet[-1], f"two tones overlapping near {f_meet:.0f} Hz (a blend)"))
        warnings.append(f"two tones crossed at t={t_meet:.2f} s near {f_meet:.0f} Hz; the taxel is kept on the line "
                        f"that {why}; {len(meet)} frames where they overlapped left out")
    role = hopped ^ on_b  # the taxel is the other line
    for _, k, _ in hops:
        i, j = voiced[k], voiced[k - 1]
        if role[i] and not left_out[i]:
            warnings.append(f"the ridge jumped at t={times[i]:.2f} s from {track[j]:.0f} Hz to another tone at "
                            f"{track[i]:.0f} Hz while the taxel's line went on: the taxel is kept on its line")
    if not np.any(role) and not np.any(left_out):
        return Identity(np.asarray(track), state, other_bin, other_excess, other_level,
                        tuple(steady_segments(times, track, state)), ())
    swapped = role & (state >= 1)
    new_track = np.where(swapped, other_hz, track)
    last = np.nan
    for i in np.flatnonzero(swapped):  # the taxel's line seen: a tone, or a line where it just was
        if tone[i] or (other_excess[i] >= WEAK_DB and abs(other_hz[i] - last) <= LINE_STEP_BINS // 2 * df):
            last = other_hz[i]
        else:
            state[i] = 0
    ridge_bin = np.clip(np.round((np.asarray(track) - band_freqs[0]) / df).astype(int), 0, len(band_freqs) - 1)
    out_bin = np.where(swapped, ridge_bin, other_bin)
    out_excess = np.where(swapped, excess, other_excess)
    out_level = np.where(swapped, -other_level, other_level)
    kept = np.where(left_out, 0, state)
    segments = steady_segments(times, new_track, kept) if np.any(kept >= 1) else []
    for first, stop, flag in reasons:
        part = np.zeros_like(state)
        part[first:stop + 1] = state[first:stop + 1]
        if np.any(part >= 1):
            segments += [replace(s, flag=flag) for s in steady_segments(times, new_track, part)]
    state[left_out & (state >= 1)] = 2
    return Identity(new_track, state, out_bin, out_excess, out_level,
                    tuple(sorted(segments, key=lambda s: s.start_s)), tuple(warnings))


def _second_tone(voiced, track, other_hz, other_excess, other_level, df) -> np.ndarray:
    """Per frame: the other line is a tone of similar level, present for ≥ MIN_RUN frames (≤ MAX_DROP_FRAMES
    missed in a row), each within
    LINE_STEP_BINS of the other line or of the ridge one frame before (after a hop the ridge's old line is the
    other line)."""
    ok = np.zeros(len(other_hz), dtype=bool)
    good = (other_excess[voiced] >= WEAK_DB) & (other_level[voiced] >= -COMPARABLE_DB)
    run: list[int] = []
    for k, i in enumerate(voiced):
        if run and i - run[-1] > MAX_DROP_FRAMES + 1:
            ok[run] = len(run) >= MIN_RUN
            run = []
        if not good[k]:
            continue
        j = run[-1] if run else -1
        if run and min(abs(other_hz[i] - other_hz[j]), abs(other_hz[i] - track[j])) > LINE_STEP_BINS * df:
            ok[run] = len(run) >= MIN_RUN
            run = []
        run.append(i)
    if len(run) >= MIN_RUN:
        ok[run] = True
    return ok


def _hops(voiced, track, other_hz, tone, df) -> list:
    """('hop', k, k) where the ridge jumps > HOP_BINS between frames k−1 and k and the second tone at k (or
    where it is first seen within HOP_LOOK_FRAMES after) sits closer to the ridge at k−1 than half the jump (the
    line the ridge left goes on), or the ridge at k lands that close to where the second tone was last seen (within
    HOP_LOOK_FRAMES before): either way the two lines swapped places on the ridge."""
    out = []
    for k in range(1, len(voiced)):
        i, j = voiced[k], voiced[k - 1]
        jump = abs(track[i] - track[j])
        if i - j > 3 or jump <= HOP_BINS * df:
            continue
        seen = [m for m in voiced[k:k + HOP_LOOK_FRAMES + 1] if tone[m] and m - i <= HOP_LOOK_FRAMES]
        was = [m for m in voiced[max(0, k - HOP_LOOK_FRAMES):k] if tone[m] and j - m <= HOP_LOOK_FRAMES]
        if ((seen and abs(other_hz[seen[0]] - track[j]) <= 0.5 * jump)
                or (was and abs(other_hz[was[-1]] - track[i]) <= 0.5 * jump)):
            out.append(("hop", k, k))
    return out


def _meetings(voiced, track, other_hz, tone, df) -> list:
    """('meet', k0, k1): frames k0..k1 where the second tone is not seen apart from the ridge (absent, or within
    NEAR_BINS; islands of < MIN_APART frames apart do not split a meeting), MIN_MEET_FRAMES to MAX_MEET_FRAMES
    long, with the second tone within APPROACH_BINS of the ridge just before and just after."""
    apart = tone[voiced] & (np.abs(other_hz[voiced] - track[voiced]) > NEAR_BINS * df)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], apart.astype(int), [0]])))
    for start, stop in zip(edges[::2], edges[1::2]):  # runs of apart frames
        if stop - start < MIN_APART and start > 0 and stop < len(apart):
            apart[start:stop] = False
    out = []
    k = 0
    while k < len(voiced):
        if apart[k]:
            k += 1
            continue
        k1 = k
        while k1 + 1 < len(voiced) and not apart[k1 + 1]:
            k1 += 1
        if 0 < k and k1 + 1 < len(voiced) and MIN_MEET_FRAMES <= k1 - k + 1 <= MAX_MEET_FRAMES:
            a, b = voiced[k - 1], voiced[k1 + 1]
            if (abs(other_hz[a] - track[a]) <= APPROACH_BINS * df
                    and abs(other_hz[b] - track[b]) <= APPROACH_BINS * df):
                out.append(("meet", k, k1))
        k = k1 + 1
    return out


def _decide(times, line_a, line_b, level_ba, was_b, before, after):
    """Whether the taxel is on line B after a crossing (True/False, and why), or (None, '') when neither slopes nor
    levels tell. ``was_b``: it was on B before; ``before``/``after``: frames of both lines around the crossing."""
    if len(before) < 3 or len(after) < 3:
        return None, ""

    from scipy.stats import theilslopes

    def slope(frames, f):  # Theil-Sen: a blend or a stray line in the window does not tip it
        return float(theilslopes(f[frames], times[frames])[0])

    s_a, s_b = slope(before, line_a), slope(before, line_b)
    s_taxel, s_rest = (s_b, s_a) if was_b else (s_a, s_b)
    s_a2, s_b2 = slope(after, line_a), slope(after, line_b)
    to_a = abs(s_taxel - s_a2) + abs(s_rest - s_b2)
    to_b = abs(s_taxel - s_b2) + abs(s_rest - s_a2)
    if abs(to_a - to_b) >= SLOPE_CLEAR_HZ_S:
        motion = "kept moving" if abs(s_taxel) > abs(s_rest) else "stayed steady"
        return to_b < to_a, f"{motion} ({s_taxel:+.0f} Hz/s before the crossing)"
    level_b = float(median(level_ba[before])) * (-1 if was_b else 1)  # the rest minus the taxel, before
    level_a = float(median(level_ba[after]))  # B minus A, after
    if abs(level_b) >= LEVEL_CLEAR_DB and abs(level_a) >= LEVEL_CLEAR_DB:
        return (level_a < 0) == (level_b > 0), (f"was {abs(level_b):.1f} dB {'weaker' if level_b > 0 else 'louder'} "
                                                "than the other")
    return None, ""
