"""Output folders of the recording loop, named so that two recordings never overwrite each other silently.

Default: out/<kind>-<file stem>-<8 hex digits of SHA-256 of the file's absolute path>; the same recording
analysed again replaces its own earlier folder, a different file with the same name gets its own. A live stream
gets out/<kind>-stdin-<UTC time>. An explicit --out that holds the report of a *different* source is refused.
"""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

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
