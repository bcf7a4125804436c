"""Frequency of a taxel's tone from a recording: short-time spectrum and a Viterbi ridge in the predicted band.

The paper used MATLAB spectrogram + tfridge and a pspectrum peak in 4–5.5 kHz. Here: scipy's ShortTimeFFT
(Hann window ~93 ms, 2× zero padding, 50 % overlap); a Viterbi ridge through the log-power in the band, with a
quadratic penalty on bin jumps so that it follows a slowly wobbling tone instead of hopping between noise peaks;
each frame's frequency refined by parabolic interpolation of log-power around the ridge. A stronger tone
outside the band (mains hum, an overblown harmonic) is reported, never taken. Frequencies Hz, times s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from matcad.loop import LoopError

WINDOW_S = 0.093
"""~4096 samples at 44.1 kHz: ~11 Hz resolution, short enough to follow a ±20 Hz wobble over seconds."""
ZERO_PAD = 2
JUMP_PENALTY_DB = 1.0
"""Viterbi cost per (bin jump)²: a 4-bin jump costs 16 dB, more than a noise peak stands above the floor."""
MAX_JUMP_BINS = 8
MIN_SNR_DB = 8.0
"""Median ridge-to-floor ratio below which there is no tone. The penalised ridge through white noise sits
~4 dB over the floor; a tone at −20 dB full-band SNR stands ~13 dB over it (tests/test_loop.py)."""
EDGE_BINS = 2
EXCLUDE_BINS = 6
"""Bins either side of the ridge left out of the noise floor (Hann main lobe is ±4 bins at 2× padding)."""


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`analyze`: statistics over frames, the track, quality figures and warnings."""

    mean_hz: float
    median_hz: float
    std_hz: float
    snr_db: float
    prominence_db: float
    band_hz: tuple[float, float]
    sample_rate_hz: float
    duration_s: float
    times_s: np.ndarray = field(repr=False)
    track_hz: np.ndarray = field(repr=False)
    frame_snr_db: np.ndarray = field(repr=False)
    band_freqs_hz: np.ndarray = field(repr=False)
    band_psd: np.ndarray = field(repr=False)  # frames × band bins
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return {"mean_hz": self.mean_hz, "median_hz": self.median_hz, "std_hz": self.std_hz,
                "snr_db": self.snr_db, "prominence_db": self.prominence_db, "band_hz": list(self.band_hz),
                "sample_rate_hz": self.sample_rate_hz, "duration_s": self.duration_s,
                "frames": int(len(self.track_hz)), "warnings": list(self.warnings)}


def stft_power(x: np.ndarray, fs: float):
    """Frequencies (Hz), frame times (s) and PSD (frequency × frame) of the frames lying wholly inside ``x``."""
    from scipy.signal import ShortTimeFFT
    from scipy.signal.windows import hann

    n = max(64, min(int(2 ** round(np.log2(WINDOW_S * fs))), len(x)))
    stft = ShortTimeFFT(hann(n, sym=False), hop=n // 2, fs=fs, mfft=ZERO_PAD * n, scale_to="psd")
    p0 = stft.lower_border_end[1]
    p1 = max(p0 + 1, stft.upper_border_begin(len(x))[1])
    return stft.f, stft.t(len(x), p0, p1), stft.spectrogram(x, p0=p0, p1=p1)


def viterbi_ridge(log_power: np.ndarray, penalty_db: float = JUMP_PENALTY_DB,
                  max_jump: int = MAX_JUMP_BINS) -> np.ndarray:
    """Bin index per frame maximising Σ log-power − penalty·Δbin² over paths (frames × bins in)."""
    frames, bins = log_power.shape
    jumps = np.arange(-max_jump, max_jump + 1)
    cost = penalty_db * jumps.astype(float) ** 2
    score = log_power[0].copy()
    back = np.zeros((frames, bins), dtype=np.int64)
    idx = np.arange(bins)
    for t in range(1, frames):
        src = idx[None, :] - jumps[:, None]  # candidate previous bin for each jump
        valid = (src >= 0) & (src < bins)
        cand = np.where(valid, score[np.clip(src, 0, bins - 1)] - cost[:, None], -np.inf)
        best = np.argmax(cand, axis=0)
        back[t] = src[best, idx]
        score = cand[best, idx] + log_power[t]
    path = np.empty(frames, dtype=np.int64)
    path[-1] = int(np.argmax(score))
    for t in range(frames - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path


def _refine(log_power: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Sub-bin ridge position: snap to the local maximum within ±1 bin, then fit a parabola to log-power."""
    frames, bins = log_power.shape
    t = np.arange(frames)
    nb = np.clip(path[:, None] + np.array([-1, 0, 1])[None, :], 0, bins - 1)
    peak = np.clip(nb[t, np.argmax(log_power[t[:, None], nb], axis=1)], 1, bins - 2)
    left, mid, right = log_power[t, peak - 1], log_power[t, peak], log_power[t, peak + 1]
    denom = left - 2 * mid + right
    delta = np.where(denom < 0, 0.5 * (left - right) / np.where(denom < 0, denom, -1.0), 0.0)
    return peak + np.clip(delta, -0.5, 0.5)


def _strongest_outside(f, mean_spectrum, lo, hi, in_band_peak) -> str:
    """'a stronger tone at … Hz outside the band (… dB above …)' if one exists above 20 Hz, else ''."""
    df = f[1] - f[0]
    outside = ((f < lo - 2 * df) | (f > hi + 2 * df)) & (f > 20.0)  # below 20 Hz: drift, not a tone
    if not np.any(outside):
        return ""
    i = int(np.argmax(np.where(outside, mean_spectrum, 0.0)))
    if mean_spectrum[i] <= in_band_peak:
        return ""
    log_power = 10 * np.log10(mean_spectrum[None, :] + np.finfo(float).tiny)
    where = f[0] + float(_refine(log_power, np.array([i]))[0]) * df
    return (f"a stronger tone near {where:.0f} Hz outside the band "
            f"({10 * np.log10(mean_spectrum[i] / in_band_peak):.1f} dB above the in-band peak)")


def band_from_prediction(band_hz: tuple[float, float]) -> tuple[float, float]:
    """Analysis band for a taxel: its predicted unloaded band, −10 % / +25 % (load raises f: +11 % at 25 N on
    the paper's Eq. 5 fit)."""
    return band_hz[0] * 0.9, band_hz[1] * 1.25


def analyze(x: np.ndarray, fs: float, band_hz: tuple[float, float]) -> Analysis:
    """The tone's frequency track inside ``band_hz`` (Hz) of samples ``x`` at ``fs`` (Hz).

    Raises LoopError (with the reason) when there is no tone or when the ridge hugs a band edge.
    """
    nyquist = fs / 2
    lo, hi = max(0.0, band_hz[0]), min(band_hz[1], nyquist)
    if not lo < hi:
        raise ValueError(f"band {band_hz[0]:g}-{band_hz[1]:g} Hz invalid for a {fs:g} Hz recording "
                         f"(must lie below {nyquist:g} Hz)")
    f, times, psd = stft_power(x, fs)
    df = f[1] - f[0]
    in_band = np.flatnonzero((f >= lo) & (f <= hi))
    if len(in_band) < 2 * EXCLUDE_BINS + 3:
        raise ValueError(f"band {lo:g}-{hi:g} Hz is narrower than the analysis needs ({(2 * EXCLUDE_BINS + 3) * df:.0f} Hz)")
    tiny = np.finfo(float).tiny
    band_power = psd[in_band].T  # frames × bins
    log_power = 10 * np.log10(band_power + tiny)
    path = viterbi_ridge(log_power)
    track_bins = _refine(log_power, path)
    track = f[in_band[0]] + track_bins * df

    frames = np.arange(len(path))
    cols = np.arange(len(in_band))
    near = np.abs(cols[None, :] - path[:, None]) <= EXCLUDE_BINS
    floor = np.nanmedian(np.where(near, np.nan, band_power), axis=1)
    peak = band_power[frames, path]
    frame_snr = 10 * np.log10((peak + tiny) / (floor + tiny))
    other = np.max(np.where(near, 0.0, band_power), axis=1)
    prominence = float(np.median(10 * np.log10((peak + tiny) / (other + tiny))))
    snr = float(np.median(frame_snr))
    loudest = _strongest_outside(f, psd.mean(axis=1), lo, hi, float(psd[in_band].mean(axis=1).max()))
    hint = f"; {loudest}" if loudest else ""
    if not snr >= MIN_SNR_DB:
        raise LoopError(f"no tone in {lo:.0f}-{hi:.0f} Hz: the ridge stands {snr:.1f} dB over the noise floor "
                        f"(needs >= {MIN_SNR_DB:g} dB){hint}")
    edge = np.mean((path <= EDGE_BINS) | (path >= len(in_band) - 1 - EDGE_BINS))
    if edge > 0.5:
        raise LoopError(f"the ridge hugs the band edge ({100 * edge:.0f} % of frames within {EDGE_BINS} bins of "
                        f"{lo:.0f} or {hi:.0f} Hz): the tone is probably outside the band; widen it{hint}")
    warnings = [f"{loudest} was ignored: hum, a harmonic or another source"] if loudest else []
    return Analysis(mean_hz=float(np.mean(track)), median_hz=float(np.median(track)), std_hz=float(np.std(track)),
                    snr_db=snr, prominence_db=prominence, band_hz=(lo, hi), sample_rate_hz=fs,
                    duration_s=len(x) / fs, times_s=times, track_hz=track, frame_snr_db=frame_snr,
                    band_freqs_hz=f[in_band], band_psd=band_power, warnings=tuple(warnings))


def write_track_csv(analysis: Analysis, path) -> None:
    """Per-frame time (s), frequency (Hz) and ridge SNR (dB)."""
    rows = ["time_s,frequency_hz,snr_db"] + [f"{t:.6f},{f:.4f},{s:.2f}" for t, f, s in
                                               zip(analysis.times_s, analysis.track_hz, analysis.frame_snr_db)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def plot(analysis: Analysis, path) -> None:
    """Spectrogram of the band (dB) with the ridge drawn over it, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4))
    db = 10 * np.log10(analysis.band_psd.T + np.finfo(float).tiny)
    ax.pcolormesh(analysis.times_s, analysis.band_freqs_hz, db, shading="nearest", cmap="magma",
                  vmin=np.percentile(db, 5), vmax=db.max())
    ax.plot(analysis.times_s, analysis.track_hz, color="cyan", lw=1, label="ridge")
    ax.set(xlabel="time [s]", ylabel="frequency [Hz]",
           title=f"mean {analysis.mean_hz:.2f} Hz, median {analysis.median_hz:.2f} Hz, SNR {analysis.snr_db:.1f} dB")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
