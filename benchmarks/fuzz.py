"""Hostile inputs and faults through the CLI, by category, printing tried / held / breaches per category.

A run *holds* when it keeps the README's contract: an exit code of its category's table (never 70, the
internal-error code, and no exception escaping ``main``), no traceback, no numpy RuntimeWarning, a one-line message
on exit 2, no temporary folder left over, and, for builds, a kit whose files match its manifest. Categories:

  specs       generated specs through `check` and `build` (tests/test_fuzz.py's strategy and read-back)
  extremes    every number, whole-number and [low, high] field at its bounds, one ulp inside, 5e-324, 1e-300,
              1e300, pairs of them (a random N of the single-field cases when N is below their count)
  toml        parser tricks: deep nesting, >= 309-digit integers, long and newline-bearing strings, unicode
  files       non-regular and oversized inputs (FIFO, /dev/zero, folder, > limit) for every input kind
  wav         valid WAVs with random header bytes changed or cut at a random length
  csv         calibration data: long fields, NUL, NaN/inf, 1e154, separators, BOM, random bytes
  calibration calibration files with random covariances, ranges and constants
  out         --out targets: '.', nested, an existing file, a folder with a user's file, a symlink
  faults      SIGINT / SIGTERM / SIGKILL at random moments of a build (tests/test_hardening.py's injector)
  sets        --set values: > 4300-digit integers, deep nesting, text after the value, over-long strings, bad keys,
              NaN/inf/1e400, tables and arrays where numbers belong (issue 21)
  world       files from the user's world: UTF-8 BOM and CRLF specs, UTF-16 and Latin-1 specs, specs in inches,
              European CSVs (';', decimal comma), BOM CSVs, Windows --out paths, analyze --band in kHz (issue 21)
  serve       the design server on 127.0.0.1 (in this process): hostile Host/Origin/Content-Type headers, bodies
              nested, truncated, oversized, random bytes, bad lengths, other methods, garbage request lines,
              disconnects and resets; it holds when every reply is a status of its table with a JSON error, the
              server prints nothing and still answers a good prediction (issue 21)
  sweep       `sweep` with malformed --scheduler addresses, hostile --vary and --workers (issue 21)
  loop        float WAVs at any magnitude, tones of 20-400 ms, calibration CSVs with a cycle column and subnormal or
              kHz frequencies: no numpy warning and no 'nan' in any message (issue 21)

Every `--json` run must also leave exactly one JSON document on stdout, whatever its exit code.

Run: .venv/bin/python benchmarks/fuzz.py [N] [category ...]   (N examples per category, default 200;
`specs` runs 10 N of its cheap examples and `faults` N / 10 kills)
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import random
import struct
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from matcad import spec as spec_mod  # noqa: E402
from matcad.cli import main  # noqa: E402
from tests.test_fuzz import BASE, to_toml  # noqa: E402

LASER_ONLY = {"end_cap_mold": False, "needle_mount": False, "assembly": False}


class Breach(AssertionError):
    pass


def run(argv: list[str], allowed=(0, 1, 2)) -> tuple[int, str]:
    """``main(argv)`` in this process; a Breach unless the contract holds (a numpy RuntimeWarning, which a user's
    terminal would show, is a breach too). Returns (code, stderr)."""
    import warnings

    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", RuntimeWarning)
            code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse usage errors are exit 2 by design
        code = exc.code
    except BaseException as exc:  # noqa: BLE001 - an escaping exception is a traceback for the user
        raise Breach(f"{argv}: {exc.__class__.__name__}: {exc}") from exc
    leaked = [f"{w.filename.rsplit('/', 1)[-1]}:{w.lineno}: {w.message}" for w in caught
              if issubclass(w.category, RuntimeWarning)]
    if leaked:
        raise Breach(f"{argv}: warnings on the terminal: {leaked[:3]}")
    text = err.getvalue()
    if code not in allowed or "Traceback" in text:
        raise Breach(f"{argv}: exit {code}: {text[-300:]}")
    if code == 2 and not text.strip():
        raise Breach(f"{argv}: exit 2 without a message")
    if "--json" in argv and "--live" not in argv:
        try:
            doc = json.loads(out.getvalue())
        except ValueError:
            raise Breach(f"{argv}: exit {code}, stdout is no JSON document: {out.getvalue()[:200]!r}") from None
        if code == 2 and not (isinstance(doc, dict) and doc.get("error", {}).get("exit_code") == 2):
            raise Breach(f"{argv}: exit 2 without a JSON error object: {out.getvalue()[:200]!r}")
    return code, text


def _no_litter(folder: Path) -> None:
    left = [p for p in folder.rglob(".*") if ".tmp-" in p.name or ".old-" in p.name]
    if left:
        raise Breach(f"left over: {left}")


def _doc(**sections) -> dict:
    data = json.loads(json.dumps(BASE))
    data["outputs"] = dict(LASER_ONLY)
    for section, values in sections.items():
        data.setdefault(section, {}).update(values)
    return data


def _number_fields() -> list[tuple[str, str, dict]]:
    """Every numeric spec field: numbers, whole numbers and [low, high] ranges (wall.khz_modulus_factor = 1e-300
    and wall.loss_factor = 0 are ranges: issue 21)."""
    import dataclasses

    return [(section, f.name, dict(f.metadata)) for section, cls in spec_mod.SECTIONS.items()
            for f in dataclasses.fields(cls) if f.metadata["kind"] in ("number", "integer", "range")]


def _extremes(meta: dict) -> list:
    """A field's bounds, one step inside them, and the numbers that broke fields before; a range gets each as both
    of its ends, its bounds as a pair and that pair reversed; a whole number its bounds, one inside, 0, -1, 2^63."""
    lo, hi = meta["lo"], meta["hi"]
    if meta["kind"] == "integer":
        return [lo, lo + 1, hi, hi - 1, 0, -1, 2 ** 63]
    scalars = [lo, math.nextafter(lo, math.inf), hi, math.nextafter(hi, -math.inf), 5e-324, 1e-300, 1e300,
               -0.0, -5e-324]
    if meta["kind"] == "range":
        return [[v, v] for v in scalars] + [[lo, hi], [hi, lo]]
    return scalars


def cat_extremes(n: int, rng: random.Random, work: Path):
    fields = _number_fields()
    cases = [[(s, k, v)] for s, k, m in fields for v in _extremes(m)]
    rng.shuffle(cases)  # N below their count tries a random N of them, not the first fields' alone
    while len(cases) < n:
        cases.append([(s, k, rng.choice(_extremes(m))) for s, k, m in rng.sample(fields, 2)])
    for case in cases[:max(n, 1)]:
        doc = _doc()
        for s, k, v in case:
            doc.setdefault(s, {})[k] = v
        path = work / "s.toml"
        path.write_text(to_toml(doc))
        yield lambda p=path: (run(["predict", p, "--json"], (0, 2)), run(["check", p]))


def cat_toml(n: int, rng: random.Random, work: Path):
    minimal = 'name = "t"\n[cavity]\ndiameter = 3.18\nlength = 4.76\n[neck]\ndiameter = 2.1\nlength = 6.35\n'
    makers = [
        lambda: "x = " + "[" * rng.randint(10, 20000) + "\n" + minimal,
        lambda: (lambda d: "x = " + "[" * d + "]" * d + "\n" + minimal)(rng.randint(30, 20000)),
        lambda: minimal + "[cavity.a" + ".b" * rng.randint(30, 3000) + "]\nz = 1\n",
        lambda: minimal.replace("length = 4.76", "length = " + "9" * rng.randint(300, 6000)),
        lambda: minimal.replace("length = 4.76", "length = -" + "9" * rng.randint(300, 4000)),
        lambda: minimal.replace('name = "t"', 'name = "' + "x" * rng.randint(60, 2_000_000) + '"'),
        lambda: minimal.replace('name = "t"', rng.choice(['name = "abc\\n"', 'name = "a\\u0000"', "name = 'é'",
                                                          'name = "a b"', 'name = ".."', 'name = "日本"'])),
        lambda: minimal + "[plate]\nlabel = " + json.dumps("".join(chr(rng.randint(0, 0x2FFF)) for _ in range(50))),
        lambda: minimal + "[air]\nspeed_of_sound = " + rng.choice(["1e-300", "5e-324", "nan", "inf", "-0.0",
                                                                    "1_000_000", "0x10", "1e400"]) + "\n",
        lambda: minimal + "[mold]\ncount = " + rng.choice(["1e3", "true", str(2 ** 64), "-1", "0"]) + "\n",
        lambda: minimal + '[cavity]\nlength = 5\n',  # duplicate table
        lambda: minimal + "[calibration]\nv0_mm3 = 32\na = 0\nb = 0.1\ncovariance = " +
        json.dumps([rng.uniform(-1, 1) for _ in range(rng.choice([3, 9, 10]))]) + "\n",
    ]
    for _ in range(n):
        path = work / "s.toml"
        path.write_text(rng.choice(makers)(), encoding="utf-8")
        yield lambda p=path: run(["check", p])


def cat_files(n: int, rng: random.Random, work: Path):
    from matcad.inputs import CALIBRATION_MAX_BYTES, SPEC_MAX_BYTES

    fifo = work / "fifo"
    if not fifo.exists():
        os.mkfifo(fifo)
    big_spec = work / "big.toml"
    big_spec.write_bytes(b"#" * (SPEC_MAX_BYTES + 1))
    big_cal = work / "big_cal.toml"
    big_cal.write_bytes(b"#" * (CALIBRATION_MAX_BYTES + 1))
    wav = work / "ok.wav"
    from scipy.io import wavfile
    import numpy as np

    wavfile.write(wav, 8000, np.zeros(800, np.int16))
    bad = [fifo, "/dev/zero", work, big_spec, work / "missing.toml"]
    for _ in range(n):
        target = rng.choice(bad)
        kind = rng.choice(["spec", "calibration", "csv", "wav"])
        argv = {"spec": ["check", target], "calibration": ["sense", wav, "--calibration", rng.choice([target, big_cal])],
                "csv": ["calibrate", target, "--spec", ROOT / "templates" / "mat-paper.toml", "--out", work / "c"],
                "wav": ["analyze", target, "--band", "1000", "3000", "--out", work / "a"]}[kind]
        yield lambda a=argv: (run(a, (2,)), _no_litter(work))


def _good_wav() -> bytes:
    import numpy as np

    x = (np.sin(np.arange(8000) * 2 * np.pi * 2000 / 8000) * 20000).astype("<i2").tobytes()
    fmt = struct.pack("<HHIIHH", 1, 1, 8000, 16000, 2, 16)
    body = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"LIST" + struct.pack("<I", 4) + b"INFO" + \
        b"data" + struct.pack("<I", len(x)) + x
    return b"RIFF" + struct.pack("<I", len(body)) + body


def cat_wav(n: int, rng: random.Random, work: Path):
    good = _good_wav()
    for _ in range(n):
        blob = bytearray(good)
        mode = rng.choice(["cut", "flip", "both"])
        if mode in ("flip", "both"):
            for _ in range(rng.randint(1, 4)):
                blob[rng.randrange(56)] = rng.randrange(256)
        if mode in ("cut", "both"):
            blob = blob[:rng.randrange(len(blob))]
        path = work / "r.wav"
        path.write_bytes(bytes(blob))
        yield lambda p=path: (run(["analyze", p, "--band", "1500", "2500", "--out", work / "a"]), _no_litter(work))


def cat_csv(n: int, rng: random.Random, work: Path):
    spec = ROOT / "templates" / "mat-paper.toml"
    cells = ["0", "1", "2.5", "nan", "inf", "-inf", "1e154", "-1e154", "1e308", "4500", "4600.5", "", " ",
             "x" * 200_000, "1\x00", "\ufeff0", "0,5", '"4700"', "1e-320"]
    for _ in range(n):
        rows = ["force_n,frequency_hz"] if rng.random() < 0.7 else []
        sep = rng.choice([",", ";", "\t", ","])
        for i in range(rng.randint(0, 12)):
            if rng.random() < 0.6:
                rows.append(f"{i * 2}{sep}{4500 + 15 * i + rng.gauss(0, 2):.2f}")
            else:
                rows.append(sep.join(rng.choice(cells) for _ in range(rng.randint(1, 3))))
        path = work / "d.csv"
        path.write_text("\n".join(rows) + "\n", encoding="utf-8")
        yield lambda p=path: (run(["calibrate", p, "--spec", spec, "--out", work / "c"]), _no_litter(work))


def cat_calibration(n: int, rng: random.Random, work: Path):
    from scipy.io import wavfile
    import numpy as np

    wav = work / "tone.wav"
    t = np.arange(44100) / 44100
    wavfile.write(wav, 44100, (np.sin(2 * np.pi * 4600 * t) * 20000).astype(np.int16))
    for _ in range(n):
        cov = [rng.choice([0.0, rng.uniform(-1e-3, 1e-3), rng.uniform(0, 1e-3), 1e30, -1e30]) for _ in range(9)]
        lo = rng.choice([0.0, -5.0, 10.0])
        text = ("[calibration]\n" f"v0_mm3 = {rng.choice([32.0, 1e-9, 1e18, 0.5])}\n"
                f"a = {rng.choice([-0.0086, 0.0086, 0.0, 1e12])}\nb = {rng.choice([0.4626, -0.4626, 0.0, 1e-12])}\n"
                f"k_mm3_hz2 = {rng.choice([2.2e8, 1e-300, 1e30, 6.8e8])}\n"
                f"force_range_n = [{lo}, {lo + rng.choice([0.0, 20.0, 1e6])}]\n"
                f"covariance = [{', '.join(repr(c) for c in cov)}]\n"
                f"residual_std_mm3 = {rng.choice([0.0, 0.01, 1e30])}\ndof = {rng.choice([1, 8, 10 ** 9])}\n")
        path = work / "cal.toml"
        path.write_text(text)
        yield lambda p=path: run(["sense", wav, "--calibration", p, "--json"])


def cat_out(n: int, rng: random.Random, work: Path):
    spec = work / "laser.toml"
    spec.write_text(to_toml(_doc()))
    for i in range(n):
        case = work / f"case{i}"
        case.mkdir()
        kind = rng.choice(["dot", "nested", "file", "notes", "symlink", "twice", "kit-notes"])
        allowed = (0,)
        if kind == "dot":
            target = Path(".")
        elif kind == "nested":
            target = case / "a" / "b" / "c"
        elif kind == "file":
            target = case / "f"
            target.write_text("user file")
            allowed = (2,)
        elif kind == "notes":
            target = case / "k"
            target.mkdir()
            (target / "notes.txt").write_text("mine")
            allowed = (2,)
        elif kind == "symlink":
            (case / "real").mkdir()
            target = case / "link"
            target.symlink_to(case / "real")
            allowed = (2,)
        else:
            target = case / "k"

        def one(c=case, t=target, k=kind, a=allowed):
            cwd = os.getcwd()
            os.chdir(c)
            try:
                run(["build", spec, "--out", t], a)
                if k in ("twice", "kit-notes"):
                    if k == "kit-notes":
                        (c / "k" / "notes.txt").write_text("mine")
                    run(["build", spec, "--out", t], (2,) if k == "kit-notes" else (0,))
                    if k == "kit-notes" and (c / "k" / "notes.txt").read_text() != "mine":
                        raise Breach("a user's file was deleted")
                for f in ("notes.txt",):
                    if k == "notes" and not (c / "k" / f).exists():
                        raise Breach("a user's file was deleted")
            finally:
                os.chdir(cwd)
            _no_litter(c)
        yield one


def cat_specs(n: int, rng: random.Random, work: Path):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from tests.test_fuzz import out_args, run_one, spec_documents

    results = []

    @given(data=spec_documents(), out_arg=out_args, force=st.booleans())
    @settings(max_examples=n, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    def one(data, out_arg, force):
        workdir = Path(tempfile.mkdtemp(dir=work))
        cwd = os.getcwd()
        os.chdir(workdir)
        try:
            run_one(data, workdir, out_arg, force)
            results.append(None)
        except AssertionError as exc:
            results.append(exc)
        finally:
            os.chdir(cwd)

    one()
    for r in results:
        def check(r=r):
            if r is not None:
                raise Breach(str(r)[:300])
        yield check


def cat_faults(n: int, rng: random.Random, work: Path):
    from tests.test_hardening import _inject_faults

    def one():
        counts = _inject_faults(Path(tempfile.mkdtemp(dir=work)), trials=max(1, n), seed=rng.randrange(10 ** 6))
        return counts
    yield one


def cat_sets(n: int, rng: random.Random, work: Path):
    spec = ROOT / "templates" / "mat-laser-only.toml"
    keys = ["neck.diameter", "cavity.length", "name", "wall.model", "wall.khz_modulus_factor", "air.temperature_c",
            "wall.loss_factor", "mechanics.steps", "plate.label", "neck", "nosuch.key", "a.b.c", "", ".x", "neck."]
    makers = [
        lambda: "9" * rng.randint(300, 8000), lambda: "-" + "9" * rng.randint(4300, 6000),
        lambda: (lambda d: "[" * d + "]" * d)(rng.randint(20, 50000)), lambda: "[" * rng.randint(1, 40000),
        lambda: (lambda d: "{a=" * d + "1" + "}" * d)(rng.randint(20, 3000)),
        lambda: rng.choice(["2.0", "1", "silicone"]) + rng.choice(["\n[air]\ntemperature_c=-20", " extra",
                                                                   "\nx=1", "\r\ny=2", " # comment", "\n"]),
        lambda: '"' + "x" * rng.choice([100, 70000, 1_100_000]) + '"', lambda: "x" * rng.choice([100, 1_100_000]),
        lambda: rng.choice(["nan", "inf", "-inf", "1e400", "-0.0", "5e-324", "1e-300", "0x10", "true", "{a=1}",
                            "[1,2]", "2024-01-01", "'é'", "日本", '"a\\u0000"', "", "=", "1e-320"]),
    ]
    for _ in range(n):
        sets = []
        for _ in range(rng.randint(1, 3)):
            sets += ["--set", f"{rng.choice(keys)}={rng.choice(makers)()}"]
        argv = [rng.choice(["check", "predict"]), spec, *sets] + (["--json"] if rng.random() < 0.5 else [])
        yield lambda a=argv: run(a)


def cat_world(n: int, rng: random.Random, work: Path):
    laser = (ROOT / "templates" / "mat-laser-only.toml").read_text(encoding="utf-8")
    inches = 'name = "t"\n[cavity]\ndiameter = 0.125\nlength = 0.1875\n[neck]\ndiameter = 0.0827\nlength = 0.25\n'
    from scipy.io import wavfile
    import numpy as np

    wav = work / "tone.wav"
    wavfile.write(wav, 44100, (np.sin(2 * np.pi * 4600 * np.arange(22050) / 44100) * 2e4).astype(np.int16))
    rows = [(f, 4500 + 9 * f + 0.1 * f * f) for f in range(0, 20, 2)]

    def csv_bytes():
        sep, dec = rng.choice([(",", "."), (";", ","), (";", "."), ("\t", ","), (",", ",")])
        quote = '"' if sep == dec else ""
        text = f"force_n{sep}frequency_hz\n" + "".join(
            f"{quote}{str(a).replace('.', dec)}{quote}{sep}{quote}{str(round(b, 2)).replace('.', dec)}{quote}\n"
            for a, b in rows)
        if rng.random() < 0.3:
            text = text.replace("\n", "\r\n")
        data = text.encode(rng.choice(["utf-8", "utf-8-sig", "utf-16"]))
        return data

    def spec_bytes():
        text = rng.choice([laser, inches, laser.replace('name = "', 'name = "é')])
        if rng.random() < 0.3:
            text = text.replace("\n", "\r\n")
        return text.encode(rng.choice(["utf-8", "utf-8-sig", "utf-16", "latin-1"]), errors="replace")

    for i in range(n):
        kind = rng.choice(["spec", "csv", "out", "band"])
        json_flag = ["--json"] if rng.random() < 0.5 else []
        if kind == "spec":
            path = work / "w.toml"
            path.write_bytes(spec_bytes())
            argv = [rng.choice(["check", "predict"]), path, *json_flag]
        elif kind == "csv":
            path = work / "w.csv"
            path.write_bytes(csv_bytes())
            argv = ["calibrate", path, "--spec", ROOT / "templates" / "mat-paper.toml", "--out", work / "c",
                    *json_flag]
        elif kind == "out":
            target = rng.choice(["C:\\Users\\lab\\out", "D:/kits", "kits\\paper", "\\\\server\\share",
                                 "c:", "ok-folder"])
            argv = ["build", ROOT / "templates" / "mat-laser-only.toml", "--out", work / f"o{i}" / target
                    if target == "ok-folder" else target, *json_flag]
        else:
            lo = rng.choice([4.5, 0.0045, 4500.0, 45.0, 1e-300])
            argv = ["analyze", wav, "--band", lo, lo * rng.choice([1.2, 1.0, 0.5]), "--out", work / "a", *json_flag]

        def one(a=argv):
            cwd = os.getcwd()
            os.chdir(work)
            try:
                run(a)
            finally:
                os.chdir(cwd)
            _no_litter(work)
            if any(work.glob("C:*")) or any(work.glob("*\\*")):
                raise Breach(f"{a}: a Windows path became a folder here")
        yield one


def cat_sweep(n: int, rng: random.Random, work: Path):
    """`sweep` with malformed --scheduler addresses (refused before anything connects), hostile --vary and
    --workers; valid grids run in this process (--workers 1) and read back as a table of their size."""
    from matcad.sweep.executor import check_address

    spec = ROOT / "templates" / "mat-laser-only.toml"
    malformed = ["nonsense", "tcp://host:notaport", "tcp://127.0.0.1:99999", "localhost:8786x", "http://127.0.0.1:8786",
                 "tcp://:8786", "tcp://127.0.0.1:0", "tcp://[::1:8786", "inproc://", "tcp://a b:1", ":", "", "x" * 5000]

    def address() -> str:
        while True:
            text = rng.choice(malformed + ["".join(chr(rng.randint(32, 0x24F)) for _ in range(rng.randint(1, 30)))])
            try:
                check_address(text)
            except ValueError:
                return text  # only addresses refused before connecting (an unreachable one waits 10 s by design)

    varies = ["cavity.length=3:6:4", "cavity.length=3,4", "neck.diameter=1.5,2.1", "cavity.length=3:x:4",
              "cavity.lenght=3:6:4", "neck.mouth=1,2", "cavity.length=6:3:4", "cavity.length=3:6:0",
              f"cavity.length=3:6:{10 ** 7}", "mold.count=1.5,2", "cavity.length=1e-300,1e300", "cavity.length=nan",
              "cavity.length=" + "9" * 5000, "cavity.length", "=1,2", "cavity.length=3:6:4:5", "wall.loss_factor=0,1",
              "wall.khz_modulus_factor=0.5,2", "mechanics.steps=1,200"]
    for i in range(n):
        out = work / f"s{i}"
        argv = ["sweep", spec, "--out", out, "--no-rules"] if rng.random() < 0.7 else ["sweep", spec, "--out", out]
        for _ in range(rng.randint(1, 3)):  # three axes: the maps of every pair's slice
            argv += ["--vary", rng.choice(varies)]
        kind = rng.choice(["scheduler", "workers", "plain"])
        if kind == "scheduler":
            argv += ["--scheduler", address()]
        argv += ["--workers", rng.choice(["0", "-3", "x", "257", "1e3"]) if kind == "workers" else "1"]
        argv += ["--json"] if rng.random() < 0.5 else []

        def one(a=argv, o=out):
            code, _ = run(a)
            if code == 2 and o.exists():
                raise Breach(f"{a}: refused, yet {o} was made")
            _no_litter(work)
        yield one


def cat_loop(n: int, rng: random.Random, work: Path):
    """The recording loop's inputs: float WAVs at any magnitude (±1e300, 1e-320, NaN, inf: refused, never a numpy
    warning or a 'nan dB'), clean tones of 20-400 ms (too short is told as such), calibration CSVs with a `cycle`
    column, subnormal or kHz frequencies and repeated forces (a studentized residual is a sane number or none)."""
    import warnings

    import numpy as np
    from scipy.io import wavfile

    spec = ROOT / "templates" / "mat-paper.toml"
    rate = 44100
    for i in range(n):
        kind = rng.choice(["float", "short", "cycles"])
        if kind == "float":
            path = work / "f.wav"
            x = np.sin(2 * np.pi * 4600 * np.arange(rate // 2) / rate)
            x = x * rng.choice([1e300, 1e13, 1e12, 1.0, 1e-320, 0.0])
            for _ in range(rng.randint(0, 3)):
                x[rng.randrange(len(x))] = rng.choice([math.nan, math.inf, -math.inf, 1e300, -1e300])
            wavfile.write(path, rate, x.astype(rng.choice([np.float64, np.float32])) if abs(x).max() < 3e38
                          else x)
            argv = ["analyze", path, "--band", "4000", "5500", "--out", work / "a"]
        elif kind == "short":
            path = work / "s.wav"
            t = np.arange(int(rate * rng.uniform(0.02, 0.4))) / rate
            wavfile.write(path, rate, (np.sin(2 * np.pi * 4600 * t) * 2e4).astype(np.int16))
            argv = ["analyze", path, "--band", "4000", "5500", "--out", work / "a"]
        else:
            path = work / "c.csv"
            cycles, points = rng.randint(1, 5), rng.randint(2, 12)
            unit = rng.choice([1.0, 1.0, 1e-3, 1e-322])
            rows = [(f, (4500 + 9 * f - 0.1 * f * f + rng.gauss(0, 2)) * unit, rng.choice(["c", "", "run "]) + str(c))
                    for c in range(cycles) for f in np.linspace(0, rng.choice([0.0, 1e-9, 20.0]), points).tolist()]
            path.write_text("force_n,frequency_hz,cycle\n" + "".join(f"{f},{h!r},{c}\n" for f, h, c in rows))
            argv = ["calibrate", path, "--spec", spec, "--out", work / "c"]
        argv += ["--json"] if rng.random() < 0.5 else []

        def one(a=argv):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", UserWarning)
                _, text = run(a)
            told = [str(w.message)[:120] for w in caught if issubclass(w.category, UserWarning)]
            if told or " nan" in text:
                raise Breach(f"{a}: {told or text[-200:]}")
            _no_litter(work)
        yield one


def cat_serve(n: int, rng: random.Random, work: Path):
    """Hostile HTTP against one in-process server (deadline lowered to 1 s to keep the run short)."""
    import socket
    import struct
    import threading
    import tomllib

    from matcad.serve import server as srv

    deadline, srv.REQUEST_DEADLINE_S = srv.REQUEST_DEADLINE_S, 1.0
    server = srv.make_server(0)
    port = server.server_address[1]
    threading.Thread(target=server.serve_forever, daemon=True).start()
    good = json.dumps({"spec": tomllib.loads((ROOT / "templates" / "mat-laser-only.toml").read_text())}).encode()
    statuses = {200, 400, 403, 404, 408, 411, 413, 415, 422, 431, 501, 503, 505}

    def exchange(payload: bytes, reset: bool = False, cut: bool = False):
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(payload)
            if reset:
                s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                return None
            if cut:
                return None
            data = b""
            with contextlib.suppress(ConnectionResetError):
                while chunk := s.recv(65536):
                    data += chunk
            return data

    def request(path="/predict", body=good, method="POST", **headers):
        fields = {"Host": f"127.0.0.1:{port}", "Content-Type": "application/json",
                  "Content-Length": str(len(body)), "Connection": "close"} | headers
        head = f"{method} {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in fields.items() if v is not None)
        return head.encode() + b"\r\n" + body

    def hostile() -> tuple[bytes, bool, bool]:
        kind = rng.choice(["host", "origin", "ctype", "nested", "bytes", "length", "method", "garbage", "cut",
                           "reset", "path", "good"])
        if kind == "host":
            return request(Host=rng.choice(["evil.example", f"evil.example:{port}", None, "", "127.0.0.1",
                                            f"localhost:{port + 1}", "[::1]:" + str(port), "x" * 5000])), 0, 0
        if kind == "origin":
            return request(Origin=rng.choice(["null", "http://evil.example", f"http://127.0.0.1:{port}.evil",
                                              f"https://127.0.0.1:{port}", "\u00e9"]),
                           **{"Sec-Fetch-Site": rng.choice([None, "cross-site", "same-origin"])}), 0, 0
        if kind == "ctype":
            return request(**{"Content-Type": rng.choice([None, "text/plain", "multipart/form-data; boundary=x",
                                                          "application/x-www-form-urlencoded", "application/jsonx",
                                                          "APPLICATION/JSON"])}), 0, 0
        if kind == "nested":
            d = rng.randint(20, 60000)
            body = rng.choice([b"[" * d + b"]" * d, b'{"spec": ' + b'{"a": ' * min(d, 9000) + b"1" +
                               b"}" * min(d, 9000) + b"}", b"[" * d])
            return request(body=body[:srv.MAX_BODY_BYTES]), 0, 0
        if kind == "bytes":
            return request(body=bytes(rng.randrange(256) for _ in range(rng.randint(1, 3000)))), 0, 0
        if kind == "length":
            body = good[:rng.randrange(len(good))] if rng.random() < 0.5 else good
            return request(body=body, **{"Content-Length": rng.choice(["-1", "0", "abc", "1e3", str(2 ** 70),
                                                                       str(len(good) + 50), None])}), 0, 0
        if kind == "method":
            return request(method=rng.choice(["PUT", "DELETE", "PATCH", "OPTIONS", "HEAD", "CONNECT", "TRACE",
                                              "get"])), 0, 0
        if kind == "garbage":
            return bytes(rng.randrange(256) for _ in range(rng.randint(0, 400))) + b"\r\n\r\n", 0, 0
        if kind == "cut":
            full = request()
            return full[:rng.randrange(len(full))], 0, True
        if kind == "reset":
            return request(), True, 0
        if kind == "path":
            return request(path=rng.choice(["/", "/schema.json", "/../etc/passwd", "/build?x=" + "y" * 9000,
                                            "/predict%00", "*", "//predict"]), method=rng.choice(["GET", "POST"])), 0, 0
        return request(), 0, 0

    def check(payload: bytes, reset: bool, cut: bool):
        data = exchange(payload, reset, cut)
        if data is None:
            return
        head, _, body = data.partition(b"\r\n\r\n")
        if not data.startswith(b"HTTP/"):  # HTTP/0.9: the body alone, or nothing for an empty request
            body, status = data, None
        else:
            status = int(head.split(b" ", 2)[1])
            if status not in statuses:
                raise Breach(f"status {status} for {payload[:120]!r}")
        if body and (status is None or status >= 400) and b"HEAD " not in payload[:5]:
            try:
                json.loads(body)["error"]["message"]
            except (ValueError, KeyError, TypeError):
                raise Breach(f"status {status}, no JSON error: {body[:120]!r} for {payload[:120]!r}") from None

    def alive():
        data = exchange(request())
        if not data.startswith(b"HTTP/1.0 200") and not data.startswith(b"HTTP/1.1 200"):
            raise Breach(f"a good prediction afterwards got {data[:120]!r}")

    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            for i in range(n):
                case = hostile()

                def one(c=case, last=(i == n - 1 or i % 10 == 9)):
                    check(*c)
                    if last:
                        time.sleep(1.2)  # the cut uploads reach their deadline
                        alive()
                    if err.getvalue():
                        raise Breach(f"the server printed: {err.getvalue()[:300]}")
                yield one
    finally:
        server.shutdown()
        server.server_close()
        srv.REQUEST_DEADLINE_S = deadline


CATEGORIES = {"specs": cat_specs, "extremes": cat_extremes, "toml": cat_toml, "files": cat_files, "wav": cat_wav,
              "csv": cat_csv, "calibration": cat_calibration, "out": cat_out, "faults": cat_faults,
              "sets": cat_sets, "world": cat_world, "serve": cat_serve, "sweep": cat_sweep, "loop": cat_loop}


def main_(n: int, names: list[str]) -> None:
    import warnings

    warnings.simplefilter("ignore")
    rng = random.Random(10)
    print(f"{'category':<12} {'tried':>6} {'held':>6} {'breaches':>8} {'s':>6}")
    for name in names:
        work = Path(tempfile.mkdtemp(prefix=f"matcad-fuzz-{name}-"))
        count = {"specs": 10 * n, "faults": max(1, n // 10)}.get(name, n)
        tried = held = 0
        breaches = []
        t0 = time.perf_counter()
        for case in CATEGORIES[name](count, rng, work):
            try:
                result = case()
            except (Breach, AssertionError) as exc:
                tried += 1
                breaches.append(str(exc)[:300])
                continue
            if name == "faults":  # one case runs many kills
                tried += sum(t for t, _ in result.values())
                held += sum(h for _, h in result.values())
            else:
                tried += 1
                held += 1
        print(f"{name:<12} {tried:>6} {held:>6} {len(breaches):>8} {time.perf_counter() - t0:>6.0f}", flush=True)
        for b in breaches[:5]:
            print(f"    breach: {b}")


if __name__ == "__main__":
    args = sys.argv[1:]
    count = int(args.pop(0)) if args and args[0].isdigit() else 200
    main_(count, args or list(CATEGORIES))
