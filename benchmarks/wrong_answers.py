"""The loop's wrong answers with exit 0 (issue 24), on recordings made for it (matcad.loop.synth_faults and
matcad.loop.synth_board), run exactly as `matcad sense` runs them (in-process: analyze, sense, the refusals).

Per case over seeds: how often sense exits 0, how often it exits 0 with a wrong answer, and how often the fault
passes without a word. Wrong means, per case:

- slow-stage, press-2n: a steady segment whose 95 % force interval misses the true force in more than half of its
  frames (the share of all segment frames missed is printed too). The calibration here states no hysteresis
  (cycle_std_n = 0) and the temperature is given, so that only the segmentation is judged.
- two-tones-*: any force printed whose interval misses the taxel's 8 N (overall, a segment, or > 5 % of frames).
- talker, reverberant-room, room-and-talker (no taxel sings): any force printed at all.
- pressed-out (a board taxel pressed out of its band): a segment of t2 within 3 bins of its band edge while t2's
  tone is outside the band, or another taxel reporting t2's tone; unwarned: no warning that t2 left its band.
- overblown-out (t1 jumps x1.22 out of its band, into t3's, for 1.2 s while the others sing): any taxel reporting
  t1's overblown tone as a load-bearing tone in > 3 frames; unwarned: no warning naming the jump.

Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/wrong_answers.py [--seeds N]. Prints numbers, asserts nothing.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matcad.acoustics.eq5fit import fit  # noqa: E402
from matcad.errors import LoopError  # noqa: E402
from matcad.loop import synth, synth_board, synth_faults  # noqa: E402
from matcad.loop.analyze import analyze_stream  # noqa: E402
from matcad.loop.board import analyze_board, sense_board  # noqa: E402
from matcad.loop.sense import listening_band_hz, require_in_range, sense  # noqa: E402

T_C = 20.0


def calibration(k_hz2=synth.K_MM3_HZ2, law=synth.EQ5):
    forces = np.tile(np.linspace(0.0, 15.0, 11), 2)
    freqs = law.__class__(law.v0_mm3, law.a, law.b, k_hz2).frequency_hz(forces)
    freqs = freqs + np.random.default_rng(0).normal(0.0, 0.3, len(freqs))
    return fit(forces, freqs, k_hz2, cycles=np.repeat([0, 1], 11), temperature_c=T_C, cycle_std_n=0.0).law


def run_single(rec, cal):
    """(exit code, analysis or None, reading or None) of `matcad sense REC --calibration CAL --temperature-c 20`."""
    try:
        a = analyze_stream([rec.x], rec.fs, [listening_band_hz(cal)])[0]
        r = sense(a, cal, T_C)
        require_in_range(r)
        return 0, a, r
    except LoopError:
        return 1, None, None


def truth_force_at(rec, times):
    return rec.force_n[np.clip((np.asarray(times) * rec.fs).astype(int), 0, len(rec.force_n) - 1)]


def judge_segments(rec, a, r):
    """(wrong segments, frames missed, frames in segments)."""
    wrong = missed = total = 0
    for seg, (f, lo, hi) in zip(a.segments, r.segments_n):
        if seg.flag or not np.isfinite(f):
            continue
        inside = (a.times_s >= seg.start_s) & (a.times_s <= seg.end_s) & a.voiced
        truth = truth_force_at(rec, a.times_s[inside])
        miss = (truth < lo) | (truth > hi)
        wrong += np.mean(miss) > 0.5
        missed += int(miss.sum())
        total += len(miss)
    return wrong, missed, total


def single_case(name, seeds):
    cal = calibration()
    exits = wrong = unwarned = 0
    missed = total = 0
    for seed in range(seeds):
        rec = synth_faults.scenario(name, seed=seed)
        code, a, r = run_single(rec, cal)
        exits += code == 0
        if code != 0:
            continue
        if name in ("slow-stage", "press-2n"):
            w, m, t = judge_segments(rec, a, r)
            wrong += w > 0
            missed, total = missed + m, total + t
        elif name.startswith("two-tones"):
            bad = not (r.force_interval_n[0] <= 8.0 <= r.force_interval_n[1])
            bad |= any(np.isfinite(f) and not lo <= 8.0 <= hi for f, lo, hi in r.segments_n)
            ok = np.isfinite(r.frames_n)
            frames_bad = np.mean((r.frames_interval_n[ok, 0] > 8.0) | (r.frames_interval_n[ok, 1] < 8.0)) \
                if ok.any() else 0.0
            wrong += bad or frames_bad > 0.05
            unwarned += not any("tone" in w for w in list(a.warnings) + list(r.warnings))
        else:
            wrong += 1
            unwarned += not a.warnings
    detail = f"{100 * missed / total:.0f} % of {total} segment frames missed" if total else ""
    return exits, wrong, unwarned, detail


def board_calibrations():
    return {f"t{k + 1}": calibration(synth.EQ5.v0_mm3 * f0 ** 2) for k, f0 in enumerate(synth.BOARD_F0_HZ)}


def board_case(name, seeds):
    cals = board_calibrations()
    exits = wrong = unwarned = 0
    detail = []
    for seed in range(seeds):
        rec = synth_board.fault_scenario(name, seed=seed)
        try:
            tracks = analyze_board([rec.x], rec.fs, list(zip(rec.names, rec.bands_hz)))
            sense_board(tracks, cals, T_C)
            code = 0
        except LoopError:
            code = 1
        exits += code == 0
        if code:
            continue
        warnings = [w for t in tracks if t.analysis is not None for w in t.analysis.warnings]
        if name == "pressed-out":
            t2 = tracks[1].analysis
            lo, hi = rec.bands_hz[1]
            outside = rec.truth_at(1, t2.times_s) > hi
            edge = [s for s in t2.segments if not s.flag and abs(s.mean_hz - hi) < 3 * 5.4
                    and np.any(outside & (t2.times_s >= s.start_s) & (t2.times_s <= s.end_s))]
            stolen = 0
            for k, t in enumerate(tracks):
                if k == 1 or t.analysis is None:
                    continue
                at = np.abs(t.analysis.track_hz - rec.truth_at(1, t.analysis.times_s)) < 10
                other = np.abs(t.analysis.track_hz - rec.truth_at(k, t.analysis.times_s)) > 10
                stolen += int(np.sum(t.analysis.voiced & at & other))
            wrong += bool(edge) or stolen > 3
            unwarned += not any("left" in w and "t2" in w or "left its band" in w for w in
                                tracks[1].analysis.warnings)
            detail.append(f"{len(edge)} edge segments, {stolen} frames taken")
        else:
            jump_hz = 1.22 * synth.frequency_of_force(4.0, synth.EQ5.v0_mm3 * synth.BOARD_F0_HZ[0] ** 2)
            taken = 0
            for t in tracks:
                a = t.analysis
                if a is None:
                    continue
                during = (a.times_s > 3.1) & (a.times_s < 4.1)
                taken += int(np.sum(a.voiced & during & (np.abs(a.track_hz - jump_hz) < 15)))
            wrong += taken > 3
            unwarned += not any("overblow" in w or "jump" in w for w in warnings)
            detail.append(f"{taken} frames")
    return exits, wrong, unwarned, "; ".join(detail[:3])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=10)
    args = parser.parse_args()
    print(f"Wrong answers with exit 0 (issue 24), {args.seeds} seeds per case:\n")
    print("| case | exit 0 | wrong with exit 0 | no warning | detail | time [s] |")
    print("|---|---:|---:|---:|---|---:|")
    for name in (*synth_faults.CASES, *synth_board.FAULTS):
        t0 = time.perf_counter()
        run = board_case if name in synth_board.FAULTS else single_case
        exits, wrong, unwarned, detail = run(name, args.seeds)
        print(f"| {name} | {exits}/{args.seeds} | {wrong}/{args.seeds} | {unwarned}/{args.seeds} | {detail} | "
              f"{time.perf_counter() - t0:.0f} |", flush=True)


if __name__ == "__main__":
    main()
