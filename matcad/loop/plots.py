"""Pictures of the recording loop: the band's spectrogram kept while tracking (max-pooled in time, bounded memory)
and the figures drawn from it — one taxel's track and segments, a board's taxels, forces against time. PNG;
frequencies Hz, times s, forces N. Drawn with matcad.canvas (Pillow): no plotting stack on the loop's path."""

from __future__ import annotations

import numpy as np

from matcad.loop.stats import median, percentile

PLOT_COLUMNS = 1200
SPECTROGRAM_PX = (800, 320)
"""Width of the spectrogram picture and height of each of its panels (px)."""
SPECTROGRAM_BOX = (85, 35, 785, 315)
"""The spectrogram's axes in the picture (left, top, right, bottom px; one panel lower under a long recording's
overview): a reader can map a pixel to (s, Hz), the time axis starting at 0 s."""
OVERVIEW_S = 60.0
"""A recording longer than this (s) gets an overview panel above its spectrogram: at 10 min the spectrogram alone
is a strip of hundreds of segments."""
OVERVIEW_WINDOWS = 60
"""The overview's time windows: the median voiced frequency (and force) per window, with its spread."""


class PlotPool:
    """A band's spectrogram (level dB per frame) max-pooled in time to at most 2·PLOT_COLUMNS columns: each time
    the columns reach that, neighbouring pairs merge and the pool doubles."""

    def __init__(self):
        self._cols: list[np.ndarray] = []
        self._times: list[float] = []
        self._pool = 1
        self._acc: list[np.ndarray] = []

    def push(self, times, level_db) -> None:
        """Frames at ``times`` (s) with their band's levels (frames × bins, dB)."""
        for t, row in zip(times, level_db):
            self._acc.append(row.astype(np.float32))
            if len(self._acc) == self._pool:
                self._cols.append(np.max(self._acc, axis=0))
                self._times.append(t)
                self._acc = []
                if len(self._cols) >= 2 * PLOT_COLUMNS:
                    self._cols = [np.maximum(a, b) for a, b in zip(self._cols[::2], self._cols[1::2])]
                    self._times = self._times[1::2]
                    self._pool *= 2

    def finish(self, last_time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(column times s, levels dB frequency × column); a partly filled last column is kept at
        ``last_time_s``."""
        if self._acc:
            self._cols.append(np.max(self._acc, axis=0))
            self._times.append(last_time_s)
        return np.array(self._times), np.array(self._cols).T


def plot(analysis, path, forces=None) -> None:
    """Spectrogram of an :class:`matcad.loop.analysis.Analysis`'s band (dB, max-pooled in time, 'magma' from the
    5th percentile to the loudest) with the voiced track (cyan) and segments (white, red when flagged); with
    ``forces`` (per frame: force, low, high in N) a second panel of force against time. Drawn with
    :mod:`matcad.canvas` (Pillow), not matplotlib: `analyze` stays near the cost of its tracker."""
    from matcad.canvas import Canvas, colour_map

    long = len(analysis.times_s) > 0 and analysis.times_s[-1] > OVERVIEW_S
    rows = 1 + (forces is not None) + long
    width, panel = SPECTROGRAM_PX
    canvas = Canvas(width, panel * rows + 45)
    t = analysis.plot_times_s
    xlim = (0.0, max(float(t[-1]) if len(t) else 1.0, 1e-3))  # the recording starts at 0 s, not at its first frame
    left, top, right, bottom = SPECTROGRAM_BOX
    if long:
        overview(canvas, SPECTROGRAM_BOX, analysis, None if forces is None else forces[0])
        top, bottom = top + panel, bottom + panel
    db = analysis.plot_db
    freqs = analysis.plot_freqs_hz
    ax = canvas.axes((left, top, right, bottom), xlim, (float(freqs[0]), float(freqs[-1])))
    ax.image(colour_map(db[::-1], float(percentile(db, 5)), float(db.max())),
             (float(t[0]), float(t[-1]), float(freqs[0]), float(freqs[-1])) if len(t) > 1 else None)
    ax.line(analysis.times_s, np.where(analysis.voiced, analysis.track_hz, np.nan), "cyan", 1)
    for s in analysis.segments:
        ax.line([s.start_s, s.end_s], [s.mean_hz, s.mean_hz], "red" if s.flag else "white", 2)
    ax.frame(ylabel="frequency [Hz]", xlabel="" if forces is not None else "time [s]",
             title=f"mean {analysis.mean_hz:.2f} Hz over {100 * analysis.tone_fraction:.0f} % of frames (voiced), "
                   f"{len(analysis.segments)} segments")
    ax.legend([("voiced track", "cyan", "line"), ("segment (red: flagged)", "#888888", "line")])
    if forces is not None:
        force, low, high = (np.asarray(v, dtype=float) for v in forces)
        ok = np.isfinite(low) & np.isfinite(high)
        span = np.concatenate([low[ok], high[ok], force[np.isfinite(force)]]) if ok.any() else np.array([0.0, 1.0])
        lo, hi = float(span.min()), float(span.max())
        pad = 0.05 * (hi - lo) or 0.5
        bx = canvas.axes((left, top + panel, right, bottom + panel), xlim, (lo - pad, hi + pad))
        times = analysis.times_s
        _interval(bx, times, low, high, "#b5d0e8")
        for x, f in zip(times, force):
            if np.isfinite(f):
                bx.marker(x, f, "o", "black", 1.2)
        bx.frame(xlabel="time [s]", ylabel="force [N]", grid="y")
        bx.legend([("95 % interval", "#b5d0e8", "bar"), ("force per voiced frame", "black", "o")])
    canvas.save(path)


def _interval(ax, times, low, high, colour) -> None:
    """The band from ``low`` to ``high`` (a force's interval in N, a frequency's spread in Hz) over ``times`` (s)
    filled in ``colour``: one polygon per run of two or more points where both ends are finite."""
    ok = np.isfinite(low) & np.isfinite(high)
    for run in np.split(np.arange(len(times)), np.flatnonzero(~ok) + 1):
        run = run[ok[run]]
        if len(run) > 1:
            ax.polygon(list(zip(times[run], high[run])) + list(zip(times[run][::-1], low[run][::-1])), colour)


def _windowed(times, values, edges):
    """Per window of ``edges`` (s): the 10th, 50th and 90th percentile of the finite ``values`` (NaN if none)."""
    out = np.full((len(edges) - 1, 3), np.nan)
    which = np.digitize(times, edges) - 1
    for k in range(len(edges) - 1):
        v = values[(which == k) & np.isfinite(values)]
        if len(v):
            out[k] = percentile(v, [10, 50, 90])
    return out


def overview(canvas, box, analysis, force=None):
    """The overview of a long recording in the pixel ``box`` of ``canvas``: per window (:data:`OVERVIEW_WINDOWS`)
    the median voiced frequency (blue) with its 10-90 % spread on an axis from 0 Hz; with ``force`` (per frame, N)
    the median force (red) on its own axis from 0 N, scaled into the same box (ticks on the right); a summary of the
    segments and forces in the title. Returns the frequency axes, the force axes (or None) and the title."""
    times = analysis.times_s
    edges = np.linspace(0.0, float(times[-1]), OVERVIEW_WINDOWS + 1)
    mids = (edges[:-1] + edges[1:]) / 2
    hz = _windowed(times, np.where(analysis.voiced, analysis.track_hz, np.nan), edges)
    top_hz = 1.15 * max(float(np.nanmax(hz[:, 2])) if np.isfinite(hz).any() else 1.0, float(analysis.band_hz[1]))
    ax = canvas.axes(box, (0.0, float(times[-1])), (0.0, top_hz))
    _interval(ax, mids, hz[:, 0], hz[:, 2], "#c5d7ec")
    ax.line(mids, hz[:, 1], "#1f4e8c", 1)
    means = np.array([s.mean_hz for s in analysis.segments])
    summary = (f"{len(means)} segments, means {means.min():.0f}-{means.max():.0f} Hz (median {median(means):.0f})"
               if len(means) else "no steady segment")
    legend = [("median voiced frequency (10-90 %)", "#1f4e8c", "line")]
    fx = None
    if force is not None:
        f = _windowed(times, np.asarray(force, dtype=float), edges)
        top_n = 1.15 * max(float(np.nanmax(f[:, 2])) if np.isfinite(f).any() else 1.0, 1e-3)
        fx = canvas.axes(box, ax.xlim, (0.0, top_n))
        fx.line(mids, f[:, 1], "#c0392b", 1)
        from matcad.canvas import nice_ticks, tick_label

        ticks = [v for v in nice_ticks(0.0, top_n, 5) if 0.0 <= v <= top_n]
        for v in ticks:
            canvas.text(box[2] + 4, fx.y(v), tick_label(v, ticks), 9, "#c0392b", anchor="lm")
        finite = np.asarray(force, dtype=float)
        finite = finite[np.isfinite(finite)]
        if len(finite):
            summary += f"; force {finite.min():.2f}-{finite.max():.2f} N (median {median(finite):.2f})"
        legend.append(("median force [N], right axis", "#c0392b", "line"))
    title = f"overview of {times[-1]:.0f} s: {summary}"
    ax.frame(ylabel="frequency [Hz]", grid="y", size=10, title=title)
    ax.legend(legend, 9, corner="upper left")
    return ax, fx, title


def plot_board(tracks, path, readings=None) -> None:
    """One figure: every taxel's band (:class:`matcad.loop.board.TaxelTrack`) as spectrogram (dB, grey) with its
    voiced track, a colour and a label per taxel; with ``readings`` ({name: Reading}) a second panel of force
    against time, one line and 95 % band per taxel. Drawn with :mod:`matcad.canvas` (no matplotlib)."""
    from matcad.canvas import GREYS_R, TAB10, Canvas, colour_map, tint

    rows = 2 if readings else 1
    width, panel = 900, 360
    canvas = Canvas(width, panel * rows + 45)
    box = (85, 35, width - 15, panel - 5)
    present = [t for t in tracks if t.analysis is not None]
    levels = np.concatenate([t.analysis.plot_db.ravel() for t in present]) if present else np.zeros(1)
    vmin, vmax = float(percentile(levels, 5)), float(levels.max())
    times = np.concatenate([t.analysis.plot_times_s for t in present]) if present else np.array([0.0, 1.0])
    xlim = (0.0, max(float(times.max()), 1e-3))  # the recording starts at 0 s
    lo, hi = min(t.band_hz[0] for t in tracks), max(t.band_hz[1] for t in tracks)
    ax = canvas.axes(box, xlim, (lo, hi))
    legend = []
    for k, t in enumerate(tracks):
        colour = TAB10[k % 10]
        ax.rect(xlim[0], t.band_hz[0], xlim[1], t.band_hz[1], fill=tint(colour, 0.08))
        if t.analysis is None:
            ax.text(xlim[0] + 0.01 * (xlim[1] - xlim[0]), float(np.mean(t.band_hz)), f"{t.name}: no tone", 10,
                    colour, anchor="lm")
            continue
        a = t.analysis
        ax.image(colour_map(a.plot_db[::-1], vmin, vmax, GREYS_R),
                 (float(a.plot_times_s[0]), float(a.plot_times_s[-1]), float(a.plot_freqs_hz[0]),
                  float(a.plot_freqs_hz[-1])))
    for k, t in enumerate(tracks):
        if t.analysis is not None:
            a, colour = t.analysis, TAB10[k % 10]
            ax.line(a.times_s, np.where(a.voiced, a.track_hz, np.nan), colour, 2)
            legend.append((f"{t.name}: {a.mean_hz:.0f} Hz, tone {100 * a.tone_fraction:.0f} %", colour, "line"))
    ax.frame(ylabel="frequency [Hz]", xlabel="" if readings else "time [s]",
             title=f"{len(tracks)} taxels, one band each")
    ax.legend(legend, 9)
    if readings:
        shown = [(k, t, readings[t.name]) for k, t in enumerate(tracks)
                 if readings.get(t.name) is not None and t.analysis is not None]
        values = np.concatenate([np.ravel(r.frames_interval_n) for _, _, r in shown] +
                                [np.ravel(r.frames_n) for _, _, r in shown]) if shown else np.array([0.0, 1.0])
        values = values[np.isfinite(values)] if np.isfinite(values).any() else np.array([0.0, 1.0])
        flo, fhi = float(values.min()), float(values.max())
        pad = 0.05 * (fhi - flo) or 0.5
        bx = canvas.axes((box[0], box[1] + panel, box[2], box[3] + panel), xlim, (flo - pad, fhi + pad))
        for k, t, r in shown:
            colour, times = TAB10[k % 10], t.analysis.times_s
            low, high = np.asarray(r.frames_interval_n[:, 0], float), np.asarray(r.frames_interval_n[:, 1], float)
            _interval(bx, times, low, high, tint(colour, 0.25))
        for k, t, r in shown:
            bx.line(t.analysis.times_s, np.asarray(r.frames_n, float), TAB10[k % 10], 1)
        bx.frame(xlabel="time [s]", ylabel="force [N]", grid="y")
        bx.legend([(t.name, TAB10[k % 10], "line") for k, t, _ in shown], 9)
    canvas.save(path)

