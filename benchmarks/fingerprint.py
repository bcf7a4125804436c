"""Fingerprint of everything matcad writes and prints, to prove a change leaves outputs unchanged.

Runs the real command line (a fresh interpreter per command) on every shipped template and on synthetic
recordings and calibration data with known truth, and records the SHA-256 of every file written and of every
command's standard output, exit code and standard error. Run times and temporary paths are masked (keys named
``seconds``/``worker_seconds`` in JSON, "N.NN s" in text, the temporary root), nothing else.

    .venv/bin/python benchmarks/fingerprint.py --write before.json     # record
    .venv/bin/python benchmarks/fingerprint.py --compare before.json   # exit 1 and list what differs

``--quick`` leaves out the board's cap mechanics (``sense``/``analyze --spec`` of the board, ``predict --load``).
"""

import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
import wave
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from matcad.loop import synth  # noqa: E402

TEMPLATES = sorted((ROOT / "templates").glob("*.toml"))
UNHASHED = ("kit.zip", ".matcad-manifest.json")
"""Derived from the files hashed one by one (and holding their unmasked run times)."""
SECONDS_RE = re.compile(r"\d+(\.\d+)? ?(s|ms)\b")


def _mask_json(value, digits=None):
    """Run times masked; with ``digits``, every float rounded to that many significant digits."""
    if isinstance(value, dict):
        return {k: ("<t>" if "seconds" in k else _mask_json(v, digits)) for k, v in value.items()}
    if isinstance(value, list):
        return [_mask_json(v, digits) for v in value]
    if digits and isinstance(value, float):
        return float(f"{value:.{digits}g}")
    return value


def _digest(data: bytes, name: str, tmp: str) -> str:
    """SHA-256 of a file's bytes, after masking run times (JSON/text) and the temporary root."""
    if name.endswith((".json", ".md", ".html", ".csv", ".toml", ".txt")):
        text = data.decode("utf-8", "replace").replace(tmp, "<tmp>").replace(str(ROOT), "<root>")
        if name.endswith(".json"):
            try:
                text = json.dumps(_mask_json(json.loads(text)), sort_keys=True, ensure_ascii=False)
            except ValueError:
                pass
        data = SECONDS_RE.sub("<t>", text).encode()
    return hashlib.sha256(data).hexdigest()


def _folder(path: Path, tmp: str) -> dict:
    return {p.relative_to(path).as_posix(): _digest(p.read_bytes(), p.name, tmp)
            for p in sorted(path.rglob("*")) if p.is_file() and p.name not in UNHASHED}


def _run(args, tmp: str, digits=None) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # this checkout's matcad, whatever the interpreter has installed
    proc = subprocess.run([sys.executable, "-m", "matcad", *map(str, args)], capture_output=True, cwd=tmp, env=env)
    out = proc.stdout.decode("utf-8", "replace").replace(tmp, "<tmp>").replace(str(ROOT), "<root>")
    try:
        out = json.dumps(_mask_json(json.loads(out), digits), sort_keys=True, ensure_ascii=False)
    except ValueError:
        pass
    out = SECONDS_RE.sub("<t>", out)
    err = SECONDS_RE.sub("<t>", re.sub(r"/tmp/matcad-internal-error-\S+", "<log>",
                                       proc.stderr.decode("utf-8", "replace").replace(tmp, "<tmp>")
                                       .replace(str(ROOT), "<root>")))
    return {"exit": proc.returncode, "stdout": hashlib.sha256(out.encode()).hexdigest(), "stderr": err[-400:]}


def _wav(path: Path, x: np.ndarray, fs: float) -> str:
    """Write 16-bit PCM; returns its SHA-256 (a recording that changed makes every analysis of it differ)."""
    pcm = np.clip(np.round(x / max(1.0, float(np.max(np.abs(x)))) * 32767), -32768, 32767).astype("<i2")
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(int(fs))
        w.writeframes(pcm.tobytes())
    return hashlib.sha256(path.read_bytes()).hexdigest()


def fingerprint(quick: bool) -> dict:
    out: dict = {}
    with tempfile.TemporaryDirectory(prefix="matcad-fp-") as tmp:
        t = Path(tmp)

        def record(key, args, folder=None, digits=None):
            out[key] = _run(args, tmp, digits)
            if folder is not None and (t / folder).is_dir():
                out[key]["files"] = _folder(t / folder, tmp)

        for spec in TEMPLATES:
            name = spec.stem
            record(f"build {name}", ["build", spec, "--out", f"kit-{name}", "--json"], f"kit-{name}")
            record(f"predict {name}", ["predict", spec, "--json"])
            record(f"predict-text {name}", ["predict", spec])
            record(f"check {name}", ["check", spec, "--json"])
        paper = ROOT / "templates" / "mat-paper.toml"
        laser = ROOT / "templates" / "mat-laser-only.toml"
        board = ROOT / "templates" / "mat-array-4.toml"
        record("coupon laser-only", ["coupon", laser, "--out", "coupon"], "coupon")
        # ARPACK starts from a random vector: the FEM's f0 varies in its 14th digit from run to run
        record("predict fem", ["predict", laser, "--model", "fem", "--json"], digits=10)
        record("predict relative", ["predict", board.parent / "mat-sla-array.toml", "--json"])
        if not quick:
            record("predict load", ["predict", paper, "--load", "0", "2", "5", "--json"])
        record("sweep laser", ["sweep", laser, "--vary", "cavity.length=3:6:4", "--vary", "neck.diameter=1.5,2.1",
                               "--workers", "1", "--out", "sweep", "--json"], "sweep")
        record("design target", ["design", laser, "--target-hz", "5000", "--vary", "neck.diameter", "--out", "design",
                                 "--json"], "design")
        # recordings with known truth
        for case in ("steady", "presses", "speech+tone", "neighbour", "overblown", "gaps"):
            rec = synth.scenario(case, seconds=6.0, seed=1)
            out[f"recording {case}"] = {"exit": 0, "stdout": _wav(t / f"{case}.wav", rec.x, rec.fs), "stderr": ""}
            record(f"analyze {case}", ["analyze", f"{case}.wav", "--band", "3900", "5600", "--out", f"an-{case}",
                                       "--json"], f"an-{case}")
        rec = synth.crossing_scenario("pass", seconds=8.0, seed=2)
        out["recording crossing"] = {"exit": 0, "stdout": _wav(t / "crossing.wav", rec.x, rec.fs), "stderr": ""}
        record("analyze crossing", ["analyze", "crossing.wav", "--band", "3900", "5600", "--out", "an-crossing"],
               "an-crossing")
        record("analyze spec", ["analyze", "steady.wav", "--spec", paper, "--out", "an-spec", "--json"], "an-spec")
        # a calibration from synthetic presses (Eq. 5 with the paper's b, a), two cycles
        forces = np.tile(np.linspace(0.0, 20.0, 11), 2)
        freqs = synth.frequency_of_force(forces) + np.random.default_rng(3).normal(0.0, 2.0, len(forces))
        rows = ["force_n,frequency_hz,cycle"] + [f"{f:.3f},{h:.3f},{1 + i // 11}"
                                                 for i, (f, h) in enumerate(zip(forces, freqs))]
        (t / "cal.csv").write_text("\n".join(rows) + "\n")
        record("calibrate", ["calibrate", "cal.csv", "--spec", paper, "--out", "cal", "--json"], "cal")
        record("calibrate text", ["calibrate", "cal.csv", "--spec", paper, "--out", "cal2"])
        record("sense presses", ["sense", "presses.wav", "--calibration", "cal/calibration.toml", "--out", "se",
                                 "--json"], "se")
        record("sense presses text", ["sense", "presses.wav", "--calibration", "cal/calibration.toml", "--out",
                                      "se2"])
        rec = synth.board_scenario(seconds=6.0, seed=1)
        out["recording board"] = {"exit": 0, "stdout": _wav(t / "board.wav", rec.x, rec.fs), "stderr": ""}
        record("analyze board bands", ["analyze", "board.wav", "--band", "3500", "5600", "--out", "an-board"],
               "an-board")
        if not quick:
            record("analyze board spec", ["analyze", "board.wav", "--spec", board, "--out", "an-board-spec"],
                   "an-board-spec")
            record("sense board spec", ["sense", "board.wav", "--spec", board, "--calibration",
                                        "t1=cal/calibration.toml", "--out", "se-board", "--json"], "se-board")
        record("schema", ["schema", "--json"])
        record("bad input", ["predict", paper, "--set", "neck.diameter=-1"])
    return out


def compare(before: dict, after: dict) -> list[str]:
    diffs = []
    for key in sorted(set(before) | set(after)):
        a, b = before.get(key), after.get(key)
        if a is None or b is None:
            diffs.append(f"{key}: only {'after' if a is None else 'before'}")
            continue
        for field in ("exit", "stdout", "stderr"):
            if a[field] != b[field]:
                diffs.append(f"{key}: {field} differs" + (f" ({a[field]!r} -> {b[field]!r})" if field != "stdout"
                                                          else ""))
        fa, fb = a.get("files", {}), b.get("files", {})
        for name in sorted(set(fa) | set(fb)):
            if fa.get(name) != fb.get(name):
                diffs.append(f"{key}: {name} differs" if name in fa and name in fb else
                             f"{key}: {name} only {'before' if name in fa else 'after'}")
    return diffs


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", type=Path)
    ap.add_argument("--compare", type=Path)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    now = fingerprint(args.quick)
    files = sum(len(v.get("files", {})) for v in now.values())
    print(f"{len(now)} commands, {files} files fingerprinted")
    if args.write:
        args.write.write_text(json.dumps(now, indent=1, sort_keys=True) + "\n")
    if args.compare:
        diffs = compare(json.loads(args.compare.read_text()), now)
        print("\n".join(diffs) if diffs else "identical: every exit code, output and file")
        return 1 if diffs else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
