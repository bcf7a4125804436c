"""Steady segments of a voiced frequency track, and mode jumps among them. Frequencies Hz, times s.

Voiced frames are cut into steady segments at gaps and at steps larger than :data:`STEP_HZ` between frames, and
then by a trend test, so that a slow change is never one "steady" segment: a frame whose local slope (least squares
over :data:`TREND_FRAMES` frames, ~0.4 s) exceeds :data:`SLOPE_HZ_S` is moving and belongs to no segment, and a
stretch whose fitted drift exceeds :data:`DRIFT_HZ` with a significant slope is cut in halves until no piece
drifts (issue 24: a 2 → 12 N press over 4 s, < 12 Hz a frame, was one segment whose 95 % force interval missed the
true force 93 % of the time). A segment that sits more than :data:`MODE_JUMP_RATIO` above or below the one before
it, without a ramp in between, cannot be a press (Eq. 5 spans ~+11 % from 0 to 25 N): it is flagged as a mode
jump (overblowing) and its frames are left out of the statistics.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from matcad.loop.stats import median

STEP_HZ = 12.0
"""Frame-to-frame change that ends a steady segment (a ±20 Hz wobble over 2.5 s moves ≤ 2.5 Hz per frame; a
2→12 N press ramped in 0.2 s moves ~60 Hz per frame)."""
MIN_SEGMENT_FRAMES = 3
MAX_GAP_FRAMES = 1
MODE_JUMP_RATIO = 1.11
JUMP_GAP_FRAMES = 8
"""A jump across at most this many frames (~0.37 s) with no voiced frame between the two levels is abrupt."""
TREND_FRAMES = 9
"""Frames (~0.42 s) of the least-squares line that gives a frame's local slope."""
SLOPE_HZ_S = 40.0
"""Local slope above which a frame is moving (a press or release ramp, a slow stage). The slope of a steady line
over TREND_FRAMES scatters by ~5 Hz/s per 2 Hz of frame-to-frame jitter (the synthetic taxels' track RMS), so this
is ~8 standard deviations: ~1.3 N/s at the paper's 30 Hz/N."""
DRIFT_HZ = 6.0
"""Largest fitted change across one steady segment (0.2 N at 30 Hz/N): a longer or faster drift is cut."""
DRIFT_T = 4.0
"""...and only when its slope stands this many standard errors from zero (jitter alone does not cut)."""
TRIM_SD = 3.0
TRIM_MIN_HZ = 1.0
"""End frames of a segment farther than TRIM_SD robust jitter sds (at least TRIM_MIN_HZ) from its median are
ramp, not hold (:func:`_trimmed`)."""


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

    def to_text(self, force=None) -> str:
        """One line: start-end (s), mean and sd (Hz), with ``force`` (force, low, high in N; NaN: outside the
        calibrated range) the force and its 95 % interval, and the flag."""
        line = (f"  {self.start_s:8.2f}-{self.end_s:8.2f} s  {self.mean_hz:9.2f} Hz (sd {self.std_hz:5.2f})")
        if force is not None and self.flag == "":
            f, lo, hi = force
            line += f"  F = {f:.3f} N (95 %: {lo:.3f} .. {hi:.3f})" if f == f else "  outside the calibrated range"
        return line + (f"  [{self.flag}]" if self.flag else "")


def _slope(t, f) -> tuple[float, float]:
    """Least-squares slope of f(t) (Hz/s) and its standard error (inf with < 3 points)."""
    n = len(t)
    tc = t - t.mean()
    sxx = float(tc @ tc)
    if n < 3 or sxx <= 0:
        return 0.0, np.inf
    slope = float(tc @ (f - f.mean())) / sxx
    resid = f - f.mean() - slope * tc
    return slope, float(np.sqrt(max(resid @ resid, 0.0) / (n - 2) / sxx))


def _local_slopes(t, f) -> np.ndarray:
    """Per frame of one run: its local slope (Hz/s, over TREND_FRAMES frames centred on it; 0 in a shorter run)."""
    half = TREND_FRAMES // 2
    out = np.zeros(len(t))
    if len(t) < TREND_FRAMES:
        return out
    for i in range(len(t)):
        a = min(max(0, i - half), len(t) - TREND_FRAMES)
        out[i] = _slope(t[a:a + TREND_FRAMES], f[a:a + TREND_FRAMES])[0]
    return out


def _untrended(times, track, run) -> list[list[int]]:
    """A run of frames cut where it moves (local slope over SLOPE_HZ_S) and halved where it still drifts
    (DRIFT_HZ, DRIFT_T). A piece shorter than TREND_FRAMES between moving frames that move the same way is the
    middle of one ramp (the local slope dipped), not a hold: dropped."""
    run = np.asarray(run)
    slopes = _local_slopes(times[run], track[run])
    moving = np.abs(slopes) > SLOPE_HZ_S
    pieces, cur = [], []
    for k, (i, m) in enumerate(zip(run, moving)):
        if m:
            if cur:
                pieces.append((cur, k))
            cur = []
        else:
            cur.append(int(i))
    if cur:
        pieces.append((cur, len(run)))
    kept = []
    for piece, after in pieces:
        before = after - len(piece) - 1
        in_ramp = (before >= 0 and after < len(run) and len(piece) < TREND_FRAMES
                   and slopes[before] * slopes[after] > 0)
        if not in_ramp:
            kept.append(piece)
    pieces = kept
    out = []
    pieces = [(piece, False) for piece in pieces]
    while pieces:
        piece, halved = pieces.pop(0)
        t, f = times[piece], track[piece]
        slope, se = _slope(t, f)
        if len(piece) >= 2 * MIN_SEGMENT_FRAMES and abs(slope) * (t[-1] - t[0]) > DRIFT_HZ and \
                abs(slope) > DRIFT_T * se:
            half = len(piece) // 2
            pieces[:0] = [(piece[:half], True), (piece[half:], True)]
        elif not (halved and len(piece) < TREND_FRAMES):  # a short half of a drifting stretch: too few to tell
            out.append(_trimmed(track, piece))
    return out


def _trimmed(track, piece) -> list[int]:
    """``piece`` without the end frames that lie farther than TRIM_SD jitter sds (robust, from frame-to-frame
    differences; at least TRIM_MIN_HZ) from its median: the corner of a ramp that the local slope cannot pin (its
    window straddles ramp and hold)."""
    if len(piece) < 2 * MIN_SEGMENT_FRAMES:
        return piece
    f = track[piece]
    jitter = 1.4826 * float(median(np.abs(np.diff(f) - median(np.diff(f))))) / np.sqrt(2.0)
    tol = max(TRIM_SD * jitter, TRIM_MIN_HZ)
    keep = np.flatnonzero(np.abs(f - median(f)) <= tol)
    return piece[keep[0]:keep[-1] + 1] if len(keep) else []


def _passage(track, runs, k) -> bool:
    """Run ``k`` is shorter than TREND_FRAMES and cut at steps on both sides that go the same way (the frame before
    it below and the frame after it above, or the reverse): a stretch of one ramp between two large steps, not a
    hold."""
    run = runs[k]
    if len(run) >= TREND_FRAMES or k == 0 or k == len(runs) - 1:
        return False
    before, after = runs[k - 1][-1], runs[k + 1][0]
    if run[0] - before > MAX_GAP_FRAMES + 1 or after - run[-1] > MAX_GAP_FRAMES + 1:
        return False
    mean = float(np.mean(track[run]))
    return (track[before] - mean) * (track[after] - mean) < 0


def steady_segments(times, track, state) -> list[Segment]:
    """Steady segments of voiced frames (``state`` >= 1) of ``track`` (Hz) at ``times`` (s): cut at gaps, steps
    and trends (module docstring). A segment reached by an abrupt jump (no ramp frames) of more than
    MODE_JUMP_RATIO whose mean also lies that far from the median of all voiced frames is flagged as a mode
    jump."""
    times, track = np.asarray(times, dtype=float), np.asarray(track, dtype=float)
    runs, cur = [], []
    for i in np.flatnonzero(state >= 1):
        if cur and (i - cur[-1] > MAX_GAP_FRAMES + 1 or abs(track[i] - track[cur[-1]]) > STEP_HZ):
            runs.append(cur)
            cur = []
        cur.append(int(i))
    if cur:
        runs.append(cur)
    runs = [run for k, run in enumerate(runs) if not _passage(track, runs, k)]
    runs = [piece for run in runs for piece in _untrended(times, track, run)]
    reference = float(median(track[state >= 1]))
    out, last = [], None
    for run in runs:
        if len(run) < MIN_SEGMENT_FRAMES:
            continue
        f = track[run]
        mean = float(np.mean(f))
        flag = ""
        between = track[last[1] + 1:run[0]][state[last[1] + 1:run[0]] >= 1] if last is not None else []
        # no ramp frame in between (frames by the jump are left out as moving: TREND_FRAMES more may separate them)
        jump = 0.0 if last is None else abs(mean - last[0])
        ramp = [b for b in between if min(abs(b - last[0]), abs(b - mean)) > 0.1 * jump
                and (b - last[0]) * (b - mean) < 0]
        abrupt = last is not None and run[0] - last[1] <= JUMP_GAP_FRAMES + TREND_FRAMES and not ramp
        ratio = mean / reference
        far = max(ratio, 1 / ratio) > MODE_JUMP_RATIO
        if far and abrupt and max(mean / last[0], last[0] / mean) > MODE_JUMP_RATIO:
            flag = (f"abrupt jump x{mean / last[0]:.3f} from {last[0]:.0f} Hz, x{ratio:.3f} from the recording's "
                    f"median, more than a press can give (Eq. 5: x{MODE_JUMP_RATIO:g} over 0-25 N): a mode jump "
                    "(overblowing)")
        elif far and last is not None and last[2] and max(mean / last[0], last[0] / mean) <= MODE_JUMP_RATIO:
            flag = last[2]  # the same jumped mode, after a dropout
        last = (mean, run[-1], flag)
        out.append(Segment(float(times[run[0]]), float(times[run[-1]]), len(run), mean, float(median(f)),
                           float(np.std(f)), flag))
    return out
