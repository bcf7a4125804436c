"""Inverse design: accuracy by `predict` and time per solve; the band allocation of a 4-taxel array; the capacity
of one microphone (issue 24).

Capacity (``--capacity-only``): `design --taxels N` on a rigid-wall taxel whose load rise is the paper's Eq. 5
(calipered sheet, max force F, neck diameter, cavity diameter and length free per taxel; the neck length is the
plate's sheet, one stock thickness per board), at 44.1 and 96 kHz: the most taxels that fit, whether `check`
passes, and each taxel tracked on a synthetic board recording (matcad.loop.synth_board: every taxel singing in its
listening band with 2f/3f at -20/-30 dB, presses to F on every third, a room heard from ``--mic-distance-m``,
default the paper's 0.10 m; 5 seeds) — the per-taxel |mean error| and track RMS (Hz) over voiced frames, and per
seed how many taxels are within 1 Hz and the worst one.

Room shift (``--room-shift``): how far the board recordings' room alone moves a steady line's heard pitch, per
microphone distance (:func:`room_shift`).

Capacity figure (``--figure docs/capacity.png``): the most taxels that fit below 0.45 fs against the max force per
taxel, at 44.1 and 96 kHz, for two routes with buildable caps (no tracking), and every design's loaded bands.

Prints numbers, asserts nothing. Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/design.py [--capacity-only
[--mic-distance-m M] | --room-shift | --figure PNG]
"""

import dataclasses
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad import spec as spec_mod  # noqa: E402
from matcad.prediction import predict  # noqa: E402
from matcad.design import RulesFailed, Unreachable  # noqa: E402
from matcad.design.solve import parse_vary, solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TARGETS = np.arange(4000.0, 6001.0, 250.0)
VARY = (["neck.diameter"], ["cavity.length"], ["cavity.diameter", "neck.diameter"], ["neck.length", "neck.diameter"])


def inverse_design():
    for template in ("mat-laser-only", "mat-paper"):
        s = spec_mod.load(ROOT / "templates" / f"{template}.toml")
        for vary in VARY:
            errors, times, refused = [], [], []
            for target in TARGETS:
                t0 = time.perf_counter()
                try:
                    r = solve(s, float(target), parse_vary(s, vary))
                except (Unreachable, RulesFailed) as exc:
                    refused.append(f"{target:.0f} Hz ({type(exc).__name__})")
                    continue
                times.append(time.perf_counter() - t0)
                errors.append(abs(predict(r.spec).f0_hz / target - 1))
            print(f"{template:<15} {'+'.join(vary):<28} {len(errors)}/{len(TARGETS)} solved, max |error| by predict "
                  f"{max(errors):.1e}, time per solve median {1e3 * statistics.median(times):.0f} ms, max "
                  f"{1e3 * max(times):.0f} ms" + (f"; refused {', '.join(refused)}" if refused else ""))


def allocation():
    from matcad.listening import guard_hz
    from matcad.prediction.bands import conflicts, taxel_bands
    from matcad.design.allocate import allocate

    s = spec_mod.load(ROOT / "templates" / "mat-laser-only.toml")
    s = dataclasses.replace(s, plate=dataclasses.replace(s.plate, thickness_measured=True),
                            mechanics=dataclasses.replace(s.mechanics, max_force_n=5.0))
    t0 = time.perf_counter()
    a = allocate(s, 4, 3500.0, 7000.0, parse_vary(s, ["neck.diameter"]), "laser-4taxels")
    print(f"\nallocate 4 taxels in 3500-7000 Hz (mat-laser-only, calipered sheet, max force 5 N, cap mechanics): "
          f"{time.perf_counter() - t0:.1f} s, guard {a.guard_hz:.1f} Hz")
    bands = taxel_bands(a.spec)
    for b, sol in zip(bands, a.solutions):
        print(f"  {b.name} ({b.x_mm:+.3f}, {b.y_mm:+.3f}) mm  neck {sol.spec.neck.diameter:.4f} mm  f0 {b.f0_hz:7.1f} Hz  "
              f"unloaded {b.unloaded_hz[0]:7.1f}-{b.unloaded_hz[1]:7.1f}  loaded {b.loaded_hz[0]:7.1f}-"
              f"{b.loaded_hz[1]:7.1f} Hz  rise {100 * (b.rise - 1):+.2f} %")
    gaps = [b2.loaded_hz[0] - b1.loaded_hz[1] for b1, b2 in zip(bands, bands[1:])]
    print(f"  gaps {', '.join(f'{g:.1f}' for g in gaps)} Hz; conflicts "
          f"{len(conflicts(bands, guard_hz(a.spec.microphone.sample_rate_hz)))}; "
          f"room left {7000 - bands[-1].loaded_hz[1]:.0f} Hz")


BOARD_BASE = """name = "arr"
[cavity]
diameter = 3.18
length = 4.76
[neck]
diameter = 2.1
length = {sheet}
[plate]
thickness_measured = true
[outputs]
end_cap_mold = false
needle_mount = false
assembly = false
[mechanics]
max_force_n = {force}
[microphone]
sample_rate_hz = {rate}
[calibration]
v0_mm3 = 32.21
a = -0.0086
b = 0.4626
area_convention = "d2/4"
"""
THREE = ["neck.diameter=0.5:7", "cavity.length", "cavity.diameter=2.1:12"]
LENGTH = ["cavity.length=0.3:30"]
CAPACITY = ((44100.0, 12, (1700.0, 11000.0), 1.5875, THREE), (44100.0, 12, (1700.0, 19800.0), 3.175, LENGTH),
            (44100.0, 24, (1700.0, 19800.0), 1.5875, LENGTH),
            (96000.0, 16, (1200.0, 30000.0), 0.8, THREE), (96000.0, 16, (1200.0, 30000.0), 3.175, THREE),
            (96000.0, 16, (2000.0, 40000.0), 0.8, LENGTH), (96000.0, 16, (1700.0, 43000.0), 3.175, LENGTH),
            (96000.0, 24, (1700.0, 43000.0), 0.8, LENGTH))
"""(sample rate Hz, taxels asked, band Hz, sheet = neck length mm, --vary). The three-field route of
matcad.design.solve stops near 10.5 / 12.1 kHz; the cavity length alone reaches higher (a shorter cavity). The 1/8 in
rows are 96 kHz boards whose plate stays flat on its posts (docs/arrays.md); the cavity-length one keeps every cap's
wall (the three-field one lets the cavity reach 12 mm in a 7.95 mm cap)."""


def most_that_fit(s, n, band, vary):
    """(allocation of the most taxels <= n that fit, the message when n did not)."""
    import re

    from matcad.design.allocate import allocate

    why = ""
    while n >= 2:
        try:
            return allocate(s, n, *band, vary), why
        except (Unreachable, RulesFailed) as exc:  # the top band breaking acoustic.band_high, too
            why = why or str(exc)
            hit = re.search(r"taxel (\d+) of", str(exc))
            k = int(hit.group(1)) if hit else 1
            n = min(n - 1, k - 1) if k > 1 else n - 1  # taxel 1 failing is the board itself: a plate past the bed
    return None, why


def capacity(forces=(5.0,), seeds=5, mic_distance_m=None):
    import tomllib

    from matcad.loop import synth, synth_board
    from matcad.loop.board import analyze_board
    from matcad.prediction.bands import listening_bands, taxel_bands
    from matcad.rules import check, errors

    mic_distance_m = synth_board.MIC_DISTANCE_M if mic_distance_m is None else mic_distance_m
    wet = synth.reverb_share(mic_distance_m, synth_board.BOARD_RT60_S)
    print("\ncapacity: taxels per microphone (rigid walls, Eq. 5 rise, calipered sheet; guard from the tracker); "
          f"board recordings heard from {mic_distance_m:.3f} m in the {synth.LAB_VOLUME_M3:g} m³ lab at RT60 "
          f"{synth_board.BOARD_RT60_S:g} s (direct {-20 * np.log10(wet):+.1f} dB over the reverberant field)")
    print("| rate [kHz] | max force [N] | sheet [mm] | vary | asked | fit | reach [Hz] | check errors | design [s] | "
          "board: worst per-taxel |mean error| [Hz] | worst track RMS [Hz] | taxels with a tone | "
          "largest neck boundary-layer drop [%] |")
    print("|---:|---:|---:|---|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for rate, n, band, sheet, vary in CAPACITY:
        for force in forces:
            s = spec_mod.from_dict(tomllib.loads(BOARD_BASE.format(sheet=sheet, force=force, rate=rate)))
            t0 = time.perf_counter()
            a, why = most_that_fit(s, n, band, parse_vary(s, vary))
            took = time.perf_counter() - t0
            if a is None:
                print(f"| {rate / 1e3:g} | {force:g} | {sheet:g} | {' '.join(vary)} | {n} | 0 | - | - | {took:.0f} "
                      "| - | - | - | - |")
                continue
            bad = len(errors(check(a.spec)))
            bands = taxel_bands(a.spec)
            listen = listening_bands(a.spec)
            worst_mean = worst_rms = 0.0
            heard, per_seed = [], []
            for seed in range(seeds):
                rec = synth_board.board_recording([(b.name, b.loaded_hz) for b in bands], [b.rise for b in bands],
                                                  force, seconds=6.0, seed=seed,
                                                  fs=rate, mic_distance_m=mic_distance_m)
                tracks = analyze_board([rec.x], rec.fs, listen)
                count, errors_hz = 0, []
                for k, t in enumerate(tracks):
                    if t.analysis is None:
                        errors_hz.append((float("inf"), t.name))
                        continue
                    v = t.analysis.voiced
                    err = t.analysis.track_hz[v] - rec.truth_at(k, t.analysis.times_s[v])
                    errors_hz.append((abs(float(np.mean(err))), t.name))
                    worst_rms = max(worst_rms, float(np.sqrt(np.mean(err ** 2))))
                    count += 1
                heard.append(count)
                worst = max(errors_hz)
                worst_mean = max(worst_mean, worst[0])
                per_seed.append(f"seed {seed}: {sum(e < 1.0 for e, _ in errors_hz)}/{len(bands)} within 1 Hz, "
                                f"worst {worst[1]} {worst[0]:.2f} Hz ("
                                + " ".join(f"{name} {e:.2f}" for e, name in errors_hz) + ")")
            reach = f"{bands[0].loaded_hz[0]:.0f}-{bands[-1].loaded_hz[1]:.0f}"
            from matcad.acoustics.air import boundary_layer_drop
            from matcad.spec import taxels

            loss = max(boundary_layer_drop(b.f0_hz, t.neck.diameter / 2) for b, t in zip(bands, taxels(a.spec)))
            print(f"| {rate / 1e3:g} | {force:g} | {sheet:g} | {' '.join(vary)} | {n} | {len(bands)} | {reach} | "
                  f"{bad} | {took:.0f} | "
                  f"{worst_mean:.2f} | {worst_rms:.2f} | {min(heard)}/{len(bands)} | {100 * loss:.1f} |", flush=True)
            print("\n".join(f"    {line}" for line in per_seed))
            if len(bands) < n:
                print(f"    ({n} asked: {why[:260]})")


def room_shift(seeds=5, step_hz=0.1):
    """How far the board recordings' room alone moves a steady line's heard pitch, per microphone distance: the
    paper's 0.10 m, 0.20 m, half the critical distance (the +6 dB room the board recordings had before) and the
    critical distance. The heard pitch is the peak of the expected frame spectrum — the taxel's Lorentzian line
    times the room's |H(f)|² (synth.reverb's impulse response, the rooms of board_recording's seeds
    0..``seeds``-1), smoothed by the tracker's Hann window's |W|² — against the line's centre, for tones every 7.3 Hz
    over 2-12 kHz: the share of 1 Hz-wide lines (synth.taxel's) shifted by >= 0.5 and >= 1 Hz, the largest shift
    (Hz), and the largest for a 0.05 Hz-wide line."""
    from matcad.listening import window_samples
    from matcad.loop import synth, synth_board

    rt60 = synth_board.BOARD_RT60_S
    rc = synth.critical_distance_m(synth.LAB_VOLUME_M3, rt60)
    tones = np.arange(2000.0, 12000.0, 7.3)
    offsets = np.arange(-40.0, 40.0 + step_hz / 2, step_hz)
    core = offsets[np.abs(offsets) < 15.0]
    lines = [1 / (1 + (2 * offsets / width) ** 2) for width in (1.0, 0.05)]
    print(f"\nroom shift of a steady line (room alone: {synth.LAB_VOLUME_M3:g} m³ lab, RT60 {rt60:g} s, critical "
          f"distance {rc:.2f} m; {len(tones) * seeds} tones 2-12 kHz)")
    print("| rate [kHz] | distance [m] | direct over reverberant [dB] | 1 Hz line shifted >= 0.5 Hz | >= 1 Hz | "
          "largest [Hz] | 0.05 Hz line: largest [Hz] |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for fs in (44100.0, 96000.0):
        n = window_samples(fs)
        window = np.hanning(n + 1)[:-1]
        lags = np.arange(-80.0, 80.0 + step_hz / 2, step_hz)
        w2 = np.abs(np.exp(-2j * np.pi * np.outer(lags, np.arange(n)) / fs) @ window) ** 2
        smooth = w2[np.round((core[:, None] - offsets[None, :]) / step_hz).astype(int) + len(lags) // 2]
        impulse = np.zeros(int(rt60 * fs) + 1)
        impulse[0] = 1.0
        for r in (0.10, 0.20, rc / 2, rc):
            wet = synth.reverb_share(r, rt60)
            shifts = []
            for seed in range(seeds):
                h = synth.reverb(impulse, fs, rt60, seed + 1, wet)
                h2 = np.abs(np.fft.rfft(h, int(round(fs / step_hz)))) ** 2
                for f in tones:
                    i = int(round(f / step_hz)) - len(offsets) // 2
                    room = h2[i: i + len(offsets)]
                    shifts.append([core[np.argmax(smooth @ (line * room))] for line in lines])
            wide, narrow = np.abs(np.array(shifts)).T
            print(f"| {fs / 1e3:g} | {r:.2f} | {-20 * np.log10(wet) + 0.0:+.1f} | {100 * np.mean(wide >= 0.5):.1f} % | "
                  f"{100 * np.mean(wide >= 1.0):.1f} % | {wide.max():.1f} | {narrow.max():.1f} |", flush=True)


SWEEP = ((44100.0, (1700.0, 19800.0), 1.5875, 40), (44100.0, (1700.0, 19800.0), 3.175, 40),
         (96000.0, (1700.0, 43000.0), 0.8, 48), (96000.0, (1700.0, 43000.0), 3.175, 48))
"""(sample rate Hz, band Hz up to 0.45 fs, sheet mm, taxels asked: more than fit) of the capacity figure: the 1/8 in
rows are boards whose plate the support posts can hold flat (docs/arrays.md)."""
ROUTES = {("neck.diameter=0.5:7", "cavity.length", "cavity.diameter"): "neck, cavity diameter and length",
          tuple(LENGTH): "cavity length alone"}
"""The --vary routes of the capacity figure, with their legend text: the cavity diameter in its default range,
which leaves a silicone wall that demolds (CAPACITY's THREE lets it reach 12 mm: the 12- and 16-taxel designs there
have five caps each with walls under 1 mm, `cap.wall`)."""


def capacity_sweep(forces, path):
    """Taxels per microphone against the max force per taxel (N), at 44.1 and 96 kHz, for each route of
    :data:`ROUTES` (the most that fit of :data:`SWEEP`'s ask; no tracking): a table, and the figure at ``path``
    (:func:`capacity_figure`)."""
    import tomllib

    print("\ncapacity sweep: the most taxels that fit below 0.45 fs (rigid walls, Eq. 5 rise, calipered sheet); "
          "plate: flat, or bends (plate.bending, with support posts where they fit)")
    print("| rate [kHz] | sheet [mm] | vary | max force [N] | fit | reach [Hz] | plate | design [s] |")
    print("|---:|---:|---|---:|---:|---|---|---:|")
    results = []
    for rate, band, sheet, ask in SWEEP:
        for vary in ROUTES:
            for force in forces:
                s = spec_mod.from_dict(tomllib.loads(BOARD_BASE.format(sheet=sheet, force=force, rate=rate)))
                t0 = time.perf_counter()
                a, _ = most_that_fit(s, ask, band, parse_vary(s, list(vary)))
                bands = () if a is None else tuple(b.loaded_hz for b in a.bands)
                flat = a is not None and not any(f.id == "plate.bending" for f in a.findings)
                results.append((rate, sheet, vary, force, bands, flat))
                reach = f"{bands[0][0]:.0f}-{bands[-1][1]:.0f}" if bands else "-"
                print(f"| {rate / 1e3:g} | {sheet:g} | {' '.join(vary)} | {force:g} | {len(bands)} | {reach} | "
                      f"{'flat' if flat else 'bends'} | {time.perf_counter() - t0:.0f} |", flush=True)
    capacity_figure(results, path)


def capacity_figure(results, path):
    """The capacity figure (issue 24): left, taxels per microphone against the max force per taxel, per sample
    rate, sheet and route (the guard in the legend; a filled marker: the plate stays flat, hollow: it bends,
    ``plate.bending``); right, every design's loaded bands (Hz, log axis) at the first force, with the microphone's
    top, 0.45 fs (:data:`matcad.rules.acoustic.NYQUIST_MARGIN`). ``results``: (rate Hz, sheet mm, --vary, max force
    N, loaded bands Hz, flat) per design."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    from matcad.listening import guard_hz
    from matcad.rules.acoustic import NYQUIST_MARGIN

    fig, (left, right) = plt.subplots(1, 2, figsize=(14, 7.5), gridspec_kw={"width_ratios": [1, 1.4]})
    first = results[0][3]
    rows = [r for r in results if r[3] == first]
    for k, (rate, sheet, vary, _, bands, _) in enumerate(rows):
        colour = f"C{k}"
        same = sorted((force, len(b), flat) for r, t, v, force, b, flat in results
                      if (r, t, v) == (rate, sheet, vary))
        left.plot([x for x, _, _ in same], [n for _, n, _ in same], color=colour,
                  label=f"{rate / 1e3:g} kHz, {sheet:g} mm sheet, {ROUTES[vary]} (guard {guard_hz(rate):.0f} Hz)")
        for force, n, flat in same:
            left.plot([force], [n], marker="o", color=colour, markerfacecolor=colour if flat else "white")
        for lo, hi in bands:
            right.plot([lo, hi], [k, k], color=colour, linewidth=7, solid_capstyle="butt")
        top = NYQUIST_MARGIN * rate
        right.plot([top, top], [k - 0.35, k + 0.35], color="black", linewidth=2)
        right.annotate(f"{len(bands)}", (bands[-1][1] if bands else top, k), xytext=(4, -4),
                       textcoords="offset points", fontsize=9)
    left.set(xlabel="max force per taxel [N]", ylabel="taxels on one microphone",
             title="design --taxels, rigid walls, Eq. 5 rise\n(filled: the plate stays flat; hollow: it bends)",
             ylim=(0, None))
    left.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12))
    left.grid(True, alpha=0.3)
    ticks = [1e3, 2e3, 5e3, 1e4, 2e4, 5e4]
    right.set(xscale="log", xlabel="loaded band [Hz]", yticks=range(len(rows)),
              yticklabels=[f"{r / 1e3:g} kHz, {t:g} mm\n{ROUTES[v]}" for r, t, v, _, _, _ in rows],
              title=f"loaded bands to {first:g} N (black: 0.45 fs, the microphone's top)")
    right.set_xticks(ticks, [f"{t / 1e3:g} k" for t in ticks])  # after the log scale, which resets them
    right.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    right.grid(True, which="both", axis="x", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"figure: {path}")


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser()
    parser.add_argument("--capacity-only", action="store_true")
    parser.add_argument("--seeds", type=int, default=5, help="synthetic board recordings per design")
    parser.add_argument("--room-shift", action="store_true", help="only the room's shift of a steady line per "
                        "microphone distance (no design)")
    parser.add_argument("--mic-distance-m", type=float, help="microphone distance of the board recordings (m; "
                        "default the paper's 0.10; 0.31863968679372007, half the critical distance, is the +6 dB room "
                        "the board recordings had before)")
    parser.add_argument("--figure", metavar="PNG", help="only the capacity sweep (--forces) and its figure "
                                                        "(docs/capacity.png)")
    parser.add_argument("--forces", type=float, nargs="+", default=[5.0, 2.0, 20.0],
                        help="max forces per taxel (N) of the sweep; the figure's bands at the first")
    args = parser.parse_args()
    if args.figure:
        capacity_sweep(args.forces, args.figure)
    elif args.room_shift:
        room_shift()
    else:
        if not args.capacity_only:
            inverse_design()
            allocation()
        capacity(seeds=args.seeds, mic_distance_m=args.mic_distance_m)
