"""Spectra of a recording, frame by frame, and each bin's strength over its local noise floor.

:class:`Framer` cuts blocks of samples into Hann-windowed, zero-padded power spectra (the window of
:mod:`matcad.listening`: ~93 ms, 2× zero padding, 50 % overlap). :func:`levels` divides each bin's power by the
running median of the power over ±:data:`FLOOR_BINS`/2 bins (≈ ±170 Hz) around it: the excess in dB. The median
follows coloured noise (pink, brown, a speech or fan hump) where a band-wide mean would not. Under white or smoothly
coloured noise a bin's power is exponential; with a *known* median the tail would be exp(−ln 2 · 10^(x/10)) per
bin, but the floor is itself estimated from ~30 independent bins, so the measured tail is far heavier: 1.2e-4 over
12 dB (law 2e-5), ~8e-7 over 15 dB (law 3e-10) per bin (benchmarks/analyze.py; the order-statistic law for a median
of 31–41 bins brackets it within ×2). A noise-free recording has no floor: a tone an exact number of cycles
per window leaves every other bin of the zero-padded spectrum at round-off (−300 dB), and the median of such bins
made a Hann sidelobe 86 dB under the tone 200 dB "over the floor" (a clean 1500 Hz tone at 48 kHz read 1283 Hz);
so the floor never lies more than :data:`DYNAMIC_RANGE_DB` under the frame's strongest bin. Frequencies Hz, times
s, levels dB.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matcad.listening import BAND_BINS, ZERO_PAD, window_samples

FLOOR_BINS = 63
"""Width of the running median that sets the local noise floor (≈ 340 Hz at 44.1 kHz)."""
DYNAMIC_RANGE_DB = 140.0
"""The floor lies at most this far under the frame's strongest bin (dB, per bin of the :class:`Framer`'s PSD).
Per bin a recording's range is its broadband range plus the Hann window's processing gain, 10·log10(n/(2·1.5)) =
31–34 dB (n 4096–8192 samples): a full-scale tone stands 128–131 dB over 16-bit PCM's own floor (98 dB broadband;
measured at 44.1 and 96 kHz), so nothing a 16-bit file holds is touched; the MEMS and electret microphones a taxel
is heard with (60–75 dB SNR on their data sheets) stay far inside it. Only a measurement chain at full scale
(~120 dB broadband) could pass it, and a line over a floor deeper than 140 dB under the frame's strongest bin would
lose as much excess as the floor lies beyond. Further down is numerical nothing (round-off; a synthesis without
noise), never evidence: an exact-bin tone's sidelobes now stand ≤ 56 dB over the floor, its own line ~80 dB."""
LINE_DB = 6.0
"""A local maximum this far over the floor counts as a line in the comb and second-source tests."""


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


def running_median_rows(rows: np.ndarray, width: int) -> np.ndarray:
    """Median over ``width`` (odd) neighbouring columns of each row, edges continued by their end values (the
    same numbers as scipy's median_filter(size=(1, width), mode='nearest')): Bottleneck's moving median (a double
    heap, O(log width) per value) over the edge-padded rows. scipy.ndimage is not imported: its import alone costs
    ~0.3 s, several times the tracker's own work on a 10 s recording; numpy's partition of every window took
    2.6 times as long as the heap on a 10 s recording's spectra."""
    import bottleneck

    half = width // 2
    padded = np.pad(np.asarray(rows, dtype=np.float64), ((0, 0), (half, half)), mode="edge")
    return bottleneck.move_median(padded, width, axis=1)[:, width - 1:]


def running_max(x: np.ndarray, size: int, mode: str = "reflect") -> np.ndarray:
    """Maximum over ``size`` (odd) neighbouring columns of each row of ``x`` (the same numbers as scipy's
    maximum_filter1d(x, size, axis=1, mode=mode)): ``mode`` 'reflect' (edges mirrored, d c b a | a b c d) or
    'constant' (zeros beyond the edges)."""
    half = size // 2
    if mode == "constant":
        padded = np.pad(x, ((0, 0), (half, half)), mode="constant", constant_values=0)
    else:
        padded = np.pad(x, ((0, 0), (half, half)), mode="symmetric")
    n = x.shape[1]
    out = padded[:, :n].copy()
    for k in range(1, size):
        np.maximum(out, padded[:, k:k + n], out=out)
    return out


def noise_floor(power: np.ndarray, peak: np.ndarray) -> np.ndarray:
    """Per frame and bin of ``power`` (frames × bins, PSD): the running median over FLOOR_BINS bins, never under
    the frame's strongest bin ``peak`` (one per frame, PSD: the whole spectrum's, of which ``power`` may be a slab)
    DYNAMIC_RANGE_DB down."""
    return np.maximum(running_median_rows(power, FLOOR_BINS), (peak * 10 ** (-DYNAMIC_RANGE_DB / 10))[:, None])


def levels(power: np.ndarray, peak: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame and bin of ``power`` (frames × bins, PSD): (level dB, excess over the :func:`noise_floor` dB,
    lines: the excess where a bin is a local maximum ≥ LINE_DB over the floor, else −inf). ``peak``: each frame's
    strongest bin over the whole spectrum (PSD)."""
    tiny = np.finfo(float).tiny
    excess = 10 * np.log10((power + tiny) / (noise_floor(power, peak) + tiny))
    level = 10 * np.log10(power + tiny)
    is_max = (excess >= running_max(excess, 3)) & (excess >= LINE_DB)
    return level, excess, np.where(is_max, excess, -np.inf)


@dataclass(frozen=True)
class BandBins:
    """Where a band lies in a :class:`Framer`'s spectrum: the spectrum's bins ``freqs`` (Hz, ``df`` apart) at sample
    rate ``fs`` (Hz), the band (low, high Hz, clipped to 0 … Nyquist), its bins ``in_band``, and the wider ``slab``
    of bins around it that the floor and the comb tests need, the band starting ``offset`` bins into the slab."""

    freqs: np.ndarray
    fs: float
    band_hz: tuple[float, float]
    df: float
    in_band: np.ndarray
    slab: np.ndarray
    offset: int

    @classmethod
    def locate(cls, freqs: np.ndarray, fs: float, band_hz: tuple[float, float], reach_hz: float) -> "BandBins":
        """The bins of ``band_hz`` (Hz) among ``freqs`` (Hz) at ``fs`` (Hz), the slab reaching FLOOR_BINS/2 bins
        and ``reach_hz`` (Hz, plus 2 bins) beyond it, whichever is wider. ValueError when the band lies above
        Nyquist or is narrower than a line and its neighbours (:data:`matcad.listening.BAND_BINS`)."""
        nyquist = fs / 2
        lo, hi = max(0.0, band_hz[0]), min(band_hz[1], nyquist)
        if not lo < hi:
            raise ValueError(f"band {band_hz[0]:g}-{band_hz[1]:g} Hz invalid for a {fs:g} Hz recording "
                             f"(must lie below {nyquist:g} Hz)")
        df = float(freqs[1] - freqs[0])
        in_band = np.flatnonzero((freqs >= lo) & (freqs <= hi))
        if len(in_band) < BAND_BINS:
            raise ValueError(f"band {lo:g}-{hi:g} Hz is narrower than the analysis needs "
                             f"({BAND_BINS * df:.0f} Hz)")
        margin = max(FLOOR_BINS // 2, int(np.ceil(reach_hz / df)) + 2)
        slab = np.arange(max(0, in_band[0] - margin), min(len(freqs), in_band[-1] + margin + 1))
        return cls(freqs, fs, (lo, hi), df, in_band, slab, int(in_band[0] - slab[0]))

    @property
    def band_freqs(self) -> np.ndarray:
        """The band's bins (Hz)."""
        return self.freqs[self.in_band]
