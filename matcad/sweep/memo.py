"""Exact memoisation of functions of a spec over a sweep's grid: a function (a design rule, the calibration's slope)
is run once per distinct combination of the varied fields it actually reads, and its result is given to every
variant that agrees on those fields.

While the function runs on one variant's resolved spec, every field it reads is recorded (the spec's tables are
wrapped in subclasses that note each attribute read). A function of the spec is deterministic, so any variant
that agrees with this one on the fields read follows the same path, reads the same fields and returns the same
result: that is the memo's key. Reading more than needed (a ``dataclasses.replace``, a hash) only makes the key
finer, never wrong. A rule reading one varied field runs once per value of that field, however large the grid.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import threading

import numpy as np

_state = threading.local()


def _record(key: str) -> None:
    reads = getattr(_state, "reads", None)
    if reads is not None:
        reads.add(key)


@functools.cache
def _traced_class(cls: type) -> type:
    keys = {f.name: f"{cls.table}.{f.name}" for f in dataclasses.fields(cls)}
    keys["__dict__"] = f"{cls.table}.*"  # every field at once
    key_of, attribute = keys.get, object.__getattribute__

    def __getattribute__(self, name):
        key = key_of(name)
        if key is not None:
            _record(key)
        return attribute(self, name)

    return type(f"Traced{cls.__name__}", (cls,), {"__getattribute__": __getattribute__})


def _wrap(section):
    traced = object.__new__(_traced_class(type(section)))
    object.__getattribute__(traced, "__dict__").update(vars(section))
    return traced


def traced(spec):
    """A copy of the resolved ``spec`` whose tables record every field read (see :func:`run`)."""
    from matcad.spec import SECTIONS

    out = copy.copy(spec)
    for name in SECTIONS:
        section = getattr(spec, name)
        if section is not None:
            object.__setattr__(out, name, _wrap(section))
    return out


def run(function, spec) -> tuple[frozenset, object]:
    """(fields read, result) of ``function(spec)`` on a traced copy; an exception is the result
    ``("failed", "Type: message")``."""
    copy_ = traced(spec)  # made before recording starts: copying is not reading
    _state.reads = set()
    try:
        try:
            result = function(copy_)
        except Exception as exc:  # noqa: BLE001 - a variant's failure is a row of the table, never fatal
            result = ("failed", f"{exc.__class__.__name__}: {exc}")
        return frozenset(_state.reads), result
    finally:
        _state.reads = None


class Table:
    """{integer code: integer number} that also looks up a whole array of codes at once: its keys ascending and
    their numbers as arrays, remade only after it has grown (a chunk's lookup is a binary search, not a Python
    loop over its codes)."""

    def __init__(self):
        self._numbers: dict[int, int] = {}
        self._arrays: tuple[np.ndarray, np.ndarray] | None = None

    def __len__(self) -> int:
        return len(self._numbers)

    def __contains__(self, code: int) -> bool:
        return code in self._numbers

    def __setitem__(self, code: int, number: int) -> None:
        self._numbers[code] = number
        self._arrays = None

    def items(self):
        """(code, number) pairs."""
        return self._numbers.items()

    def find(self, codes: np.ndarray) -> np.ndarray:
        """The number of each of ``codes`` (int64 array), -1 where the table has none."""
        if self._arrays is None:
            keys = np.fromiter(self._numbers, dtype=np.int64, count=len(self._numbers))
            numbers = np.fromiter(self._numbers.values(), dtype=np.int64, count=len(self._numbers))
            order = np.argsort(keys)
            self._arrays = keys[order], numbers[order]
        return lookup(*self._arrays, codes)


def lookup(keys: np.ndarray, numbers: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """``numbers[i]`` where ``keys[i]`` is the code, for each of ``codes``, -1 where no key is (``keys``: distinct,
    ascending; int64 arrays)."""
    codes = np.asarray(codes, dtype=np.int64)
    if not len(keys):
        return np.full(codes.shape, -1, dtype=np.int64)
    at = np.minimum(np.searchsorted(keys, codes), len(keys) - 1)
    return np.where(keys[at] == codes, numbers[at], -1)


class Memo:
    """One function's results over a grid: for each set of axes it was seen to read, a :class:`Table` {code of those
    axes' value indices: outcome number}; outcomes are stored once each (:attr:`outcomes`)."""

    def __init__(self, function):
        self.function = function
        self.tables: dict[tuple[int, ...], Table] = {}
        self.outcomes: list = []
        self._number: dict = {}

    def merge(self, tables: dict, outcomes: list) -> None:
        """Adds another process's memo of the same function on the same grid (its ``tables`` over its
        ``outcomes``): a code both know has the same outcome, a new one joins with its outcome renumbered here."""
        number = [self._intern(outcome) for outcome in outcomes]
        for axes, table in tables.items():
            mine = self.tables.setdefault(axes, Table())
            for code, k in table.items():
                if code not in mine:
                    mine[code] = number[k]

    def _intern(self, outcome) -> int:
        key = repr(outcome)
        if key not in self._number:
            self._number[key] = len(self.outcomes)
            self.outcomes.append(outcome)
        return self._number[key]

    def apply(self, grid) -> np.ndarray:
        """Outcome numbers of the chunk's variants (``grid``: a :class:`GridChunk`), running the function only on
        variants whose combination of read fields has not been seen yet."""
        n = len(grid)
        out = np.full(n, -1, dtype=np.int64)
        for axes, table in self.tables.items():
            self._fill(out, grid, axes, table)
        while (todo := np.flatnonzero(out < 0)).size:
            reads, outcome = run(self.function, grid.spec(int(todo[0])))
            axes = grid.axes_of(reads)
            table = self.tables.setdefault(axes, Table())
            codes = grid.codes(axes, todo)
            first = {}
            for j, code in zip(todo.tolist(), codes.tolist()):
                first.setdefault(code, j)
            for code, j in first.items():  # one run per new combination of the fields read
                if code in table:
                    continue
                if j == todo[0]:
                    table[code] = self._intern(outcome)
                    continue
                reads_j, outcome_j = run(self.function, grid.spec(j))
                if grid.axes_of(reads_j) == axes:
                    table[code] = self._intern(outcome_j)
                else:  # another path through the function: its own key
                    other = grid.axes_of(reads_j)
                    self.tables.setdefault(other, Table())[int(grid.codes(other, np.array([j]))[0])] = \
                        self._intern(outcome_j)
            for axes_k, table_k in self.tables.items():
                self._fill(out, grid, axes_k, table_k)
        return out

    @staticmethod
    def _fill(out, grid, axes, table) -> None:
        todo = np.flatnonzero(out < 0)
        if not todo.size or not table:
            return
        out[todo] = table.find(grid.codes(axes, todo))
