"""Realistic synthetic taxel recordings with known truth, for tests and benchmarks/analyze.py.

A singing taxel is a self-sustained oscillator: a limit cycle whose phase diffuses (a Wiener process in phase gives
the Lorentzian line of a noise-driven oscillator, linewidth ``linewidth_hz``) and whose amplitude jitters, plus the
same resonator's response to the jet's turbulence (white noise through a two-pole resonator at the instantaneous
frequency, Q ``q``), which makes the skirt around the line. Its pitch follows paper Eq. 5 through a force profile
(steps, ramps, taps). Around it: coloured (1/f^alpha) background, mains hum and buzz (a comb at multiples of 50 or
60 Hz), speech-like harmonic sound, a neighbouring taxel, silences, an overblown stretch (the tone jumps to another
mode), room reverberation (exponentially decaying noise impulse response with the given RT60) and a tablet
microphone (automatic gain control with attack/release, then clipping at full scale).

Every generator is a pure function of its arguments and seed. Frequencies Hz, times s, forces N, volumes mm³.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from matcad.acoustics.eq5 import Eq5

FS = 44100.0
EQ5 = Eq5(v0_mm3=37.8, a=-0.0086, b=0.4626, name="synthetic")
"""Eq. 5 with the paper's b and a (paper Eq. 5, Fig. 9) and V0 = 37.8 mm³ (mm³, mm³/N², mm³/N)."""
K_MM3_HZ2 = EQ5.v0_mm3 * 4400.0**2
"""K = c²A/(4π² l) (mm³·Hz²) chosen so that the taxel sings 4.40 kHz unloaded, 4.67 kHz at 12 N, as the
paper's did (Fig. 6, Fig. 7)."""


def frequency_of_force(force_n, k_mm3_hz2: float = K_MM3_HZ2, eq5=EQ5):
    """Paper Eq. 5: f = sqrt(K / (V0 − aF² − bF)) (Hz) with ``eq5``'s constants and this K (mm³·Hz²)."""
    return dataclasses.replace(eq5, k_mm3_hz2=k_mm3_hz2).frequency_hz(force_n)


@dataclass(frozen=True)
class Recording:
    """Samples and the truth behind them: per-sample frequency of the taxel (NaN where it is silent) and force."""

    x: np.ndarray = field(repr=False)
    fs: float
    truth_hz: np.ndarray = field(repr=False)
    force_n: np.ndarray = field(repr=False)
    band_hz: tuple[float, float] = (3900.0, 5600.0)

    def truth_at(self, times_s) -> np.ndarray:
        """Taxel frequency (Hz, NaN when silent) at each time (s)."""
        i = np.clip((np.asarray(times_s) * self.fs).astype(int), 0, len(self.truth_hz) - 1)
        return self.truth_hz[i]


def press_profile(seconds: float, fs: float, steps, ramp_s: float = 0.15, base_n: float = 2.0) -> np.ndarray:
    """Force (N) per sample: ``base_n``, and ``(start_s, end_s, force_n)`` holds reached by linear ramps."""
    t = np.arange(int(seconds * fs)) / fs
    force = np.full(len(t), base_n)
    for start, end, level in steps:
        up = np.clip((t - start) / max(ramp_s, 1e-9), 0.0, 1.0)
        down = np.clip((end - t) / max(ramp_s, 1e-9), 0.0, 1.0)
        force += (level - base_n) * np.minimum(up, down)
    return force


HARMONICS_DB = (-20.0, -30.0)
"""Levels of the 2nd and 3rd harmonic against the fundamental (dB) of a realistic taxel: a Helmholtz resonator has no
resonance at its harmonics, so the edge tone's harmonic drive is not amplified and vessel flutes sound almost
overtone-free ("Vessel flute", Acoustics: the resonator amplifies one frequency only); -20/-30 dB is a generous
reading of that (benchmarks/analyze.py also runs -10 dB)."""


def taxel(freq_hz: np.ndarray, fs: float, seed: int, amplitude: float = 0.1, linewidth_hz: float = 1.0,
          q: float = 40.0, skirt: float = 0.3, gate=None, harmonics_db=()) -> np.ndarray:
    """The self-sustained oscillator at per-sample ``freq_hz``: phase-diffusing line plus resonant jet noise, and
    phase-locked harmonics 2f, 3f, … at ``harmonics_db`` (dB against the line; those above 0.45 fs are left out,
    as a microphone's anti-alias filter does).

    ``gate`` (0..1 per sample) switches the sound on and off with 20 ms fades.
    """
    rng = np.random.default_rng(seed)
    n = len(freq_hz)
    # phase diffusion D = π·linewidth gives a Lorentzian of FWHM linewidth_hz (Lax 1967)
    dphi = 2 * np.pi * freq_hz / fs + np.sqrt(2 * np.pi * linewidth_hz / fs) * rng.standard_normal(n)
    amp = amplitude * (1 + 0.05 * _lowpass(rng.standard_normal(n), fs, 5.0))
    phase = np.cumsum(dphi)
    line = amp * np.sin(phase)
    for k, level in enumerate(harmonics_db, 2):
        audible = k * np.asarray(freq_hz) < 0.45 * fs
        line += audible * amp * 10 ** (level / 20) * np.sin(k * phase + rng.uniform(0, 2 * np.pi))
    jet = _resonated_noise(freq_hz, fs, q, rng) * amplitude * skirt
    x = line + jet
    if gate is not None:
        x = x * _smooth_gate(gate, fs)
    return x


def _lowpass(x, fs, cutoff_hz):
    from scipy.signal import butter, sosfilt

    y = sosfilt(butter(2, cutoff_hz, fs=fs, output="sos"), x)
    return y / max(np.std(y), 1e-12)


def _resonated_noise(freq_hz, fs, q, rng, block=441):
    """White noise through a two-pole resonator retuned every ``block`` samples (unit RMS)."""
    from scipy.signal import lfilter

    noise = rng.standard_normal(len(freq_hz))
    out = np.empty_like(noise)
    zi = np.zeros(2)
    for s in range(0, len(noise), block):
        f = float(freq_hz[min(s + block // 2, len(freq_hz) - 1)])
        r = np.exp(-np.pi * f / (q * fs))
        a = [1.0, -2 * r * np.cos(2 * np.pi * f / fs), r * r]
        out[s:s + block], zi = lfilter([1 - r], a, noise[s:s + block], zi=zi)
    return out / max(np.std(out), 1e-12)


def _smooth_gate(gate, fs, fade_s=0.02):
    k = max(1, int(fade_s * fs))
    return np.convolve(np.asarray(gate, float), np.ones(k) / k, mode="same")


def coloured_noise(n: int, fs: float, seed: int, alpha: float = 1.0, rms: float = 0.01) -> np.ndarray:
    """Noise with power ∝ 1/f^alpha (alpha 0 white, 1 pink, 2 brown), scaled to ``rms``."""
    rng = np.random.default_rng(seed)
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, 1 / fs)
    spec *= np.where(f > 20.0, f, 20.0) ** (-alpha / 2)
    x = np.fft.irfft(spec, n)
    return rms * x / max(np.std(x), 1e-12)


def buzz(n: int, fs: float, mains_hz: float = 60.0, rms: float = 0.01, seed: int = 0) -> np.ndarray:
    """Mains buzz: every harmonic of ``mains_hz`` up to 10 kHz with 1/k amplitudes and random phases."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    x = np.zeros(n)
    for k in range(1, int(10000 / mains_hz) + 1):
        x += np.sin(2 * np.pi * k * mains_hz * t + rng.uniform(0, 2 * np.pi)) / k**0.5
    return rms * x / np.std(x)


def speech_like(n: int, fs: float, seed: int, rms: float = 0.02) -> np.ndarray:
    """Voiced-speech-like sound: a harmonic series on a gliding 100–220 Hz pitch, formant-shaped, in syllables."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    f0 = 150 + 50 * np.sin(2 * np.pi * 0.7 * t + rng.uniform(0, 6)) + 15 * _lowpass(rng.standard_normal(n), fs, 4)
    phase = 2 * np.pi * np.cumsum(f0) / fs
    x = np.zeros(n)
    for k in range(1, int(8000 / 100)):
        fk = k * f0
        envelope = sum(np.exp(-0.5 * ((fk - c) / w) ** 2) for c, w in ((700, 300), (1200, 400), (2600, 500),
                                                                       (4500, 900)))
        x += envelope * np.sin(k * phase) * (fk < fs / 2)
    syllables = (np.sin(2 * np.pi * 3.0 * t + rng.uniform(0, 6)) > -0.2).astype(float)
    x *= _smooth_gate(syllables, fs, 0.03)
    return rms * x / max(np.std(x), 1e-12)


LAB_VOLUME_M3 = 50.0
"""Volume of the lab room of the synthetic board recordings (m³): a small lab, 4 x 5 x 2.5 m."""


def critical_distance_m(volume_m3: float, rt60_s: float) -> float:
    """Critical (reverberation) distance (m) of an omnidirectional source in a diffuse room of ``volume_m3`` (m³)
    with reverberation time ``rt60_s`` (s): where the direct sound's energy density equals the reverberant field's,
    r_c = sqrt(A/16π) with Sabine's absorption area A = 0.163·V/T60 (m²), r_c ≈ 0.057·sqrt(V/T60) (Kuttruff, Room
    Acoustics, ch. 5, the reverberation distance). At a distance r the direct-to-reverberant energy ratio is
    (r_c/r)²: 50 m³ at RT60 0.4 s gives r_c = 0.64 m."""
    return 0.057 * float(np.sqrt(volume_m3 / rt60_s))


def reverb_share(distance_m: float, rt60_s: float, volume_m3: float = LAB_VOLUME_M3) -> float:
    """The ``wet`` of :func:`reverb` for a microphone ``distance_m`` (m) from the source in a diffuse room
    (m³, s): r/r_c, the reverberant field's RMS over the direct sound's, so that the direct-to-reverberant
    energy ratio is (r_c/r)² (:func:`critical_distance_m`)."""
    return distance_m / critical_distance_m(volume_m3, rt60_s)


def reverb(x: np.ndarray, fs: float, rt60_s: float, seed: int, wet: float = 0.5) -> np.ndarray:
    """Room: ``x`` convolved with an impulse response of the direct sound (a unit impulse) plus an exponentially
    decaying noise tail (−60 dB after ``rt60_s``, s) of total energy ``wet``²: a steady tone's reverberant field
    has ``wet`` times the direct sound's RMS, a direct-to-reverberant ratio of −20·log10(``wet``) dB (0.5: +6 dB,
    a microphone at half the critical distance, :func:`reverb_share`). The tail's spectrum is a random one: at
    any frequency the room's response differs from the direct sound's by a draw whose spread grows with ``wet``."""
    from scipy.signal import oaconvolve

    rng = np.random.default_rng(seed)
    t = np.arange(int(rt60_s * fs)) / fs
    ir = rng.standard_normal(len(t)) * 10 ** (-3 * t / rt60_s)
    ir *= wet / np.sqrt(np.sum(ir**2))
    ir[0] += 1.0
    return oaconvolve(x, ir)[: len(x)]


def microphone(x: np.ndarray, fs: float, target_rms: float = 0.3, attack_s: float = 0.05,
               release_s: float = 0.5, clip: float = 1.0) -> np.ndarray:
    """Tablet microphone: automatic gain control (envelope follower, fast attack, slow release) then clipping."""
    from scipy.signal import lfilter

    hop = max(1, int(0.01 * fs))
    blocks = np.sqrt(np.mean(np.square(x[: len(x) // hop * hop]).reshape(-1, hop), axis=1) + 1e-12)
    env = np.empty_like(blocks)
    level = blocks[0]
    up, down = np.exp(-hop / (attack_s * fs)), np.exp(-hop / (release_s * fs))
    for i, b in enumerate(blocks):  # one step per 10 ms: cheap
        k = up if b > level else down
        level = k * level + (1 - k) * b
        env[i] = level
    gain = np.minimum(target_rms / env, 100.0)
    gain = np.repeat(gain, hop)
    gain = np.concatenate([gain, np.full(len(x) - len(gain), gain[-1] if len(gain) else 1.0)])
    gain = lfilter([0.01], [1, -0.99], gain, zi=[gain[0] * 0.99])[0]
    return np.clip(x * gain, -clip, clip)


# --- scenarios: the cases of benchmarks/analyze.py, usable at any length -----------------------------------------

def _base(seconds, fs, seed, force, gate=None, amplitude=0.1, freq=None):
    freq = frequency_of_force(force) if freq is None else freq
    x = taxel(freq, fs, seed, amplitude=amplitude, gate=gate)
    truth = np.where(np.asarray(gate if gate is not None else np.ones(len(freq))) > 0.5, freq, np.nan)
    return x, truth


def room(x, fs, seed, rt60=0.5, pink_rms=0.01, wet=0.5):
    """``x`` heard in a room: reverb of RT60 ``rt60`` (s) and reverberant share ``wet`` (:func:`reverb`), pink
    noise of RMS ``pink_rms``, the tablet microphone."""
    return microphone(reverb(x, fs, rt60, seed + 1, wet) + coloured_noise(len(x), fs, seed + 2, 1.0, pink_rms), fs)


def scenario(name: str, seconds: float = 10.0, seed: int = 0, fs: float = FS) -> Recording:
    """One named case of :data:`CASES` (truth, force and samples)."""
    n = int(seconds * fs)
    t = np.arange(n) / fs
    steady = np.full(n, 8.0)
    if name == "steady":
        force = steady
        x, truth = _base(seconds, fs, seed, force)
        x = room(x, fs, seed)
    elif name == "presses":  # 2 → 12 N presses held 0.5 s with 0.15 s ramps
        starts = np.arange(1.0, seconds - 1.0, 2.0)
        force = press_profile(seconds, fs, [(s, s + 0.8, 12.0) for s in starts], ramp_s=0.15)
        x, truth = _base(seconds, fs, seed, force)
        x = room(x, fs, seed, rt60=0.3)
    elif name == "tapping":  # 2 taps a second to 10 N: 50 ms ramps, 0.2 s held, 0.2 s released
        starts = np.arange(0.5, seconds - 0.5, 0.5)
        force = press_profile(seconds, fs, [(s, s + 0.3, 10.0) for s in starts], ramp_s=0.05)
        x, truth = _base(seconds, fs, seed, force)
        x = room(x, fs, seed, rt60=0.3)
    elif name == "gaps":  # sings half the time; starts silent (the paper: may not sing unloaded)
        gate = ((t % 2.0) > 1.0).astype(float)
        force = steady
        x, truth = _base(seconds, fs, seed, force, gate=gate)
        x = room(x, fs, seed)
    elif name == "short-tone":  # 1 s of tone in a long quiet recording
        gate = ((t > seconds / 2) & (t < seconds / 2 + 1.0)).astype(float)
        force = steady
        x, truth = _base(seconds, fs, seed, force, gate=gate)
        x = room(x, fs, seed)
    elif name == "buzz-only":  # silent taxel, 60 Hz buzz
        force = steady
        truth = np.full(n, np.nan)
        x = buzz(n, fs, 60.0, rms=0.05, seed=seed) + coloured_noise(n, fs, seed + 2, 1.0, 0.01)
        x = microphone(reverb(x, fs, 0.5, seed + 1), fs)
    elif name == "buzz+tone":
        force = steady
        x, truth = _base(seconds, fs, seed, force)
        x = room(x + buzz(n, fs, 60.0, rms=0.05, seed=seed), fs, seed)
    elif name == "speech-only":
        force = steady
        truth = np.full(n, np.nan)
        x = room(speech_like(n, fs, seed, rms=0.1), fs, seed)
    elif name == "speech+tone":
        force = steady
        x, truth = _base(seconds, fs, seed, force)
        x = room(x + speech_like(n, fs, seed, rms=0.1), fs, seed)
    elif name == "neighbour":  # a louder second taxel 300 Hz above in the band
        force = steady
        x, truth = _base(seconds, fs, seed, force)
        other = taxel(frequency_of_force(force) + 300.0, fs, seed + 7, amplitude=0.3)
        x = room(x + other, fs, seed)
    elif name == "overblown":  # from 6 to 7 s the jet drives another mode, 25 % higher
        force = steady
        jump = (t > seconds * 0.6) & (t < seconds * 0.7)
        freq = frequency_of_force(force) * np.where(jump, 1.22, 1.0)
        x, truth = _base(seconds, fs, seed, force, freq=freq)
        truth = np.where(jump, np.nan, truth)  # not the taxel's load-bearing mode: must be flagged, not sensed
        x = room(x, fs, seed)
    elif name == "room-noise":  # a fan's broadband noise heard through a reverberant room (RT60 0.6 s), no tone
        force = steady
        truth = np.full(n, np.nan)
        x = microphone(reverb(coloured_noise(n, fs, seed, 1.0, 0.05), fs, 0.6, seed + 1, wet=0.8), fs)
    elif name == "white-noise":
        force = steady
        truth = np.full(n, np.nan)
        x = np.random.default_rng(seed).standard_normal(n) * 0.1
    elif name == "brown-noise":
        force = steady
        truth = np.full(n, np.nan)
        x = coloured_noise(n, fs, seed, 2.0, 0.1)
    else:
        raise ValueError(f"scenario {name!r} invalid, must be one of {CASES}")
    return Recording(x, fs, truth, force)


CASES = ("steady", "presses", "tapping", "gaps", "short-tone", "buzz-only", "buzz+tone", "speech-only",
         "speech+tone", "neighbour", "overblown", "white-noise", "brown-noise", "room-noise")


# --- a board: several taxels heard by one microphone ---------------------------------------------------------------

@dataclass(frozen=True)
class BoardRecording:
    """Samples of several taxels at once and the truth behind them: per taxel (rows, in ``names`` order) the
    per-sample frequency (Hz, NaN when silent) and force (N), and each taxel's listening band (Hz)."""

    x: np.ndarray = field(repr=False)
    fs: float
    names: tuple[str, ...]
    truth_hz: np.ndarray = field(repr=False)
    force_n: np.ndarray = field(repr=False)
    bands_hz: tuple[tuple[float, float], ...]

    def truth_at(self, k: int, times_s) -> np.ndarray:
        """Taxel ``k``'s frequency (Hz, NaN when silent) at each time (s)."""
        i = np.clip((np.asarray(times_s) * self.fs).astype(int), 0, self.truth_hz.shape[1] - 1)
        return self.truth_hz[k, i]


BOARD_F0_HZ = (3600.0, 4050.0, 4550.0, 5100.0)
"""Unloaded pitches of the four-taxel board: loaded bands (0-15 N by Eq. 5, +7.4 %) ~60 Hz apart, no 2f or 3f of one
inside another's band."""


def board_band_hz(f0_hz: float, max_force_n: float = 15.0) -> tuple[float, float]:
    """A taxel's listening band (Hz): 2 % below its unloaded pitch to 1 % above its Eq. 5 pitch at
    ``max_force_n`` (N) — what matcad.prediction.bands' loaded band is for a well-predicted taxel."""
    rise = float(frequency_of_force(max_force_n) / frequency_of_force(0.0))
    return 0.98 * f0_hz, 1.01 * rise * f0_hz


def board_scenario(seconds: float = 10.0, seed: int = 0, fs: float = FS, f0_hz=BOARD_F0_HZ,
                   pressed=(1, 3), amplitudes=(0.1, 0.3, 0.1, 0.15)) -> BoardRecording:
    """Four taxels singing at once in a room (pink noise, reverb RT60 0.4 s, tablet microphone): the ``pressed``
    ones (0-based) pressed 2 → 12 N for 0.8 s every 2 s (0.15 s ramps, the two out of phase), the others held at
    4 N; amplitudes differ (taxel 2 is 10 dB louder than taxel 1, its lower neighbour). The room's reverberant
    share is :func:`room`'s 0.5 (direct sound +6 dB: a microphone at half the critical distance, 0.32 m in the
    50 m³ lab, :func:`reverb_share`), farther than :mod:`matcad.loop.synth_board`'s paper-like 0.10 m."""
    n = int(seconds * fs)
    forces, freqs = [], []
    for k, f0 in enumerate(f0_hz):
        if k in pressed:
            starts = np.arange(1.0 + 1.0 * (pressed.index(k) % 2), seconds - 1.0, 2.0)
            force = press_profile(seconds, fs, [(s, s + 0.8, 12.0) for s in starts], ramp_s=0.15)
        else:
            force = np.full(n, 4.0)
        forces.append(force)
        freqs.append(frequency_of_force(force, EQ5.v0_mm3 * f0**2))
    x = sum(taxel(f, fs, seed + 11 * k, amplitude=a) for k, (f, a) in enumerate(zip(freqs, amplitudes)))
    x = room(x, fs, seed, rt60=0.4)
    return BoardRecording(x, fs, tuple(f"t{k + 1}" for k in range(len(f0_hz))), np.array(freqs), np.array(forces),
                          tuple(board_band_hz(f0) for f0 in f0_hz))


# --- two taxels of equal level crossing inside one band --------------------------------------------------------------

CROSSING_KINDS = ("pass", "touch", "other-pressed")
"""Kinds of :func:`crossing_scenario`: the taxel pressed through the neighbour's steady tone and back ("pass"), the
taxel pressed up to the neighbour's pitch and released ("touch"), the neighbour pressed through the taxel's steady
tone and back ("other-pressed")."""


def crossing_forces(kind: str, seconds: float = 10.0, fs: float = FS) -> tuple[np.ndarray, np.ndarray]:
    """Per-sample forces (N) of the taxel and of the neighbour in :func:`crossing_scenario`: the pressed one goes
    2 → 14 N with 1 s ramps (Eq. 5: ~4450 → ~4710 Hz, ~250 Hz/s) through the other's steady 8 N pitch (~4600 Hz)
    and back, or, for "touch", 2 → 8 N and back (0.3 s at the other's pitch)."""
    if kind not in CROSSING_KINDS:
        raise ValueError(f"crossing kind {kind!r} invalid, must be one of {CROSSING_KINDS}")
    up = seconds * 0.25
    steps = [(up, up + 2.3, 8.0)] if kind == "touch" else [(up, up + 4.5, 14.0)]
    moving = press_profile(seconds, fs, steps, ramp_s=1.0)
    still = np.full(len(moving), 8.0)
    return (still, moving) if kind == "other-pressed" else (moving, still)


def crossing_scenario(kind: str, seconds: float = 10.0, seed: int = 0, fs: float = FS) -> Recording:
    """The taxel (truth) and a second taxel of EQUAL level in one band whose pitches cross (kinds
    :data:`CROSSING_KINDS`, forces :func:`crossing_forces`). The neighbour starts singing 1 s after the taxel: with
    equal levels and one band nothing else says which tone is the taxel. Room as :func:`scenario` (pink noise,
    RT60 0.5 s, tablet microphone)."""
    force, other = crossing_forces(kind, seconds, fs)
    x, truth = _base(seconds, fs, seed, force)
    t = np.arange(len(force)) / fs
    x = x + taxel(frequency_of_force(other), fs, seed + 7, gate=(t > 1.0).astype(float))
    return Recording(room(x, fs, seed), fs, truth, force)
