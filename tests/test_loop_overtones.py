"""Every taxel's predicted harmonics discounted in the other taxels' trackers (matcad.loop.overtones, issue 24),
and the room's tail before a fast pitch step left out of a board taxel's frames (matcad.loop.board.room_tails).
The full check is benchmarks/design.py --capacity-only (the 16-taxel 96 kHz board over 5 seeds)."""

import numpy as np
import pytest

from matcad.listening import EXCLUDE_BINS
from matcad.loop import synth_board
from matcad.loop.board import analyze_board
from matcad.loop.overtones import Overtones, half_width
from matcad.loop.spectrum import Framer

BANDS = [("t1", (3000.0, 3300.0)), ("t2", (4000.0, 4400.0)), ("t3", (6050.0, 6600.0))]
"""t3's band holds all of t1's 2f (6000-6600 Hz), as a 96 kHz board's t8 holds t1's."""


def _spectrum(lines):
    """One frame's power spectrum on a Framer's bins at 44.1 kHz: a floor of 1e-6 and ``lines`` (Hz, power) each
    spread over its bin and neighbours like a Hann main lobe."""
    freqs = Framer(44100.0).freqs
    power = np.full((1, len(freqs)), 1e-6)
    for f, p in lines:
        k = int(np.argmin(np.abs(freqs - f)))
        power[0, k - 2:k + 3] += p * np.array([0.1, 0.5, 1.0, 0.5, 0.1])
    return freqs, power


def test_a_weaker_line_on_a_predicted_harmonic_is_discounted():
    """t1's tone at 3150 Hz and a line at 6300 Hz 20 dB weaker: inside the bands, the bins around 2f (and only
    there) are marked (outside every band, where the floor lies far below, 3f of each band's peak is marked too:
    no tracker listens there)."""
    freqs, power = _spectrum([(3150.0, 1.0), (6300.0, 0.01)])
    mask = Overtones(freqs, [b for _, b in BANDS]).mask(power)[0]
    inside = np.any([(freqs >= lo) & (freqs <= hi) for _, (lo, hi) in BANDS], axis=0)
    marked = freqs[mask & inside]
    df = freqs[1] - freqs[0]
    assert marked.min() >= 6300.0 - (half_width(2) + 1) * df and marked.max() <= 6300.0 + (half_width(2) + 1) * df
    assert len(marked) == 2 * half_width(2) + 1 and half_width(2) > EXCLUDE_BINS


def test_a_line_as_strong_as_the_tone_is_not_discounted():
    """Deliberate fault caught: discounting every line at m·f would hide a taxel pressed onto a neighbour's 2f —
    a line only 3 dB weaker than the tone is a taxel's own, kept (3f of 3150 Hz, 9450 Hz, lies in no band here, its
    bins are marked only where it is weaker: nothing sings there, so nothing is marked)."""
    freqs, power = _spectrum([(3150.0, 1.0), (6300.0, 0.5)])
    mask = Overtones(freqs, [b for _, b in BANDS]).mask(power)[0]
    assert not np.any(mask[(freqs > 6000) & (freqs < 6600)])


@pytest.mark.parametrize("seed", [0, 5])
def test_a_pressed_taxel_is_tracked_through_a_pressed_neighbours_harmonic(seed):
    """Deliberate fault caught: without the predicted harmonics the crossing logic took t1's moving 2f (-15 dB,
    levels spread over 12 dB) for a second taxel in pressed t3's band: t3 read -4.57 Hz off on seed 5, and the
    room's tail before t1's press steps put t1 at -1.55 Hz on seed 0. Now every taxel is within 1 Hz."""
    rec = synth_board.board_recording(BANDS, (1.05,) * 3, 5.0, seconds=6.0, seed=seed, pressed=(0, 2),
                                      harmonics_db=(-15.0, -25.0), level_spread_db=12.0)
    tracks = analyze_board([rec.x], rec.fs, BANDS)
    for k, t in enumerate(tracks):
        a = t.analysis
        assert a is not None, t.reason
        assert a.voiced.sum() > 0.3 * len(a.voiced), t.name
        assert abs(np.mean(a.track_hz[a.voiced] - rec.truth_at(k, a.times_s[a.voiced]))) < 1.0, t.name
