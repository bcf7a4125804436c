"""The design page as a user meets it, timed in headless Chromium against a fresh in-process server.

  board      open ?template=mat-array-4 in a fresh server: ms from navigation to the four bands drawn (browser's
             performance.now() when the chart is drawn), and to their rise under load drawn (the cap mechanics,
             FElupe per cap unless in the cache: MATCAD_CACHE_DIR=<empty folder> times a first visit), then again
             on a second page load (server warm)
  section    mat-paper: the first section (the preview process loads the CAD kernel), then N edits of
             cavity.length, each timed from the edit's request to the section shown (ms, median and max)
  mesh       the 3-D view's meshes after the first section: the assembly, then with the mold (ms)
  board-section  the same for the board's section: the first, then N edits of t1's cavity_length (the taxel in the
             section's plane), each timed from the edit's request to the section shown and to the meshes shown (the
             preview process keeps built parts: an edit rebuilds the edited taxel's cap and the mold only)

  mold-edit  no browser, in this process: the preview's own work for N edits of t1's cavity_length on the board
             with its cache warm, CPU s (process_time, every thread) and wall s per edit: the mold's meshes (mesh
             booleans of the kept tool meshes, matcad.serve.tessellate) and the assembly's; against the B-rep route
             the preview took before (the build's mold solids, booleans in the kernel, build123d's
             tessellate at the preview's tolerance) and the ratio

With --shots DIR it saves a screenshot of the board page and of the single-taxel page there (PNG). --cpu runs the
mold-edit rows only.

Run: PYTHONPATH=. .venv/bin/python benchmarks/page.py [N] [--shots DIR] [--cpu]   (default N 5)
"""

from __future__ import annotations

import statistics
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from matcad.serve import make_server  # noqa: E402
from tests.browser import chromium  # noqa: E402


def wait(driver, script: str, timeout: float = 300.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = driver.execute_script(script)
        if value:
            return value
        time.sleep(0.05)
    raise TimeoutError(script)


def edits_timed(driver, field: str, values: list[float]) -> tuple[list[float], list[float], list[float]]:
    """Set input ``field`` to each value in turn, waiting for the section and the meshes after each: (section ms,
    assembly mesh ms, assembly + mold meshes ms) per edit, from each request, as the page timed them."""
    sections, meshes, molds = [], [], []
    for value in values:
        before = driver.execute_script("return window.matcad.previewMs.length")
        driver.execute_script(f"const b = document.getElementById('{field}'); b.value = '{value:.2f}'; "
                              "b.dispatchEvent(new Event('input')); "
                              "window.matcad.meshMs = window.matcad.moldMs = null;")
        wait(driver, f"return window.matcad.previewMs.length > {before}")
        sections.append(driver.execute_script("return window.matcad.previewMs[window.matcad.previewMs.length - 1]"))
        meshes.append(wait(driver, "return window.matcad.meshMs"))
        molds.append(wait(driver, "return window.matcad.moldMs"))
        wait(driver, "return !previewBusy")
    return sections, meshes, molds


def timed(work) -> tuple[float, float]:
    """(CPU s, wall s) of ``work()``."""
    cpu, wall = time.process_time(), time.perf_counter()
    work()
    return time.process_time() - cpu, time.perf_counter() - wall


def mold_edits_cpu(n: int) -> None:
    """The mold-edit rows (module docstring): median (max) CPU and wall s per edit."""
    import copy
    import tomllib

    from matcad.parts.registry import part
    from matcad.serve import preview
    from matcad.spec import from_dict

    data = tomllib.loads((ROOT / "templates" / "mat-array-4.toml").read_text(encoding="utf-8"))
    cache = preview.PartCache()
    first = timed(lambda: preview.meshes(from_dict(data), cache))
    print(f"mold-edit  board, first meshes (every part built): {first[0]:6.2f} s CPU, {first[1]:6.2f} s wall")
    rows = {"molds": [], "assembly": [], "B-rep molds": []}
    for i in range(n):
        edited = copy.deepcopy(data)
        edited["taxel"][0]["cavity_length"] = 4.5 + 0.05 * i
        spec = from_dict(edited)
        rows["molds"].append(timed(lambda: preview.meshes(spec, cache, groups=("molds",))))
        rows["assembly"].append(timed(lambda: preview.meshes(spec, cache, groups=("assembly",))))
        rows["B-rep molds"].append(timed(lambda: [part(name).make(spec).tessellate(preview.MESH_TOLERANCE_MM,
                                                                                   preview.ANGULAR_TOLERANCE_RAD)
                                                  for name in preview.MOLD_PARTS]))
    for name, times in rows.items():
        cpu, wall = [statistics.median(t[k] for t in times) for k in (0, 1)]
        print(f"mold-edit  board, t1 cavity_length x {n}, {name:12s}: median {cpu:6.3f} s CPU "
              f"(max {max(t[0] for t in times):.3f}), {wall:6.3f} s wall")
    ratio = statistics.median(t[0] for t in rows["B-rep molds"]) / statistics.median(t[0] for t in rows["molds"])
    print(f"mold-edit  B-rep route / mesh booleans, CPU: {ratio:5.1f}x")


def main(argv: list[str]) -> None:
    n = int(argv[0]) if argv and argv[0].isdigit() else 5
    shots = Path(argv[argv.index("--shots") + 1]) if "--shots" in argv else None
    mold_edits_cpu(n)
    if "--cpu" in argv:
        return
    server = make_server(0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    url = f"http://127.0.0.1:{server.server_address[1]}"
    try:
        with chromium() as d:
            d.set_window_size(1500, 1900)
            for visit in ("cold", "warm"):
                d.get(url + "/?template=mat-array-4")
                ms = wait(d, "return document.querySelectorAll('#bandchart g.band').length === 4 "
                             "&& window.matcad.bandsShownMs")
                risen = wait(d, "return window.matcad.riseShownMs")
                print(f"board {visit}: page opened -> 4 bands shown {ms:8.0f} ms, with their rise under load "
                      f"{risen:8.0f} ms")
            first = wait(d, "return window.matcad.previewMs.length && window.matcad.previewMs[0]")
            mesh, mold = wait(d, "return window.matcad.meshMs"), wait(d, "return window.matcad.moldMs")
            print(f"board-section first {first:8.0f} ms   board mesh: assembly {mesh:8.0f} ms, with the mold "
                  f"{mold:8.0f} ms")
            sections, meshes, molds = edits_timed(d, "in-taxel[1].cavity_length", [4.5 + 0.1 * i for i in range(n)])
            print(f"board edits (t1 cavity_length, {n}), median (max) ms from the request: section shown "
                  f"{statistics.median(sections):6.0f} ({max(sections):.0f}); assembly meshes shown "
                  f"{statistics.median(meshes):6.0f} ({max(meshes):.0f}); with the mold "
                  f"{statistics.median(molds):6.0f} ({max(molds):.0f})")
            if shots:
                shots.mkdir(parents=True, exist_ok=True)
                d.save_screenshot(str(shots / "page-board.png"))
            d.get(url + "/?template=mat-paper")
            wait(d, "return window.matcad.meshMs")
            times = []
            for i in range(n):
                before = d.execute_script("return window.matcad.previewMs.length")
                d.execute_script("const b = document.getElementById('in-cavity.length'); "
                                 f"b.value = '{4.5 + 0.1 * i:.2f}'; b.dispatchEvent(new Event('input'));")
                wait(d, f"return window.matcad.previewMs.length > {before}")
                times.append(d.execute_script("return window.matcad.previewMs[window.matcad.previewMs.length - 1]"))
                wait(d, "return !previewBusy")
            edits = d.execute_script("return window.matcad.editToSectionMs")
            print(f"section request -> shown (mat-paper, {n} edits): median {statistics.median(times):6.0f} ms, "
                  f"max {max(times):6.0f} ms")
            print(f"edit -> f0 predicted -> section shown (debounces 200 + 150 ms included): median "
                  f"{statistics.median(edits):6.0f} ms, max {max(edits):6.0f} ms")
            if shots:
                d.save_screenshot(str(shots / "page-taxel.png"))
    finally:
        server.shutdown()
        server.server_close()


if __name__ == "__main__":
    main(sys.argv[1:])
