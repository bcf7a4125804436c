"""`matcad serve`: a local design page — the spec as a form, live prediction, build to a zip with previews.

stdlib only (``http.server.ThreadingHTTPServer``), bound to 127.0.0.1. The server keeps no state: each request
carries the whole spec as JSON; a build goes to its own temporary folder, is zipped into the response and the
folder deleted. Request bodies are bounded (:data:`MAX_BODY_BYTES`). Predictions run concurrently; builds take
turns (:data:`BUILD_LOCK`), since neither the CAD kernel nor matplotlib promise thread safety.

Endpoints: ``GET /`` the page (``?template=NAME`` picks the starting values), ``GET /schema.json``,
``POST /predict`` and ``POST /build`` with ``{"spec": {...}}``. Errors come back as
``{"error": {"field": "neck.diameter", "message": "..."}}`` (HTTP 422 for a bad spec or a design-rule failure).
"""

from __future__ import annotations

import base64
import io
import json
import tempfile
import threading
import tomllib
import zipfile
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from pathlib import Path
from urllib.parse import parse_qs, urlparse

from matcad.init import DEFAULT_TEMPLATE

HOST = "127.0.0.1"
DEFAULT_PORT = 8765
MAX_BODY_BYTES = 64 * 1024
"""A spec is a few kB of JSON; anything bigger is refused before it is read."""
BUILD_LOCK = threading.Lock()
MIME = {".png": "image/png", ".svg": "image/svg+xml"}


def _error(field, message: str) -> dict:
    return {"error": {"field": field, "message": message}}


def _spec(payload: dict):
    from matcad.spec import from_dict

    data = payload.get("spec")
    if not isinstance(data, dict):
        raise ValueError('the request must be {"spec": {...}}')
    return from_dict(data)


def predict_json(payload: dict) -> dict:
    """The prediction for the request's spec, as plain data (Hz, mm)."""
    from matcad.prediction import predict
    from matcad.spec import spec_notes

    spec = _spec(payload)
    p = predict(spec)
    return {"name": spec.name, "f0_hz": p.f0_hz, "band_hz": list(p.band_hz), "model": p.model,
            "models": {k: {"f0_hz": m.f0_hz, "valid": m.valid} for k, m in p.models.items()},
            "budget": [{"source": b.source, "low_hz": b.low_hz, "high_hz": b.high_hz} for b in p.budget],
            "warnings": list(p.warnings), "notes": spec_notes(spec, payload["spec"])}


def build_json(payload: dict) -> tuple[int, dict]:
    """Build the request's spec in a temporary folder: the kit as a base64 zip and the previews as data URIs."""
    from matcad.build import DesignRuleFailure, build
    from matcad.report import KIT_ARCHIVE

    spec = _spec(payload)
    with BUILD_LOCK, tempfile.TemporaryDirectory(prefix="matcad-serve-") as tmp:
        try:
            result = build(spec, Path(tmp) / spec.name)
        except DesignRuleFailure as exc:
            errors = [f.to_dict() for f in exc.findings if f.level == "error"]
            return 422, {"error": {"field": errors[0].get("field"), "message": str(exc)}, "findings": errors}
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
            for name in result.files:
                if name != KIT_ARCHIVE:  # the build's own archive of these same files
                    z.write(result.out_dir / name, f"{spec.name}/{name}")
        previews = []
        for fig in result.report.get("figures", ()):
            data = (result.out_dir / fig["file"]).read_bytes()
            previews.append({"caption": fig["caption"], "file": fig["file"],
                             "src": f"data:{MIME[Path(fig['file']).suffix]};base64,"
                                    f"{base64.b64encode(data).decode()}"})
    return 200, {"name": spec.name, "verdict": result.report["verdict"], "files": list(result.files),
                 "zip": base64.b64encode(buf.getvalue()).decode(), "previews": previews,
                 "findings": [f.to_dict() for f in result.findings if f.level != "info"]}


def page_html(template: str) -> str:
    """The design page with the schema and the template's values built in (no network, no external files)."""
    from matcad.init import template_names, template_path
    from matcad.spec import schema

    raw = tomllib.loads(template_path(template).read_text(encoding="utf-8"))
    boot = json.dumps({"schema": schema(), "initial": raw, "template": template,
                       "templates": template_names()}).replace("</", "<\\/")
    page = (resources.files("matcad") / "web" / "design.html").read_text(encoding="utf-8")
    return page.replace("/*BOOT*/null", boot)


class Handler(BaseHTTPRequestHandler):
    server_version = "matcad"

    def log_message(self, fmt, *args):  # quiet: the terminal shows the URL, not every request
        pass

    def _send(self, status: int, body: bytes, ctype: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(body)

    def _json(self, status: int, data: dict) -> None:
        self._send(status, json.dumps(data, allow_nan=False).encode(), "application/json")

    def do_GET(self):
        url = urlparse(self.path)
        try:
            if url.path == "/":
                template = parse_qs(url.query).get("template", [DEFAULT_TEMPLATE])[0]
                self._send(200, page_html(template).encode(), "text/html; charset=utf-8")
            elif url.path == "/schema.json":
                from matcad.spec import schema

                self._json(200, {"schema": schema()})
            else:
                self._json(404, _error(None, f"no page {url.path}"))
        except ValueError as exc:
            self._json(400, _error("template", str(exc)))

    def do_POST(self):
        routes = {"/predict": lambda p: (200, predict_json(p)), "/build": build_json}
        route = routes.get(urlparse(self.path).path)
        if route is None:
            return self._json(404, _error(None, f"no endpoint {self.path}"))
        try:
            length = int(self.headers.get("Content-Length", ""))
        except ValueError:
            return self._json(411, _error(None, "Content-Length required"))
        if not 0 < length <= MAX_BODY_BYTES:
            self.close_connection = True
            return self._json(413, _error(None, f"request body must be 1-{MAX_BODY_BYTES} bytes"))
        from matcad.spec import SpecError

        try:
            payload = json.loads(self.rfile.read(length))
            if not isinstance(payload, dict):
                raise ValueError('the request must be {"spec": {...}}')
            status, data = route(payload)
        except SpecError as exc:
            status, data = 422, _error(exc.field, str(exc))
        except (ValueError, OSError) as exc:  # bad JSON, a rule the kernel refuses, an unwritable temp folder
            status, data = 422, _error(getattr(exc, "field", None), str(exc))
        self._json(status, data)


def make_server(port: int = DEFAULT_PORT) -> ThreadingHTTPServer:
    """The design page's server on 127.0.0.1:``port`` (0 picks a free port); call ``serve_forever``."""
    server = ThreadingHTTPServer((HOST, port), Handler)
    server.daemon_threads = True
    return server
