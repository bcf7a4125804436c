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
import threading
import zipfile
from pathlib import Path

from matcad.serve.common import BUILD_TIMEOUT_S, MIME, Refused, error, spec_of


class Builds:
    """The build processes and temporary folders of a server, so that stopping it ends and removes them all."""

    def __init__(self):
        self.lock = threading.Lock()
        self.folders: set[Path] = set()
        self.processes: set[subprocess.Popen] = set()
        self.stopping = False

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
    """Build the request's spec with `matcad build` in a temporary folder: the kit as a base64 zip and the previews
    as data URIs; a design-rule failure as 422 with its findings."""
    from matcad.report import KIT_ARCHIVE

    spec = spec_of(payload)  # a bad spec is told at once, before a process starts
    tmp = builds.folder()
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
        return 200, {"name": spec.name, "verdict": report["verdict"], "files": result["written"],
                     "zip": base64.b64encode(buf.getvalue()).decode(), "previews": previews,
                     "findings": [f for f in result["findings"] if f["level"] != "info"]}
    finally:
        builds.remove(tmp)
