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
"""Deflection of the preview mesh, relative as build123d's ``tessellate`` passes it (0.08 x each edge's size;
on the parts' small circles the angular tolerance governs): a few thousand triangles a part."""
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

def _lists(name: str, colour: str, vertices, triangles) -> dict:
    """A mesh as the page's viewer draws it: flat vertex list (x, y, z mm, 3 decimals) and triangle indices."""
    import numpy as np

    return {"name": name, "colour": colour, "vertices": (np.round(vertices, 3) + 0.0).ravel().tolist(),
            "triangles": np.asarray(triangles, dtype=np.int64).ravel().tolist()}


def _mesh(name: str, solid, colour: str) -> dict:
    """One solid as the page's viewer draws it (:func:`_lists`), triangulated at the preview's tolerance."""
    from matcad.serve.tessellate import triangulate

    return _lists(name, colour, *triangulate(solid, MESH_TOLERANCE_MM, ANGULAR_TOLERANCE_RAD))


ACOUSTIC_TABLES = ("air", "wall", "microphone", "silicone", "calibration", "mechanics", "reference", "measured")
"""Spec tables no solid reads (the physics' inputs): an edit there rebuilds no part."""
CAP_ONLY = ("cavity_diameter", "cavity_length", "cap_top_thickness", "calibration")
"""[[taxel]] keys only that taxel's cap reads: an edit there rebuilds that cap alone."""
CACHE_SIZE = 128
"""Solids kept, and meshes kept, least recently used dropped first: a board's 18 parts for several edits (a mesh
is up to ~1 MB of lists)."""
TOOL_CACHE_SIZE = 1024
"""Meshes of the molds' tools kept (:class:`matcad.parts.recipe.Tool`; a board's mold has ~80, mostly vent
cylinders of a few kB)."""


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
    each tool of the mold (:class:`matcad.parts.recipe.Tool`) by its call, a cap's spec in it without the physics'
    tables (:func:`_tool_key`), and the mold by its tools. An edit to one taxel's cavity rebuilds its cap and
    meshes its mold tools only; a move rebuilds the board's flat parts, mount and needles but no cap and no mold
    tool. ``built`` counts the parts built and the mold tools meshed (name → times), for the tests."""

    def __init__(self):
        from collections import Counter, OrderedDict

        self.solids: OrderedDict = OrderedDict()
        self.meshes: OrderedDict = OrderedDict()
        self.tools: OrderedDict = OrderedDict()
        self.built: Counter = Counter()

    @staticmethod
    def _get(store, key, make, size: int = CACHE_SIZE):
        if key in store:
            store.move_to_end(key)
            return store[key]
        value = store[key] = make()
        if len(store) > size:
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

    def mold(self, recipe) -> tuple:
        """The printed mold part ``recipe`` makes (design frame) as a manifold3d mesh, made from its tools' meshes
        (:func:`matcad.serve.tessellate.recipe_mesh`), and its key. Each tool is meshed once and kept (``built``
        counts the tools meshed by their function's name)."""
        from matcad.serve.tessellate import manifold, recipe_mesh

        keys = {tool: _tool_key(tool) for tool in (recipe.stock, *recipe.add, *recipe.cut)}

        def tool_meshes(tool):
            return self._get(self.tools, keys[tool], lambda: self._count(
                tool.make.__name__, lambda: [manifold(s, MESH_TOLERANCE_MM, ANGULAR_TOLERANCE_RAD)
                                             for s in tool.solids()]), TOOL_CACHE_SIZE)

        key = ("mold", *keys.values())
        return self._get(self.solids, key, lambda: recipe_mesh(recipe, tool_meshes)), key

    def mold_mesh(self, name: str, recipe, x: float, colour: str) -> tuple[dict, float]:
        """The page's mesh of the mold part ``name`` (:meth:`mold`) set with its lowest x at ``x``, centred on
        y = 0, its underside on z = 0, kept; and its length along x (mm)."""
        mold, key = self.mold(recipe)
        (x0, y0, z0), (x1, y1, _) = _corners(mold)
        move = (x - x0, -(y0 + y1) / 2, -z0)

        def draw():
            mesh = mold.translate(move).to_mesh()
            return _lists(name, colour, mesh.vert_properties[:, :3], mesh.tri_verts)

        return self._get(self.meshes, (key, move, colour), draw) | {"name": name}, x1 - x0

    def mesh(self, key, name: str, solid, colour: str) -> dict:
        """:func:`_mesh` of ``solid`` (made from ``key``; its bounding box tells where it was placed), kept."""
        box = solid.bounding_box()
        where = tuple(round(c, 6) for c in (box.min.X, box.min.Y, box.min.Z, box.max.X, box.max.Y, box.max.Z))
        return self._get(self.meshes, (key, where, colour), lambda: _mesh(name, solid, colour)) | {"name": name}


def _tool_key(tool) -> tuple:
    """The key a mold tool's mesh is kept by: its function and arguments, a spec among them without the tables no
    solid reads (:func:`_projection`)."""
    from matcad.spec import Spec

    return tool.make, tuple(_projection(a) if isinstance(a, Spec) else a for a in tool.args)


def _corners(mesh) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """The lowest and highest corner of a manifold3d mesh's bounding box (mm)."""
    x0, y0, z0, x1, y1, z1 = mesh.bounding_box()
    return (x0, y0, z0), (x1, y1, z1)


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
"""A mesh request's ``what`` → the groups it draws: the page asks for the assembly, then the molds (the slower on
a board: any cap edit meshes that cap's mold tools and redoes the mold's mesh booleans), so an edit made meanwhile
waits for the assembly only."""


def meshes(spec, cache: PartCache | None = None, groups=("assembly", "molds")) -> dict:
    """The meshes of the assembled parts (group "assembly") and of the cap mold's parts when the spec asks for the
    mold (group "molds"), the molds set beside the plate (+x), and the time it took (ms)."""
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
        if "molds" in groups and part(name).wanted(spec):
            mesh, length = cache.mold_mesh(name, part(name).recipe(spec), x,
                                           "#b0b8c8" if name.endswith("lid") else "#8890a8")
            out.append(mesh)
            x += length + 4.0
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
