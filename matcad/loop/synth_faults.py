"""Recordings that tempted the loop into a wrong answer with exit 0 (issue 24), made independently of the cases the
loop was tuned on (:mod:`matcad.loop.synth`): slow presses, two taxels in one band, a room and a talker with no
taxel at all. Pure functions of their arguments and seed. Frequencies Hz, times s, forces N.

- :func:`slow_press`: the taxel pressed 2 → 12 N by a slow stage (linear over ``ramp_s``), held, released the same
  way; or "press-2n": 2 → 4 N presses with 0.3 s ramps (a 2 N press: ~60 Hz, < 12 Hz a frame).
- :func:`two_tones`: the taxel held at 8 N and a second taxel 150 Hz above it, both singing from the start, at
  ``level_db`` against the taxel: nothing says which tone is which.
- :func:`talker` and :func:`reverberant_room`: a voice from a glottal pulse train through four formant resonators
  with random vowels and fricatives, and broadband noise heard through discrete early reflections (an
  image-source room: the comb of fixed spectral ripples is what looks steady) and a late tail; no taxel.
"""

from __future__ import annotations

import numpy as np

from matcad.loop import synth

CASES = ("slow-stage", "press-2n", "two-tones-6db", "two-tones-0db", "talker", "reverberant-room",
         "room-and-talker")


def slow_press(seconds: float = 12.0, seed: int = 0, fs: float = synth.FS, ramp_s: float = 4.0):
    """2 → 12 N over ``ramp_s`` (s), held 1.5 s, released over ``ramp_s``, starting at 1 s."""
    force = synth.press_profile(seconds, fs, [(1.0, 1.0 + 2 * ramp_s + 1.5, 12.0)], ramp_s=ramp_s)
    freq = synth.frequency_of_force(force)
    x = synth.room(synth.taxel(freq, fs, seed + 3), fs, seed, rt60=0.4)
    return synth.Recording(x, fs, freq, force)


def press_2n(seconds: float = 10.0, seed: int = 0, fs: float = synth.FS):
    """2 → 4 N presses held 1 s every 2.5 s with 0.3 s ramps (~62 Hz at ~10 Hz a frame)."""
    starts = np.arange(1.0, seconds - 2.0, 2.5)
    force = synth.press_profile(seconds, fs, [(s, s + 1.6, 4.0) for s in starts], ramp_s=0.3)
    freq = synth.frequency_of_force(force)
    x = synth.room(synth.taxel(freq, fs, seed + 3), fs, seed, rt60=0.4)
    return synth.Recording(x, fs, freq, force)


def two_tones(level_db: float, seconds: float = 8.0, seed: int = 0, fs: float = synth.FS):
    """The taxel held at 8 N and a neighbour 150 Hz above at ``level_db`` (dB against the taxel), both from 0 s."""
    n = int(seconds * fs)
    force = np.full(n, 8.0)
    freq = synth.frequency_of_force(force)
    x = synth.taxel(freq, fs, seed + 3) + synth.taxel(freq + 150.0, fs, seed + 5,
                                                      amplitude=0.1 * 10 ** (level_db / 20))
    return synth.Recording(synth.room(x, fs, seed, rt60=0.4), fs, freq, force)


def _formant(x, fs, centre_hz, bandwidth_hz):
    from scipy.signal import lfilter

    r = np.exp(-np.pi * bandwidth_hz / fs)
    return lfilter([1 - r], [1.0, -2 * r * np.cos(2 * np.pi * centre_hz / fs), r * r], x)


VOWELS = ((730, 1090, 2440, 3400), (270, 2290, 3010, 3700), (300, 870, 2240, 3500), (530, 1840, 2480, 3600),
          (570, 840, 2410, 3300), (660, 1720, 2410, 3500))
"""Formants (Hz) of six English vowels (Peterson & Barney 1952, male speakers; 4th formant ~3.3-3.7 kHz)."""


def talker(n: int, fs: float, seed: int, rms: float = 0.05) -> np.ndarray:
    """A voice: glottal pulses at a 90-250 Hz pitch with jitter and vibrato through four formant resonators, the
    vowel changing every 0.15-0.3 s, fricative noise (3-8 kHz) between syllables."""
    from scipy.signal import butter, sosfilt

    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    pitch = 140 + 60 * np.sin(2 * np.pi * 0.3 * t + rng.uniform(0, 6)) + 5 * np.sin(2 * np.pi * 5.5 * t)
    pitch *= 1 + 0.01 * rng.standard_normal(n)
    phase = np.cumsum(pitch / fs)
    pulses = np.diff(np.floor(phase), prepend=0.0)  # one impulse per glottal cycle
    source = np.convolve(pulses, np.hanning(int(0.003 * fs)), mode="same")  # a smooth glottal pulse
    out = np.zeros(n)
    edges = np.cumsum(rng.uniform(0.15, 0.3, int(n / fs / 0.15) + 2) * fs).astype(int)
    start = 0
    for stop in edges:
        stop = min(stop, n)
        if stop <= start:
            break
        vowel = VOWELS[rng.integers(len(VOWELS))]
        chunk = source[start:stop]
        voiced = sum(_formant(chunk, fs, f, 60 + 0.05 * f) * g for f, g in zip(vowel, (1.0, 0.7, 0.4, 0.25)))
        if rng.uniform() < 0.3:  # a fricative instead
            voiced = sosfilt(butter(4, (3000, min(8000, 0.45 * fs)), "bandpass", fs=fs, output="sos"),
                             rng.standard_normal(len(chunk))) * 0.3
        out[start:stop] = voiced * np.hanning(len(chunk))
        start = stop
    return rms * out / max(np.std(out), 1e-12)


def reverberant_room(x: np.ndarray, fs: float, seed: int, reflections: int = 14) -> np.ndarray:
    """``x`` heard through an image-source room: the direct sound, ``reflections`` discrete early reflections (2-30
    ms, gains 0.3-0.8, random sign) and a late exponential tail (RT60 0.7 s), then the tablet microphone."""
    rng = np.random.default_rng(seed)
    ir = np.zeros(int(0.032 * fs))
    ir[0] = 1.0
    for delay, gain in zip(rng.uniform(0.002, 0.030, reflections), rng.uniform(0.3, 0.8, reflections)):
        ir[int(delay * fs)] += gain * rng.choice((-1.0, 1.0))
    from scipy.signal import oaconvolve

    early = oaconvolve(x, ir)[: len(x)]
    return synth.microphone(synth.reverb(early, fs, 0.7, seed + 1, wet=0.6), fs)


def scenario(name: str, seconds: float = 8.0, seed: int = 0, fs: float = synth.FS) -> synth.Recording:
    """One case of :data:`CASES` (truth NaN where no taxel sings)."""
    n = int(seconds * fs)
    silent = np.full(n, np.nan)
    if name == "slow-stage":
        return slow_press(max(seconds, 12.0), seed, fs)
    if name == "press-2n":
        return press_2n(seconds, seed, fs)
    if name.startswith("two-tones"):
        return two_tones(float(name.split("-")[-1].removesuffix("db")), seconds, seed, fs)
    if name == "talker":
        x = synth.room(talker(n, fs, seed), fs, seed, rt60=0.5)
    elif name == "reverberant-room":
        x = reverberant_room(synth.coloured_noise(n, fs, seed, 1.0, 0.05), fs, seed)
    elif name == "room-and-talker":
        x = reverberant_room(synth.coloured_noise(n, fs, seed, 1.0, 0.02) + talker(n, fs, seed + 9), fs, seed)
    else:
        raise ValueError(f"case {name!r} invalid, must be one of {CASES}")
    return synth.Recording(x, fs, silent, np.zeros(n))
