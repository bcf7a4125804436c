"""Chunk functions for the sweep executor's tests (a dead worker, shared processes, their initializer), in a module of
their own: a spawned worker imports only this one (the test module would cost each worker numpy, scipy and
matcad's prediction, ~0.7 s of CPU)."""

import os
import signal
import time

BUSY_S = 0.3
"""How long a surviving variant takes (s of sleep, no CPU): long enough that its chunk is still running or queued
when the other worker is killed, so a pool that breaks loses it."""


def killed_on_index_1(tasks):
    """Chunk function (list of task dicts → result dicts) whose worker process is killed on variant 1 (SIGKILL, as
    the out-of-memory killer does); other variants come back ok after :data:`BUSY_S`."""
    if any(t["index"] == 1 for t in tasks):
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(BUSY_S)
    return [{"index": t["index"], "status": "ok", "reason": ""} for t in tasks]


def process_of(tasks):
    """Chunk function: each task's result names the process that ran it (after :data:`BUSY_S`/3, so both workers
    take tasks)."""
    time.sleep(BUSY_S / 3)
    return [{"index": t["index"], "status": "ok", "reason": "", "pid": os.getpid()} for t in tasks]


def heap_kept(tasks):
    """Chunk function: each task's result says whether its process had :func:`matcad.sweep.heap.keep_freed_memory`
    run (its only import)."""
    from matcad.sweep import heap

    kept = heap.keep_freed_memory.cache_info().currsize == 1
    return [{"index": t["index"], "status": "ok", "reason": "", "kept": kept} for t in tasks]
