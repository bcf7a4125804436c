"""An array sweep's rule memos warmed before the grid streams, their work split over the local worker processes.

Each process of an array sweep memoises the design rules per distinct combination of the varied fields they read
(:mod:`matcad.sweep.memo`), and a process meets nearly every combination in its first chunks (the grid's inner
axes cycle through them in each chunk), so on N processes the rules ran N times over. Warmed, the combinations are
split over the N processes once, their memos merged, and every process of the sweep starts from the merge
(:func:`matcad.sweep.run.array_chunks`). A combination the warm-up did not meet (a rule that reads another field
on another variant) is still run where it is met: the outputs are those of an unwarmed sweep, byte for byte. Not
on a Dask cluster (its workers are not known ahead) nor in one process (nothing to split).
"""

from __future__ import annotations

import math

import numpy as np

from matcad.sweep import arrays
from matcad.sweep.executor import Executor, stream

WARM_SHARE = 4
"""Warm only where the rules' distinct inputs are at most 1/WARM_SHARE of the grid: with fewer repeats each chunk
meets mostly new combinations anyway, and the warm-up would be most of the sweep."""


def warmed(data: dict, axes, executor: Executor) -> list | None:
    """The rule memos (:func:`matcad.sweep.arrays.rule_memos`) filled on every combination of the axes the rules
    read on the grid's first valid variant (the other axes at their first value), split over the executor's local
    processes and merged: [(tables, outcomes)] per memo, as :meth:`matcad.sweep.memo.Memo.merge` takes them; None
    where warming does not pay (one process, a Dask cluster, no valid variant in the first chunk, or inputs that
    hardly repeat)."""
    from matcad.spec import from_dict

    if executor.scheduler or executor.workers <= 1:
        return None
    shape = tuple(len(a.values) for a in axes)
    first = arrays.GridChunk(data, axes, np.arange(min(arrays.CHUNK, math.prod(shape))))
    valid = np.flatnonzero(arrays.validate(first, from_dict(data)) == "")
    if not len(valid):
        return None
    probe = arrays.rule_memos()
    for memo in probe:
        memo.apply(first.subset(valid[:1]))
    read = sorted({k for memo in probe for key in memo.tables for k in key})
    count = math.prod(shape[k] for k in read)
    if count * WARM_SHARE > math.prod(shape) or count < executor.workers:
        return None
    index = np.zeros((len(axes), count), dtype=np.int64)
    if read:
        index[read] = np.unravel_index(np.arange(count), tuple(shape[k] for k in read))
    rows = np.ravel_multi_index(tuple(index), shape)
    tasks = [{"index": k, "data": data, "axes": tuple(axes), "rows": part}
             for k, part in enumerate(np.array_split(rows, executor.workers))]
    merged = arrays.rule_memos()
    for results in stream(warm_chunks, tasks, executor):
        for memo, (tables, outcomes) in zip(merged, results[0].get("memos", ())):  # a lost worker: not warmed
            memo.merge(tables, outcomes)
    return [(memo.tables, memo.outcomes) for memo in merged]


def warm_chunks(tasks: list[dict]) -> list[dict]:
    """Executor function: each task's variants (``rows`` of the grid; the valid ones) through every rule memo →
    {"index", "memos": [(tables, outcomes)] per memo}."""
    from matcad.spec import from_dict

    out = []
    for task in tasks:
        chunk = arrays.GridChunk(task["data"], task["axes"], np.asarray(task["rows"], dtype=np.int64))
        good = chunk.subset(np.flatnonzero(arrays.validate(chunk, from_dict(task["data"])) == ""))
        memos = arrays.rule_memos()
        for memo in memos:
            memo.apply(good)
        out.append({"index": task["index"], "memos": [(memo.tables, memo.outcomes) for memo in memos]})
    return out
