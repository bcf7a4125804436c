"""Every command against its floor, in one run: each matcad command alternated with the bare import (or run) it is
measured against, whole process, medians (issue 25's table).

    python benchmarks/floors.py                       # this checkout, every row
    python benchmarks/floors.py --tree before=/path/to/an/older/checkout --runs 5
    python benchmarks/floors.py --only predict analyze --readme   # also rewrite README's performance table

Each row runs its command and its floor alternately (command, floor, command, floor, ...) in fresh interpreters and
reports the medians (with ``--tree``, the trees take turns at going first: the second of two back-to-back runs was
measured 2-5 % slower, enough to invert a small difference); CPU is user + system time of the process and every process it waited for (``os.wait4``),
peak memory its largest resident set. ``--tree LABEL=PATH`` measures the same commands on another checkout
(``PYTHONPATH=PATH``), alternated with this one, so a before/after table comes from one run on one machine. The
machine's load average is printed with the table: on a shared machine the ratios are what to compare, not the
seconds. Bytecode is written (``PYTHONDONTWRITEBYTECODE`` is cleared) so that matcad is timed as installed.
Prints numbers; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import wave
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable
README_MARK = ("<!-- performance table: benchmarks/floors.py --readme -->", "<!-- end of performance table -->")
LASER = "templates/mat-laser-only.toml"
PAPER = "templates/mat-paper.toml"
RECORDING_S = 10.0


@dataclass
class Row:
    """One line of the table: ``command`` (matcad arguments, or a full argv starting with this interpreter) against ``floor`` (an
    argv; None for an absolute target), compared by ``metric`` ('wall' s, 'cpu' s, 'rate' designs per CPU s or
    'wall_rate' designs per wall s) against ``target`` (a ratio to the floor, or the metric's own value)."""

    key: str
    label: str
    command: list
    floor: list | None
    floor_label: str
    metric: str
    target: str
    runs: int
    variants: int = 0
    results: dict = field(default_factory=dict)


def measure(argv, env, cwd) -> dict:
    """Wall (s), CPU (user + system, s, children included) and peak RSS (MiB) of one process."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    err = proc.stderr.read().decode("utf-8", "replace")
    proc.stderr.close()
    code = os.waitstatus_to_exitcode(status)
    if code not in (0, 1):
        raise RuntimeError(f"{' '.join(map(str, argv))} exited {code}:\n{err[-2000:]}")
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "rss_mib": usage.ru_maxrss / 1024}


def environment(tree: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(tree)
    env["OMP_NUM_THREADS"] = env.get("OMP_NUM_THREADS", "1")
    return env


def write_recording(path: Path, seconds: float) -> None:
    """A 10 s, 44.1 kHz tone wobbling around 4.7 kHz in noise (16-bit PCM)."""
    import numpy as np

    fs = 44100
    t = np.arange(int(seconds * fs)) / fs
    x = 0.3 * np.sin(2 * np.pi * (4700 * t - 20 * 2.5 / (2 * np.pi) * np.cos(2 * np.pi * t / 2.5)))
    x += 0.05 * np.random.default_rng(0).standard_normal(len(t))
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(fs)
        w.writeframes(np.round(x * 30000).astype("<i2").tobytes())


TRACKER_ONLY = ("import sys, time; from matcad.loop.wav import read_mono; from matcad.loop.analyze import analyze; "
                "x, fs = read_mono(sys.argv[1]); analyze(x, fs, (3900.0, 5600.0)); c = time.process_time(); "
                "analyze(x, fs, (3900.0, 5600.0)); print(time.process_time() - c)")
"""The tracker's CPU on the recording, warm (its imports done): what analyze costs beyond loading and writing."""
THROUGHPUT = ("import time, numpy as np; from matcad.acoustics import models; n = 1_000_000; "
              "r = np.random.default_rng(0); d = r.uniform(0.5, 3, n); D = d / r.uniform(0.05, 1, n); "
              "a, s = np.pi * d * d / 4, np.pi * D * D / 4; l = r.uniform(0.5, 20, n); L = r.uniform(0.5, 20, n); "
              "best = min((lambda t: (models.transmission_line_hz(343.0, a, s, l, L), time.perf_counter() - t)[1])"
              "(time.perf_counter()) for _ in range(5)); print(n / best)")


def rows(tmp: Path, quick: bool) -> list[Row]:
    rec = tmp / "tone.wav"
    write_recording(rec, RECORDING_S)
    numpy, b123d = [PY, "-c", "import numpy"], [PY, "-c", "import build123d"]
    few = 3 if quick else 9
    out = [
        Row("predict", f"`predict {PAPER}`", ["predict", PAPER], numpy, '`python -c "import numpy"`', "wall",
            "1.3", 7 if quick else 21),
        Row("laser", f"`build {LASER}`", ["build", LASER, "--out", "{tmp}/laser"], numpy,
            '`python -c "import numpy"`', "wall", "3", 5 if quick else 15),
        Row("build", f"`build {PAPER}`", ["build", PAPER, "--out", "{tmp}/paper"], b123d,
            '`python -c "import build123d"`', "wall", "1.3", few),
        Row("analyze", f"`analyze` of a {RECORDING_S:g} s recording (CPU, whole process)",
            ["analyze", str(rec), "--band", "3900", "5600", "--out", "{tmp}/an"], [PY, "-c", TRACKER_ONLY, str(rec)],
            "the tracker itself (in-process CPU)", "cpu", "0.3 s", few),
        Row("sweep-laser", "`sweep` laser-only, 20 000 variants, rules on (the default), 1 process",
            ["sweep", LASER, "--vary", "cavity.length=3:6:200", "--vary", "neck.diameter=1.2:2.4:100",
             "--workers", "1", "--out", "{tmp}/sl"], [PY, "-c", THROUGHPUT],
            "the vectorised transmission line", "rate", "1e5/s", 1 if quick else 3, 20_000),
        Row("sweep-paper", "`sweep` mat-paper (silicone wall), 1 000 variants, rules off, 1 process",
            ["sweep", PAPER, "--vary", "cavity.length=3:6:40", "--vary", "neck.diameter=1.5:2.4:25", "--no-rules",
             "--workers", "1", "--out", "{tmp}/sp"], None, "", "rate", "1e5/s", 1 if quick else 3, 1_000),
        Row("sweep-paper-rules", "`sweep` mat-paper (silicone wall, its calibration anchor), 10^4 variants (3 axes), "
            "rules on, 1 process",
            ["sweep", PAPER, "--vary", "cavity.length=3:6:20", "--vary", "neck.diameter=1.5:2.4:20", "--vary",
             "neck.length=1:8:25", "--workers", "1", "--out", "{tmp}/spr"], None, "", "rate", "1e5/s", 1, 10_000),
        Row("sweep-paper-2", "`sweep` mat-paper (silicone wall, its calibration anchor), 10^5 variants (3 axes), "
            "rules on, Parquet, 2 processes (`--workers 2`), designs per wall second",
            ["sweep", PAPER, "--vary", "cavity.length=3:6:40", "--vary", "neck.diameter=1.5:2.4:50", "--vary",
             "neck.length=1:8:50", "--workers", "2", "--table", "parquet", "--out", "{tmp}/spr2"], None, "",
            "wall_rate", "1e5/s", 1, 100_000),
        Row("sweep-million", "`sweep` laser-only, 10^6 variants (3 axes), rules on, 1 process: CPU and peak memory",
            ["sweep", LASER, "--vary", "cavity.length=2:10:100", "--vary", "neck.diameter=0.8:2.4:100",
             "--vary", "neck.length=1:8:100", "--workers", "1", "--out", "{tmp}/sm"], None, "", "rate", "1e5/s", 1,
            1_000_000),
        Row("sweep-million-parquet", "the same to `--table parquet`", ["sweep", LASER, "--vary",
            "cavity.length=2:10:100", "--vary", "neck.diameter=0.8:2.4:100", "--vary", "neck.length=1:8:100",
            "--workers", "1", "--table", "parquet", "--out", "{tmp}/smp"], None, "", "rate", "1e5/s", 1, 1_000_000),
        Row("sweep-million-2", "the same on 2 processes (`--workers 2`), designs per wall second", ["sweep", LASER,
            "--vary", "cavity.length=2:10:100", "--vary", "neck.diameter=0.8:2.4:100", "--vary",
            "neck.length=1:8:100", "--workers", "2", "--table", "parquet", "--out", "{tmp}/smp2"], None, "",
            "wall_rate", "1e5/s", 1, 1_000_000),
        Row("fem", "`predict --model fem`, coupled, `baffled` mouth (CPU)",
            ["predict", PAPER, "--model", "fem", "--set", "neck.mouth='baffled'"],
            ["predict", PAPER, "--model", "fem"], "the same with `mount`", "cpu", "2", few),
    ]
    return out


def argv_of(args: list, scratch: Path) -> list:
    """A full argv: matcad arguments run as ``python -m matcad``, ``{tmp}`` replaced by the scratch folder."""
    args = [a.replace("{tmp}", str(scratch)) if isinstance(a, str) else a for a in args]
    return args if args[0] == PY else [PY, "-m", "matcad", *args]


def _clear(folder: Path) -> None:
    for stale in folder.iterdir():
        shutil.rmtree(stale) if stale.is_dir() else stale.unlink()


def run_row(row: Row, trees: dict[str, Path], scratch: Path) -> None:
    """Alternate the row's command on every tree with its floor; medians into ``row.results``.

    Floors: a matcad command is run on each tree beside it; a bare interpreter command that prints a number (the
    tracker's CPU, the vectorised rate) gives that number; any other bare command (an import) is timed."""
    samples: dict[str, list] = {label: [] for label in trees}
    floors: dict[str, list] = {label: [] for label in trees}
    per_tree = row.floor is not None and row.floor[0] != PY
    prints = row.floor is not None and not per_tree and "print(" in row.floor[2]
    warm = 1 if row.metric == "wall" else 0  # a first round warms the file cache and writes bytecode: not counted
    for i in range(1 - warm, row.runs + 1):
        order = list(trees.items())
        for label, tree in order if i % 2 else order[::-1]:  # each tree first in every other round
            env = environment(tree)
            _clear(scratch)
            try:
                m = measure(argv_of(row.command, scratch), env, tree)
            except RuntimeError as exc:
                m = None
                print(f"  {row.key} on {label}: {str(exc).splitlines()[0]}", file=sys.stderr)
            if i:
                samples[label].append(m)
            if row.floor is None or (not per_tree and label != "this"):
                continue
            _clear(scratch)
            if prints:
                out = subprocess.run(argv_of(row.floor, scratch), env=environment(ROOT), cwd=ROOT,
                                     capture_output=True, text=True)
                value = float(out.stdout.split()[-1]) if out.returncode == 0 else None
            else:
                value = measure(argv_of(row.floor, scratch), env, tree)[row.metric]
            if i:
                floors[label].append(value)
    for label, ms in samples.items():
        ok = [m for m in ms if m is not None]
        if not ok:
            row.results[label] = None
            continue
        row.results[label] = {k: statistics.median(m[k] for m in ok) for k in ("wall", "cpu", "rss_mib")}
        own = [f for f in floors[label if per_tree else "this"] if f is not None]
        row.results[label]["floor"] = statistics.median(own) if own else None


def cell(row: Row, label: str) -> tuple[str, str]:
    """(measured, ratio or rate) cells of ``row`` on tree ``label``."""
    r = row.results.get(label)
    if r is None:
        return "—", "—"
    if row.metric in ("rate", "wall_rate"):
        seconds = r["cpu" if row.metric == "rate" else "wall"]
        rate = row.variants / seconds
        what = "CPU" if row.metric == "rate" else "wall"
        floor = r.get("floor")
        note = f" (1/{floor / rate:.3g} of it)" if floor else ""
        return f"{seconds:.2f} s {what}, {r['rss_mib']:.0f} MiB", f"{rate:.3g} designs/s{note}"
    value = r[row.metric]
    floor = r.get("floor")
    shown = f"{value:.3g} s" + (" CPU" if row.metric == "cpu" else "")
    if row.key == "analyze":
        return shown, f"{value:.3g} s CPU (tracker {floor:.3g} s)" if floor else "—"
    return shown, (f"{value / floor:.2f}×" if floor else "—")


def floor_text(row: Row, label: str) -> str:
    r = row.results.get(label) or {}
    value = r.get("floor")
    if value is None:
        return row.floor_label or "—"
    unit = " designs/s" if row.metric in ("rate", "wall_rate") else " s" + (" CPU" if row.metric == "cpu" else "")
    return f"{row.floor_label} {value:.3g}{unit}"


def table(selected: list[Row], trees: dict[str, Path], load: tuple[float, float]) -> str:
    labels = list(trees)
    head = "| path | floor | target | " + " | ".join(f"{lab}: measured | {lab}: ratio" for lab in labels) + " |"
    lines = [head, "|---|---|---|" + "---:|---:|" * len(labels)]
    for row in selected:
        cells = " | ".join(" | ".join(cell(row, lab)) for lab in labels)
        target = f"≤ {row.target}×" if row.metric in ("wall",) or row.key == "fem" else f"≥ {row.target}" \
            if "rate" in row.metric else f"≤ {row.target}"
        lines.append(f"| {row.label} | {floor_text(row, labels[-1])} | {target} | {cells} |")
    lines.append("")
    lines.append(f"Medians of alternating runs (command, floor, command, floor, ...); {os.cpu_count()} cores; "
                 f"load average {load[0]:.1f} before and {load[1]:.1f} after the run. Measured by "
                 "`python benchmarks/floors.py`.")
    return "\n".join(lines)


def write_readme(text: str) -> None:
    readme = ROOT / "README.md"
    doc = readme.read_text(encoding="utf-8")
    start, end = README_MARK
    pattern = re.compile(re.escape(start) + ".*?" + re.escape(end), re.S)
    if not pattern.search(doc):
        raise SystemExit(f"README.md has no {start} ... {end} block")
    readme.write_text(pattern.sub(lambda _: f"{start}\n{text}\n{end}", doc), encoding="utf-8")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tree", action="append", default=[], metavar="LABEL=PATH",
                    help="also measure another checkout (alternated with this one)")
    ap.add_argument("--only", nargs="+", metavar="ROW", help="rows to run: predict laser build analyze "
                                                              "sweep-laser sweep-paper sweep-paper-rules "
                                                              "sweep-paper-2 sweep-million sweep-million-parquet "
                                                              "sweep-million-2 fem")
    ap.add_argument("--runs", type=int, help="runs per command (default per row)")
    ap.add_argument("--quick", action="store_true", help="fewer runs per row")
    ap.add_argument("--readme", action="store_true", help="rewrite README's performance table with the result")
    args = ap.parse_args()
    trees = {}
    for text in args.tree:
        label, _, path = text.partition("=")
        trees[label] = Path(path).resolve()
    trees["this"] = ROOT
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="matcad-floors-") as tmp:
        tmp = Path(tmp)
        scratch = tmp / "out"
        scratch.mkdir()
        selected = [r for r in rows(tmp, args.quick) if not args.only or r.key in args.only]
        for row in selected:
            if args.runs:
                row.runs = args.runs
            t0 = time.perf_counter()
            run_row(row, trees, scratch)
            print(f"  {row.key}: {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    text = table(selected, trees, (load0, os.getloadavg()[0]))
    print(text)
    if args.readme:
        write_readme(text)


if __name__ == "__main__":
    main()
