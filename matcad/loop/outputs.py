"""What the recording loop writes: its output folders, and one writer per file in them.

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
    head = "start_s,end_s,frames,mean_hz,median_hz,std_hz"
    head += ",force_n,force_low_n,force_high_n" if forces is not None else ""
    rows = [head + ",flag"]
    for i, s in enumerate(analysis.segments):
        row = f"{s.start_s:.3f},{s.end_s:.3f},{s.frames},{s.mean_hz:.3f},{s.median_hz:.3f},{s.std_hz:.3f}"
        if forces is not None:
            row += "," + ",".join(_cell(v) for v in forces[i])
        rows.append(row + "," + s.flag.replace(",", ";"))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
