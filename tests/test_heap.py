"""A sweep's processes keep freed memory (matcad.sweep.heap): the kernel stops zeroing pages for every chunk."""

import platform
import subprocess
import sys

import pytest

from tests.conftest import ROOT

CHURN = """
import resource, sys
import numpy as np
from matcad.sweep import heap
kept = heap.keep_freed_memory() if sys.argv[1] == "keep" else None
faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(100):  # a chunk's arrays: 40 live at once, allocated and freed together
    live = [np.ones(4096 * int(sys.argv[2])) * k for k in range(40)]
    del live
print(kept, resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults,
      resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def _churn(mode: str, columns: int) -> tuple[str, int, int]:
    out = subprocess.run([sys.executable, "-c", CHURN, mode, str(columns)], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout.split()
    return out[0], int(out[1]), int(out[2])


@pytest.mark.parametrize("columns", [1, 8])  # 32 kB arrays (under glibc's first mmap threshold), 256 kB (over it)
def test_kept_memory_is_not_faulted_again(columns):
    """Arrays the size of a chunk's columns, allocated and freed 100 times: by default the kernel faults their pages
    in again each time (~300 faults a round at 32 kB, ~2 500 at 256 kB); kept, under 5 % of that, for at most
    :data:`TOP_PAD_MIB` more peak memory. Elsewhere than glibc nothing is changed."""
    from matcad.sweep.heap import TOP_PAD_MIB

    if platform.libc_ver()[0] != "glibc":
        assert _churn("keep", columns)[0] == "False"
        return
    _, plain, plain_rss = _churn("plain", columns)
    kept, faults, rss = _churn("keep", columns)
    assert kept == "True"
    assert plain > 100 * 40 and faults < 0.05 * plain, (plain, faults)
    assert rss - plain_rss < TOP_PAD_MIB * 1024, (plain_rss, rss)  # kB


def test_a_sweeps_local_workers_keep_freed_memory():
    """The processes a sweep spawns (matcad.sweep.executor.processes with the sweep's initializer) have run it before
    their first chunk; processes started without it have not."""
    from matcad.sweep import heap
    from matcad.sweep.executor import Executor, processes, stream
    from tests.dying_worker import heap_kept

    tasks = [{"index": i} for i in range(4)]
    for initializer, expected in ((heap.keep_freed_memory, True), (None, False)):
        with processes(Executor(2), len(tasks), initializer) as shared:
            kept = {r["kept"] for chunk in stream(heap_kept, tasks, Executor(2), shared) for r in chunk}
        assert kept == {expected}
