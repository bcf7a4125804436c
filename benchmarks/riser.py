"""What a [riser] buys `matcad design`: each taxel's neck through the riser (neck.length + riser.thickness) or its
cap in a pocket of it, chosen per taxel by ``--vary neck.riser`` (docs/arrays.md).

1. Reach and time of one taxel (``solve``): the laser-only template (rigid wall, 6.35 mm plate), neck and cavity
   diameter and cavity length free in their default ranges, with and without ``neck.riser`` for 1.5 and 3.0 mm
   risers: the f0 span the route reaches (Hz), a target below the plate's reach met through the riser, which way
   each target takes (a 3 mm riser's pocket leaves the cap too short for the cap mechanics' 2 mm travel:
   ``matcad.design.solve.unpressable``), and the time per solve (median over 2-6 kHz).
2. Taxels per band (``allocate``, the most that fit, benchmarks/design.py's ``most_that_fit``):
   a. the laser-only template on a calipered plate, 2 N per taxel, its cap mechanics (FElupe) for the rise, in
      1300-7000 Hz (2 N: the softest caps, 1 mm walls, reach only 3.2-3.9 N on the cap mechanics' curve);
   b. the capacity board of docs/bands.md (rigid wall, Eq. 5 rise, 5 N, 44.1 kHz) on a 1/16 in plate, neck
      0.5-7 mm and cavity 2.1-12 mm free, in 1100-11000 Hz, with a 3.0 or 6.35 mm riser for the low taxels.
   For each: taxels that fit, the loaded bands' reach (Hz), how many necks run through the riser, the cavities
   (mm; the cap's outside is the template's) and the run time.

Prints numbers, asserts nothing. Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/riser.py [--solve-only | --row K]
"""

import dataclasses
import statistics
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks.design import BOARD_BASE, THREE, most_that_fit  # noqa: E402
from matcad import spec as spec_mod  # noqa: E402
from matcad.design import RulesFailed, Unreachable  # noqa: E402
from matcad.design.solve import parse_vary, solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FIELDS = ["neck.diameter", "cavity.diameter", "cavity.length"]
TARGETS = np.arange(2000.0, 6001.0, 500.0)
BELOW_HZ = 1500.0
"""A target under the laser-only plate's reach (its route's lowest f0, 1604 Hz)."""


def laser(riser_mm=None, calipered=False, force=None):
    """templates/mat-laser-only.toml with a [riser] of ``riser_mm`` (mm; None: none), the plate and riser
    calipered and ``force`` N per taxel when asked."""
    s = spec_mod.load(ROOT / "templates" / "mat-laser-only.toml")
    if riser_mm is not None:
        s = dataclasses.replace(s, riser=spec_mod.Riser(thickness=riser_mm, thickness_measured=calipered))
    if calipered:
        s = dataclasses.replace(s, plate=dataclasses.replace(s.plate, thickness_measured=True))
    if force is not None:
        s = dataclasses.replace(s, mechanics=dataclasses.replace(s.mechanics, max_force_n=force))
    return s


def reach(s, vary) -> str:
    """The f0 span (Hz) the solver's route reaches, from its Unreachable message."""
    try:
        solve(s, 1.0, parse_vary(s, vary))
    except Unreachable as exc:
        return str(exc).split(" reaches ")[1].split(";")[0]
    return "?"


def one_taxel():
    print("one taxel: templates/mat-laser-only.toml, --vary " + " ".join(FIELDS) + " [neck.riser]")
    print("| riser | --vary neck.riser | reach | ways over 2-6 kHz (through/pocket) | solve median [ms] | "
          f"{BELOW_HZ:g} Hz |")
    print("|---|---|---|---|---:|---|")
    for riser_mm in (1.5, 3.0):
        s = laser(riser_mm)
        for extra in ([], ["neck.riser"]):
            vary = FIELDS + extra
            times, ways, refused = [], [], []
            for target in TARGETS:
                t0 = time.perf_counter()
                try:
                    r = solve(s, float(target), parse_vary(s, vary))
                except (Unreachable, RulesFailed):
                    refused.append(f"{target:.0f}")
                    continue
                times.append(time.perf_counter() - t0)
                ways.append(r.spec.neck.riser)
            try:
                r = solve(s, BELOW_HZ, parse_vary(s, vary))
                below = (f"neck {spec_mod.neck_length_mm(r.spec):g} x {r.spec.neck.diameter:.3f} mm, cavity "
                         f"{r.spec.cavity.diameter:.3f} x {r.spec.cavity.length:.3f} mm, f0 {r.f0_hz:.1f} Hz")
            except (Unreachable, RulesFailed) as exc:
                below = type(exc).__name__
            print(f"| {riser_mm:g} mm | {'yes' if extra else 'no'} | {reach(s, vary)} | {sum(ways)}/"
                  f"{len(ways) - sum(ways)}" + (f" (refused {', '.join(refused)} Hz)" if refused else "") +
                  f" | {1e3 * statistics.median(times):.0f} | {below} |", flush=True)


def board_row(label, s, ask, band, vary):
    t0 = time.perf_counter()
    a, why = most_that_fit(s, ask, band, parse_vary(s, vary))
    seconds = time.perf_counter() - t0
    if a is None:
        print(f"| {label} | 0 | - | - | - | {seconds:.0f} |  {why[:120]}", flush=True)
        return
    board = spec_mod.taxels(a.spec)
    through = sum(t.neck.riser for t in board)
    cavities = [(t.cavity.diameter, t.cavity.length) for t in board]
    walls = min(t.end_cap.outer_diameter - t.cavity.diameter for t in board) / 2
    print(f"| {label} | {len(board)} | {a.bands[0].loaded_hz[0]:.0f}-{a.bands[-1].loaded_hz[1]:.0f} | "
          f"{through} | D {min(c[0] for c in cavities):.2f}-{max(c[0] for c in cavities):.2f}, L "
          f"{min(c[1] for c in cavities):.2f}-{max(c[1] for c in cavities):.2f}, wall >= {walls:.2f} | "
          f"{seconds:.0f} |", flush=True)


def capacity_board(riser_mm=None):
    """docs/bands.md's capacity board (rigid wall, Eq. 5 rise, 5 N, 44.1 kHz) on a 1/16 in plate, with a [riser] of
    ``riser_mm`` (mm, calipered; None: none)."""
    text = BOARD_BASE.format(sheet=1.5875, force=5.0, rate=44100.0)
    if riser_mm is not None:
        text += f"[riser]\nthickness = {riser_mm}\nthickness_measured = true\n"
    return spec_mod.from_dict(tomllib.loads(text))


ROWS = [(f"laser-only, 1300-7000 Hz, {'no riser' if r is None else f'{r:g} mm riser, --vary ... neck.riser'}",
         lambda r=r: laser(r, calipered=True, force=2.0), 16, (1300.0, 7000.0), FIELDS + ([] if r is None else
                                                                                          ["neck.riser"]))
        for r in (None, 1.5, 3.0)] + \
       [(f"capacity 1/16 in, 1100-11000 Hz, {'no riser' if r is None else f'{r:g} mm riser, --vary ... neck.riser'}",
         lambda r=r: capacity_board(r), 32, (1100.0, 11000.0), THREE + ([] if r is None else ["neck.riser"]))
        for r in (None, 3.0, 6.35)]
"""(label, spec, taxels asked, band Hz, --vary) of each board row."""


def boards():
    """Each row in its own process with no cap-curve cache (``MATCAD_CACHE_DIR=''``): cold, comparable times."""
    import os
    import subprocess

    print("\ntaxels per band: the most that fit (design --taxels N --band LO HI), each row cold (no cap-curve cache)")
    print("| board | taxels | loaded bands [Hz] | necks through the riser | cavities [mm] | design [s] |")
    print("|---|---:|---|---:|---|---:|", flush=True)
    for k in range(len(ROWS)):
        subprocess.run([sys.executable, __file__, "--row", str(k)], check=True,
                       env={**os.environ, "MATCAD_CACHE_DIR": "", "OMP_NUM_THREADS": "1"})


if __name__ == "__main__":
    if "--row" in sys.argv:
        label, make, ask, band, vary = ROWS[int(sys.argv[sys.argv.index("--row") + 1])]
        board_row(label, make(), ask, band, vary)
        sys.exit(0)
    one_taxel()
    if "--solve-only" not in sys.argv:
        boards()
