"""What the design server's parts share: its limits (sizes bytes, times s) and how a request is refused."""

from __future__ import annotations

HOST = "127.0.0.1"
DEFAULT_PORT = 8765
MAX_BODY_BYTES = 64 * 1024
"""A spec is a few kB of JSON; anything bigger is refused before it is read."""
WORKERS = 2
"""Predictions computed at once (the machine's cores; more only queue on the interpreter lock)."""
BUILDS = 1
"""Builds at once: each is a `matcad build` process loading the CAD kernel (~0.5 GB)."""
MAX_CONNECTIONS = 32
"""Connections being read, computed, waiting or answered at once; one thread each. Beyond: 503 at once."""
BACKLOG = 128
"""Listen backlog: a burst of connections waits in the kernel for the accepting thread instead of being reset."""
QUEUE_WAIT_S = 60.0
REQUEST_DEADLINE_S = 10.0
"""The whole request, headers and body (≤ 64 KiB), must arrive within this: a stalled upload frees its thread."""
WRITE_TIMEOUT_S = 30.0
BUILD_TIMEOUT_S = 900.0
MIME = {".png": "image/png", ".svg": "image/svg+xml"}


class Refused(Exception):
    """A request refused with an HTTP status and a message."""

    def __init__(self, status: int, message: str, field: str | None = None):
        super().__init__(message)
        self.status, self.field = status, field


def error(field, message: str) -> dict:
    """The JSON error object the page shows next to ``field``."""
    return {"error": {"field": field, "message": message}}


def spec_of(payload: dict):
    """The validated spec of a request ``{"spec": {...}}`` (SpecError, ValueError otherwise)."""
    from matcad.spec import from_dict

    data = payload.get("spec")
    if not isinstance(data, dict):
        raise ValueError('the request must be {"spec": {...}}')
    spec = from_dict(data)
    if spec.kind == "tube":
        raise ValueError("the design page edits MAT specs; a kind = 'tube' spec goes to matcad predict, check, build "
                         "and design (docs/tube.md)")
    return spec
