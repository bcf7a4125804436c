"""The design page's geometry preview: the report's dimensioned section (section.svg,
:func:`matcad.render.section.write_section_svg`) and a coarse mesh of the assembled stack, the cap mold and the
plate for the page's 3-D view. Lengths mm, times ms.

Both need the CAD kernel (build123d, ~0.5 GB and seconds to import), which the server process never loads (its
predictions stay light): :class:`PreviewWorker` keeps ONE child process, ``python -m matcad.serve.preview``,
that imports the kernel once and then answers one request per line (JSON in on stdin, JSON out on stdout), so
each preview after the first costs only the geometry (measure: ``benchmarks/page.py``). The child is started when
the page is served (:meth:`PreviewWorker.warm`) or on the first preview, restarted if it dies or overruns
:data:`PREVIEW_TIMEOUT_S`, and ended with the server. It keeps the parts it built (:class:`PartCache`): an edit
rebuilds only the parts built from the fields it changed.
"""

from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

PREVIEW_TIMEOUT_S = 120.0
"""The first preview imports the CAD kernel (5-15 s on a loaded 2-core machine); a board's parts take seconds."""
MESH_TOLERANCE_MM = 0.08
"""Chordal deviation of the preview mesh: coarse enough for a few thousand triangles a part."""
ANGULAR_TOLERANCE_RAD = 0.35
MOLD_PARTS = ("end_cap_mold_base", "end_cap_mold_lid")
"""Printed parts drawn beside the assembly (they are not in it)."""


class PreviewWorker:
    """The one preview child process of a server (see the module docstring); thread-safe, one request at a time."""

    def __init__(self):
        self.lock = threading.Lock()
        self.proc: subprocess.Popen | None = None
        self.stopped = False

    def _start(self) -> subprocess.Popen:
        package_root = str(Path(__file__).resolve().parents[2])
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [package_root,
                                                                         os.environ.get("PYTHONPATH")]))}
        return subprocess.Popen([sys.executable, "-m", "matcad.serve.preview"], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)

    def warm(self) -> None:
        """Start the child now if none runs and no preview is in flight (the page was just opened: the child loads
        the CAD kernel while the page predicts, and its first preview costs only the geometry)."""
        if not self.lock.acquire(blocking=False):
            return
        try:
            if not self.stopped and (self.proc is None or self.proc.poll() is not None):
                self.proc = self._start()
        finally:
            self.lock.release()

    def ask(self, spec_data: dict, what: str = "section", timeout_s: float = PREVIEW_TIMEOUT_S) -> dict:
        """The preview of the validated spec data ``spec_data``: ``what`` = "section" → {"svg", "ms"}, "mesh",
        "assembly" or "molds" (:data:`MESHES`) → {"parts", "ms"}; or {"error": ...}.
        TimeoutError when the child does not answer within ``timeout_s`` (it is then ended)."""
        from matcad.serve.common import Refused

        with self.lock:
            if self.stopped:
                raise Refused(503, "the server is stopping")
            if self.proc is None or self.proc.poll() is not None:
                self.proc = self._start()
            proc = self.proc
            try:
                proc.stdin.write(json.dumps({"spec": spec_data, "what": what}).encode() + b"\n")
                proc.stdin.flush()
                line = _read_line(proc.stdout, time.monotonic() + timeout_s)
            except (OSError, TimeoutError) as exc:
                self._end()
                raise Refused(503 if self.stopped else 504, f"the preview did not finish ({exc})") from None
            return json.loads(line)

    def _end(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None

    def stop(self) -> None:
        """End the child (the server is stopping); a request in flight gets 503."""
        self.stopped = True
        proc = self.proc
        if proc is not None and proc.poll() is None:
            proc.kill()  # unblocks a reader waiting under the lock
        with self.lock:
            self._end()


def _read_line(pipe, deadline: float) -> bytes:
    """One line from ``pipe`` by ``deadline`` (monotonic s); TimeoutError, or OSError if the child ended."""
    data = b""
    fd = pipe.fileno()
    while not data.endswith(b"\n"):
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError(f"no answer within {PREVIEW_TIMEOUT_S:g} s")
        ready, _, _ = select.select([fd], [], [], left)
        if ready:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                raise OSError("the preview process ended")
            data += chunk
    return data


# ---- the child's side -----------------------------------------------------------------------------------------

def _mesh(name: str, solid, colour: str) -> dict:
    """One solid as the page's viewer draws it: flat vertex list (x, y, z mm, 3 decimals) and triangle indices."""
    vertices, triangles = solid.tessellate(MESH_TOLERANCE_MM, ANGULAR_TOLERANCE_RAD)
    return {"name": name, "colour": colour,
            "vertices": [round(c, 3) for v in vertices for c in (v.X, v.Y, v.Z)],
            "triangles": [i for t in triangles for i in t]}


ACOUSTIC_TABLES = ("air", "wall", "microphone", "silicone", "calibration", "mechanics", "reference", "measured")
"""Spec tables no solid reads (the physics' inputs): an edit there rebuilds no part."""
CAP_ONLY = ("cavity_diameter", "cavity_length", "cap_top_thickness", "calibration")
"""[[taxel]] keys only that taxel's cap reads: an edit there rebuilds that cap alone."""
MOLD_IGNORES = ("x", "y")
"""[[taxel]] keys the cap mold does not read (it casts the caps side by side, wherever they sit on the plate)."""
CACHE_SIZE = 128
"""Solids kept, and meshes kept, least recently used dropped first: a board's 18 parts for several edits (a mesh
is up to ~1 MB of lists, a mold solid a few MB)."""


def _projection(spec, drop: tuple[str, ...] = ()) -> str:
    """``spec`` as text without the tables no solid reads, the shared [cavity] if ``drop`` names it, and the
    [[taxel]] keys ``drop`` names: the key of the parts built from it."""
    import dataclasses

    data = dataclasses.asdict(spec)
    for table in ACOUSTIC_TABLES + tuple(t for t in drop if t == "cavity"):
        data.pop(table, None)
    data["taxel"] = [{k: v for k, v in entry.items() if k not in drop} for entry in data.get("taxel", ())]
    return repr(data)


class PartCache:
    """The child's solids and meshes kept between requests, keyed by what they are built from: a board part by the
    spec without the physics' tables and the caps' own fields; a cap by its single-taxel spec (position dropped);
    the mold by the spec without the physics' tables and the positions. An edit to one taxel's cavity rebuilds its
    cap and the mold only; a move rebuilds the board's flat parts, mount and needles but no cap and no mold. ``built``
    counts the parts built (name → times), for the tests."""

    def __init__(self):
        from collections import Counter, OrderedDict

        self.solids: OrderedDict = OrderedDict()
        self.meshes: OrderedDict = OrderedDict()
        self.built: Counter = Counter()

    @staticmethod
    def _get(store, key, make):
        if key in store:
            store.move_to_end(key)
            return store[key]
        value = store[key] = make()
        if len(store) > CACHE_SIZE:
            store.popitem(last=False)
        return value

    def assembled(self, spec) -> tuple[dict, dict]:
        """The assembled parts of ``spec`` (name → solid, :func:`matcad.parts.assembly.assembled_parts`) and each
        one's cache key (name → key)."""
        from matcad.parts.assembly import assembled_parts

        board_key, keys = _projection(spec, ("cavity", *CAP_ONLY)), {}

        def memo(name, cap, build):
            key = keys[name] = ("end_cap", _projection(cap)) if cap is not None \
                else (name, board_key)
            return self._get(self.solids, key, lambda: self._count(name, build))

        parts = assembled_parts(spec, memo=memo)
        return parts, keys

    def _count(self, name, build):
        self.built[name] += 1
        return build()

    def mold(self, spec, name: str):
        """The printed mold part ``name`` of ``spec`` (design frame) and its key."""
        from matcad.parts.registry import part

        key = (name, _projection(spec, MOLD_IGNORES))
        return self._get(self.solids, key, lambda: self._count(name, lambda: part(name).make(spec))), key

    def mesh(self, key, name: str, solid, colour: str) -> dict:
        """:func:`_mesh` of ``solid`` (made from ``key``; its bounding box tells where it was placed), kept."""
        box = solid.bounding_box()
        where = tuple(round(c, 6) for c in (box.min.X, box.min.Y, box.min.Z, box.max.X, box.max.Y, box.max.Z))
        return self._get(self.meshes, (key, where, colour), lambda: _mesh(name, solid, colour)) | {"name": name}


CACHE = PartCache()
"""The child's one cache."""


def section(spec, cache: PartCache | None = None) -> dict:
    """The report's dimensioned section of ``spec`` as SVG text, and the time it took (ms); parts from ``cache``
    (default :data:`CACHE`)."""
    from matcad.render.section import write_section_svg

    t0 = time.perf_counter()
    parts, _ = (cache or CACHE).assembled(spec)
    with tempfile.TemporaryDirectory(prefix="matcad-preview-") as tmp:
        path = Path(tmp) / "section.svg"
        write_section_svg(spec, path, parts)
        svg = path.read_text(encoding="utf-8")
    return {"svg": svg, "ms": round(1e3 * (time.perf_counter() - t0))}


MESHES = {"mesh": ("assembly", "molds"), "assembly": ("assembly",), "molds": ("molds",)}
"""A mesh request's ``what`` → the groups it draws: the page asks for the assembly, then the molds (slow on a
board: the mold is rebuilt on any cap edit), so an edit made meanwhile waits for the assembly only."""


def meshes(spec, cache: PartCache | None = None, groups=("assembly", "molds")) -> dict:
    """The meshes of the assembled parts (group "assembly") and of the cap mold's parts when the spec asks for the
    mold (group "molds"), the molds set beside the plate (+x), and the time it took (ms)."""
    from build123d import Pos

    from matcad.parts.registry import part
    from matcad.render.section import layer_of, section_colours

    t0 = time.perf_counter()
    colours, cache = section_colours(), cache or CACHE
    out = []
    if "assembly" in groups:
        parts, keys = cache.assembled(spec)
        out = [cache.mesh(keys[name], name, solid, colours.get(layer_of(name), "#999999")) if name in keys
               else _mesh(name, solid, colours.get(layer_of(name), "#999999")) for name, solid in parts.items()]
    x = spec.plate.width / 2 + 6.0
    for name in MOLD_PARTS:
        if "molds" not in groups or not part(name).wanted(spec):
            continue
        solid, key = cache.mold(spec, name)
        box = solid.bounding_box()
        placed = Pos(x - box.min.X, -(box.min.Y + box.max.Y) / 2, -box.min.Z) * solid
        x += box.max.X - box.min.X + 4.0
        out.append(cache.mesh(key, name, placed, "#b0b8c8" if name.endswith("lid") else "#8890a8"))
    return {"parts": out, "ms": round(1e3 * (time.perf_counter() - t0))}


def serve_requests(stdin, stdout) -> None:
    """Answer one JSON line per request line until stdin closes (the child's loop)."""
    import build123d  # noqa: F401 - the kernel is loaded once, before the first request

    from matcad.spec import SpecError, from_dict

    for line in stdin:
        try:
            request = json.loads(line)
            what = request.get("what", "section")
            answer = meshes(from_dict(request["spec"]), groups=MESHES[what]) if what in MESHES \
                else section(from_dict(request["spec"]))
        except (SpecError, ValueError) as exc:
            answer = {"error": {"field": getattr(exc, "field", None), "message": str(exc)}}
        except Exception as exc:  # noqa: BLE001 - a bug in a preview is told to the page, the child lives on
            answer = {"error": {"field": None, "message": f"preview failed ({exc.__class__.__name__}: "
                                                          f"{str(exc)[:200]})"}}
        stdout.write(json.dumps(answer, allow_nan=False).encode() + b"\n")
        stdout.flush()


if __name__ == "__main__":
    out = sys.stdout.buffer
    sys.stdout = sys.stderr  # the kernel's chatter must not garble the protocol
    try:
        serve_requests(sys.stdin.buffer, out)
    except KeyboardInterrupt:
        pass
