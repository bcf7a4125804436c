"""Run plain-data tasks on local processes (concurrent.futures) or on a Dask cluster (``--scheduler``).

Tasks go out in chunks (one round trip per chunk) and come back as plain dicts in task order. A chunk whose
worker dies (out of memory, killed) is recorded as ``status = "failed"`` for each of its variants, never fatal.
``dask.distributed`` is imported only when a scheduler address is given (the optional extra ``matcad[cluster]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

CHUNKS_PER_WORKER = 4
"""Chunks per worker: few enough to amortise the per-task overhead, enough to balance uneven variants."""
CONNECT_TIMEOUT_S = 10.0


@dataclass(frozen=True)
class Executor:
    """Where tasks run: ``workers`` local processes (1 = in this process), or the Dask scheduler at ``scheduler``
    (then ``workers`` is ignored; the cluster's threads are used)."""

    workers: int = 1
    scheduler: str | None = None

    def describe(self) -> str:
        if self.scheduler:
            return f"dask scheduler {self.scheduler}"
        return "this process" if self.workers == 1 else f"{self.workers} local processes"


def _chunks(items: list, n_workers: int) -> list[list]:
    size = max(1, math.ceil(len(items) / (n_workers * CHUNKS_PER_WORKER)))
    return [items[i:i + size] for i in range(0, len(items), size)]


def _lost(chunk: list[dict], exc: BaseException) -> list[dict]:
    reason = f"worker lost: {exc.__class__.__name__}: {exc}"
    return [{"index": t["index"], "status": "failed", "reason": reason} for t in chunk]


def run(fn_chunk, tasks: list[dict], executor: Executor) -> list[dict]:
    """``fn_chunk`` (a module-level function: list of task dicts → list of result dicts) over ``tasks``."""
    if not tasks:
        return []
    if executor.scheduler:
        return _dask(fn_chunk, tasks, executor.scheduler)
    workers = min(executor.workers, len(tasks))  # never more processes than variants
    if workers == 1:
        return fn_chunk(tasks)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    # spawn: workers start clean (no inherited threads or CAD-kernel state), the same on every platform
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        chunks = _chunks(tasks, workers)
        futures = [pool.submit(fn_chunk, c) for c in chunks]
        return _collect(chunks, futures)


def _collect(chunks, futures) -> list[dict]:
    out = []
    for chunk, future in zip(chunks, futures):
        try:
            out += future.result()
        except Exception as exc:  # noqa: BLE001 - a dead worker fails its variants, not the sweep
            out += _lost(chunk, exc)
    return out


def _dask(fn_chunk, tasks: list[dict], address: str) -> list[dict]:
    try:
        from dask.distributed import Client
    except ImportError:
        raise ValueError("--scheduler needs dask.distributed: pip install 'matcad[cluster]'") from None
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ValueError(f"--scheduler {address}: cannot connect to a Dask scheduler there ({exc})") from None
    with client:
        n_workers = max(1, sum(client.nthreads().values()))
        chunks = _chunks(tasks, n_workers)
        futures = client.map(fn_chunk, chunks, pure=False)
        return _collect(chunks, futures)
