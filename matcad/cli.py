"""Command line. Thin: parse, call one function, print text or --json, map errors to exit codes.

Exit codes (one table, :data:`EXIT_CODES`, enforced in :func:`main`):
  0   ok
  1   design-rule failure, or for analyze/calibrate/sense no trustworthy result (no tone, a tone at the band
      edge, degenerate or flat data, a force outside the calibrated range)
  2   bad input or unusable file (spec, data, recording, output folder, the file system refusing a write)
  70  internal error (a bug): one line "internal error, please report" with the path of a log holding the
      traceback (in the temporary folder, never under $HOME) — never 1, which is reserved for the rules
  130 interrupted (Ctrl-C, SIGINT), anywhere, including while the CAD kernel loads; no traceback
  143 terminated (SIGTERM), handled exactly like an interrupt
On an interrupt the output folder is left as it was (matcad.output), further interrupts are ignored while
the temporary folder is removed.
"""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
from pathlib import Path

from matcad import __version__

EXIT_OK, EXIT_RULES, EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPT, EXIT_TERMINATED = 0, 1, 2, 70, 130, 143
EXIT_CODES = {EXIT_OK: "ok", EXIT_RULES: "design-rule failure or no trustworthy result",
              EXIT_INPUT: "bad input or unusable file", EXIT_INTERNAL: "internal error (please report)",
              EXIT_INTERRUPT: "interrupted (SIGINT)", EXIT_TERMINATED: "terminated (SIGTERM)"}


def _print_json(data) -> None:
    import json

    print(json.dumps(data, indent=2, allow_nan=False))


def _load_spec(path, args):
    """The validated spec at ``path`` (TOML or a build's report.json) with ``--set`` applied; likely unit slips
    and silent defaults are printed to stderr as notes (never changing a value)."""
    from matcad.spec import load_spec, spec_notes

    spec, data = load_spec(path, getattr(args, "set", None))
    for note in spec_notes(spec, data):
        print(f"matcad: note: {note}", file=sys.stderr)
    return spec


def _format_prediction(spec, p) -> str:
    cav, neck = spec.cavity, spec.neck
    lines = [
        f"{spec.name}: cavity D {cav.diameter:g} x L {cav.length:g} mm, neck d {neck.diameter:g} x "
        f"l {neck.length:g} mm, mouth {neck.mouth}, wall {spec.wall.model}",
        f"  cavity volume   {p.cavity_volume_mm3:10.4f} mm^3    neck area {p.neck_area_mm2:.4f} mm^2",
        f"  A*l/V           {p.neck_air_ratio:10.4f}         xi = d/D  {p.diameter_ratio:.4f}",
        f"  speed of sound  {p.speed_of_sound_m_s:10.2f} m/s     end corrections: outer "
        f"{p.outer_end_correction_mm:.3f} mm, inner {p.inner_end_correction_mm:.3f} mm",
        "",
        f"  {'model':<18} {'f0 [Hz]':>9}  {'valid':<5}  failed checks",
    ]
    for name, r in p.models.items():
        failed = ", ".join(k for k, ok in r.checks.items() if not ok) or "-"
        mark = "*" if name == p.model else " "
        lines.append(f"{mark} {name:<18} {r.f0_hz:9.1f}  {'yes' if r.valid else 'no':<5}  {failed}")
    lines += ["", f"  f0 = {p.f0_hz:.0f} Hz ({p.model}), band {p.band_hz[0]:.0f}-{p.band_hz[1]:.0f} Hz "
                  "(root-sum-square in ln f of):"]
    lines += [f"    {b.source:<28} {b.tolerance:<52} {b.low_hz:+8.1f} {b.high_hz:+8.1f} Hz" for b in p.budget]
    if p.load_curve:
        lines += _format_load_curve(p)
    if p.warnings:
        lines += ["", "  warnings:"] + [f"  - {w}" for w in p.warnings]
    return "\n".join(lines)


def _format_load_curve(p) -> list[str]:
    """The load curve by source (Eq. 5 calibration, cap mechanics) and the mechanics summary."""
    lines = []
    for source in dict.fromkeys(pt.source for pt in p.load_curve):
        lines += ["", f"  load curve from {source}:", f"  {'F [N]':>9} {'f [Hz]':>9} {'x [mm]':>8} {'V [mm^3]':>9}"]
        for pt in (q for q in p.load_curve if q.source == source):
            if pt.f_hz is None:
                lines.append(f"  {pt.force_n:9.3f} {'n/a':>9}  {pt.reason}")
                continue
            x, v = (f"{q:8.3f}" if q is not None else f"{'-':>8}" for q in (pt.displacement_mm, pt.cavity_volume_mm3))
            lines.append(f"  {pt.force_n:9.3f} {pt.f_hz:9.1f} {x} {v:>9}")
    m = p.load_model
    if m:
        turn = f"stops rising at {m['turn_force_n']:.3g} N" if m["turn_force_n"] is not None else \
            f"still rising at the curve's end, {m['max_force_n']:.3g} N"
        lines += [f"  cap mechanics: df/dF = {m['sensitivity_hz_per_n_at_0']:.1f} Hz/N at 0 N; f {turn}; "
                  f"f shift by {m['route']}; {m['nodes']} nodes, {m['seconds']:.1f} s"]
        for key in ("eq5", "eq5_paper_convention"):
            if m[key]:
                e = m[key]
                lines.append(f"  Eq. 5 fit to it ({e['area_convention']}): V0 = {e['v0_mm3']:.4g} mm^3, "
                             f"a = {e['a']:.4g} mm^3/N^2, b = {e['b']:.4g} mm^3/N")
        lines += [f"  {m[k]}" for k in ("fit_note", "fem_note") if m[k]]
    return lines


def _check_fem_level(args) -> None:
    if args.fem_level is not None and args.model != "fem":
        raise ValueError(f"--fem-level {args.fem_level} applies only with --model fem (it sets the FEM's mesh)")
    if args.fem_level is not None and not 1 <= args.fem_level <= 64:
        raise ValueError(f"--fem-level {args.fem_level} invalid, must be 1-64 elements across the neck radius")


def cmd_predict(args) -> int:
    from matcad.prediction import predict

    _check_fem_level(args)
    if args.force_deprecated:
        print("matcad: note: predict --force is deprecated (it clashed with build --force); use --load",
              file=sys.stderr)
    spec = _load_spec(args.spec, args)
    from matcad.spec import is_array

    if is_array(spec):
        return _predict_array(spec, args)
    result = predict(spec, forces_n=args.load or args.force_deprecated or (), model=args.model,
                     fem_level=args.fem_level)
    if args.json:
        _print_json(result.to_dict())
    else:
        print(_format_prediction(spec, result))
    return EXIT_OK


def _predict_array(spec, args) -> int:
    """`predict` of an array spec: each taxel's f0, unloaded and loaded band (matcad.prediction.bands), and the
    band conflicts; --json adds each taxel's whole prediction."""
    from matcad.prediction import predict
    from matcad.prediction.bands import summary, taxel_band
    from matcad.spec import taxel_spec, taxels

    bands, predictions = [], {}
    for t in taxels(spec):
        one = taxel_spec(spec, t)
        p = predict(one, forces_n=args.load or args.force_deprecated or (), model=args.model, fem_level=args.fem_level)
        bands.append(taxel_band(one, t.name, t.x, t.y, prediction=p))
        predictions[t.name] = p
    data = summary(spec, bands)
    if args.json:
        _print_json({"name": spec.name, **data, "predictions": {k: p.to_dict() for k, p in predictions.items()}})
        return EXIT_OK
    lines = [f"{spec.name}: {len(bands)} taxels; loaded band = predicted band + rise to {data['max_force_n']:g} N; "
             f"guard {data['guard_hz']:.0f} Hz",
             f"  {'taxel':<8} {'x, y [mm]':>14} {'f0 [Hz]':>8}  {'model':<18} {'unloaded [Hz]':>13} "
             f"{'loaded [Hz]':>13} {'rise':>7}"]
    for b in bands:
        lines.append(f"  {b.name:<8} {f'{b.x_mm:g}, {b.y_mm:g}':>14} {b.f0_hz:8.0f}  {b.model:<18} "
                     f"{f'{b.unloaded_hz[0]:.0f}-{b.unloaded_hz[1]:.0f}':>13} "
                     f"{f'{b.loaded_hz[0]:.0f}-{b.loaded_hz[1]:.0f}':>13} {100 * (b.rise - 1):+6.1f}%")
    lines += [f"  rise from {source}" for source in dict.fromkeys(b.rise_source for b in bands)]
    lines += [f"  conflict: {c['message']}" for c in data["conflicts"]] or ["  bands disjoint (guard and 2f/3f rule)"]
    for name, p in predictions.items():
        lines += [f"  {name} warning: {w}" for w in p.warnings]
        if p.load_curve:
            lines += [f"  {name}:"] + _format_load_curve(p)
    print("\n".join(lines))
    return EXIT_OK


def _format_findings(findings) -> str:
    if not findings:
        return "  no findings"
    return "\n".join(f"  {f.level:<7} {f.id:<24} {f.message}" + (f"\n  {'':<7} {'':<24} fix: {f.fix}" if f.fix
                                                                  and f.level != "info" else "")
                     for f in findings)


def cmd_check(args) -> int:
    from matcad.rules import check, errors

    findings = check(_load_spec(args.spec, args))
    if args.json:
        _print_json({"findings": [f.to_dict() for f in findings],
                     "verdict": "fail" if errors(findings) else "pass"})
    else:
        print(_format_findings(findings))
    return EXIT_RULES if errors(findings) else EXIT_OK


def cmd_build(args) -> int:
    from matcad.build import DesignRuleFailure, build

    spec = _load_spec(args.spec, args)
    try:
        result = build(spec, out_dir=args.out, force=args.force)
    except DesignRuleFailure as exc:
        if args.json:
            _print_json({"verdict": "fail", "written": [], "findings": [f.to_dict() for f in exc.findings]})
        else:
            print(_format_findings([f for f in exc.findings if f.level == "error"]))
            print("matcad: design-rule errors: nothing written (fix the spec or use --force)", file=sys.stderr)
        return EXIT_RULES
    board = result.report["bands"]["taxels"] if "taxels" in result.report else None
    p = result.prediction
    if args.json:  # a board has no single f0: its taxels' bands instead
        _print_json({"verdict": result.report["verdict"], "out_dir": str(result.out_dir),
                     "written": list(result.files), "f0_hz": None if board else p.f0_hz,
                     "band_hz": None if board else list(p.band_hz)} | ({"taxels": board} if board else {})
                    | {"findings": [f.to_dict() for f in result.findings]})
    else:
        print(f"{spec.name}: {len(result.files)} files in {result.out_dir}/")
        for name in result.files:
            print(f"  {name}")
        for t in board or ():
            print(f"{t['name']} at ({t['x_mm']:g}, {t['y_mm']:g}) mm: f0 = {t['f0_hz']:.0f} Hz ({t['model']}), band "
                  f"{t['unloaded_hz'][0]:.0f}-{t['unloaded_hz'][1]:.0f} Hz, loaded to {t['max_force_n']:g} N "
                  f"{t['loaded_hz'][0]:.0f}-{t['loaded_hz'][1]:.0f} Hz")
        print((f"{len(board)} taxels" if board else f"f0 = {p.f0_hz:.0f} Hz ({p.model}), band "
               f"{p.band_hz[0]:.0f}-{p.band_hz[1]:.0f} Hz") + f"; verdict {result.report['verdict']}")
        print(_format_findings([f for f in result.findings if f.level != "info"]))
    return EXIT_OK


def cmd_coupon(args) -> int:
    from matcad.build import build_coupon

    target, table = build_coupon(_load_spec(args.spec, args), out_dir=args.out)
    if args.json:
        _print_json({"out_dir": str(target), **table})
    else:
        print(f"coupons in {target}/: coupon_<sheet>.dxf/.svg, one per sheet with its kerf (engraved sizes), "
              "coupon_printed.stl/.step (needle bores at theta and dowel holes, ascending left to right), "
              "needle_mount_y*.stl (y sweep, notches on +x) and needle_mount_theta*.stl (theta sweep, notches on "
              "-x); report.json lists which is which")
    return EXIT_OK


def _band(args):
    if args.band:
        lo, hi = args.band
        if not (0 <= lo < hi):
            raise ValueError(f"--band {lo:g} {hi:g} invalid, must be 0 <= LO < HI (Hz)")
        return lo, hi
    if args.spec:
        from matcad.listening import PREDICTED_MARGIN, listening_band
        from matcad.prediction import predict

        return listening_band(predict(_load_spec(args.spec, args)).band_hz, PREDICTED_MARGIN)
    raise ValueError("analyze needs --spec SPEC (its predicted band) or --band LO HI (Hz)")


def _recording_blocks(args):
    """(sample blocks, rate Hz, name) of the recording argument: a WAV file read in blocks, or '-' for standard
    input (WAV, or raw PCM with --format/--rate)."""
    from matcad.loop import wav

    if str(args.recording) == "-":
        stream = sys.stdin.buffer
        info = wav.stream_info(stream, getattr(args, "rate", None), getattr(args, "format", None),
                               getattr(args, "channels", 1))
        return wav.iter_stream(stream, info), info.sample_rate_hz, "standard input"
    if getattr(args, "format", None):
        raise ValueError("--format/--rate describe raw PCM on standard input: give the recording as '-'")
    info = wav.read_info(args.recording)
    return wav.iter_blocks(args.recording, info), info.sample_rate_hz, str(args.recording)


def _loop_output(args, kind: str, source: str) -> Path:
    from matcad.loop.outputs import output_folder

    return output_folder(args.out, kind, source)


def cmd_analyze(args) -> int:
    from matcad.loop import outputs
    from matcad.loop.analyze import analyze_stream
    from matcad.loop.plots import plot
    from matcad.output import staged_output

    board = _board_bands(args)
    if board is not None:
        return _analyze_board(args, board)
    band = _band(args)
    blocks, fs, name = _recording_blocks(args)
    result = analyze_stream(blocks, fs, [band])[0]
    target = _loop_output(args, "analyze", name)
    with staged_output(target) as tmp:
        outputs.write_track_csv(result, tmp / "track.csv")
        outputs.write_segments_csv(result, tmp / "segments.csv")
        plot(result, tmp / "spectrogram.png")
        outputs.write_json(tmp / "report.json", {"recording": name, **result.to_dict()})
    if args.json:
        _print_json({**result.to_dict(), "out_dir": str(target)})
    else:
        print(result.to_text(name))
        print(f"  track.csv, segments.csv, spectrogram.png, report.json in {target}/")
    return EXIT_OK


def _board_spec(args):
    """The spec of ``--spec`` when it names an array (and no --band is given), else None."""
    if not getattr(args, "spec", None) or getattr(args, "band", None):
        return None
    from matcad.spec import is_array

    spec = _load_spec(args.spec, args)
    return spec if is_array(spec) else None


def _board_bands(args):
    """(name, listening band Hz) per taxel when ``--spec`` names an array (and no --band is given), else None."""
    spec = _board_spec(args)
    if spec is None:
        return None
    from matcad.prediction.bands import listening_bands

    return listening_bands(spec)


def _analyze_board(args, named_bands) -> int:
    from matcad.loop import board, outputs
    from matcad.loop.plots import plot_board
    from matcad.output import staged_output

    blocks, fs, name = _recording_blocks(args)
    tracks = board.analyze_board(blocks, fs, named_bands)
    target = _loop_output(args, "analyze", name)
    report = {"recording": name, "taxels": board.taxels_dict(tracks)}
    with staged_output(target) as tmp:
        outputs.write_board_track_csv(tracks, tmp / "track.csv")
        outputs.write_board_segments_csv(tracks, tmp / "segments.csv")
        plot_board(tracks, tmp / "spectrogram.png")
        outputs.write_json(tmp / "report.json", report)
    if args.json:
        _print_json({**report, "out_dir": str(target)})
    else:
        print(board.board_text(name, tracks))
        print(f"  track.csv, segments.csv, spectrogram.png, report.json in {target}/")
    return EXIT_OK


def cmd_calibrate(args) -> int:
    from matcad.loop import outputs
    from matcad.loop.calibrate import fit_from_spec, plot, read_csv
    from matcad.output import staged_output
    from matcad.spec import frequency_notes

    spec = _one_taxel(_load_spec(args.spec, args), args.taxel)
    if args.temperature_c is not None and not -60.0 <= args.temperature_c <= 100.0:
        raise ValueError(f"--temperature-c {args.temperature_c:g} invalid, must be -60 to 100 degC")
    if args.cycle_std_n is not None and not 0.0 <= args.cycle_std_n <= 100.0:
        raise ValueError(f"--cycle-std-n {args.cycle_std_n:g} invalid, must be 0-100 N")
    forces, freqs, cycles = read_csv(args.data)
    for note in frequency_notes(freqs, f"{args.data} frequency_hz"):
        print(f"matcad: note: {note}", file=sys.stderr)
    cal = fit_from_spec(forces, freqs, spec, k_free=args.k_free, cycles=cycles, temperature_c=args.temperature_c,
                        cycle_std_n=args.cycle_std_n)
    target = _loop_output(args, "calibrate", str(args.data))
    with staged_output(target) as tmp:
        outputs.write_calibration_toml(cal.law, tmp / "calibration.toml")
        if args.taxel is not None:  # the same table to paste under that [[taxel]] entry of the board spec
            outputs.write_calibration_toml(cal.law, tmp / "taxel_calibration.toml", args.taxel, args.spec)
        plot(cal, tmp / "residuals.png")
        outputs.write_json(tmp / "report.json", {"data": str(args.data), "spec": spec.name, **cal.to_dict()})
    if args.json:
        _print_json({**cal.to_dict(), "out_dir": str(target)})
    else:
        print(cal.to_text())
        extra = f"taxel_calibration.toml ([taxel.calibration] of {args.taxel}), " if args.taxel is not None else ""
        print(f"  calibration.toml, {extra}residuals.png in {target}/")
    return EXIT_OK


def _one_taxel(spec, name):
    """The single-taxel spec of taxel ``name`` of an array (a calibration is one taxel's); a one-taxel spec as is."""
    from matcad.spec import taxel_spec, taxels

    board = taxels(spec)
    names = ", ".join(t.name for t in board)
    if name is None:
        if len(board) > 1:
            raise ValueError(f"{spec.name} has {len(board)} taxels: calibrate one at a time with --taxel NAME, NAME "
                             f"one of {names}")
        return spec
    match = [t for t in board if t.name == name]
    if not match:
        raise ValueError(f"--taxel {name!r} invalid, must be one of {names}")
    return taxel_spec(spec, match[0])


def cmd_sense(args) -> int:
    from functools import partial

    from matcad.loop import live, outputs
    from matcad.loop.analyze import analyze_stream
    from matcad.loop.plots import plot
    from matcad.loop.sense import listening_band_hz, require_in_range, sense, sensing_law
    from matcad.output import staged_output
    from matcad.spec import load_calibration

    board_spec = _board_spec(args)
    if board_spec is not None:
        return _sense_board(args, board_spec)
    if not args.calibration:
        raise ValueError("--calibration FILE is required (calibration.toml from `matcad calibrate`, or a spec with "
                         "a [calibration] table); an array --spec may carry [taxel.calibration] tables instead")
    if len(args.calibration) != 1:
        raise ValueError(f"--calibration given {len(args.calibration)} times: several calibrations need --spec "
                         "naming an array, one NAME=FILE per taxel")
    cal = sensing_law(load_calibration(args.calibration[0]))
    cal.temperature_factor(args.temperature_c)  # bad temperature: exit 2 before reading anything
    band = listening_band_hz(cal)
    blocks, fs, name = _recording_blocks(args)
    on_frame = live.taxel_printer(cal, args.temperature_c, partial(print, flush=True)) if args.live else None
    result = analyze_stream(blocks, fs, [band], on_frame)[0]
    reading = sense(result, cal, args.temperature_c)
    target = _loop_output(args, "sense", name) if not (args.live and args.out is None) else None
    if target is not None:
        with staged_output(target) as tmp:
            outputs.write_segments_csv(result, tmp / "segments.csv", reading.segments_n)
            outputs.write_forces_csv(result, reading, tmp / "forces.csv")
            plot(result, tmp / "force.png", (reading.frames_n, *reading.frames_interval_n.T))
            outputs.write_json(tmp / "report.json", {"recording": name, "calibration": str(args.calibration[0]),
                                                     **reading.report_dict(result)})
    if args.json:
        _print_json({**reading.detail_dict(result), "out_dir": None if target is None else str(target)})
    else:
        print(reading.to_text(name, result))
        if target is not None:
            print(f"  forces.csv, segments.csv, force.png, report.json in {target}/")
    require_in_range(reading)
    return EXIT_OK


def _sense_board(args, spec) -> int:
    from functools import partial

    from matcad.prediction.bands import listening_bands
    from matcad.loop import board, live, outputs
    from matcad.loop.plots import plot_board
    from matcad.loop.sense import sensing_law
    from matcad.output import staged_output

    named_bands = listening_bands(spec)
    names = [n for n, _ in named_bands]
    given = board.board_calibrations(spec, args.calibration)
    cals = {n: sensing_law(cal) for n, (_, cal) in given.items()}
    for cal in cals.values():
        cal.temperature_factor(args.temperature_c)  # bad temperature: exit 2 before reading anything
    blocks, fs, name = _recording_blocks(args)
    on_frame = live.board_printer(names, cals, args.temperature_c, partial(print, flush=True)) if args.live else None
    try:
        tracks = board.analyze_board(blocks, fs, named_bands, on_frame)
    finally:
        if on_frame is not None:
            on_frame.flush()
    readings = board.sense_board(tracks, cals, args.temperature_c)
    report = {"recording": name, "calibrations": {n: source for n, (source, _) in given.items()},
              "taxels": board.taxels_dict(tracks, readings)}
    target = _loop_output(args, "sense", name) if not (args.live and args.out is None) else None
    if target is not None:
        with staged_output(target) as tmp:
            outputs.write_board_segments_csv(tracks, tmp / "segments.csv", readings)
            outputs.write_board_forces_csv(tracks, readings, tmp / "forces.csv")
            plot_board(tracks, tmp / "force.png", readings)
            outputs.write_json(tmp / "report.json", report)
    if args.json:
        _print_json({**report, "out_dir": None if target is None else str(target)})
    else:
        print(board.board_text(name, tracks, readings))
        if target is not None:
            print(f"  forces.csv, segments.csv, force.png, report.json in {target}/")
    return EXIT_OK


def cmd_sweep(args) -> int:
    from matcad.spec import apply_sets, read_spec_data
    from matcad.sweep import Executor, parse_axes, sweep
    from matcad.sweep.outputs import write

    if not 1 <= args.workers <= 256:
        raise ValueError(f"--workers {args.workers} invalid, must be 1-256 local processes")
    _check_fem_level(args)
    axes = parse_axes(args.vary)
    data = apply_sets(read_spec_data(args.spec), args.set)
    _load_spec(args.spec, args)  # validates the base spec (exit 2 naming the field) and prints its notes
    result = sweep(data, axes, model=args.model, executor=Executor(args.workers, args.scheduler),
                   rules=not args.no_rules, cad=args.cad, fem_level=args.fem_level)
    target, files = write(result, args.out or Path("out") / f"{result.name}-sweep")
    counts = {s: sum(r["status"] == s for r in result.rows) for s in ("ok", "invalid", "failed")}
    counts["rule_errors"] = sum(bool(r.get("rule_errors")) for r in result.rows)
    if args.json:
        _print_json({"out_dir": str(target), "written": files, "model": result.model, "variants": len(result.rows),
                     **counts, "seconds": round(result.seconds, 3)})
    else:
        print(f"{result.name}: {len(result.rows)} variants ({counts['ok']} ok, {counts['invalid']} invalid, "
              f"{counts['failed']} failed; {counts['rule_errors']} with design-rule errors) by {result.model} on "
              f"{result.executor} in {result.seconds:.1f} s")
        print(f"  {', '.join(files)} in {target}/")
    return EXIT_OK


def cmd_design(args) -> int:
    """Inverse design: one taxel onto --target-hz, or --taxels N disjoint bands in --band LO HI."""
    import dataclasses

    from matcad.design import RulesFailed
    from matcad.design.spec_toml import write_design

    spec = _load_spec(args.spec, args)
    if (args.target_hz is None) == (args.taxels is None):
        raise ValueError("design needs either --target-hz F (one taxel) or --taxels N --band LO HI (an array)")
    try:
        if args.target_hz is not None:
            from matcad.design.solve import parse_vary, solve

            if args.band:
                raise ValueError("--band goes with --taxels, not with --target-hz")
            if not args.vary:
                raise ValueError("--target-hz needs --vary FIELD [FIELD ...] (the fields the solver may change)")
            result = solve(spec, args.target_hz, parse_vary(spec, args.vary))
            result = dataclasses.replace(result, spec=dataclasses.replace(
                result.spec, name=args.name or f"{spec.name}-{args.target_hz:.0f}hz"))
        else:
            from matcad.design.allocate import allocate
            from matcad.design.solve import CONTINUOUS, parse_vary

            if not args.band:
                raise ValueError("--taxels needs --band LO HI (Hz)")
            result = allocate(spec, args.taxels, *args.band, parse_vary(spec, args.vary or ["neck.diameter"],
                                                                       CONTINUOUS), args.name)
    except RulesFailed as exc:
        if args.json:
            _print_json({"verdict": "fail", "error": str(exc), "findings": [f.to_dict() for f in exc.findings]})
        else:
            print(_format_findings([f for f in exc.findings if f.level == "error"]))
        print(f"matcad: {exc}; nothing written", file=sys.stderr)
        return EXIT_RULES
    target = args.out or Path("out") / f"{result.spec.name}-design"
    report = {"source": str(args.spec), **result.to_dict()}
    write_design(target, result.spec, report, f"written by `matcad design` from {args.spec}")
    if args.json:
        _print_json({**report, "out_dir": str(target), "spec_file": str(target / f"{result.spec.name}.toml")})
    else:
        print(_format_design(result))
        print(f"  {result.spec.name}.toml and design.json in {target}/")
    return EXIT_OK


def _format_design(result) -> str:
    if hasattr(result, "target_hz"):
        fields = ", ".join(f"{k} {a:g} -> {b:.4g} mm" for k, (a, b) in result.fields.items())
        lines = [f"{result.spec.name}: f0 = {result.f0_hz:.1f} Hz by predict ({result.model}) for target "
                 f"{result.target_hz:g} Hz, error {100 * result.error:+.3f} %; {fields}; {result.seconds:.2f} s, "
                 f"{result.evaluations} model evaluations"]
        return "\n".join(lines + [f"  note: {n}" for n in result.notes])
    lines = [f"{result.spec.name}: {len(result.bands)} taxels in {result.band_hz[0]:g}-{result.band_hz[1]:g} Hz, "
             f"guard {result.guard_hz:.0f} Hz, {result.seconds:.1f} s"]
    for b, s in zip(result.bands, result.solutions):
        fields = ", ".join(f"{k} {v[1]:.4g} mm" for k, v in s.fields.items())
        lines.append(f"  {b.name} at ({b.x_mm:g}, {b.y_mm:g}) mm: f0 {b.f0_hz:.0f} Hz, unloaded "
                     f"{b.unloaded_hz[0]:.0f}-{b.unloaded_hz[1]:.0f} Hz, loaded {b.loaded_hz[0]:.0f}-"
                     f"{b.loaded_hz[1]:.0f} Hz; {fields}")
    return "\n".join(lines)


def cmd_schema(args) -> int:
    from matcad.spec import schema

    rows = schema()
    if args.json:
        _print_json(rows)
        return EXIT_OK
    for row in rows:
        default = "(required)" if row["required"] else f"default {row['default']!r}"
        unit = f" [{row['unit']}]" if row["unit"] else ""
        print(f"{row['key']}{unit}  {default}\n    {row['doc']}\n    allowed: {row['allowed']}")
    return EXIT_OK


def cmd_init(args) -> int:
    from matcad.init import new_spec

    try:
        path = new_spec(args.name, args.template, args.out)
    except FileExistsError as exc:
        raise ValueError(f"{exc.filename}: exists; refusing to overwrite it (choose another NAME or --out)") from None
    if args.json:
        _print_json({"spec": str(path), "template": args.template})
    else:
        print(f"{path}: a copy of the {args.template} template named {args.name!r}; edit it, then "
              f"`matcad predict {path}` and `matcad build {path}`")
    return EXIT_OK


def cmd_completion(args) -> int:
    from matcad.completion import script

    print(script(_parser(), args.shell), end="")
    return EXIT_OK


def cmd_serve(args) -> int:
    from matcad.serve import DEFAULT_PORT, HOST, make_server

    port = DEFAULT_PORT if args.port is None else args.port
    if not 0 <= port <= 65535:
        raise ValueError(f"--port {port} invalid, must be 0-65535 (0 picks a free port)")
    server = make_server(port)
    print(f"matcad design page on http://{HOST}:{server.server_address[1]}/ (local only; Ctrl-C stops it)",
          flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return EXIT_OK


def _out_path(text: str) -> Path:
    """``--out``: made absolute at once, so that `--out .` stays meaningful after the folder is replaced."""
    return Path(os.path.abspath(text))


def _force_n(text: str) -> float:
    """A ``--force`` value: finite, within the calibration's force bounds (N)."""
    from matcad.loop.calibrate import FORCE_LIMIT_N

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not abs(value) <= FORCE_LIMIT_N:
        from matcad.errors import shorten

        raise argparse.ArgumentTypeError(f"{shorten(text)} invalid, must be a finite force with |F| <= "
                                         f"{FORCE_LIMIT_N:g} N")
    return value


def _parser() -> argparse.ArgumentParser:
    import matcad
    from matcad.acoustics.registry import model_choices

    parser = argparse.ArgumentParser(prog="matcad", description=matcad.__doc__,
                                     epilog="exit codes: " + "; ".join(f"{k} {v}" for k, v in EXIT_CODES.items()))
    parser.add_argument("--version", action="version", version=f"matcad {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    def command(name, func, help_text, out_default=None):
        cmd = sub.add_parser(name, help=help_text)
        cmd.set_defaults(func=func)
        cmd.add_argument("--json", action="store_true", help="print JSON instead of text")
        if out_default:
            cmd.add_argument("--out", type=_out_path, help=f"output folder (default {out_default})")
        return cmd

    def spec_arg(cmd, flag=None, **kw):
        """The spec argument (positional, or ``flag``) and --set overrides, for every spec-taking command."""
        cmd.add_argument(flag or "spec", help="spec TOML file, or a build's report.json (its resolved spec)", **kw)
        cmd.add_argument("--set", action="append", metavar="KEY=VALUE",
                         help="override one spec field, value as TOML (e.g. --set neck.diameter=2.0); repeatable")

    p = command("predict", cmd_predict, "predict the taxel's resonance frequency from a spec")
    spec_arg(p)
    p.add_argument("--load", type=_force_n, nargs="+", metavar="F",
                   help="normal loads in N: f(F) from the cap mechanics ([mechanics]; FElupe) and, with a "
                        "[calibration], from paper Eq. 5 as well")
    p.add_argument("--force", dest="force_deprecated", type=_force_n, nargs="+", metavar="F",
                   help="deprecated spelling of --load")
    p.add_argument("--model", choices=model_choices(),
                   help="use this model's f0 instead of the automatic choice ('fem' adds the FEM)")
    p.add_argument("--fem-level", type=int, help="FEM mesh refinement: elements across the neck radius (default 8)")

    spec_arg(command("check", cmd_check, "run the design rules without building (exit 1 on errors)"))

    b = command("build", cmd_build, "write the fabrication kit and report to out/<name>/", "out/<name>")
    spec_arg(b)
    b.add_argument("--force", action="store_true", help="build despite design-rule errors")

    spec_arg(command("coupon", cmd_coupon, "test coupons sweeping neck, dowel and needle-bore sizes",
                     "out/<name>-coupon"))

    a = command("analyze", cmd_analyze, "the taxel's frequency in a recording (spectrogram ridge)",
                "out/analyze-<recording>-<hash>")
    a.add_argument("recording", help="WAV file (mono/stereo; 8-32-bit integer or float; any sample rate), or "
                                     "'-' for standard input")
    group = a.add_mutually_exclusive_group()
    group.add_argument("--spec", help="spec TOML: analyse its predicted band (-10 %% / +25 %% for load); an array "
                                      "spec: every taxel at once, each in its loaded band, per-taxel columns")
    group.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"), help="analysis band in Hz")
    a.add_argument("--set", action="append", metavar="KEY=VALUE", help="override one field of --spec (TOML value)")

    c = command("calibrate", cmd_calibrate, "fit paper Eq. 5 to force/frequency pairs, with uncertainty",
                "out/calibrate-<data>-<hash>")
    c.add_argument("data", help="CSV with force_n and frequency_hz columns (and optionally cycle: several load "
                                "cycles give the between-cycle variance)")
    spec_arg(c, "--spec", required=True)
    c.add_argument("--k-free", action="store_true", help="fix V0 to the as-built cavity and fit K instead")
    c.add_argument("--taxel", metavar="NAME", help="with an array spec: the taxel DATA was measured on (its own "
                                                   "geometry sets K or V0); give the result to sense as NAME=FILE")
    c.add_argument("--temperature-c", type=float, help="air temperature during calibration (degC; default the "
                                                       "spec's [air] temperature_c), recorded for `sense`")
    c.add_argument("--cycle-std-n", type=float, help="between-cycle (hysteresis) sd in N assumed when DATA holds "
                                                     "one load cycle (default 0.7, from the paper's ~1 N)")

    n = command("sense", cmd_sense, "force from a recording through a calibration, with 95 %% intervals",
                "out/sense-<recording>-<hash>")
    n.add_argument("recording", help="WAV file, or '-' for standard input (WAV, or raw PCM with --format --rate)")
    n.add_argument("--calibration", action="append", metavar="[NAME=]FILE",
                   help="calibration.toml from `matcad calibrate`, or a spec; with --spec naming an array, one "
                        "NAME=FILE per taxel (repeat the option; it overrides that taxel's [taxel.calibration] in "
                        "the spec; a taxel with neither gets frequencies only)")
    n.add_argument("--spec", help="spec TOML of an array: every taxel tracked in its own (loaded) band")
    n.add_argument("--set", action="append", metavar="KEY=VALUE", help="override one field of --spec (TOML value)")
    n.add_argument("--temperature-c", type=float, help="air temperature now (degC): frequencies are scaled by "
                                                       "sqrt(T_cal/T) to the calibration's temperature")
    n.add_argument("--live", action="store_true", help="print each frame's force as it is decided (~1 s lag, up "
                                                       "to ~2 s while a new line is held: a voice, a reverberant "
                                                       "room); no output folder unless --out")
    for cmd in (a, n):
        cmd.add_argument("--format", choices=("s16le", "s24le", "s32le", "u8", "f32le", "f64le"),
                         help="raw PCM sample format on standard input (default: a WAV header is expected)")
        cmd.add_argument("--rate", type=float, help="raw PCM sample rate (Hz)")
        cmd.add_argument("--channels", type=int, default=1, help="raw PCM channels (default 1), averaged")

    w = command("sweep", cmd_sweep, "f0, band, sensitivity and rule verdicts over a grid of designs (table + maps)",
                "out/<name>-sweep")
    spec_arg(w)
    w.add_argument("--vary", action="append", required=True, metavar="FIELD=LO:HI:N",
                   help="vary a numeric spec field over N evenly spaced values (or FIELD=a,b,c); repeat for a "
                        "full grid (e.g. --vary cavity.length=3:6:7 --vary neck.diameter=1.5,2.1)")
    w.add_argument("--model", choices=model_choices(),
                   help="model for every variant (default the spec's own choice; 'fem' adds the FEM)")
    w.add_argument("--fem-level", type=int, help="FEM mesh refinement with --model fem (default 8)")
    w.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="local processes for the per-variant work (default one per CPU; 1 = in this process)")
    w.add_argument("--scheduler", metavar="ADDRESS", help="run the per-variant work on this Dask scheduler "
                                                          "(tcp://host:8786; needs matcad[cluster])")
    w.add_argument("--no-rules", action="store_true", help="skip the design rules (fast-model sweeps then "
                                                           "need no per-variant work)")
    w.add_argument("--cad", action="store_true", help="also build each variant's end cap (build123d) and read "
                                                      "its STL volume back")

    d = command("design", cmd_design, "solve a taxel for a target f0, or N taxels for disjoint bands; writes a spec",
                "out/<name>-design")
    spec_arg(d)
    d.add_argument("--target-hz", type=float, metavar="F", help="target unloaded f0 (Hz) of one taxel")
    d.add_argument("--vary", nargs="+", metavar="FIELD[=LO:HI]",
                   help="fields the solver may change: neck.diameter, cavity.diameter, cavity.length (optional range "
                        "in mm) and neck.length (a stock sheet); with --taxels default neck.diameter")
    d.add_argument("--taxels", type=int, metavar="N", help="design an array of N taxels with disjoint bands")
    d.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"), help="with --taxels: the band (Hz) they share")
    d.add_argument("--name", help="name of the written spec (default <name>-<F>hz or <name>-<N>taxels)")

    command("schema", cmd_schema, "print every spec field with unit, default and allowed range")

    i = command("init", cmd_init, "start a new spec from a shipped template (never overwrites)")
    i.add_argument("name", help="design name (also the file name NAME.toml and the build folder out/NAME)")
    i.add_argument("--from", dest="template", default="mat-paper",
                   help="template: mat-paper (default), mat-laser-only, mat-sla-array, mat-array-4")
    i.add_argument("--out", type=Path, help="spec file to write (default NAME.toml)")

    sh = sub.add_parser("completion", help="print a shell completion script (bash; zsh via bashcompinit)")
    sh.set_defaults(func=cmd_completion)
    sh.add_argument("shell", choices=("bash", "zsh"))

    sv = sub.add_parser("serve", help="a local design page: the spec as a form, live prediction, build to a zip")
    sv.set_defaults(func=cmd_serve)
    sv.add_argument("--port", type=int, help="port on 127.0.0.1 (default 8765; 0 picks a free one)")
    return parser


_SIGNALLED: list[int] = []
"""The signal that interrupted this run, if any (set by :func:`_on_signal`)."""


def _on_signal(signum, frame) -> None:
    """SIGINT and SIGTERM: remember which, ignore any further one while cleaning up, unwind as an interrupt."""
    _SIGNALLED.append(signum)
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)
    raise KeyboardInterrupt


def _install_signal_handlers() -> dict:
    """Route SIGINT and SIGTERM to :func:`_on_signal`; returns the handlers they replace."""
    _SIGNALLED.clear()  # a new run in the same interpreter (tests call main() repeatedly)
    previous = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            previous[sig] = signal.signal(sig, _on_signal)
        except ValueError:  # not the main thread: leave Python's default handling
            pass
    return previous


def _private_caches() -> None:
    """Libraries' caches (ezdxf's font cache, matplotlib's config and font list) default to folders under
    $HOME; unless the user chose them, point them at a private folder in the temporary directory."""
    import tempfile

    if all(os.environ.get(v) for v in ("XDG_CACHE_HOME", "MPLCONFIGDIR")):
        return
    folder = Path(tempfile.gettempdir()) / f"matcad-cache-{os.getuid() if hasattr(os, 'getuid') else 0}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        st = folder.lstat()
        if folder.is_symlink() or (hasattr(os, "getuid") and st.st_uid != os.getuid()):
            folder = Path(tempfile.mkdtemp(prefix="matcad-cache-"))
    except OSError:
        folder = Path(tempfile.mkdtemp(prefix="matcad-cache-"))
    os.environ.setdefault("XDG_CACHE_HOME", str(folder))
    os.environ.setdefault("MPLCONFIGDIR", str(folder / "matplotlib"))


def _deliberate(exc: ValueError) -> bool:
    """A ValueError is a refusal of input when matcad's own code raised it (``raise ValueError(...)`` in a
    matcad module, or InputError/SpecError); one raised inside a library or by a math function is a bug."""
    from matcad.errors import InputError

    if isinstance(exc, InputError):
        return True
    if str(exc) in ("math domain error", "math range error"):
        return False
    tb = exc.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    package = str(Path(__file__).resolve().parent)
    return tb is not None and str(Path(tb.tb_frame.f_code.co_filename).resolve()).startswith(package)


def _internal_error(exc: BaseException) -> int:
    """Log the traceback to a fresh file in the temporary folder and print one line pointing at it."""
    import tempfile
    import time
    import traceback

    text = "".join(traceback.format_exception(exc))
    try:
        fd, log = tempfile.mkstemp(prefix=f"matcad-internal-error-{time.strftime('%Y%m%dT%H%M%S')}-",
                                   suffix=".log")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(f"matcad {__version__}\nargv: {sys.argv!r}\n\n{text}")
    except OSError:
        log = "(no log: the temporary folder is not writable)"
    print(f"matcad: internal error, please report it with the log {log} ({exc.__class__.__name__})",
          file=sys.stderr)
    return EXIT_INTERNAL


def _interrupted() -> int:
    terminated = bool(_SIGNALLED) and _SIGNALLED[0] == signal.SIGTERM
    print(f"matcad: {'terminated' if terminated else 'interrupted'}; no output folder is left half-written",
          file=sys.stderr)
    return EXIT_TERMINATED if terminated else EXIT_INTERRUPT


def _quiet_stdout() -> None:
    """After a broken pipe: send further output (and the interpreter's final flush) to /dev/null."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


def main(argv: list[str] | None = None) -> int:
    """Run one command; every outcome maps to one row of :data:`EXIT_CODES`."""
    previous = _install_signal_handlers()
    try:
        _private_caches()
        args = _parser().parse_args(argv)
        return _dispatch(args)
    except KeyboardInterrupt:
        return _interrupted()
    except BaseException as exc:  # noqa: BLE001 - the last line of the exit-code table
        if isinstance(exc, SystemExit):  # argparse: usage error (2), --help/--version (0)
            raise
        if _SIGNALLED:  # an interrupt inside a C extension's import surfaces as ImportError/SystemError
            return _interrupted()
        return _internal_error(exc)
    finally:
        if not _SIGNALLED:  # after a signal both stay ignored: the process is on its way out
            for sig, handler in previous.items():
                signal.signal(sig, handler)


def _dispatch(args) -> int:
    from matcad.errors import OutputError
    from matcad.errors import LoopError
    from matcad.spec import SpecError

    try:
        return args.func(args)
    except SpecError as exc:
        print(f"matcad: spec error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except OutputError as exc:
        print(f"matcad: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except LoopError as exc:
        print(f"matcad: {exc}", file=sys.stderr)
        return EXIT_RULES
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours (before OSError: a subclass)
        _quiet_stdout()
        return EXIT_OK
    except OSError as exc:  # unwritable output folder, full disk, unreadable input: the user's file system
        from matcad.errors import shorten

        where = f"{shorten(str(exc.filename))}: " if exc.filename else ""
        print(f"matcad: error: {where}{exc.strerror or exc} (check the path, its permissions and free space)",
              file=sys.stderr)
        return EXIT_INPUT
    except ValueError as exc:
        if not _deliberate(exc):
            raise
        print(f"matcad: error: {exc}", file=sys.stderr)
        return EXIT_INPUT


def quiet_exit() -> None:
    """Outside :func:`main` (starting up, finishing) there is nothing to clean up: a signal exits at once with
    its code and no traceback."""
    signal.signal(signal.SIGINT, lambda *_: os._exit(EXIT_INTERRUPT))
    signal.signal(signal.SIGTERM, lambda *_: os._exit(EXIT_TERMINATED))


def run() -> None:
    """Console entry point. After a command that loaded OpenCASCADE (or was interrupted, perhaps half-way through
    loading it), every output file is closed and moved into place or cleaned up, yet interpreter teardown would
    spend 0.3-0.7 s destroying kernel objects, and on a half-imported kernel abort ("Fatal Python error ...
    finalizing", exit -6): flush and leave at once."""
    quiet_exit()
    code = main()
    for sig in (signal.SIGINT, signal.SIGTERM):  # the answer is decided: a late signal must not become a traceback
        signal.signal(sig, signal.SIG_IGN)
    kernel = any(name.partition(".")[0] in ("OCP", "build123d") for name in sys.modules)
    if kernel or _SIGNALLED:  # also a kernel import cut short by a signal: its half-made objects abort teardown
        try:
            sys.stdout.flush()
        except BrokenPipeError:
            _quiet_stdout()
        sys.stderr.flush()
        os._exit(code)
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
    sys.exit(code)
