"""The report's files: report.json, and report.md and report.html from one Markdown rendering of the same data;
the manifest (size and sha256) of every other file of the build."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from matcad.report.page import render_html, render_markdown

KIT_ARCHIVE = "kit.zip"
"""Every file of the build in one archive, written last."""
REPORT_FILES = ("report.json", "report.md", "report.html", KIT_ARCHIVE)
"""Written after the manifest: the reports, and the archive that holds everything."""


def manifest(folder: Path) -> list[dict]:
    """Every output file (except the reports themselves) with its size and sha256."""
    rows = []
    for path in sorted(folder.iterdir()):
        if path.name in REPORT_FILES:
            continue
        data = path.read_bytes()
        rows.append({"file": path.name, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()})
    return rows


def write_report(report: dict, folder: Path) -> None:
    """report.json, and report.md and report.html from one Markdown rendering of the same data."""
    (folder / "report.json").write_text(json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    text = render_markdown(report)
    (folder / "report.md").write_text(text, encoding="utf-8")
    (folder / "report.html").write_text(render_html(text, f"{report['name']} — matcad report"), encoding="utf-8")
