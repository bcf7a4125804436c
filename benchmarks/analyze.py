"""Analysis speed and accuracy: time per 10 s 44.1 kHz recording (target < 0.1 s), and the error of the mean
frequency against SNR for the Viterbi ridge, a Welch-spectrum peak and a band power centroid.

The tone wobbles ±20 Hz around 4700 Hz over 2.5 s (four whole periods: its true mean is 4700 Hz); white noise
is set to the SNR over the full band. Run: .venv/bin/python benchmarks/analyze.py
"""

import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.loop import LoopError  # noqa: E402
from matcad.loop.analyze import analyze  # noqa: E402
from matcad.loop.wav import read_mono  # noqa: E402

FS, SECONDS, F0, BAND = 44100, 10.0, 4700.0, (4000.0, 5500.0)
SNRS = (20, 10, 0, -10, -20)
SEEDS = 10


def tone(snr_db, seed):
    t = np.arange(int(SECONDS * FS)) / FS
    x = 0.3 * np.sin(2 * np.pi * (F0 * t - 20 * 2.5 / (2 * np.pi) * np.cos(2 * np.pi * t / 2.5)))
    sigma = np.sqrt(0.3**2 / 2 / 10 ** (snr_db / 10))
    return x + sigma * np.random.default_rng(seed).standard_normal(len(t))


def welch_peak(x):
    from scipy.signal import welch

    f, p = welch(x, FS, nperseg=4096)
    band = (f >= BAND[0]) & (f <= BAND[1])
    i = np.flatnonzero(band)[np.argmax(p[band])]
    a, b, c = np.log(p[i - 1:i + 2])
    return f[i] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0])


def centroid(x):
    from scipy.signal import welch

    f, p = welch(x, FS, nperseg=4096)
    band = (f >= BAND[0]) & (f <= BAND[1])
    return float(np.sum(f[band] * p[band]) / np.sum(p[band]))


def ridge(x):
    return analyze(x, FS, BAND).mean_hz


def main():
    from scipy.io import wavfile

    x = tone(0, 0)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tone.wav"
        wavfile.write(path, FS, (x * 30000).astype(np.int16))
        analyze(*read_mono(path), BAND)  # warm imports
        times = []
        for _ in range(15):
            t0 = time.perf_counter()
            analyze(*read_mono(path), BAND)
            times.append(time.perf_counter() - t0)
    print(f"read + analyze, 10 s at 44.1 kHz: median {statistics.median(times) * 1e3:.1f} ms (target < 100 ms)\n")
    methods = {"Viterbi ridge (matcad)": ridge, "Welch peak": welch_peak, "power centroid": centroid}
    print("| method | " + " | ".join(f"RMS error at {s:+d} dB [Hz]" for s in SNRS) + " | time per file |")
    print("|---|" + "---:|" * (len(SNRS) + 1))
    for name, method in methods.items():
        cells, spent = [], []
        for snr in SNRS:
            errors = []
            for seed in range(SEEDS):
                x = tone(snr, seed)
                t0 = time.perf_counter()
                try:
                    errors.append(method(x) - F0)
                except LoopError:
                    errors.append(np.nan)
                spent.append(time.perf_counter() - t0)
            rms = np.sqrt(np.nanmean(np.square(errors)))
            refused = int(np.sum(np.isnan(errors)))
            cells.append(f"{rms:.3f}" + (f" ({refused} refused)" if refused else ""))
        print(f"| {name} | " + " | ".join(cells) + f" | {statistics.median(spent) * 1e3:.0f} ms |")


if __name__ == "__main__":
    main()
