"""Command line. Thin: parse, call one function, print text or --json, map errors to exit codes.

Exit codes: 0 ok; 1 design-rule failure, or for analyze/calibrate/sense no trustworthy result (no tone, a
tone at the band edge, degenerate data, a force outside the calibrated range); 2 bad input.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from matcad import __version__

EXIT_OK, EXIT_RULES, EXIT_INPUT = 0, 1, 2


def _print_json(data) -> None:
    import json

    print(json.dumps(data, indent=2, allow_nan=False))


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
        lines += ["", f"  load curve, paper Eq. 5, calibration {p.calibration}:", f"  {'F [N]':>9} {'f [Hz]':>9}"]
        for pt in p.load_curve:
            value = f"{pt.f_hz:9.1f}" if pt.f_hz is not None else f"{'n/a':>9}  {pt.reason}"
            lines.append(f"  {pt.force_n:9.3f} {value}")
    if p.warnings:
        lines += ["", "  warnings:"] + [f"  - {w}" for w in p.warnings]
    return "\n".join(lines)


def cmd_predict(args) -> int:
    from matcad import spec as spec_mod
    from matcad.acoustics.predict import predict

    spec = spec_mod.load(args.spec)
    if args.fem_level is not None and not 1 <= args.fem_level <= 64:
        raise ValueError(f"--fem-level {args.fem_level} invalid, must be 1-64 elements across the neck radius")
    result = predict(spec, forces_n=args.force or (), model=args.model, fem_level=args.fem_level)
    if args.json:
        _print_json(result.to_dict())
    else:
        print(_format_prediction(spec, result))
    return EXIT_OK


def _format_findings(findings) -> str:
    if not findings:
        return "  no findings"
    return "\n".join(f"  {f.level:<7} {f.id:<24} {f.message}" + (f"\n  {'':<7} {'':<24} fix: {f.fix}" if f.fix
                                                                  and f.level != "info" else "")
                     for f in findings)


def cmd_check(args) -> int:
    from matcad import spec as spec_mod
    from matcad.rules import check, errors

    findings = check(spec_mod.load(args.spec))
    if args.json:
        _print_json({"findings": [f.to_dict() for f in findings],
                     "verdict": "fail" if errors(findings) else "pass"})
    else:
        print(_format_findings(findings))
    return EXIT_RULES if errors(findings) else EXIT_OK


def cmd_build(args) -> int:
    from matcad import spec as spec_mod
    from matcad.build import DesignRuleFailure, build

    spec = spec_mod.load(args.spec)
    try:
        result = build(spec, out_dir=args.out, force=args.force)
    except DesignRuleFailure as exc:
        if args.json:
            _print_json({"verdict": "fail", "written": [], "findings": [f.to_dict() for f in exc.findings]})
        else:
            print(_format_findings([f for f in exc.findings if f.level == "error"]))
            print("matcad: design-rule errors: nothing written (fix the spec or use --force)", file=sys.stderr)
        return EXIT_RULES
    if args.json:
        _print_json({"verdict": result.report["verdict"], "out_dir": str(result.out_dir),
                     "written": list(result.files), "f0_hz": result.prediction.f0_hz,
                     "band_hz": list(result.prediction.band_hz),
                     "findings": [f.to_dict() for f in result.findings]})
    else:
        p = result.prediction
        print(f"{spec.name}: {len(result.files)} files in {result.out_dir}/")
        for name in result.files:
            print(f"  {name}")
        print(f"f0 = {p.f0_hz:.0f} Hz ({p.model}), band {p.band_hz[0]:.0f}-{p.band_hz[1]:.0f} Hz; "
              f"verdict {result.report['verdict']}")
        print(_format_findings([f for f in result.findings if f.level != "info"]))
    return EXIT_OK


def cmd_coupon(args) -> int:
    from matcad import spec as spec_mod
    from matcad.build import build_coupon

    target, table = build_coupon(spec_mod.load(args.spec), out_dir=args.out)
    if args.json:
        _print_json({"out_dir": str(target), **table})
    else:
        print(f"coupons in {target}/: coupon_laser.dxf/.svg (neck and dowel sweeps, engraved sizes), "
              "coupon_printed.stl/.step (needle bores and dowel holes, ascending left to right)")
    return EXIT_OK


def _band(args):
    if args.band:
        lo, hi = args.band
        if not (0 <= lo < hi):
            raise ValueError(f"--band {lo:g} {hi:g} invalid, must be 0 <= LO < HI (Hz)")
        return lo, hi
    if args.spec:
        from matcad import spec as spec_mod
        from matcad.acoustics.predict import predict
        from matcad.loop.analyze import band_from_prediction

        return band_from_prediction(predict(spec_mod.load(args.spec)).band_hz)
    raise ValueError("analyze needs --spec SPEC (its predicted band) or --band LO HI (Hz)")


def cmd_analyze(args) -> int:
    from matcad.loop.analyze import analyze, plot, write_track_csv
    from matcad.loop.wav import read_mono
    from matcad.output import staged_output

    band = _band(args)
    x, fs = read_mono(args.recording)
    result = analyze(x, fs, band)
    target = args.out or Path("out") / f"analyze-{Path(args.recording).stem}"
    with staged_output(target) as tmp:
        write_track_csv(result, tmp / "track.csv")
        plot(result, tmp / "spectrogram.png")
        _write_json(tmp / "report.json", {"recording": str(args.recording), **result.to_dict()})
    if args.json:
        _print_json({**result.to_dict(), "out_dir": str(target)})
    else:
        print(f"{args.recording}: mean {result.mean_hz:.2f} Hz, median {result.median_hz:.2f} Hz, "
              f"sd {result.std_hz:.2f} Hz over {len(result.track_hz)} frames; SNR {result.snr_db:.1f} dB, "
              f"prominence {result.prominence_db:.1f} dB (band {result.band_hz[0]:.0f}-{result.band_hz[1]:.0f} Hz)")
        for w in result.warnings:
            print(f"  warning: {w}")
        print(f"  track.csv, spectrogram.png, report.json in {target}/")
    return EXIT_OK


def cmd_calibrate(args) -> int:
    from matcad import spec as spec_mod
    from matcad.loop.calibrate import fit_from_spec, plot, read_csv
    from matcad.output import staged_output

    spec = spec_mod.load(args.spec)
    forces, freqs = read_csv(args.data)
    cal = fit_from_spec(forces, freqs, spec, k_free=args.k_free)
    target = args.out or Path("out") / f"calibrate-{Path(args.data).stem}"
    with staged_output(target) as tmp:
        (tmp / "calibration.toml").write_text(cal.to_toml(), encoding="utf-8")
        plot(cal, tmp / "residuals.png")
        _write_json(tmp / "report.json", {"data": str(args.data), "spec": spec.name, **cal.to_dict()})
    if args.json:
        _print_json({**cal.to_dict(), "out_dir": str(target)})
    else:
        d = cal.to_dict()
        print(f"Eq. 5 fit to {d['points']} points, {d['force_range_n'][0]:g}-{d['force_range_n'][1]:g} N "
              f"({'K free, V0 = as-built cavity' if cal.k_free else 'K from the as-built geometry'}):")
        for name in ("v0", "b", "a"):
            value = d["v0_mm3"] if name == "v0" else d[name]
            lo, hi = d[f"{name}_ci95"]
            print(f"  {name:<3}= {value:.6g} +- {d[name + '_se']:.3g}  (95 %: {lo:.6g} .. {hi:.6g})")
        print(f"  residual RMS {d['residual_rms_hz']:.2f} Hz; calibration.toml, residuals.png in {target}/")
    return EXIT_OK


def cmd_sense(args) -> int:
    import numpy as np

    from matcad.loop.analyze import analyze
    from matcad.loop.sense import SensorCalibration, require_in_range, sense
    from matcad.loop.wav import read_mono
    from matcad.spec import load_calibration

    cal = SensorCalibration.from_spec_calibration(load_calibration(args.calibration))
    f_lo, f_hi = cal.frequency_range_hz()
    x, fs = read_mono(args.recording)
    result = analyze(x, fs, (0.8 * f_lo, 1.25 * f_hi))
    reading = sense(result.track_hz, cal)
    if args.json:
        frames = [{"time_s": float(t), "frequency_hz": float(f), "force_n": None if np.isnan(force) else float(force),
                   "force_interval_n": None if np.isnan(force) else [float(lo), float(hi)]}
                  for t, f, force, (lo, hi) in zip(result.times_s, result.track_hz, reading.frames_n,
                                                   reading.frames_interval_n)]
        _print_json({**reading.to_dict(), "warnings": list(result.warnings), "frames": frames})
    elif np.isfinite(reading.force_n):
        lo, hi = reading.force_interval_n
        print(f"{args.recording}: F = {reading.force_n:.3f} N (95 %: {lo:.3f} .. {hi:.3f} N) at "
              f"{reading.frequency_hz:.2f} Hz; {int(np.sum(np.isfinite(reading.frames_n)))}/{len(reading.frames_n)} "
              "frames inside the calibrated range")
    require_in_range(reading)
    return EXIT_OK


def _write_json(path: Path, data) -> None:
    import json

    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


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


def _parser() -> argparse.ArgumentParser:
    import matcad

    parser = argparse.ArgumentParser(prog="matcad", description=matcad.__doc__,
                                     epilog="exit codes: 0 ok; 1 design-rule error or no trustworthy result; "
                                            "2 bad input")
    parser.add_argument("--version", action="version", version=f"matcad {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    def command(name, func, help_text, out_default=None):
        cmd = sub.add_parser(name, help=help_text)
        cmd.set_defaults(func=func)
        cmd.add_argument("--json", action="store_true", help="print JSON instead of text")
        if out_default:
            cmd.add_argument("--out", type=Path, help=f"output folder (default {out_default})")
        return cmd

    p = command("predict", cmd_predict, "predict the taxel's resonance frequency from a spec")
    p.add_argument("spec", help="spec TOML file")
    p.add_argument("--force", type=float, nargs="+", metavar="F",
                   help="normal loads in N: add paper Eq. 5 f(F) using the spec's [calibration]")
    p.add_argument("--model", help="use this model's f0 instead of the automatic choice ('fem' adds the FEM)")
    p.add_argument("--fem-level", type=int, help="FEM mesh refinement: elements across the neck radius (default 8)")

    command("check", cmd_check, "run the design rules without building (exit 1 on errors)").add_argument(
        "spec", help="spec TOML file")

    b = command("build", cmd_build, "write the fabrication kit and report to out/<name>/", "out/<name>")
    b.add_argument("spec", help="spec TOML file")
    b.add_argument("--force", action="store_true", help="build despite design-rule errors")

    command("coupon", cmd_coupon, "test coupons sweeping neck, dowel and needle-bore sizes",
            "out/<name>-coupon").add_argument("spec", help="spec TOML file")

    a = command("analyze", cmd_analyze, "the taxel's frequency in a recording (spectrogram ridge)",
                "out/analyze-<recording>")
    a.add_argument("recording", help="WAV file (mono/stereo; 8-32-bit integer or float; any sample rate)")
    group = a.add_mutually_exclusive_group()
    group.add_argument("--spec", help="spec TOML: analyse its predicted band (-10 %% / +25 %% for load)")
    group.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"), help="analysis band in Hz")

    c = command("calibrate", cmd_calibrate, "fit paper Eq. 5 to force/frequency pairs, with uncertainty",
                "out/calibrate-<data>")
    c.add_argument("data", help="CSV with force_n and frequency_hz columns")
    c.add_argument("--spec", required=True, help="spec TOML of the taxel (its as-built K or V0)")
    c.add_argument("--k-free", action="store_true", help="fix V0 to the as-built cavity and fit K instead")

    n = command("sense", cmd_sense, "force from a recording through a calibration, with 95 %% intervals")
    n.add_argument("recording", help="WAV file")
    n.add_argument("--calibration", required=True, help="calibration.toml from `matcad calibrate`, or a spec")

    command("schema", cmd_schema, "print every spec field with unit, default and allowed range")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from matcad.errors import OutputError
    from matcad.loop import LoopError
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
    except OSError as exc:  # unwritable output folder, unreadable input: the user's file system, not a bug
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"matcad: error: {where}{exc.strerror or exc} (check the path and its permissions)", file=sys.stderr)
        return EXIT_INPUT
    except ValueError as exc:
        print(f"matcad: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours
        sys.stdout = open(os.devnull, "w")
        return EXIT_OK


def run() -> None:
    """Console entry point. After a command that loaded OpenCASCADE, every output file is closed and moved into
    place, yet interpreter teardown would spend 0.3-0.7 s destroying kernel objects: flush and leave at once."""
    code = main()
    if "OCP" in sys.modules:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)
