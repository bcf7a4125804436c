"""Steady segments of a voiced frequency track, and mode jumps among them. Frequencies Hz, times s.

Voiced frames are cut into steady segments at gaps and at steps larger than :data:`STEP_HZ` between frames; a
segment that sits more than :data:`MODE_JUMP_RATIO` above or below the one before it, without a ramp in between,
cannot be a press (Eq. 5 spans ~+11 % from 0 to 25 N): it is flagged as a mode jump (overblowing) and its frames
are left out of the statistics.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

STEP_HZ = 12.0
"""Frame-to-frame change that ends a steady segment (a ±20 Hz wobble over 2.5 s moves ≤ 2.5 Hz per frame; a
2→12 N press ramped in 0.2 s moves ~60 Hz per frame)."""
MIN_SEGMENT_FRAMES = 3
MAX_GAP_FRAMES = 1
MODE_JUMP_RATIO = 1.11
JUMP_GAP_FRAMES = 8
"""A jump across at most this many frames (~0.37 s) with no voiced frame between the two levels is abrupt."""


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


def steady_segments(times, track, state) -> list[Segment]:
    """Steady segments of voiced frames (``state`` >= 1) of ``track`` (Hz) at ``times`` (s). A segment reached by
    an abrupt jump (no ramp frames) of more than MODE_JUMP_RATIO whose mean also lies that far from the median of
    all voiced frames is flagged as a mode jump."""
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
