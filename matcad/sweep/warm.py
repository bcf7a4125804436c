"""An array sweep's memos warmed before the grid streams, their work split over the local worker processes.

Each process of an array sweep memoises the design rules and Eq. 5's slope per distinct combination of the varied
fields they read (:mod:`matcad.sweep.memo`), and a process meets nearly every combination in its first chunks (the
grid's inner axes cycle through them in each chunk), so on N processes they ran N times over. Warmed, the
combinations are split over the N processes once (the processes the grid then runs on), their memos merged, and
every process of the sweep starts from the merge (:func:`matcad.sweep.run.array_chunks`). A combination the warm-up
did not meet (a rule that reads another field on another variant) is still run where it is met: the outputs are
those of an unwarmed sweep, byte for byte. Not on a Dask cluster (its workers are not known ahead) nor in one
process (nothing to split).
"""

from __future__ import annotations

import math

import numpy as np

from matcad.sweep import arrays
from matcad.sweep.executor import Executor, Processes, stream

WARM_SHARE = 4
"""Warm only where the rules' distinct inputs are at most 1/WARM_SHARE of the grid: with fewer repeats each chunk
meets mostly new combinations anyway, and the warm-up would be most of the sweep."""


def warmed(data: dict, axes, rules: bool, executor: Executor, shared: Processes | None = None) -> list | None:
    """The sweep's memos (:func:`matcad.sweep.arrays.memos`: Eq. 5's slope, and the design rules when ``rules``)
    filled on every combination of the axes each memo reads on the grid's first valid variant, the other axes at
    that variant's values (a rule reading the neck meets every neck, one reading the cavity every cavity, not every
    neck with every cavity), split over the executor's local processes (``shared``: the sweep's own,
    :func:`matcad.sweep.executor.processes`) and merged: [(tables, outcomes)] per memo, as
    :meth:`matcad.sweep.memo.Memo.merge` takes them; None where warming does not pay (one process, a Dask cluster,
    no valid variant in the first chunk, or inputs that hardly repeat)."""
    from matcad.spec import from_dict

    if executor.scheduler or executor.workers <= 1:
        return None
    shape = tuple(len(a.values) for a in axes)
    first = arrays.GridChunk(data, axes, np.arange(min(arrays.CHUNK, math.prod(shape))))
    valid = np.flatnonzero(arrays.validate(first, from_dict(data)) == "")
    if not len(valid):
        return None
    probe = arrays.memos(rules)
    for memo in probe:
        memo.apply(first.subset(valid[:1]))
    at = first.rows[valid[0]]  # the first valid variant: the axes a memo does not read stay at its values
    base = np.array(np.unravel_index(at, shape), dtype=np.int64)
    rows = np.unique(np.concatenate([combinations(base, shape, read) for read in
                                     {key for memo in probe for key in memo.tables}]))
    if len(rows) * WARM_SHARE > math.prod(shape) or len(rows) < executor.workers:
        return None
    tasks = [{"index": k, "data": data, "axes": tuple(axes), "rules": rules, "rows": part}
             for k, part in enumerate(np.array_split(rows, executor.workers))]
    merged = arrays.memos(rules)
    for results in stream(warm_chunks, tasks, executor, shared):
        for memo, (tables, outcomes) in zip(merged, results[0].get("memos", ())):  # a lost worker: not warmed
            memo.merge(tables, outcomes)
    return [(memo.tables, memo.outcomes) for memo in merged]


def combinations(base: np.ndarray, shape: tuple, read: tuple) -> np.ndarray:
    """Grid rows (flat indices into ``shape``) of every combination of the axes ``read``, the other axes at the
    indices ``base``."""
    count = math.prod(shape[k] for k in read)
    index = np.repeat(base[:, None], count, axis=1)
    if read:
        index[list(read)] = np.unravel_index(np.arange(count), tuple(shape[k] for k in read))
    return np.ravel_multi_index(tuple(index), shape)


def warm_chunks(tasks: list[dict]) -> list[dict]:
    """Executor function: each task's variants (``rows`` of the grid; the valid ones) through every rule memo →
    {"index", "memos": [(tables, outcomes)] per memo}."""
    from matcad.spec import from_dict

    out = []
    for task in tasks:
        chunk = arrays.GridChunk(task["data"], task["axes"], np.asarray(task["rows"], dtype=np.int64))
        good = chunk.subset(np.flatnonzero(arrays.validate(chunk, from_dict(task["data"])) == ""))
        memos = arrays.memos(task["rules"])
        for memo in memos:
            memo.apply(good)
        out.append({"index": task["index"], "memos": [(memo.tables, memo.outcomes) for memo in memos]})
    return out
