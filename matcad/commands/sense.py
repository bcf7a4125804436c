"""`matcad sense REC --calibration CAL`: force from sound through Eq. 5 calibrations, with 95 % intervals."""

from __future__ import annotations

from functools import partial

from matcad.commands.common import board_spec, loop_output, print_json, recording_arguments, recording_blocks
from matcad.errors import EXIT_OK

HELP = "force from a recording through a calibration, with 95 %% intervals"
OUT = "out/sense-<recording>-<hash>"


def arguments(cmd) -> None:
    cmd.add_argument("recording", help="WAV file, or '-' for standard input (WAV, or raw PCM with --format --rate)")
    cmd.add_argument("--calibration", action="append", metavar="[NAME=]FILE",
                     help="calibration.toml from `matcad calibrate`, or a spec; with --spec naming an array, one "
                          "NAME=FILE per taxel (repeat the option; it overrides that taxel's [taxel.calibration] in "
                          "the spec; a taxel with neither gets frequencies only)")
    cmd.add_argument("--spec", help="spec TOML of an array: every taxel tracked in its own (loaded) band")
    cmd.add_argument("--set", action="append", metavar="KEY=VALUE", help="override one field of --spec (TOML value)")
    cmd.add_argument("--temperature-c", type=float, help="air temperature now (degC): frequencies are scaled by "
                                                         "sqrt(T_cal/T) to the calibration's temperature")
    cmd.add_argument("--live", action="store_true", help="print each frame's force as it is decided (~1 s lag, up "
                                                         "to ~2 s while a new line is held: a voice, a reverberant "
                                                         "room); no output folder unless --out")
    recording_arguments(cmd)


def run(args) -> int:
    from matcad.loop import live, outputs
    from matcad.loop.analyze import analyze_stream
    from matcad.loop.plots import plot
    from matcad.loop.sense import listening_band_hz, require_in_range, sense, sensing_law
    from matcad.output import staged_output
    from matcad.spec import load_calibration

    spec = board_spec(args)
    if spec is not None:
        return _board(args, spec)
    if not args.calibration:
        raise ValueError("--calibration FILE is required (calibration.toml from `matcad calibrate`, or a spec with "
                         "a [calibration] table); an array --spec may carry [taxel.calibration] tables instead")
    if len(args.calibration) != 1:
        raise ValueError(f"--calibration given {len(args.calibration)} times: several calibrations need --spec "
                         "naming an array, one NAME=FILE per taxel")
    cal = sensing_law(load_calibration(args.calibration[0]))
    cal.temperature_factor(args.temperature_c)  # bad temperature: exit 2 before reading anything
    band = listening_band_hz(cal)
    from matcad.progress import line

    on_frame = live.taxel_printer(cal, args.temperature_c, partial(print, flush=True)) if args.live else None
    with line("sense", "s of recording", quiet=args.json or args.live) as progress:  # --live prints its own lines
        blocks, fs, name = recording_blocks(args, progress)
        result = analyze_stream(blocks, fs, [band], on_frame)[0]
    reading = sense(result, cal, args.temperature_c)
    target = loop_output(args, "sense", name) if not (args.live and args.out is None) else None
    if target is not None:
        with staged_output(target) as tmp:
            outputs.write_segments_csv(result, tmp / "segments.csv", reading.segments_n)
            outputs.write_forces_csv(result, reading, tmp / "forces.csv")
            plot(result, tmp / "force.png", (reading.frames_n, *reading.frames_interval_n.T))
            outputs.write_json(tmp / "report.json", {"recording": name, "calibration": str(args.calibration[0]),
                                                     **reading.report_dict(result)})
    if args.json:
        print_json({**reading.detail_dict(result), "out_dir": None if target is None else str(target)})
    else:
        print(reading.to_text(name, result))
        if target is not None:
            print(f"  forces.csv, segments.csv, force.png, report.json in {target}/")
    require_in_range(reading)
    return EXIT_OK


def _board(args, spec) -> int:
    """Every taxel of the board ``spec`` in its own band, each with its calibration (the spec's [taxel.calibration]
    or ``--calibration NAME=FILE``) read as force."""
    from matcad.loop import board, live, outputs
    from matcad.loop.plots import plot_board
    from matcad.loop.sense import sensing_law
    from matcad.output import staged_output
    from matcad.prediction.bands import listening_bands

    named_bands = listening_bands(spec)
    names = [n for n, _ in named_bands]
    given = board.board_calibrations(spec, args.calibration)
    cals = {n: sensing_law(cal) for n, (_, cal) in given.items()}
    for cal in cals.values():
        cal.temperature_factor(args.temperature_c)  # bad temperature: exit 2 before reading anything
    from matcad.progress import line

    on_frame = live.board_printer(names, cals, args.temperature_c, partial(print, flush=True)) if args.live else None
    try:
        with line("sense", "s of recording", quiet=args.json or args.live) as progress:
            blocks, fs, name = recording_blocks(args, progress)
            tracks = board.analyze_board(blocks, fs, named_bands, on_frame)
    finally:
        if on_frame is not None:
            on_frame.flush()
    readings = board.sense_board(tracks, cals, args.temperature_c)
    report = {"recording": name, "calibrations": {n: source for n, (source, _) in given.items()},
              "taxels": board.taxels_dict(tracks, readings)}
    target = loop_output(args, "sense", name) if not (args.live and args.out is None) else None
    if target is not None:
        with staged_output(target) as tmp:
            outputs.write_board_segments_csv(tracks, tmp / "segments.csv", readings)
            outputs.write_board_forces_csv(tracks, readings, tmp / "forces.csv")
            plot_board(tracks, tmp / "force.png", readings)
            outputs.write_json(tmp / "report.json", report)
    if args.json:
        print_json({**report, "out_dir": None if target is None else str(target)})
    else:
        print(board.board_text(name, tracks, readings))
        if target is not None:
            print(f"  forces.csv, segments.csv, force.png, report.json in {target}/")
    return EXIT_OK
