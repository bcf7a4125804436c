"""Cold `matcad build` against bare imports, in the same run.

Targets: full paper build / `import build123d` ≤ 1.3; laser-only build / `import numpy` ≤ 2.
Run: .venv/bin/python benchmarks/build.py
"""

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks._timing import matcad, median_ratio  # noqa: E402


def main(runs=5):
    with tempfile.TemporaryDirectory() as tmp:
        full = matcad("build", "templates/mat-paper.toml", "--out", f"{tmp}/paper")
        t, b, r = median_ratio(full, [sys.executable, "-c", "import build123d"], runs=runs, warmup=1)
        print(f"matcad build templates/mat-paper.toml:     median {t:.2f} s")
        print(f"python -c 'import build123d':              median {b:.2f} s")
        print(f"ratio {r:.2f} (target <= 1.3)")
        laser = matcad("build", "templates/mat-laser-only.toml", "--out", f"{tmp}/laser")
        t, b, r = median_ratio(laser, [sys.executable, "-c", "import numpy"], runs=3 * runs, warmup=2)
        print(f"matcad build templates/mat-laser-only.toml: median {t * 1e3:.0f} ms")
        print(f"python -c 'import numpy':                   median {b * 1e3:.0f} ms")
        print(f"ratio {r:.2f} (target <= 2)")


if __name__ == "__main__":
    main()
