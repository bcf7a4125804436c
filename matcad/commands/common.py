"""What several commands share: the spec argument and its loading (with unit-slip notes), JSON printing, the
recording argument of the loop commands and their output folders, argument types with their bounds."""

from __future__ import annotations

import math
import sys
from pathlib import Path


def print_json(data) -> None:
    """``data`` as indented JSON on stdout (NaN refused: a bug, not a number)."""
    import json

    print(json.dumps(data, indent=2, allow_nan=False))


def note(text: str) -> None:
    """A ``matcad: note:`` line on stderr (a likely unit slip, a deprecated spelling); never changes a value."""
    print(f"matcad: note: {text}", file=sys.stderr)


def spec_argument(cmd, flag: str | None = None, **kw) -> None:
    """The spec argument (positional, or ``flag``) and ``--set`` overrides, for every spec-taking command."""
    cmd.add_argument(flag or "spec", help="spec TOML file, or a build's report.json (its resolved spec)", **kw)
    cmd.add_argument("--set", action="append", metavar="KEY=VALUE",
                     help="override one spec field, value as TOML (e.g. --set neck.diameter=2.0); repeatable")


def load_spec(path, args):
    """The validated spec at ``path`` (TOML or a build's report.json) with ``--set`` applied; likely unit slips
    and silent defaults are printed to stderr as notes (never changing a value)."""
    from matcad.spec import load_spec as load, spec_notes

    spec, data = load(path, getattr(args, "set", None))
    command = getattr(args, "command", None)
    if spec.kind == "tube" and command not in TUBE_COMMANDS:
        raise ValueError(f"matcad {command} takes MAT specs only; a kind = 'tube' spec goes to "
                         f"{', '.join(TUBE_COMMANDS)} (docs/tube.md)")
    for text in spec_notes(spec, data):
        note(text)
    return spec


TUBE_COMMANDS = ("predict", "check", "build", "design")
"""The commands that take a ``kind = "tube"`` spec (docs/tube.md); the others refuse it with exit 2."""


def force_n(text: str) -> float:
    """A force argument (N): finite, within the calibration's force bounds."""
    import argparse

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


def check_fem_level(args) -> None:
    """``--fem-level`` only with ``--model fem``, and 1-64 elements across the neck radius."""
    if args.fem_level is not None and args.model != "fem":
        raise ValueError(f"--fem-level {args.fem_level} applies only with --model fem (it sets the FEM's mesh)")
    if args.fem_level is not None and not 1 <= args.fem_level <= 64:
        raise ValueError(f"--fem-level {args.fem_level} invalid, must be 1-64 elements across the neck radius")


def recording_arguments(cmd) -> None:
    """How raw PCM on standard input is described (analyze, sense)."""
    cmd.add_argument("--format", choices=("s16le", "s24le", "s32le", "u8", "f32le", "f64le"),
                     help="raw PCM sample format on standard input (default: a WAV header is expected)")
    cmd.add_argument("--rate", type=float, help="raw PCM sample rate (Hz)")
    cmd.add_argument("--channels", type=int, default=1, help="raw PCM channels (default 1), averaged")


def recording_blocks(args, progress=None):
    """(sample blocks, rate Hz, name) of the recording argument: a WAV file read in blocks, a FLAC/OGG file
    (the optional extra ``matcad[audio]``), or '-' for standard input (WAV, or raw PCM with --format/--rate).
    ``progress(seconds read, seconds)`` (:mod:`matcad.progress`) is told as blocks are read (seconds unknown on
    standard input)."""
    from matcad.loop import audio, wav

    if str(args.recording) == "-":
        stream = sys.stdin.buffer
        info = wav.stream_info(stream, getattr(args, "rate", None), getattr(args, "format", None),
                               getattr(args, "channels", 1))
        return _told(wav.iter_stream(stream, info), info.sample_rate_hz, None, progress), info.sample_rate_hz, \
            "standard input"
    if getattr(args, "format", None):
        raise ValueError("--format/--rate describe raw PCM on standard input: give the recording as '-'")
    reader = audio if audio.compressed(args.recording) else wav
    info = reader.read_info(args.recording)
    blocks = reader.iter_blocks(args.recording, info) if reader is wav else reader.iter_blocks(args.recording)
    return (_told(blocks, info.sample_rate_hz, info.frames / info.sample_rate_hz, progress), info.sample_rate_hz,
            str(args.recording))


def _told(blocks, rate_hz: float, total_s, progress):
    """``blocks`` as they are, telling ``progress`` the seconds of recording read so far."""
    if progress is None:
        yield from blocks
        return
    frames = 0
    for block in blocks:
        yield block
        frames += len(block)
        progress(round(frames / rate_hz), None if total_s is None else round(total_s))


def loop_output(args, kind: str, source: str) -> Path:
    """The output folder of a loop command (``--out``, or one named by the source's path)."""
    from matcad.loop.outputs import output_folder

    return output_folder(args.out, kind, source)


def board_spec(args):
    """The spec of ``--spec`` when it names an array (and no --band is given), else None."""
    if not getattr(args, "spec", None) or getattr(args, "band", None):
        return None
    from matcad.spec import is_array

    spec = load_spec(args.spec, args)
    return spec if is_array(spec) else None
