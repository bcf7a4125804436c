"""Builds for the design page: each a `matcad build` process in its own temporary folder, zipped into the reply;
:class:`Builds` keeps the processes and folders of a server so that stopping it ends and removes them all."""

from __future__ import annotations

import base64
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import re
import threading
import time
import zipfile
from pathlib import Path

from matcad.serve.common import BUILD_TIMEOUT_S, MIME, Refused, error, spec_of

BUILD_ID = re.compile(r"[A-Za-z0-9_-]{8,64}")
"""A build's id, chosen by the page so that it can ask for the build's progress while it waits for the kit."""
STAGES = (
    ("starting", "starting: loading matcad, checking the rules, predicting every band", ()),
    ("laser", "laser parts and cut sheets (DXF, SVG, PDF)", (".dxf", ".pdf")),
    ("solids", "printed parts (STL, STEP; the CAD kernel)", (".stl",)),
    ("assembly", "assembly and section", ("assembly.step", "section.svg")),
    ("print", "print job (3MF)", (".3mf",)),
    ("pictures", "pictures (previews, plots, band chart)", (".png",)),
    ("report", "report", ("report.json", "report.md", "report.html")),
    ("zip", "packing the kit", ()),
)
"""A build's stages in the order `matcad build` writes them, each with the file names (suffixes) whose first
appearance in its output folder marks it (:meth:`Builds.progress`)."""


def stage_of(names: set[str], finished: bool) -> int:
    """The index in :data:`STAGES` of the furthest stage whose files are among ``names`` (a build's folder so far);
    ``finished`` (the kit is in place) is the last stage."""
    if finished:
        return len(STAGES) - 1
    reached = 0
    for i, (_, _, marks) in enumerate(STAGES):
        if any(name == m or (m.startswith(".") and name.endswith(m)) for m in marks for name in names):
            reached = i
    return reached


class Builds:
    """The build processes and temporary folders of a server, so that stopping it ends and removes them all."""

    def __init__(self):
        self.lock = threading.Lock()
        self.folders: set[Path] = set()
        self.processes: set[subprocess.Popen] = set()
        self.running: dict[str, tuple[Path, float]] = {}  # build id → (its kit folder, start monotonic s)
        self.stopping = False

    def progress(self, build_id: str) -> dict:
        """What the build ``build_id`` has written so far: its stage (index, key, text, of how many), the files
        in its folder and the seconds since it started; ``{"running": false}`` for a build that is not running
        (not started yet: waiting for the build slot; or just finished: the page's last poll crosses the kit on
        its way), Refused(422) for an id that cannot be a build's."""
        if not BUILD_ID.fullmatch(build_id):
            raise Refused(422, "build must be 8-64 letters, digits, '_' or '-'", "build")
        with self.lock:
            entry = self.running.get(build_id)
        if entry is None:
            return {"running": False}
        kit, started = entry
        names: set[str] = set()
        for folder in (kit, *kit.parent.glob(f".{kit.name}.tmp-*")):  # matcad.output stages into a hidden sibling
            try:
                names |= {p.name for p in folder.iterdir()}
            except OSError:
                pass
        i = stage_of(names, kit.is_dir())
        key, text, _ = STAGES[i]
        return {"running": True, "stage": key, "text": text, "index": i + 1, "of": len(STAGES), "files": len(names),
                "elapsed_s": round(time.monotonic() - started, 1)}

    def folder(self) -> Path:
        with self.lock:
            if self.stopping:
                raise Refused(503, "the server is stopping")
            folder = Path(tempfile.mkdtemp(prefix="matcad-serve-"))
            self.folders.add(folder)
            return folder

    def run(self, argv: list[str]) -> tuple[int, str]:
        """Run ``matcad ARGV`` in a child process (this matcad, whatever the working folder): (exit code, stdout)."""
        package_root = str(Path(__file__).resolve().parents[1])
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [package_root,
                                                                         os.environ.get("PYTHONPATH")]))}
        with self.lock:
            if self.stopping:
                raise Refused(503, "the server is stopping")
            proc = subprocess.Popen([sys.executable, "-m", "matcad", *argv], stdin=subprocess.DEVNULL,
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
            self.processes.add(proc)
        try:
            out, _ = proc.communicate(timeout=BUILD_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, _ = proc.communicate()
        finally:
            with self.lock:
                self.processes.discard(proc)
        return proc.returncode, out

    def remove(self, folder: Path) -> None:
        shutil.rmtree(folder, ignore_errors=True)
        with self.lock:
            self.folders.discard(folder)

    def stop(self, grace_s: float = 10.0) -> None:
        """End every build process (SIGTERM: each removes its own staged output; SIGKILL after ``grace_s``) and
        remove every temporary folder."""
        with self.lock:
            self.stopping = True
            processes, folders = list(self.processes), list(self.folders)
        for proc in processes:
            proc.terminate()
        for proc in processes:
            try:
                proc.wait(timeout=grace_s)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        for folder in folders:
            shutil.rmtree(folder, ignore_errors=True)


def build_json(payload: dict, builds: Builds) -> tuple[int, dict]:
    """Build the request's spec with `matcad build` in a temporary folder: the kit as a base64 zip, the previews
    as data URIs, the verdict and, as the report's headline says it, each taxel whose chosen model fails its checks;
    a design-rule failure as 422 with its findings."""
    from matcad.render.plots import chosen_models_status
    from matcad.report import KIT_ARCHIVE

    spec = spec_of(payload)  # a bad spec is told at once, before a process starts
    build_id = payload.get("build_id")
    if build_id is not None and not (isinstance(build_id, str) and BUILD_ID.fullmatch(build_id)):
        raise Refused(422, "build_id must be 8-64 letters, digits, '_' or '-'", "build_id")
    tmp = builds.folder()
    if build_id:
        with builds.lock:
            builds.running[build_id] = (tmp / spec.name, time.monotonic())
    try:
        request = tmp / "request.json"
        request.write_text(json.dumps({"spec": payload["spec"]}), encoding="utf-8")
        kit = tmp / spec.name
        code, out = builds.run(["build", str(request), "--out", str(kit), "--json"])
        if code not in (0, 1, 2):
            raise Refused(503 if builds.stopping else 500, f"the build ended with exit code {code}")
        result = json.loads(out)
        if code == 2:
            return 422, error(result["error"]["field"], result["error"]["message"])
        if code == 1:
            errors = [f for f in result["findings"] if f["level"] == "error"]
            message = "; ".join(f"{f['id']}: {f['message']}" for f in errors)
            return 422, {"error": {"field": None, "message": message}, "findings": errors}
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
            for name in result["written"]:
                if name != KIT_ARCHIVE:  # the build's own archive of these same files
                    z.write(kit / name, f"{spec.name}/{name}")
        report = json.loads((kit / "report.json").read_text(encoding="utf-8"))
        previews = [{"caption": fig["caption"], "file": fig["file"],
                     "src": f"data:{MIME[Path(fig['file']).suffix]};base64,"
                            f"{base64.b64encode((kit / fig['file']).read_bytes()).decode()}"}
                    for fig in report.get("figures", ())]
        return 200, {"name": spec.name, "verdict": report["verdict"], "model_status": chosen_models_status(report),
                     "files": result["written"],
                     "zip": base64.b64encode(buf.getvalue()).decode(), "previews": previews,
                     "findings": [f for f in result["findings"] if f["level"] != "info"]}
    finally:
        with builds.lock:
            builds.running.pop(build_id, None)
        builds.remove(tmp)
