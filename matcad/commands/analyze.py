"""`matcad analyze REC`: the taxel's frequency over the voiced frames of a recording (every taxel of a board)."""

from __future__ import annotations

from matcad.commands.common import load_spec, loop_output, print_json, recording_arguments, recording_blocks
from matcad.errors import EXIT_OK

HELP = "the taxel's frequency in a recording (spectrogram ridge)"
OUT = "out/analyze-<recording>-<hash>"


def arguments(cmd) -> None:
    cmd.add_argument("recording", help="WAV file (mono/stereo; 8-32-bit integer or float; any sample rate), or "
                                       "'-' for standard input")
    group = cmd.add_mutually_exclusive_group()
    group.add_argument("--spec", help="spec TOML: analyse its predicted band (-10 %% / +25 %% for load); an array "
                                      "spec: every taxel at once, each in its loaded band, per-taxel columns")
    group.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"), help="analysis band in Hz")
    cmd.add_argument("--set", action="append", metavar="KEY=VALUE", help="override one field of --spec (TOML value)")
    recording_arguments(cmd)


def band(args, spec) -> tuple[float, float]:
    """The band (Hz) one taxel is listened for in: ``--band``, or the single-taxel ``spec``'s predicted band
    widened by :data:`matcad.listening.PREDICTED_MARGIN`."""
    if args.band:
        lo, hi = args.band
        if not (0 <= lo < hi):
            raise ValueError(f"--band {lo:g} {hi:g} invalid, must be 0 <= LO < HI (Hz)")
        from matcad.listening import FREQUENCY_KHZ_MAX

        if hi < FREQUENCY_KHZ_MAX:  # a taxel sings at kHz; a band below 100 Hz is a band typed in kHz
            hint = f"kHz entered? did you mean --band {lo * 1000:g} {hi * 1000:g}?" if hi * 1000 >= FREQUENCY_KHZ_MAX \
                else f"read as kHz it would lie below {FREQUENCY_KHZ_MAX:g} Hz as well: a taxel sings at kHz"
            raise ValueError(f"--band {lo:g} {hi:g} invalid: the band is in Hz and lies below {FREQUENCY_KHZ_MAX:g} "
                             f"Hz: {hint}")
        return lo, hi
    if spec is not None:
        from matcad.listening import PREDICTED_MARGIN, listening_band
        from matcad.prediction import predict

        return listening_band(predict(spec).band_hz, PREDICTED_MARGIN)
    raise ValueError("analyze needs --spec SPEC (its predicted band) or --band LO HI (Hz)")


def run(args) -> int:
    spec = load_spec(args.spec, args) if args.spec else None
    if spec is not None:
        from matcad.spec import is_array

        if is_array(spec):
            return _board(args, spec)
    from matcad.loop import outputs
    from matcad.loop.analyze import analyze_stream
    from matcad.loop.plots import plot
    from matcad.output import staged_output

    from matcad.progress import line

    listening = band(args, spec)
    with line("analyze", "s of recording", quiet=args.json) as progress:
        blocks, fs, name = recording_blocks(args, progress)
        result = analyze_stream(blocks, fs, [listening])[0]
    target = loop_output(args, "analyze", name)
    with staged_output(target) as tmp:
        outputs.write_track_csv(result, tmp / "track.csv")
        outputs.write_segments_csv(result, tmp / "segments.csv")
        plot(result, tmp / "spectrogram.png")
        outputs.write_json(tmp / "report.json", {"recording": name, **result.to_dict()})
    if args.json:
        print_json({**result.to_dict(), "out_dir": str(target)})
    else:
        print(result.to_text(name))
        print(f"  track.csv, segments.csv, spectrogram.png, report.json in {target}/")
    return EXIT_OK


def _board(args, spec) -> int:
    """Every taxel of the board ``spec`` in its own listening band, from one pass over the recording."""
    from matcad.loop import board, outputs
    from matcad.loop.plots import plot_board
    from matcad.output import staged_output
    from matcad.prediction.bands import listening_bands

    from matcad.progress import line

    named_bands = listening_bands(spec)
    with line("analyze", "s of recording", quiet=args.json) as progress:
        blocks, fs, name = recording_blocks(args, progress)
        tracks = board.analyze_board(blocks, fs, named_bands)
    target = loop_output(args, "analyze", name)
    report = {"recording": name, "taxels": board.taxels_dict(tracks)}
    with staged_output(target) as tmp:
        outputs.write_board_track_csv(tracks, tmp / "track.csv")
        outputs.write_board_segments_csv(tracks, tmp / "segments.csv")
        plot_board(tracks, tmp / "spectrogram.png")
        outputs.write_json(tmp / "report.json", report)
    if args.json:
        print_json({**report, "out_dir": str(target)})
    else:
        print(board.board_text(name, tracks))
        print(f"  track.csv, segments.csv, spectrogram.png, report.json in {target}/")
    return EXIT_OK
