"""The tone's ridge through a band: a Viterbi path with a jump allowance, decided with a fixed lag.

A path through the band's emissions (excess over the floor, dB, mains combs removed): moving Δ bins costs
:data:`JUMP_PENALTY_DB`·Δ² up to :data:`MAX_STEP_BINS`, any larger jump a flat :data:`JUMP_COST_DB` — so the ridge
follows a slow wobble smoothly, re-acquires after a gap and follows a press that jumps 300 Hz between frames.
Decisions are made with a fixed lag of :data:`LAG_FRAMES` frames (~1 s), which bounds memory. Levels dB, bins of
the band.
"""

from __future__ import annotations

import numpy as np

JUMP_PENALTY_DB = 1.0
MAX_STEP_BINS = 4
JUMP_COST_DB = 14.0
"""Any jump wider than MAX_STEP_BINS costs this once: a tone ≥ STRONG_DB repays it in one frame, noise does not."""
LAG_FRAMES = 20


class Ridge:
    """The ridge of one band of ``bins`` bins, block by block: :meth:`push` takes each block's emissions and gives
    the bins of the frames decided by it (each frame once the frame LAG_FRAMES later is in); :meth:`finish` gives
    the rest. Keeps the back pointers of the undecided frames only (≤ LAG_FRAMES + one block)."""

    def __init__(self, bins: int):
        steps = np.arange(-MAX_STEP_BINS, MAX_STEP_BINS + 1)
        src = np.arange(bins)[None, :] - steps[:, None]  # bin a state comes from, per step
        self._src = np.clip(src, 0, bins - 1)
        self._cost = np.where((src >= 0) & (src < bins), JUMP_PENALTY_DB * steps[:, None].astype(float) ** 2, np.inf)
        self._score = None
        self._back = np.zeros((0, bins), dtype=np.intp)  # per undecided frame: back pointers, and its best state
        self._best = np.zeros(0, dtype=np.intp)

    def push(self, emit: np.ndarray) -> np.ndarray:
        """The ridge bins of the oldest undecided frames that the block ``emit`` (frames × bins, dB) decides: frame
        j's bin is the best path ending at frame j + LAG_FRAMES, traced back LAG_FRAMES steps."""
        back, best = self._forward(emit)
        self._back = np.concatenate([self._back, back])
        self._best = np.concatenate([self._best, best])
        ready = len(self._best) - LAG_FRAMES
        if ready <= 0:
            return np.zeros(0, dtype=np.intp)
        states = self._best[LAG_FRAMES:LAG_FRAMES + ready].copy()
        rows = np.arange(ready)
        for s in range(LAG_FRAMES, 0, -1):
            states = self._back[rows + s, states]
        self._back, self._best = self._back[ready:], self._best[ready:]
        return states

    def finish(self) -> np.ndarray:
        """The ridge bins of every frame not yet decided: one backtrack from the best final state."""
        count = len(self._best)
        states = np.empty(count, dtype=np.intp)
        if count:
            states[-1] = self._best[-1]
            for j in range(count - 1, 0, -1):
                states[j - 1] = self._back[j, states[j]]
        self._back, self._best = self._back[count:], self._best[count:]
        return states

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
