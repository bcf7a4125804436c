"""`matcad serve`: a local design page — the spec as a form, live prediction, build to a zip with previews.

stdlib only (``http.server``), bound to 127.0.0.1. The server keeps no state: each request carries the whole spec
as JSON; a build runs as its own `matcad build` process in its own temporary folder, is zipped into the response
and the folder deleted; the section and meshes of the preview come from one child process holding the CAD
kernel (:mod:`matcad.serve.preview`). Endpoints: ``GET /`` the page (``?template=NAME`` picks the starting
values), ``GET /schema.json``, ``GET /progress?build=ID`` (a running build's stage), ``POST /predict`` (a taxel
or a whole board), ``/preview``, ``/build``, ``/toml`` with ``{"spec": {...}}`` and ``POST /parse`` with
``{"toml": "..."}`` (docs/page.md). Errors come back as ``{"error": {"field": "neck.diameter", "message": "..."}}``.

What it refuses, and how (times s, sizes bytes):

- another site's page in the user's browser: a ``Host`` other than 127.0.0.1 or localhost with the server's port
  (DNS rebinding) → 403; a POST whose ``Origin`` is not this server, or marked ``Sec-Fetch-Site: cross-site`` →
  403; a body that is not ``Content-Type: application/json`` (the only kind a page elsewhere cannot send without
  a CORS preflight, which is never granted) → 415;
- bodies over :data:`MAX_BODY_BYTES` → 413, without a Content-Length → 411, not JSON or nested deeper than
  :data:`matcad.spec.io.MAX_NESTING` levels → 422, a bad spec or a design-rule failure → 422;
- more than :data:`MAX_CONNECTIONS` connections at once → 503 at once, from the accepting thread (``Retry-After``);
  a request that waits more than :data:`QUEUE_WAIT_S` for one of the :data:`WORKERS` (predictions) or the one
  build slot → 503; a request whose headers and body do not arrive within :data:`REQUEST_DEADLINE_S` → dropped
  (408 when it can still be told); a reply not taken within :data:`WRITE_TIMEOUT_S` per send → dropped. A client
  that disconnects is dropped quietly. So the threads stay at most MAX_CONNECTIONS + 1, whatever clients do.

Stopping the server (:meth:`DesignServer.server_close`, Ctrl-C in `matcad serve`) ends every build process and
removes every temporary folder, also mid-build.
"""

from matcad.serve.common import (BUILDS, DEFAULT_PORT, HOST, MAX_BODY_BYTES, MAX_CONNECTIONS, QUEUE_WAIT_S,
                                 REQUEST_DEADLINE_S, WORKERS, WRITE_TIMEOUT_S)
from matcad.serve.server import DesignServer, build_json, make_server, page_html, predict_json

__all__ = ["BUILDS", "DEFAULT_PORT", "HOST", "MAX_BODY_BYTES", "MAX_CONNECTIONS", "QUEUE_WAIT_S", "REQUEST_DEADLINE_S",
           "WORKERS", "WRITE_TIMEOUT_S", "DesignServer", "build_json", "make_server", "page_html", "predict_json"]
