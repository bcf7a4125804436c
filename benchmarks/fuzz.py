"""≥ 10 000 generated specs through `check` and `build` (the same strategy and contract as tests/test_fuzz.py),
printing how many were invalid (exit 2), refused by the design rules (exit 1) and built and read back.

Run: .venv/bin/python benchmarks/fuzz.py [N]   (default 10 000; any contract breach raises with the example)
"""

import collections
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hypothesis import HealthCheck, given, settings  # noqa: E402

from tests.test_fuzz import out_args, run_one, spec_documents  # noqa: E402


def main(n: int) -> None:
    counts = collections.Counter()
    base = Path(tempfile.mkdtemp(prefix="matcad-fuzz-"))
    t0 = time.perf_counter()

    @given(data=spec_documents(), out_arg=out_args, force=__import__("hypothesis").strategies.booleans())
    @settings(max_examples=n, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    def one(data, out_arg, force):
        workdir = Path(tempfile.mkdtemp(dir=base))
        cwd = os.getcwd()
        os.chdir(workdir)
        try:
            counts[run_one(data, workdir, out_arg, force)] += 1
        finally:
            os.chdir(cwd)

    one()
    total = sum(counts.values())
    seconds = time.perf_counter() - t0
    print(f"{total} generated specs in {seconds:.0f} s ({1e3 * seconds / total:.0f} ms each), 0 contract breaches")
    for outcome in ("invalid", "rules", "built"):
        print(f"  {outcome:<8} {counts[outcome]:>6}  ({100 * counts[outcome] / total:.1f} %)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
