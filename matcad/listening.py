"""Where the recording loop listens: its analysis window, the guard that window implies between two taxels' bands,
and the band it listens in for a taxel. Frequencies Hz, times s.

The analysis window (:data:`WINDOW_S`, :data:`ZERO_PAD`) and the bins a line and a band edge take
(:data:`EXCLUDE_BINS`, :data:`EDGE_BINS`) set how far apart two taxels' bands must be (:func:`guard_hz`); the
design rules and the band planner read that guard here, the tracker (:mod:`matcad.loop.analyze`) reads the same
numbers. :func:`listening_band` is the one formula for the band the loop listens in, from whichever band is known:
an unloaded prediction (single-taxel ``analyze --spec``), a calibration's frequency range (``sense``) or a board
taxel's loaded band (``analyze``/``sense`` of an array spec), each widened by its own :class:`Margin`.

Base floor: the standard library only at module level (numpy inside :func:`window_samples`, for the same
arithmetic as the tracker's frames).
"""

from __future__ import annotations

from typing import NamedTuple

WINDOW_S = 0.093
"""~4096 samples at 44.1 kHz: ~11 Hz resolution (5.4 Hz bins with 2× padding), 46 ms between frames."""
ZERO_PAD = 2
"""The FFT is this many window lengths long (bins of fs / (ZERO_PAD · window))."""
HARMONICS = (2, 3)
"""Overtones of a taxel's tone that another taxel's band must avoid or its tracker discount: an edge tone is rich
in harmonics, and overblowing jumps to them (paper Sec. VI-B); the 2nd and 3rd are the strong ones."""
EXCLUDE_BINS = 6
"""Bins either side of a line that belong to it (Hann main lobe is ±4 bins at 2× padding)."""
FREQUENCY_KHZ_MAX = 100.0
"""Taxel tones are kHz; frequencies all below 100 "Hz" read as kHz (a unit slip: spec notes, `analyze --band`)."""
EDGE_BINS = 2
"""A ridge within this many bins of a band's edge is refused as hugging it (the tone probably lies outside)."""
BAND_BINS = 2 * EXCLUDE_BINS + 3
"""The fewest bins a band must hold for the tracker: a line and its neighbours (±EXCLUDE_BINS), and a bin of floor
either side."""


def window_samples(fs: float) -> int:
    """Window length (samples) at sample rate ``fs`` (Hz): the power of two nearest WINDOW_S."""
    import numpy as np

    return max(64, int(2 ** round(np.log2(WINDOW_S * fs))))


def bin_hz(sample_rate_hz: float) -> float:
    """Width (Hz) of one bin of the tracker's zero-padded spectrum at ``sample_rate_hz`` (Hz): fs / (ZERO_PAD ·
    window). 5.38 Hz at 44.1 kHz (window 4096), 5.86 Hz at 96 kHz (8192)."""
    return sample_rate_hz / (ZERO_PAD * window_samples(sample_rate_hz))


def guard_hz(sample_rate_hz: float) -> float:
    """Least gap between two taxels' bands (Hz) for the loop (:mod:`matcad.loop.analyze`) to keep them apart: a
    tone at one band's edge spreads its Hann main lobe over ±EXCLUDE_BINS bins, and a ridge within EDGE_BINS bins
    of a band's edge is refused as hugging it; so the gap is (EXCLUDE_BINS + EDGE_BINS) bins of the tracker's
    zero-padded spectrum, fs / (ZERO_PAD · window). 43 Hz at 44.1 kHz (window 4096, 5.4 Hz bins)."""
    return (EXCLUDE_BINS + EDGE_BINS) * bin_hz(sample_rate_hz)


def edge_zone_hz(sample_rate_hz: float) -> float:
    """Width (Hz) of the zone inside a band's edge where the board loop takes a ridge as the tone leaving the band
    (:func:`matcad.loop.board.off_edge`): EDGE_BINS + 1 bins of the tracker's spectrum. 16.2 Hz at 44.1 kHz, 17.6 Hz
    at 96 kHz."""
    return (EDGE_BINS + 1) * bin_hz(sample_rate_hz)


def loaded_listening_band(loaded_hz: tuple[float, float], sample_rate_hz: float) -> tuple[float, float]:
    """The band (low, high) Hz the board loop listens in for a taxel whose *loaded* band is ``loaded_hz``
    (:func:`matcad.prediction.bands.listening_bands`): widened either side by :func:`edge_zone_hz` and one bin more,
    so that a tone anywhere in its loaded band — which already holds the model's uncertainty and the rise under load
    up to the maximum force — is read with a bin (~4 sd of a frame's pitch) to spare, and only a tone outside it
    reaches the edge zone. Taken from the guard between two loaded bands (:func:`guard_hz`, EXCLUDE_BINS + EDGE_BINS
    = 8 bins): two neighbours' listening bands meet and do not overlap, and a tone at its own band's edge stays 4
    bins from its neighbour's listening band, at the first null of its Hann main lobe (±4 bins at 2× padding).
    (A band of exactly the loaded one left a rest pitch in its bottom 17.6 Hz unread at 96 kHz: the 16-taxel 1/8 in
    board's t2, 15 Hz above its band's edge, lost 107 of 139 frames.)"""
    edge = edge_zone_hz(sample_rate_hz) + bin_hz(sample_rate_hz)
    return loaded_hz[0] - edge, loaded_hz[1] + edge


def trackable(band_hz: tuple[float, float], sample_rate_hz: float) -> tuple[float, float]:
    """``band_hz`` (low, high Hz) widened about its centre to :data:`BAND_BINS` + 1 bins of the tracker's spectrum
    at ``sample_rate_hz`` (Hz) when it is narrower (the extra bin: a band off the bin grid still holds
    BAND_BINS bins); else as it is. A board taxel's loaded band, anchored to a tight calibration under a light
    touch, can be narrower than the tracker needs (75 Hz at templates/mat-array-4.toml's 1 N; 81 Hz at 44.1 kHz)."""
    width = (BAND_BINS + 1) * bin_hz(sample_rate_hz)
    low, high = band_hz
    grow = max(0.0, width - (high - low)) / 2
    return low - grow, high + grow


class Margin(NamedTuple):
    """Factors on a known band's low and high edge that give the band the loop listens in."""

    low: float
    high: float


PREDICTED_MARGIN = Margin(0.9, 1.25)
"""A single taxel's predicted *unloaded* band (``analyze --spec``): −10 % below for the model's error, +25 % above
because a press raises f (+11 % at 25 N on the paper's Eq. 5 fit) on top of the model's error."""
CALIBRATED_MARGIN = Margin(0.8, 1.25)
"""A calibration's frequency range over its force range (``sense``): wide on both sides so that a tone just
outside the calibrated range (a force beyond it, air warmer or colder than at calibration) is still tracked and
reported as outside the calibrated range rather than lost as "no tone"."""
def listening_band(band_hz: tuple[float, float], margin: Margin) -> tuple[float, float]:
    """The band (low, high) Hz the loop listens in for a taxel whose known band is ``band_hz`` (Hz), widened by
    ``margin`` (:data:`PREDICTED_MARGIN` or :data:`CALIBRATED_MARGIN`; a board's loaded band:
    :func:`loaded_listening_band`)."""
    return band_hz[0] * margin.low, band_hz[1] * margin.high
