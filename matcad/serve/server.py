"""The design page's HTTP server: one thread per connection, at most MAX_CONNECTIONS of them, each request checked
(Host, Origin, content type, size, deadline) before its spec is predicted or built (see :mod:`matcad.serve`)."""

from __future__ import annotations

import io
import json
import sys
import threading
import time
import tomllib
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from urllib.parse import parse_qs, urlparse

from matcad.init import DEFAULT_TEMPLATE
from matcad.serve.builds import Builds, build_json
from matcad.serve.common import (BACKLOG, BUILDS, DEFAULT_PORT, HOST, MAX_BODY_BYTES, MAX_CONNECTIONS, QUEUE_WAIT_S,
                                 REQUEST_DEADLINE_S, WORKERS, WRITE_TIMEOUT_S, Refused, error, spec_of)
from matcad.serve.page import predict_json, spec_from_toml, spec_toml
from matcad.serve.preview import PreviewWorker

__all__ = ["DesignServer", "make_server", "page_html", "predict_json"]


def page_html(template: str) -> str:
    """The design page with the schema and the template's values built in (no network, no external files)."""
    from matcad.init import template_names, template_path
    from matcad.spec import schema

    raw = tomllib.loads(template_path(template).read_text(encoding="utf-8"))
    boot = json.dumps({"schema": schema(), "initial": raw, "template": template,
                       "templates": template_names()}).replace("</", "<\\/")
    web = resources.files("matcad") / "web"
    scripts = "\n".join((web / name).read_text(encoding="utf-8") for name in ("viewer.js", "design.js"))
    if "</script" in scripts.lower():
        raise AssertionError("a page script may not contain '</script'")  # it would end the inline script
    page = (web / "design.html").read_text(encoding="utf-8")
    return page.replace("/*SCRIPTS*/", scripts).replace("/*BOOT*/null", boot)


def preview_json(payload: dict, worker: PreviewWorker) -> tuple[int, dict]:
    """The request's spec (validated here first) drawn by the preview process: ``"what": "section"`` (default) →
    the report's section SVG; ``"mesh"`` → the parts' meshes for the page's 3-D view, ``"assembly"`` or ``"molds"``
    → the assembled parts' or the cap mold's alone (:data:`matcad.serve.preview.MESHES`)."""
    from matcad.serve.preview import MESHES

    spec_of(payload)
    what = payload.get("what", "section")
    if what not in ("section", *MESHES):
        raise Refused(422, f"what {str(what)[:40]!r} invalid, must be one of section, {', '.join(MESHES)}", "what")
    answer = worker.ask(payload["spec"], what)
    return (422 if "error" in answer else 200), answer


class _DeadlineReader(io.RawIOBase):
    """A socket read within an overall deadline (monotonic s): each read waits at most what is left of it."""

    def __init__(self, sock, deadline: float):
        self.sock, self.deadline = sock, deadline

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError("the request did not arrive in time")
        self.sock.settimeout(left)
        return self.sock.recv_into(buffer)


def parse_body(body: bytes) -> dict:
    """A request body as a JSON object within the spec's nesting limit; Refused(422) otherwise."""
    from matcad.spec.io import MAX_NESTING, nesting_depth

    try:
        payload = json.loads(body)
    except RecursionError:
        raise Refused(422, f"the JSON nests deeper than {MAX_NESTING} levels") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise Refused(422, f"the request body must be JSON ({str(exc)[:120]})") from None
    if nesting_depth(payload, MAX_NESTING) > MAX_NESTING:
        raise Refused(422, f"the JSON nests deeper than {MAX_NESTING} levels")
    if not isinstance(payload, dict):
        raise Refused(422, 'the request must be {"spec": {...}}')
    return payload


class Handler(BaseHTTPRequestHandler):
    server_version = "matcad"
    server: DesignServer

    def log_message(self, fmt, *args):  # quiet: the terminal shows the URL, not every request
        pass

    def setup(self) -> None:
        super().setup()
        self.rfile = io.BufferedReader(_DeadlineReader(self.connection, time.monotonic() + REQUEST_DEADLINE_S))

    def handle(self) -> None:
        try:
            super().handle()
        except (OSError, ValueError):  # the client went away or stalled: nothing to tell anyone
            self.close_connection = True

    def finish(self) -> None:
        try:
            super().finish()
        except OSError:
            pass

    def send_error(self, code, message=None, explain=None) -> None:
        """The protocol's own refusals (a garbled request line, a method other than GET and POST, over-long
        headers) as the same JSON error object as every other refusal, not the library's HTML page."""
        self.close_connection = True
        try:
            self._json(code, error(None, f"{code} {message or self.responses.get(code, ('',))[0]}"[:200]))
        except OSError:
            pass

    def _send(self, status: int, body: bytes, ctype: str) -> None:
        self.connection.settimeout(WRITE_TIMEOUT_S)
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        if status == 503:
            self.send_header("Retry-After", "1")
        self.end_headers()
        self.wfile.write(body)

    def _json(self, status: int, data: dict) -> None:
        self._send(status, json.dumps(data, allow_nan=False).encode(), "application/json")

    def _check_host(self) -> None:
        port = self.server.server_address[1]
        host = (self.headers.get("Host") or "").strip().lower()
        if host not in (f"127.0.0.1:{port}", f"localhost:{port}"):
            raise Refused(403, f"Host {host[:80]!r} refused: the design page answers only at http://{HOST}:{port}/")

    def _check_post(self) -> int:
        """Origin, content type and length of a POST; returns the length."""
        port = self.server.server_address[1]
        origin = self.headers.get("Origin")
        if origin is not None and origin not in (f"http://127.0.0.1:{port}", f"http://localhost:{port}"):
            raise Refused(403, f"Origin {origin[:80]!r} refused: only the design page itself may post here")
        if (self.headers.get("Sec-Fetch-Site") or "").lower() == "cross-site":
            raise Refused(403, "a cross-site request is refused: only the design page itself may post here")
        ctype = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
        if ctype != "application/json":
            raise Refused(415, f"Content-Type {ctype[:80]!r} refused: the body must be application/json")
        try:
            length = int(self.headers.get("Content-Length", ""))
        except ValueError:
            raise Refused(411, "Content-Length required") from None
        if not 0 < length <= MAX_BODY_BYTES:
            raise Refused(413, f"request body must be 1-{MAX_BODY_BYTES} bytes")
        return length

    def _answer(self, work) -> None:
        """Run ``work()`` → (status, data) or (status, body bytes, content type) and send it; a refusal, a bad spec
        or a bug becomes a JSON error (:meth:`_failure`); a client that went away, nothing."""
        try:
            status, data, *ctype = work()
        except ConnectionError:
            raise
        except Exception as exc:  # noqa: BLE001 - every failure is told to the page as JSON
            (status, data), ctype = self._failure(exc), []
        if ctype:
            self._send(status, data, ctype[0])
        else:
            self._json(status, data)

    def _failure(self, exc: Exception) -> tuple[int, dict]:
        from matcad.spec import SpecError

        if isinstance(exc, (Refused, TimeoutError)):
            self.close_connection = True
            if isinstance(exc, TimeoutError):
                return 408, error(None, f"the request did not arrive within {REQUEST_DEADLINE_S:g} s")
            return exc.status, error(exc.field, str(exc))
        if isinstance(exc, (SpecError, ValueError)):  # a bad spec, a rule the kernel refuses
            return 422, error(getattr(exc, "field", None), str(exc))
        if isinstance(exc, OSError):
            return 500, error(None, f"the server's file system refused: {exc.strerror or exc}")
        print(f"matcad serve: internal error on {self.command} {self.path[:80]}: {exc.__class__.__name__}: "
              f"{str(exc)[:200]}", file=sys.stderr)  # a bug: one line on the terminal, a 500 to the page
        return 500, error(None, f"internal error ({exc.__class__.__name__}); please report it")

    def do_GET(self):
        def work():
            self._check_host()
            url = urlparse(self.path)
            if url.path == "/":
                template = parse_qs(url.query).get("template", [DEFAULT_TEMPLATE])[0]
                try:
                    html = page_html(template).encode()
                    self.server.preview.warm()  # the page previews once it has predicted: load the kernel now
                    return 200, html, "text/html; charset=utf-8"
                except ValueError as exc:
                    raise Refused(400, str(exc), "template") from None
            if url.path == "/schema.json":
                from matcad.spec import schema

                return 200, {"schema": schema()}
            if url.path == "/progress":
                return 200, self.server.builds.progress(parse_qs(url.query).get("build", [""])[0])
            return 404, error(None, f"no page {url.path}")

        self._answer(work)

    def do_POST(self):
        routes = {"/predict": lambda p: (200, predict_json(p)),
                  "/build": lambda p: build_json(p, self.server.builds),
                  "/preview": lambda p: preview_json(p, self.server.preview),
                  "/toml": lambda p: (200, spec_toml(p)), "/parse": lambda p: (200, spec_from_toml(p))}

        def work():
            self._check_host()
            route = routes.get(urlparse(self.path).path)
            if route is None:
                return 404, error(None, f"no endpoint {self.path[:80]}")
            length = self._check_post()
            payload = parse_body(self.rfile.read(length))
            slot = {"/build": self.server.build_slot, "/preview": self.server.preview_slot}.get(
                urlparse(self.path).path, self.server.workers)
            if not slot.acquire(timeout=QUEUE_WAIT_S):
                raise Refused(503, f"busy: no worker free within {QUEUE_WAIT_S:g} s; try again")
            try:
                return route(payload)
            finally:
                slot.release()

        self._answer(work)


class DesignServer(ThreadingHTTPServer):
    """The design page's server: one thread per connection, at most :data:`MAX_CONNECTIONS` of them."""

    request_queue_size = BACKLOG
    daemon_threads = True

    def __init__(self, port: int):
        self.connections = threading.BoundedSemaphore(MAX_CONNECTIONS)
        self.workers = threading.BoundedSemaphore(WORKERS)
        self.build_slot = threading.BoundedSemaphore(BUILDS)
        self.preview_slot = threading.BoundedSemaphore(1)
        self.builds = Builds()
        self.preview = PreviewWorker()
        super().__init__((HOST, port), Handler)

    def process_request(self, request, client_address):
        if self.builds.stopping or not self.connections.acquire(blocking=False):
            return self._busy(request)
        try:
            super().process_request(request, client_address)
        except BaseException:
            self.connections.release()
            raise

    def process_request_thread(self, request, client_address):
        try:
            super().process_request_thread(request, client_address)
        finally:
            self.connections.release()

    def _busy(self, request) -> None:
        """503 from the accepting thread: never blocks on the client (what it sent is drained, not waited for)."""
        body = json.dumps(error(None, f"busy: {MAX_CONNECTIONS} connections open; try again")).encode()
        head = (f"HTTP/1.0 503 Service Unavailable\r\nContent-Type: application/json\r\nContent-Length: {len(body)}"
                "\r\nRetry-After: 1\r\nConnection: close\r\n\r\n").encode()
        try:
            request.setblocking(False)
            request.send(head + body)
            request.shutdown(1)  # SHUT_WR: the reply is complete
            while request.recv(65536):  # what the client already sent: closing over it would reset the reply
                pass
        except OSError:
            pass
        finally:
            request.close()

    def handleerror(self, request, client_address):
        """A client that went away is no error; anything else is a bug: one line, no traceback."""
        exc = sys.exc_info()[1]
        if not isinstance(exc, OSError):
            print(f"matcad serve: internal error: {exc.__class__.__name__}: {str(exc)[:200]}", file=sys.stderr)

    def server_close(self) -> None:
        """Stop listening, end every build and remove every temporary folder."""
        super().server_close()
        self.preview.stop()
        self.builds.stop()


def make_server(port: int = DEFAULT_PORT) -> DesignServer:
    """The design page's server on 127.0.0.1:``port`` (0 picks a free port); call ``serve_forever``."""
    return DesignServer(port)
