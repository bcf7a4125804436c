"""Every taxel's predicted harmonics, fed to the other taxels' trackers of a board (issue 24).

The bands of a board may hold other taxels' 2f and 3f: the allocation interleaves bands between harmonics instead
of forbidding them (docs/bands.md). A harmonic in a taxel's band is a line the band's tracker would take for a
second tone — the ridge hops to it, the crossing logic (:mod:`matcad.loop.crossing`) reads a moving harmonic
meeting the taxel's tone as a crossing and leaves the taxel's frames out or keeps the wrong line. So each frame,
before any tracker sees it, every taxel's harmonics are predicted from that taxel's tone in the same frame and
discounted where they fall:

1. *The tone.* Each band's strongest bin, its frequency refined by a parabola through the log power of it and its
   neighbours (the same refinement as the ridge's), and its power P.
2. *Its harmonics.* m·f for m in HARMONICS (2, 3), within the spectrum.
3. *Discounted.* The bins within :func:`half_width` of m·f are marked, when the strongest of them is at least
   :data:`WEAKER_DB` below P: a Helmholtz resonator does not amplify its overtones (the synthetic board's are at
   −20/−30 dB), while a line about as strong as the tone is another taxel's own tone — pressed onto the harmonic
   it is kept, not hidden.

A tracker treats marked bins as it treats the bins of a mains comb (:class:`matcad.loop.tracker.BandTracker`):
no emission for the ridge, no line for the second-tone and crossing logic, no excess for voicing. A taxel whose
own, much weaker tone sits on a neighbour's harmonic loses those frames (they cannot be told apart); the board's
frame-by-frame check after tracking (:func:`matcad.loop.board.discount_harmonics`) stays as a second net.
Frequencies Hz, levels dB.
"""

from __future__ import annotations

import numpy as np

from matcad.listening import EXCLUDE_BINS, HARMONICS
from matcad.loop.spectrum import running_max

WEAKER_DB = 10.0
"""A line at a predicted harmonic is discounted when it is at least this much weaker than the tone it is predicted
from (as :data:`matcad.loop.board.HARMONIC_WEAKER_DB`)."""


def half_width(m: int) -> int:
    """Bins either side of m·f that are discounted: the harmonic's main lobe (EXCLUDE_BINS, which hides a line's
    own skirt) plus m bins for the error of f (a refined peak is within ~½ bin; a press moving ~12 Hz per frame
    smears the harmonic m times as far)."""
    return EXCLUDE_BINS + m


class Overtones:
    """The discounted bins of each frame for a board heard through one :class:`matcad.loop.spectrum.Framer`
    (bins ``freqs``, Hz) with listening ``bands`` (Hz)."""

    def __init__(self, freqs: np.ndarray, bands):
        self.freqs = freqs
        self.df = float(freqs[1] - freqs[0])
        self.bins = [np.flatnonzero((freqs >= lo) & (freqs <= hi)) for lo, hi in bands]

    def mask(self, power: np.ndarray) -> np.ndarray:
        """frames × bins of ``power`` (PSD): True where a bin lies on another taxel's predicted harmonic that is
        discounted (module docstring)."""
        frames, nbins = power.shape
        out = np.zeros((frames, nbins), dtype=bool)
        if frames == 0:
            return out
        tiny = np.finfo(float).tiny
        log = 10 * np.log10(power + tiny)
        rows = np.arange(frames)
        widest = {m: running_max(log, 2 * half_width(m) + 1) for m in HARMONICS}
        for bins in self.bins:
            if len(bins) < 3:
                continue
            k = np.clip(bins[0] + np.argmax(power[:, bins], axis=1), bins[0] + 1, bins[-1] - 1)
            l, c, r = log[rows, k - 1], log[rows, k], log[rows, k + 1]
            denom = l - 2 * c + r
            with np.errstate(divide="ignore", invalid="ignore"):
                delta = np.where(denom < 0, np.clip(0.5 * (l - r) / denom, -0.5, 0.5), 0.0)
            f = self.freqs[k] + delta * self.df
            for m in HARMONICS:
                w = half_width(m)
                centre = np.round((m * f - self.freqs[0]) / self.df).astype(int)
                inside = (centre - w >= 0) & (centre + w < nbins)
                hit = np.flatnonzero(inside)
                hit = hit[widest[m][hit, centre[hit]] <= c[hit] - WEAKER_DB]
                for i in hit:
                    out[i, centre[i] - w:centre[i] + w + 1] = True
        return out
