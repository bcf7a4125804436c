"""One progress line on standard error for long work, only where a person watches it.

The compute code never prints: it takes an optional callback ``progress(done, total)`` (counts of its own
units: variants, load steps, parts, seconds of a recording) and calls it as it goes. A command makes the
callback with :func:`line`; it draws ``matcad: LABEL 120/336 variants (36 %), 24 s, ~42 s left`` on one
line that it rewrites in place (at most every :data:`INTERVAL_S`; between calls a timer redraws it every
:data:`TICK_S` so the elapsed time moves during one long step, e.g. a FEM solve) and erases when the work ends,
so the command's own output is never mixed with it.

The line is drawn only when standard error is a terminal and the command was not asked for ``--json``;
in a pipe, a log file, a CI run or under ``--json`` :func:`line` gives a callback that does nothing.
``MATCAD_PROGRESS=0`` turns it off on a terminal too (``1`` forces it on, for tests of the drawing).
"""

from __future__ import annotations

import os
import sys
import time
from contextlib import contextmanager

INTERVAL_S = 0.2
"""Least time between two redraws of the line (s): a terminal is not flooded by fast loops."""
TICK_S = 1.0
"""The timer's redraw period (s) while no callback comes."""


def wanted(quiet: bool = False, stream=None) -> bool:
    """Whether a progress line is drawn: not ``quiet`` (``--json``), and ``stream`` (default standard error)
    is a terminal, unless the environment variable MATCAD_PROGRESS says 0 (never) or 1 (always)."""
    if quiet:
        return False
    forced = os.environ.get("MATCAD_PROGRESS", "").strip()
    if forced in ("0", "1"):
        return forced == "1"
    stream = stream if stream is not None else sys.stderr
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):  # a closed or replaced stream
        return False


def _nothing(done=0, total=None) -> None:
    """The callback when no line is drawn."""


class _Line:
    """The drawing callback: ``self(done, total)`` redraws the line when :data:`INTERVAL_S` has passed."""

    def __init__(self, label: str, unit: str, stream):
        import threading  # only a drawn line ticks: a command run without a terminal loads no threading

        self.label, self.unit, self.stream = label, unit, stream
        self.start = time.monotonic()
        self.last = -INTERVAL_S
        self.drawn = False
        self.state: tuple = (0, None)
        self.lock = threading.Lock()
        self.stop = threading.Event()
        self.timer = threading.Thread(target=self._tick, name="matcad-progress", daemon=True)

    def _tick(self) -> None:
        while not self.stop.wait(TICK_S):
            self._draw(*self.state)

    def text(self, done: float, total: float | None) -> str:
        elapsed = time.monotonic() - self.start
        count = f"{done:g}" if total is None else f"{done:g}/{total:g}"
        parts = [f"matcad: {self.label} {count} {self.unit}".rstrip()]
        if total:
            share = min(max(done / total, 0.0), 1.0)
            parts[0] += f" ({share * 100:.0f} %)"
            parts.append(f"{elapsed:.0f} s")
            if 0 < share < 1 and elapsed > 1.0:
                parts.append(f"~{elapsed * (1 - share) / share:.0f} s left")
        else:
            parts.append(f"{elapsed:.0f} s")
        return ", ".join(parts)

    def __call__(self, done: float = 0, total: float | None = None) -> None:
        self.state = (done, total)
        if time.monotonic() - self.last >= INTERVAL_S or (total and done >= total):
            self._draw(done, total)

    def _draw(self, done, total) -> None:
        with self.lock:
            if self.stop.is_set():  # erased: nothing draws again
                return
            self.last = time.monotonic()
            try:
                self.stream.write("\r\x1b[K" + self.text(done, total))
                self.stream.flush()
                self.drawn = True
            except (OSError, ValueError):  # the terminal went away: the work goes on without its line
                pass

    def clear(self) -> None:
        self.stop.set()
        with self.lock:
            if self.drawn:
                try:
                    self.stream.write("\r\x1b[K")
                    self.stream.flush()
                except (OSError, ValueError):
                    pass


@contextmanager
def line(label: str, unit: str = "", quiet: bool = False, stream=None):
    """A callback ``progress(done, total=None)`` for the work inside the ``with`` block: it draws the progress
    line on ``stream`` (default standard error) when :func:`wanted`, and does nothing otherwise. The line is
    erased when the block ends (normally or by an exception)."""
    stream = stream if stream is not None else sys.stderr
    if not wanted(quiet, stream):
        yield _nothing
        return
    drawing = _Line(label, unit, stream)
    drawing(0, None)
    drawing.timer.start()
    try:
        yield drawing
    finally:
        drawing.clear()
        drawing.timer.join(timeout=2 * TICK_S)
