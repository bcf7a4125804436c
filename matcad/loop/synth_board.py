"""Synthetic recordings of a board of any size, with known truth, for tests and benchmarks (issue 24): every taxel
of a designed board singing in its own loaded band with its harmonics, presses on several, a taxel pressed out of
its band, an overblown jump out of it. Built from :mod:`matcad.loop.synth` (the oscillator, the room, the
microphone). Frequencies Hz, times s, forces N.

A taxel's pitch follows paper Eq. 5's shape, V_eff = V0 − s(bF + aF²) with the paper's b and a scaled by s so that
f(max force)/f(0) is the band's rise; its unloaded pitch lies inside the band's unloaded part (where a built taxel
may land: the prediction's uncertainty), drawn per seed.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from matcad.acoustics.eq5 import Eq5
from matcad.loop import synth


def law(f0_hz: float, rise: float, max_force_n: float) -> Eq5:
    """Eq. 5 with the paper's b and a scaled so that f(0) = ``f0_hz`` (Hz) and f(``max_force_n``)/f(0) = ``rise``
    (V0 = 37.8 mm³, K = V0·f0²)."""
    v0, b, a = synth.EQ5.v0_mm3, synth.EQ5.b, synth.EQ5.a
    scale = v0 * (1 - 1 / rise ** 2) / (b * max_force_n + a * max_force_n ** 2)
    return Eq5(v0, a * scale, b * scale, v0 * f0_hz ** 2, name="synthetic board taxel")


def unloaded_pitch(band_hz, rise: float, rng) -> float:
    """An unloaded pitch (Hz) inside a loaded band (Hz) whose top is the unloaded top times ``rise``: uniform over
    the unloaded part, 0.5 % inside its ends."""
    lo, hi = band_hz
    top = hi / rise
    return float(rng.uniform(lo + 0.005 * (top - lo), top - 0.005 * (top - lo)))


def press_forces(seconds: float, fs: float, max_force_n: float, phase: float, period_s: float = 3.0,
                 hold_s: float = 0.8, ramp_s: float = 0.15, rest_share: float = 0.2) -> np.ndarray:
    """Presses to ``max_force_n`` (N) every ``period_s``, held ``hold_s`` with ``ramp_s`` ramps, starting
    ``phase`` (0-1) into the period; ``rest_share`` of the maximum between presses (s, N)."""
    starts = np.arange(0.8 + phase * period_s, seconds - hold_s - 0.5, period_s)
    return synth.press_profile(seconds, fs, [(s, s + hold_s, max_force_n) for s in starts], ramp_s=ramp_s,
                               base_n=rest_share * max_force_n)


MIC_DISTANCE_M = 0.10
"""Microphone distance of the board recordings (m): the paper recorded "from approximately 10 cm in front of the
testing configuration"."""
BOARD_RT60_S = 0.4
"""Reverberation time of the board recordings' lab (s)."""


def board_recording(bands, rises, max_force_n: float, seconds: float = 8.0, seed: int = 0, fs: float = synth.FS,
                    pressed=None, harmonics_db=synth.HARMONICS_DB, level_spread_db: float = 6.0,
                    rt60_s: float = BOARD_RT60_S, silent=(),
                    mic_distance_m: float = MIC_DISTANCE_M) -> synth.BoardRecording:
    """Every taxel of a board singing at once in a room (pink noise, reverb, tablet microphone): ``bands`` (name,
    (low, high) Hz) are the loaded bands (each taxel's unloaded pitch is drawn inside, :func:`unloaded_pitch`; its
    listening band is wider, :func:`matcad.listening.loaded_listening_band`), ``rises`` each taxel's f(max)/f(0);
    the ``pressed`` ones (indices; default every third from the second) pressed to ``max_force_n`` (N) at
    staggered times, the others held at 20 %; levels spread uniformly over ±``level_spread_db``/2 dB; harmonics
    at ``harmonics_db``; the ``silent`` ones (indices) do not sing (truth NaN).

    The room is the lab of :data:`synth.LAB_VOLUME_M3` with reverberation time ``rt60_s`` (s), heard
    ``mic_distance_m`` (m) from the board: its reverberant share follows from the critical distance
    (:func:`synth.reverb_share`; 0.10 m at RT60 0.4 s: r_c = 0.64 m, direct sound +16 dB over the reverberant
    field). The taxels' levels are the direct sound's at the microphone."""
    rng = np.random.default_rng(seed)
    n = int(seconds * fs)
    pressed = range(1, len(bands), 3) if pressed is None else pressed
    names, freqs, forces, amps = [], [], [], []
    for k, ((name, band), rise) in enumerate(zip(bands, rises)):
        f0 = unloaded_pitch(band, rise, rng)
        force = (press_forces(seconds, fs, max_force_n, (0.37 * k) % 1.0) if k in pressed
                 else np.full(n, 0.2 * max_force_n))
        names.append(name)
        forces.append(force)
        freqs.append(law(f0, rise, max_force_n).frequency_hz(force))
        amps.append(0.1 * 10 ** (rng.uniform(-0.5, 0.5) * level_spread_db / 20))
    x = sum(synth.taxel(f, fs, seed + 11 * k, amplitude=a, harmonics_db=harmonics_db)
            for k, (f, a) in enumerate(zip(freqs, amps)) if k not in silent)
    freqs = [np.full(n, np.nan) if k in silent else f for k, f in enumerate(freqs)]
    x = synth.room(x, fs, seed, rt60=rt60_s, wet=synth.reverb_share(mic_distance_m, rt60_s))
    return synth.BoardRecording(x, fs, tuple(names), np.array(freqs), np.array(forces),
                                tuple(tuple(b) for _, b in bands))


def spec_recording(spec, seed: int = 0, seconds: float = 6.0, **options) -> synth.BoardRecording:
    """:func:`board_recording` of a board spec's taxels: each in its loaded band with its rise
    (:func:`matcad.prediction.bands.taxel_bands`), pressed to mechanics.max_force_n (N), at the microphone's sample
    rate (Hz); ``options`` as for :func:`board_recording`."""
    from matcad.prediction.bands import taxel_bands

    bands = taxel_bands(spec)
    return board_recording([(b.name, b.loaded_hz) for b in bands], [b.rise for b in bands],
                           spec.mechanics.max_force_n, seconds=seconds, seed=seed,
                           fs=spec.microphone.sample_rate_hz, **options)


FAULTS = ("pressed-out", "overblown-out")
"""Kinds of :func:`fault_scenario`."""


def fault_scenario(kind: str, seconds: float = 8.0, seed: int = 0, fs: float = synth.FS) -> synth.BoardRecording:
    """The four-taxel board of :func:`matcad.loop.synth.board_scenario` (bands for 0-15 N) with one fault:

    - "pressed-out": t2 pressed to 24 N three times (1.2 s held, 0.3 s ramps): its pitch leaves its band through the
      top edge into the guard and beyond (truth kept: it is t2's tone, but no band holds it);
    - "overblown-out": t1 held at 4 N overblows from 3.0 to 4.2 s, its tone jumping x1.22 — out of its band, over
      t2's, into t3's (~4.5 kHz; truth there NaN: no load-bearing tone), while the others keep singing.
    """
    if kind not in FAULTS:
        raise ValueError(f"fault kind {kind!r} invalid, must be one of {FAULTS}")
    base = synth.board_scenario(seconds, seed, fs)
    n = int(seconds * fs)
    t = np.arange(n) / fs
    freqs, forces = base.truth_hz.copy(), base.force_n.copy()
    if kind == "pressed-out":
        forces[1] = synth.press_profile(seconds, fs, [(s, s + 1.2, 24.0) for s in (1.0, 3.5, 6.0)], ramp_s=0.3,
                                        base_n=4.0)[:n]
        freqs[1] = synth.frequency_of_force(forces[1], synth.EQ5.v0_mm3 * synth.BOARD_F0_HZ[1] ** 2)
        sounding = freqs.copy()
    else:
        jump = (t >= 3.0) & (t < 4.2)
        sounding = freqs.copy()
        sounding[0] = np.where(jump, 1.22 * freqs[0], freqs[0])
        freqs[0] = np.where(jump, np.nan, freqs[0])
    amplitudes = (0.1, 0.3, 0.1, 0.15)
    x = sum(synth.taxel(f, fs, seed + 11 * k, amplitude=a, harmonics_db=synth.HARMONICS_DB)
            for k, (f, a) in enumerate(zip(sounding, amplitudes)))
    x = synth.room(x, fs, seed, rt60=0.4)
    return dataclasses.replace(base, x=x, truth_hz=freqs, force_n=forces)
