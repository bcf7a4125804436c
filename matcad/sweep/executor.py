"""Run plain-data tasks on local processes (concurrent.futures) or on a Dask cluster (``--scheduler``).

Tasks go out in chunks (one round trip per chunk) and come back as plain dicts in task order. A local worker
that dies (out of memory, killed) breaks its pool: the chunks that did not come back are run again, each in a
fresh process of its own, and only a chunk whose process dies again is recorded as ``status = "failed"`` for each
of its variants (``reason`` "worker lost"); the sweep goes on. Dask resubmits a dead worker's tasks itself.
``dask.distributed`` is imported only when a scheduler address is given (the optional extra ``matcad[cluster]``);
the address is checked before anything connects (:func:`check_address`).
"""

from __future__ import annotations

import collections
import contextlib
import math
import re
from dataclasses import dataclass

CHUNKS_PER_WORKER = 4
"""Chunks per worker: few enough to amortise the per-task overhead, enough to balance uneven variants."""
CONNECT_TIMEOUT_S = 10.0
PROTOCOLS = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
"""The Dask comm protocols a ``--scheduler`` address may name (none: tcp)."""
_HOST_PORT = re.compile(r"^(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})$")


def check_address(address: str) -> str:
    """``address`` if it is a Dask scheduler address (``[protocol://]host:port``, port 1-65535; ``inproc://...``
    as given); otherwise ValueError naming it and the form allowed, before any connection is tried."""
    allowed = "must be [protocol://]host:port with a port 1-65535, e.g. tcp://10.0.0.5:8786"
    protocol, sep, rest = address.partition("://")
    if not sep:
        protocol, rest = "tcp", address
    if protocol not in PROTOCOLS:
        raise ValueError(f"--scheduler {address}: protocol {protocol!r} unknown, one of {', '.join(PROTOCOLS)}; "
                         f"the address {allowed}")
    if protocol == "inproc":
        if not rest:
            raise ValueError(f"--scheduler {address}: {allowed}")
        return address
    match = _HOST_PORT.match(rest)
    if not match or not 1 <= int(match.group(2)) <= 65535:
        raise ValueError(f"--scheduler {address}: {allowed}")
    return address


@dataclass(frozen=True)
class Executor:
    """Where tasks run: ``workers`` local processes (1 = in this process), or the Dask scheduler at ``scheduler``
    (then ``workers`` is ignored; the cluster's threads are used)."""

    workers: int = 1
    scheduler: str | None = None

    def __post_init__(self):
        if self.scheduler is not None:
            check_address(self.scheduler)

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


def run(fn_chunk, tasks: list[dict], executor: Executor, progress=None) -> list[dict]:
    """``fn_chunk`` (a module-level function: list of task dicts → list of result dicts) over ``tasks``;
    ``progress(tasks done, tasks)`` is called as chunks come back (in this process: every few tasks)."""
    if not tasks:
        return []
    if executor.scheduler:
        return _dask(fn_chunk, tasks, executor.scheduler)
    workers = min(executor.workers, len(tasks))  # never more processes than variants
    if workers == 1:
        if progress is None:
            return fn_chunk(tasks)
        out: list[dict] = []
        for chunk in _chunks(tasks, len(tasks)):  # one task at a time, told as each is done
            out += fn_chunk(chunk)
            progress(len(out), len(tasks))
        return out
    chunks = _chunks(tasks, workers)
    with Processes(workers) as procs:
        futures = [procs.pool.submit(fn_chunk, c) for c in chunks]
        done = _results(futures, chunks, progress)
    lost = [k for k, r in enumerate(done) if isinstance(r, BaseException)]
    if lost:  # a dead worker broke the pool: every chunk that did not come back again, one fresh process each
        for start in range(0, len(lost), workers):
            batch = lost[start:start + workers]
            pools = [procs.fresh(1) for _ in batch]
            try:
                again = _results([p.submit(fn_chunk, chunks[k]) for p, k in zip(pools, batch)])
            finally:
                for p in pools:
                    p.shutdown(wait=True, cancel_futures=True)
            for k, r in zip(batch, again):
                done[k] = r
    return _joined(chunks, done)


def _results(futures, chunks=None, progress=None) -> list:
    """Each future's result, or the exception it raised; ``progress(tasks done, tasks)`` told as each comes."""
    out = []
    total = sum(len(c) for c in chunks) if chunks else 0
    done = 0
    for k, future in enumerate(futures):
        try:
            out.append(future.result())
        except Exception as exc:  # noqa: BLE001 - a dead worker fails its variants, not the sweep
            out.append(exc)
        if progress is not None and chunks:
            done += len(chunks[k])
            progress(done, total)
    return out


def _joined(chunks, results) -> list[dict]:
    out = []
    for chunk, result in zip(chunks, results):
        out += _lost(chunk, result) if isinstance(result, BaseException) else result
    return out


def _collect(chunks, futures) -> list[dict]:
    return _joined(chunks, _results(futures))


def _client(address: str):
    """A dask.distributed Client of the scheduler at ``address``; ValueError (bad input) without the extra or when
    nothing answers there within CONNECT_TIMEOUT_S."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise ValueError("--scheduler needs dask.distributed: pip install 'matcad[cluster]'") from None
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ValueError(f"--scheduler {address}: cannot connect to a Dask scheduler there ({exc})") from None
    return client


def _dask(fn_chunk, tasks: list[dict], address: str) -> list[dict]:
    client = _client(address)
    with client:
        n_workers = max(1, sum(client.nthreads().values()))
        chunks = _chunks(tasks, n_workers)
        futures = client.map(fn_chunk, chunks, pure=False)
        return _collect(chunks, futures)


class Processes:
    """Local worker processes (spawned: they start clean, with no inherited threads or CAD-kernel state, the same on
    every platform) kept for several streams of one job: a sweep's warm-up and its grid share them, so a worker's
    start is paid once (Python and the sweep's modules, numpy among them: 0.12 s to its first task on a 2-core
    machine, then what that task imports). A context manager; the processes start with the first task (:attr:`pool`),
    :meth:`restart` replaces those a dead worker took down."""

    def __init__(self, workers: int, initializer=None):
        import functools
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        self.workers = workers
        self.fresh = functools.partial(ProcessPoolExecutor, mp_context=multiprocessing.get_context("spawn"),
                                       initializer=initializer)
        """A new pool of the given number of processes, each starting with ``initializer()`` (a module-level
        function) when given."""
        self._pool = None

    @property
    def pool(self):
        if self._pool is None:
            self._pool = self.fresh(self.workers)
        return self._pool

    def restart(self) -> None:
        self.close()
        self._pool = self.fresh(self.workers)

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def __enter__(self) -> Processes:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def processes(executor: Executor, tasks: int, initializer=None) -> Processes | contextlib.nullcontext:
    """The local processes of ``executor`` for :func:`stream` calls over up to ``tasks`` tasks to share (a context
    manager giving a :class:`Processes`, each process starting with ``initializer()``), or a context giving None
    where it has none (one process or one task: the tasks run in this one; a Dask cluster)."""
    if executor.scheduler or min(executor.workers, tasks) <= 1:
        return contextlib.nullcontext()
    return Processes(min(executor.workers, tasks), initializer)


def stream(fn_chunk, tasks: list[dict], executor: Executor, shared: Processes | None = None):
    """Like :func:`run`, but one task per chunk, yielding each task's result list in task order as it comes, with
    at most :data:`CHUNKS_PER_WORKER` tasks per worker in flight (a sweep streamed to disk holds no more). A task
    whose local worker died is run again alone in a fresh process (the processes are restarted and the tasks in
    flight resubmitted); if that dies too, its result is the lost-worker rows. ``shared``: local processes of
    :func:`processes` to run on (else this stream starts its own)."""
    if not tasks:
        return
    if executor.scheduler:
        yield from _dask_stream(fn_chunk, tasks, executor.scheduler)
        return
    if shared is not None:
        yield from _streamed(fn_chunk, tasks, shared)
        return
    if min(executor.workers, len(tasks)) == 1:
        for task in tasks:
            yield fn_chunk([task])
        return
    with Processes(min(executor.workers, len(tasks))) as own:
        yield from _streamed(fn_chunk, tasks, own)


def _streamed(fn_chunk, tasks: list[dict], procs: Processes):
    """:func:`stream` on the local processes ``procs``."""
    todo, pending = iter(tasks), collections.deque()

    def submit() -> None:
        task = next(todo, None)
        if task is not None:
            pending.append((task, procs.pool.submit(fn_chunk, [task])))

    for _ in range(procs.workers * CHUNKS_PER_WORKER):
        submit()
    while pending:
        task, future = pending.popleft()
        try:
            result = future.result()
        except Exception:  # noqa: BLE001 - a dead worker: restart the processes, resubmit, run this task alone
            procs.restart()
            pending = collections.deque((t, procs.pool.submit(fn_chunk, [t])) for t, _ in pending)
            alone = procs.fresh(1)
            try:
                result = _results([alone.submit(fn_chunk, [task])])[0]
            finally:
                alone.shutdown(wait=True, cancel_futures=True)
            result = _joined([[task]], [result])
        yield result
        submit()


def _dask_stream(fn_chunk, tasks: list[dict], address: str):
    client = _client(address)
    with client:
        futures = client.map(fn_chunk, [[t] for t in tasks], pure=False)
        for task, future in zip(tasks, futures):
            yield _joined([[task]], _results([future]))
            future.release()
