"""The harmonic-sound detector (matcad/loop/harmonic.py) on sounds with known answers."""

import numpy as np

from matcad.loop import harmonic, synth
from matcad.loop.spectrum import Framer

FS = 44100


def _periodicity(x):
    framer = Framer(FS)
    _, power = framer.feed(x)
    return harmonic.periodicity(power, framer.freqs, (harmonic.LOW_HZ, harmonic.HIGH_HZ))


def test_a_voice_like_comb_is_harmonic_at_every_pitch_of_the_range():
    t = np.arange(int(0.5 * FS)) / FS
    for pitch in (90.0, 150.0, 220.0, 380.0):
        x = sum(np.sin(2 * np.pi * k * pitch * t) / k for k in range(1, int(3000 / pitch)))
        x = x + 0.01 * np.random.default_rng(0).standard_normal(len(t))
        assert np.min(_periodicity(x)) > 0.6, pitch


def test_noise_a_lone_tone_and_a_taxel_are_not():
    rng = np.random.default_rng(1)
    n = int(2.0 * FS)
    t = np.arange(n) / FS
    white = rng.standard_normal(n)
    tone = np.sin(2 * np.pi * 1000.0 * t) + 0.01 * white
    singing = synth.taxel(np.full(n, 4700.0), FS, 2) + synth.coloured_noise(n, FS, 3, 1.0, 0.01)
    for x in (white, synth.coloured_noise(n, FS, 4, 2.0, 0.1), tone, singing):
        assert np.max(_periodicity(x)) < harmonic.THRESHOLD


def test_silence_scores_zero_and_the_detector_stays_below_the_band():
    assert np.all(_periodicity(np.zeros(FS)) == 0.0)
    assert harmonic.detector_band(4000.0) == (harmonic.LOW_HZ, harmonic.HIGH_HZ)
    assert harmonic.detector_band(2500.0) == (harmonic.LOW_HZ, 2000.0)
    assert harmonic.detector_band(1500.0) is None  # 150–1200 Hz spans fewer than 3 periods of 400 Hz
    framer = Framer(FS)
    _, power = framer.feed(np.random.default_rng(0).standard_normal(FS))
    assert not np.any(harmonic.harmonic_frames(power, framer.freqs, 1500.0))
