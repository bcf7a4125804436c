"""What the recording loop writes: its output folders, and one writer per file in them (CSV, TOML, report.json).

The loop's commands call the writers inside :func:`matcad.output.staged_output`; pictures are
:mod:`matcad.loop.plots`. Frequencies Hz, times s, forces N.

Output folders are named so that two recordings never overwrite each other silently.

Default: out/<kind>-<file stem>-<8 hex digits of SHA-256 of the file's absolute path>; the same recording
analysed again replaces its own earlier folder, a different file with the same name gets its own. A live stream
gets out/<kind>-stdin-<UTC time>. An explicit --out that holds the report of a *different* source is refused.
"""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import numpy as np

from matcad.errors import OutputError


def default_folder(kind: str, source: str) -> Path:
    """out/<kind>-<stem>-<hash of the absolute path>, or out/<kind>-stdin-<UTC time> for standard input."""
    if source == "standard input":
        return Path("out") / f"{kind}-stdin-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    path = Path(source).resolve()
    digest = hashlib.sha256(str(path).encode("utf-8", "surrogateescape")).hexdigest()[:8]
    return Path("out") / f"{kind}-{path.stem}-{digest}"


def output_folder(out: Path | None, kind: str, source: str) -> Path:
    """The folder to write: ``out`` or the default; raises OutputError when ``out`` holds another source's
    report (its report.json names a different recording or data file)."""
    target = out or default_folder(kind, source)
    report = target / "report.json"
    if out is not None and report.is_file():
        try:
            data = json.loads(report.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, ValueError):
            data = {}
        earlier = data.get("recording", data.get("data")) if isinstance(data, dict) else None
        if earlier is not None and source != "standard input" and \
                Path(str(earlier)).resolve() != Path(source).resolve():
            raise OutputError(f"output folder {target}: holds the results of {earlier}, not {source}; refusing to "
                              "overwrite them (choose another --out or delete it)")
    return target


def write_json(path: Path, data) -> None:
    """``data`` as indented JSON (report.json); NaN refused (a value without a number is written as null by the
    result's ``to_dict``)."""
    path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def frame_times(tracks) -> np.ndarray:
    """The frame times (s) the trackers of a board share."""
    return next(t.analysis.times_s for t in tracks if t.analysis is not None)


def _cell(v, fmt="{:.4f}") -> str:
    return fmt.format(v) if v is not None and np.isfinite(v) else ""


def write_track_csv(analysis, path: Path) -> None:
    """track.csv of one taxel's :class:`matcad.loop.analysis.Analysis`: per frame time (s), frequency (Hz, empty
    where unvoiced), ridge excess over the floor (dB) and voicing."""
    rows = ["time_s,frequency_hz,snr_db,voiced"] + [
        f"{t:.6f},{f'{f:.4f}' if v else ''},{s:.2f},{int(v)}"
        for t, f, s, v in zip(analysis.times_s, analysis.track_hz, analysis.frame_snr_db, analysis.voiced)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def write_segments_csv(analysis, path: Path, forces=None) -> None:
    """segments.csv of one taxel: per segment start, end (s), frames, mean/median/sd frequency (Hz), flag; and force
    with its 95 % interval (N) when ``forces`` (one (force, low, high) per segment) is given."""
    rows = [_segments_head(forces is not None)]
    rows += [_segment_row(s, None if forces is None else forces[i]) for i, s in enumerate(analysis.segments)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def _segments_head(with_force: bool) -> str:
    """segments.csv's columns after any leading ones: the segment's, the force's when ``with_force``, the flag."""
    return "start_s,end_s,frames,mean_hz,median_hz,std_hz" + (",force_n,force_low_n,force_high_n" if with_force
                                                               else "") + ",flag"


def _segment_row(s, force=None) -> str:
    """One segments.csv row after any leading columns: start, end (s), frames, mean/median/sd (Hz), the
    ``force`` cells (force, low, high in N; None: no force columns) and the flag."""
    row = f"{s.start_s:.3f},{s.end_s:.3f},{s.frames},{s.mean_hz:.3f},{s.median_hz:.3f},{s.std_hz:.3f}"
    if force is not None:
        row += "," + ",".join(_cell(v) for v in force)
    return row + "," + s.flag.replace(",", ";")


def write_forces_csv(analysis, reading, path: Path) -> None:
    """forces.csv of one taxel: per frame time (s), frequency (Hz), force and its 95 % interval (N) from
    ``reading`` (:class:`matcad.loop.sense.Reading`); empty where unvoiced or outside the calibrated range."""
    rows = ["time_s,frequency_hz,force_n,force_low_n,force_high_n"]
    for t, f, force, (lo, hi), v in zip(analysis.times_s, analysis.track_hz, reading.frames_n,
                                        reading.frames_interval_n, analysis.voiced):
        rows.append(",".join([f"{t:.6f}", f"{f:.4f}" if v else ""] + [_cell(c) for c in (force, lo, hi)]))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def write_board_track_csv(tracks, path: Path) -> None:
    """track.csv of a board (:class:`matcad.loop.board.TaxelTrack` per taxel): per frame time (s) and per taxel its
    frequency (Hz, empty where unvoiced), ridge excess (dB) and voicing (columns NAME_frequency_hz, NAME_snr_db,
    NAME_voiced)."""
    times = frame_times(tracks)
    head = ["time_s"] + [f"{t.name}_{c}" for t in tracks for c in ("frequency_hz", "snr_db", "voiced")]
    rows = [",".join(head)]
    for i, time_s in enumerate(times):
        cells = [f"{time_s:.6f}"]
        for t in tracks:
            a = t.analysis
            if a is None:
                cells += ["", "", "0"]
            else:
                cells += [_cell(a.track_hz[i]) if a.voiced[i] else "", _cell(a.frame_snr_db[i], "{:.2f}"),
                          str(int(a.voiced[i]))]
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def write_board_segments_csv(tracks, path: Path, readings=None) -> None:
    """segments.csv of a board: per taxel and segment taxel, start, end (s), frames, mean/median/sd frequency
    (Hz), with ``readings`` ({name: Reading}) force and its 95 % interval (N; empty for a taxel without
    calibration), flag."""
    rows = ["taxel," + _segments_head(readings is not None)]
    for t in tracks:
        if t.analysis is None:
            continue
        reading = (readings or {}).get(t.name)
        for i, s in enumerate(t.analysis.segments):
            force = None if readings is None else (reading.segments_n[i] if reading else (None,) * 3)
            rows.append(f"{t.name}," + _segment_row(s, force))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def write_board_forces_csv(tracks, readings, path: Path) -> None:
    """forces.csv of a board: per frame time (s) and per taxel its frequency (Hz), force and 95 % interval (N);
    empty where unvoiced, outside the calibrated range or without a calibration (columns NAME_frequency_hz,
    NAME_force_n, ...)."""
    times = frame_times(tracks)
    head = ["time_s"] + [f"{t.name}_{c}" for t in tracks
                         for c in ("frequency_hz", "force_n", "force_low_n", "force_high_n")]
    rows = [",".join(head)]
    for i, time_s in enumerate(times):
        cells = [f"{time_s:.6f}"]
        for t in tracks:
            a, r = t.analysis, readings.get(t.name)
            cells.append(_cell(a.track_hz[i]) if a is not None and a.voiced[i] else "")
            cells += [_cell(v) for v in ((r.frames_n[i], *r.frames_interval_n[i]) if r else (None,) * 3)]
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


def write_calibration_toml(cal, path: Path, taxel: str | None = None, spec_path=None) -> None:
    """calibration.toml: the [calibration] table of a fitted :class:`matcad.acoustics.eq5.Eq5`; with ``taxel``
    the [taxel.calibration] table to paste under that [[taxel]] entry of the board spec ``spec_path``."""
    if taxel is None:
        path.write_text(cal.to_toml(), encoding="utf-8")
    else:
        path.write_text(f"# paste under the [[taxel]] entry named {taxel!r} of {spec_path}\n"
                        + cal.to_toml("taxel.calibration"), encoding="utf-8")
