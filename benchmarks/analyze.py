"""Analysis accuracy and cost.

1. Clean tone: time per 10 s 44.1 kHz recording, and the error of the mean frequency against SNR for matcad's
   ridge, a Welch-spectrum peak and a band power centroid (tone wobbling ±20 Hz around 4700 Hz over 2.5 s, white
   noise set to the SNR over the full band).
2. Realistic recordings (matcad.loop.synth: a noise-driven self-sustained oscillator whose pitch follows Eq. 5,
   pink noise, reverb RT60 0.3–0.5 s, tablet microphone AGC and clipping, hum/buzz, speech, a neighbouring taxel,
   presses, taps, gaps, an overblown stretch, broadband noise through a reverberant room): a table per case over
   seeds (the speech cases over --speech-seeds, default 20).
3. Voicing false alarms on noise (white, pink, brown; many minutes): voiced frames against frames and frame×bins
   tested, with the one-sided 95 % upper bound of the per-frame rate (Clopper–Pearson), and the per-bin tail of
   the excess over the floor against the exponential law.
4. A board: four taxels singing at once (synth.board_scenario; t2 and t4 pressed 2 → 12 N), each tracked in its
   own band — per taxel the mean per-frame error, track RMS, frames wrong and voiced; and issue 11's neighbour case
   with the louder neighbour in its own band.
5. Two taxels of equal level crossing in one band (synth.crossing_scenario: pass-through, touch and return, the
   other pressed through): frames wrong, swapped and flagged, the ridge alone (before matcad.loop.crossing) and
   after.
6. Memory and time of `matcad analyze` on 10 s, 10 min and 60 min WAV files (peak RSS from /usr/bin/time -v, or
   resource.getrusage of the child when it is missing).

Run: /work/venv/bin/python benchmarks/analyze.py [--quick] [--memory-only | --no-memory | --board-only |
--crossing-only] [--noise-minutes N]
"""

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import wave
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.errors import LoopError  # noqa: E402
from matcad.loop import synth  # noqa: E402
from matcad.loop.analyze import analyze  # noqa: E402
from matcad.loop.wav import read_mono  # noqa: E402

FS, SECONDS, F0, BAND = 44100, 10.0, 4700.0, (4000.0, 5500.0)
SNRS = (20, 10, 0, -10, -20)
SEEDS = 10
WRONG_HZ = 10.0
"""A voiced frame more than this from the truth is wrong (≈ 0.35 N at the paper's sensitivity)."""


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


def clean_tone_table():
    from scipy.io import wavfile

    x = tone(0, 0)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tone.wav"
        wavfile.write(path, FS, (x * 30000).astype(np.int16))
        analyze(*read_mono(path), BAND)  # warm imports
        times, cpu = [], []
        for _ in range(5):
            t0, c0 = time.perf_counter(), time.process_time()
            analyze(*read_mono(path), BAND)
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
    print(f"read + analyze, 10 s at 44.1 kHz: median {statistics.median(times) * 1e3:.0f} ms wall, "
          f"{statistics.median(cpu) * 1e3:.0f} ms CPU (wall depends on the machine's load: {os.getloadavg()[0]:.1f})\n")
    methods = {"matcad ridge (voiced frames)": ridge, "Welch peak": welch_peak, "power centroid": centroid}
    print("| method | " + " | ".join(f"RMS error at {s:+d} dB [Hz]" for s in SNRS) + " |")
    print("|---|" + "---:|" * len(SNRS))
    for name, method in methods.items():
        cells = []
        for snr in SNRS:
            errors = []
            for seed in range(SEEDS):
                try:
                    errors.append(method(tone(snr, seed)) - F0)
                except LoopError:
                    errors.append(np.nan)
            rms = np.sqrt(np.nanmean(np.square(errors)))
            refused = int(np.sum(np.isnan(errors)))
            cells.append(f"{rms:.3f}" + (f" ({refused} refused)" if refused else ""))
        print(f"| {name} | " + " | ".join(cells) + " |")


def score(rec, seconds):
    """Per-case figures against the truth. Frames whose window reaches a start or stop of the taxel's sound, and
    the reverberant tail after a stop (0.6 s), count neither as false nor as missed."""
    t0 = time.perf_counter()
    try:
        a = analyze(rec.x, rec.fs, rec.band_hz)
    except LoopError:
        a = None
    spent = time.perf_counter() - t0
    hop = 0.0464
    times = np.arange(int(seconds / hop)) * hop + 0.0464 if a is None else a.times_s
    truth = rec.truth_at(times)
    sounding = np.isfinite(truth)
    around = np.zeros_like(sounding)
    for i in np.flatnonzero(sounding[:-1] != sounding[1:]):
        stop = sounding[i] and not sounding[i + 1]
        around[max(0, i - 1):i + 3 + (int(0.6 / hop) if stop else 0)] = True
    voiced = np.zeros(len(times), bool) if a is None else a.voiced
    flagged = 0 if a is None else sum(s.frames for s in a.segments if s.flag)
    # a frame whose 93 ms window spans a ramp sees a blend: not scored for accuracy (counted as "in ramps")
    ramp = np.fmax(*[np.abs(rec.truth_at(times + d) - truth) for d in (-0.046, 0.046)]) > WRONG_HZ
    both = voiced & sounding & ~ramp
    err = (a.track_hz[both] - truth[both]) if a is not None else np.array([])
    out = {
        "mean_err": (a.mean_hz - np.mean(truth[sounding])) if a is not None and sounding.any() else np.nan,
        "track_rms": np.sqrt(np.mean(err**2)) if len(err) else np.nan,
        "wrong": (np.sum(np.abs(err) > WRONG_HZ) + np.sum(sounding & ~voiced & ~around & ~ramp))
        / max((sounding & ~ramp).sum(), 1),
        "ramp": np.sum(ramp & sounding) / max(sounding.sum(), 1),
        "false": np.sum(voiced & ~sounding & ~around) / max((~sounding & ~around).sum(), 1),
        "missed": np.sum(sounding & ~voiced & ~around) / max((sounding & ~around).sum(), 1),
        "no_tone": a is None,
        "flagged": flagged,
        "sources": 0 if a is None else len(a.sources),
        "time": spent,
    }
    return out


def realistic_table(seeds, seconds, speech_seeds):
    print(f"\nRealistic recordings ({seconds:g} s each, {seeds} seeds, the speech cases {speech_seeds}; frames of 93 ms "
          f"every 46 ms; wrong = voiced > {WRONG_HZ:g} Hz off or missed, among frames whose window does not span a "
          "ramp):\n")
    print("| case | RMS error of mean [Hz] | track RMS [Hz] | frames wrong | false tone frames | missed frames | "
          "'no tone' | flagged frames | 2nd source reported | frames in ramps | time [s] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in synth.CASES:
        n = speech_seeds if name.startswith("speech") else seeds
        rows = [score(synth.scenario(name, seconds, seed), seconds) for seed in range(n)]
        get = lambda k: np.array([r[k] for r in rows], dtype=float)  # noqa: E731
        mean_err = get("mean_err")
        cell = lambda v, fmt: "-" if not np.any(np.isfinite(v)) else fmt.format(np.nanmean(v))  # noqa: E731
        rms = "-" if not np.any(np.isfinite(mean_err)) else f"{np.sqrt(np.nanmean(mean_err ** 2)):.2f}"
        print(f"| {name} | {rms} | {cell(get('track_rms'), '{:.2f}')} | {100 * np.mean(get('wrong')):.1f} % | "
              f"{100 * np.mean(get('false')):.2f} % | {100 * np.mean(get('missed')):.1f} % | "
              f"{int(get('no_tone').sum())}/{n} | {np.mean(get('flagged')):.0f} | "
              f"{int((get('sources') > 0).sum())}/{n} | {100 * np.mean(get('ramp')):.0f} % | "
              f"{np.mean(get('time')):.2f} |")


def false_alarm_table(minutes):
    """Voiced frames in pure noise: the detector's false-alarm rate per frame, bounded at 95 % (one-sided)."""
    from scipy.stats import beta

    from matcad.loop.analyze import analyze_stream
    from matcad.loop.spectrum import Framer, levels
    from matcad.loop.tracker import BandTracker
    from matcad.loop.voicing import STRONG_DB

    print(f"\nVoicing false alarms: {minutes:g} min of each noise at 44.1 kHz, band {BAND[0]:.0f}-{BAND[1]:.0f} Hz "
          "(per-bin tail: fraction of frame×bins over x dB; exponential law exp(-ln2·10^(x/10)) for a known "
          "median):\n")
    print("| noise | frames | frame×bins | voiced frames | 95 % upper bound per frame | frames with a ridge >= "
          f"{STRONG_DB:g} dB | per-bin P(>12 dB) | P(>15 dB) | time [s] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    law = [np.exp(-np.log(2) * 10 ** (x / 10)) for x in (12.0, 15.0)]
    totals = [0, 0, 0]
    for alpha, name in ((0.0, "white"), (1.0, "pink"), (2.0, "brown")):
        frames = voiced = strong = bins = 0
        over = np.zeros(2)
        t0 = time.perf_counter()
        for k in range(int(minutes)):
            x = synth.coloured_noise(int(60 * FS), FS, 1000 + 100 * int(alpha) + k, alpha, 0.1)
            got = []
            try:
                analyze_stream((x[i:i + 65536] for i in range(0, len(x), 65536)), FS, [BAND],
                               lambda _, t, f, e: got.append((f, e)))
            except LoopError:
                pass
            f, e = np.array(got).T
            frames += len(f)
            voiced += int(np.sum(np.isfinite(f)))
            strong += int(np.sum(e >= STRONG_DB))
            framer = Framer(FS)
            power = framer.feed(x)[1]
            tracker = BandTracker(framer.freqs, FS, BAND)
            excess = levels(power[:, tracker.slab], power.max(axis=1))[1][:, tracker.offset:
                                                                          tracker.offset + len(tracker.in_band)]
            over += [np.sum(excess > 12.0), np.sum(excess > 15.0)]
            bins += excess.size
        bound = float(beta.ppf(0.95, voiced + 1, frames - voiced))
        totals = [totals[0] + frames, totals[1] + bins, totals[2] + voiced]
        print(f"| {name} | {frames} | {bins:.3g} | {voiced} | {bound:.2g} | {strong} | {over[0] / bins:.2g} "
              f"(law {law[0]:.1g}) | {over[1] / bins:.2g} (law {law[1]:.1g}) | {time.perf_counter() - t0:.0f} |")
    frames, bins, voiced = totals
    print(f"| all | {frames} | {bins:.3g} | {voiced} | {float(beta.ppf(0.95, voiced + 1, frames - voiced)):.2g} | "
          "| | | |")


def _board_rows(rec, tracks):
    hop = 0.0464
    rows = []
    for k, t in enumerate(tracks):
        a = t.analysis
        truth = rec.truth_at(k, a.times_s) if hasattr(rec, "names") else (
            rec.truth_at(a.times_s) + (300.0 if k else 0.0))
        at = (lambda d: rec.truth_at(k, a.times_s + d)) if hasattr(rec, "names") else (lambda d: truth)
        steady = np.fmax(*[np.abs(at(d) - truth) for d in (-hop, hop)]) <= WRONG_HZ
        ok = a.voiced & steady
        err = a.track_hz[ok] - truth[ok]
        rows.append((t.name, np.mean(err), np.sqrt(np.mean(err ** 2)),
                     (np.sum(np.abs(err) > WRONG_HZ) + np.sum(~a.voiced & steady)) / max(steady.sum(), 1),
                     a.tone_fraction, len(a.segments), len(a.warnings)))
    return rows


def board_table(seeds, seconds):
    from matcad.loop.board import analyze_board

    print(f"\nA board of four taxels in one recording ({seconds:g} s, {seeds} seeds; t2 and t4 pressed 2 -> 12 N; "
          "t2 10 dB louder than t1; frames whose window spans a ramp not scored):\n")
    print("| taxel | band [Hz] | mean per-frame error [Hz] | track RMS [Hz] | frames wrong | tone fraction | "
          "segments | warnings | analyze time, 4 bands [s] |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    per, spent = [], []
    for seed in range(seeds):
        rec = synth.board_scenario(seconds, seed)
        t0 = time.perf_counter()
        tracks = analyze_board([rec.x], rec.fs, list(zip(rec.names, rec.bands_hz)))
        spent.append(time.perf_counter() - t0)
        per.append(_board_rows(rec, tracks))
    for k, name in enumerate(rec.names):
        col = np.array([p[k][1:] for p in per], dtype=float)
        lo, hi = rec.bands_hz[k]
        print(f"| {name} | {lo:.0f}-{hi:.0f} | {np.mean(col[:, 0]):+.3f} (worst {np.max(np.abs(col[:, 0])):.3f}) | "
              f"{np.mean(col[:, 1]):.2f} | {100 * np.mean(col[:, 2]):.1f} % | {np.mean(col[:, 3]):.2f} | "
              f"{np.mean(col[:, 4]):.1f} | {np.mean(col[:, 5]):.0f} | {np.mean(spent):.2f} |")
    print("\nIssue 11's neighbour case (a taxel 10 dB louder, 300 Hz above) with the neighbour in its own band:\n")
    print("| taxel | band [Hz] | mean per-frame error [Hz] | track RMS [Hz] | frames wrong | tone fraction | "
          "segments | warnings |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    ours = synth.board_band_hz(4400.0)
    bands = [("taxel", ours), ("neighbour", (ours[1] + 50.0, ours[1] + 450.0))]
    per = [_board_rows(rec, analyze_board([rec.x], rec.fs, bands))
           for rec in (synth.scenario("neighbour", seconds, seed) for seed in range(seeds))]
    for k, (name, (lo, hi)) in enumerate(bands):
        col = np.array([p[k][1:] for p in per], dtype=float)
        print(f"| {name} | {lo:.0f}-{hi:.0f} | {np.mean(col[:, 0]):+.3f} (worst {np.max(np.abs(col[:, 0])):.3f}) | "
              f"{np.mean(col[:, 1]):.2f} | {100 * np.mean(col[:, 2]):.1f} % | {np.mean(col[:, 3]):.2f} | "
              f"{np.mean(col[:, 4]):.1f} | {np.mean(col[:, 5]):.0f} |")


def _ridge_only(times, track, state, other_bin, other_excess, other_level, excess, band_freqs):
    """matcad.loop.crossing.follow_taxel doing nothing: the ridge as the tracker gives it (the code before
    crossing.py; its outputs were bit-identical to main's on every realistic case)."""
    from matcad.loop.crossing import Identity
    from matcad.loop.segments import steady_segments

    return Identity(np.asarray(track), np.asarray(state, dtype=int).copy(), other_bin, other_excess, other_level,
                    tuple(steady_segments(times, track, state)), ())


def crossing_table(seeds, seconds):
    """Two taxels of equal level crossing in one band (synth.crossing_scenario): per kind, over seeds, frames wrong
    (voiced and > WRONG_HZ off, or missed), swapped (voiced, > WRONG_HZ off and within WRONG_HZ of the other
    taxel), flagged (left out as overlapping or uncertain), ridge only (before matcad.loop.crossing) and after."""
    from unittest import mock

    print(f"\nTwo taxels of EQUAL level crossing in one band ({seconds:g} s, {seeds} seeds; frames whose window "
          "spans a ramp not scored; share of scored frames):\n")
    print("| kind | version | frames wrong | swapped frames | flagged frames | silent wrong (voiced, > 10 Hz) | "
          "seeds with a crossing warning |")
    print("|---|---|---:|---:|---:|---:|---:|")
    hop = 0.0464
    for kind in synth.CROSSING_KINDS:
        taxel_f, other_f = synth.crossing_forces(kind, seconds, FS)
        other_hz = synth.frequency_of_force(other_f)
        for version in ("ridge only", "crossing.py"):
            sums = np.zeros(4)
            warned = 0
            for seed in range(seeds):
                rec = synth.crossing_scenario(kind, seconds, seed)
                with mock.patch("matcad.loop.crossing.follow_taxel", _ridge_only) if version == "ridge only" \
                        else mock.patch.dict({}):
                    a = analyze(rec.x, rec.fs, rec.band_hz)
                truth = rec.truth_at(a.times_s)
                ramp = np.fmax(*[np.abs(rec.truth_at(a.times_s + d) - truth) for d in (-hop, hop)]) > WRONG_HZ
                scored = np.isfinite(truth) & ~ramp
                err = np.abs(a.track_hz - truth)
                other = other_hz[np.clip((a.times_s * FS).astype(int), 0, len(other_hz) - 1)]
                flagged = np.zeros(len(truth), bool)
                for s in a.segments:
                    if s.flag:
                        flagged |= (a.times_s >= s.start_s) & (a.times_s <= s.end_s)
                bad = scored & a.voiced & (err > WRONG_HZ)
                sums += [np.sum(bad | (scored & ~a.voiced)) / scored.sum(),
                         np.sum(bad & (np.abs(a.track_hz - other) <= WRONG_HZ)) / scored.sum(),
                         np.sum(scored & flagged) / scored.sum(), np.sum(bad) / scored.sum()]
                warned += any("crossed" in w for w in a.warnings)
            sums /= seeds
            print(f"| {kind} | {version} | {100 * sums[0]:.1f} % | {100 * sums[1]:.1f} % | {100 * sums[2]:.1f} % | "
                  f"{100 * sums[3]:.1f} % | {warned}/{seeds} |")


def write_long_wav(path, minutes):
    """A long 16-bit recording written 10 s at a time (never held whole): the 'presses' case repeated."""
    block = synth.scenario("presses", 10.0, 0)
    pcm = np.round(block.x / max(1.0, np.max(np.abs(block.x))) * 32000).astype("<i2").tobytes()
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(FS)
        for _ in range(int(round(minutes * 6))):
            w.writeframes(pcm)


def memory_table(durations):
    print("\n`matcad analyze` on long recordings (16-bit mono 44.1 kHz, the 'presses' case repeated):\n")
    print("| length | file [MB] | wall time [s] | peak RSS [MB] |")
    print("|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for label, minutes in durations:
            path = Path(tmp) / f"long-{label}.wav"
            write_long_wav(path, minutes)
            cmd = [sys.executable, "-m", "matcad", "analyze", str(path), "--band", "3900", "5600",
                   "--out", str(Path(tmp) / f"out-{label}")]
            env = {**os.environ, "OMP_NUM_THREADS": "1", "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
            t0 = time.perf_counter()
            if Path("/usr/bin/time").exists():
                proc = subprocess.run(["/usr/bin/time", "-v", *cmd], capture_output=True, text=True, env=env)
                rss = [ln for ln in proc.stderr.splitlines() if "Maximum resident set size" in ln]
                peak_mb = int(rss[0].split()[-1]) / 1024 if rss else float("nan")
            else:
                proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
                peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
            wall = time.perf_counter() - t0
            status = "" if proc.returncode == 0 else f" (exit {proc.returncode})"
            print(f"| {label} | {path.stat().st_size / 1e6:.0f} | {wall:.1f}{status} | {peak_mb:.0f} |")
            path.unlink()


def startup_table():
    """Issue 24: `matcad analyze REC --spec BOARD` before it listens — the board's loaded bands need every distinct
    cap's mechanics curve. Cold: an empty cap-curve cache (every FElupe run done); warm: the same command again."""
    from scipy.io import wavfile

    print("\n`matcad analyze REC --spec templates/mat-array-4.toml` (a 4 s board recording): wall time of the whole "
          "command and of the listening bands alone, cold and warm cap-curve cache (matcad.mechanics.store):\n")
    print("| cache | listening_bands [s] | whole command [s] | exit |")
    print("|---|---:|---:|---:|")
    root = Path(__file__).resolve().parents[1]
    spec = root / "templates" / "mat-array-4.toml"
    with tempfile.TemporaryDirectory() as tmp:
        rec = synth.board_scenario(4.0, seed=0)
        wavfile.write(Path(tmp) / "board.wav", int(rec.fs), np.round(rec.x / np.max(np.abs(rec.x)) * 30000)
                      .astype(np.int16))
        env = {**os.environ, "PYTHONPATH": str(root), "MATCAD_CACHE_DIR": str(Path(tmp) / "cache")}
        code = ("import time, sys; t=time.perf_counter(); from matcad import spec; "
                "from matcad.prediction.bands import listening_bands; listening_bands(spec.load(sys.argv[1])); "
                "print(time.perf_counter()-t)")
        for label in ("cold", "warm"):
            bands = subprocess.run([sys.executable, "-c", code, str(spec)], capture_output=True, text=True, env=env)
            if label == "cold":  # the command itself starts from an empty cache too
                shutil.rmtree(Path(tmp) / "cache", ignore_errors=True)
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-m", "matcad", "analyze", str(Path(tmp) / "board.wav"),
                                   "--spec", str(spec), "--out", str(Path(tmp) / f"out-{label}")],
                                  capture_output=True, text=True, env=env)
            wall = time.perf_counter() - t0
            print(f"| {label} | {float(bands.stdout.strip() or 'nan'):.1f} | {wall:.1f} | {proc.returncode} |")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="2 seeds, 5 s cases, no 60 min file")
    parser.add_argument("--memory-only", action="store_true")
    parser.add_argument("--no-memory", action="store_true", help="skip the long files")
    parser.add_argument("--board-only", action="store_true", help="only the board table")
    parser.add_argument("--crossing-only", action="store_true", help="only the crossing table")
    parser.add_argument("--startup-only", action="store_true", help="only the board start-up table")
    parser.add_argument("--speech-seeds", type=int, default=20, help="seeds of the speech cases (they vary most)")
    parser.add_argument("--noise-minutes", type=float, default=10.0,
                        help="minutes of each noise for the false-alarm table (0 skips it)")
    args = parser.parse_args()
    durations = [("10 s", 1 / 6), ("10 min", 10), ("60 min", 60)]
    if args.quick:
        durations = durations[:2]
    if args.board_only:
        board_table(3, 10.0)
        return
    if args.crossing_only:
        crossing_table(10, 10.0)
        return
    if args.startup_only:
        startup_table()
        return
    if not args.memory_only:
        clean_tone_table()
        realistic_table(2 if args.quick else 3, 5.0 if args.quick else 10.0, 2 if args.quick else args.speech_seeds)
        board_table(2 if args.quick else 3, 5.0 if args.quick else 10.0)
        crossing_table(5 if args.quick else 10, 10.0)
        if args.noise_minutes > 0:
            false_alarm_table(1 if args.quick else args.noise_minutes)
    if not args.no_memory:
        memory_table(durations)


if __name__ == "__main__":
    main()
