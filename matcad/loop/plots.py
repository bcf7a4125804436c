"""Pictures of the recording loop: the band's spectrogram kept while tracking (max-pooled in time, bounded memory)
and the figures drawn from it — one taxel's track and segments, a board's taxels, forces against time. PNG;
frequencies Hz, times s, forces N. matplotlib is imported only when a figure is drawn."""

from __future__ import annotations

import numpy as np

PLOT_COLUMNS = 1200
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
    """Spectrogram of an :class:`matcad.loop.analysis.Analysis`'s band (dB, max-pooled in time) with the voiced
    track and segments; with ``forces`` (per frame: force, low, high in N) a second panel of force against time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    long = len(analysis.times_s) > 0 and analysis.times_s[-1] > OVERVIEW_S
    rows = 1 + (forces is not None) + long
    fig, axes = plt.subplots(rows, 1, figsize=(8, 3.2 * rows + 0.8), sharex=True, squeeze=False)
    if long:
        overview(axes[0, 0], analysis, None if forces is None else forces[0])
    ax = axes[int(long), 0]
    db = analysis.plot_db
    ax.pcolormesh(analysis.plot_times_s, analysis.plot_freqs_hz, db, shading="nearest", cmap="magma",
                  vmin=np.percentile(db, 5), vmax=db.max())
    ax.plot(analysis.times_s, np.where(analysis.voiced, analysis.track_hz, np.nan), color="cyan", lw=1,
            label="voiced track")
    segs = analysis.segments
    if segs:  # one call for all segments: a 60 min file has thousands
        ax.hlines([s.mean_hz for s in segs], [s.start_s for s in segs], [s.end_s for s in segs],
                  colors=["red" if s.flag else "white" for s in segs], lw=2)
    ax.set(ylabel="frequency [Hz]",
           title=f"mean {analysis.mean_hz:.2f} Hz over {100 * analysis.tone_fraction:.0f} % of frames (voiced), "
                 f"{len(analysis.segments)} segments")
    ax.legend(loc="upper right", fontsize=8)
    if forces is not None:
        force, low, high = forces
        bx = axes[1 + int(long), 0]
        bx.fill_between(analysis.times_s, low, high, alpha=0.3, label="95 % interval")
        bx.plot(analysis.times_s, force, "k.", ms=2, label="force per voiced frame")
        bx.set(ylabel="force [N]")
        bx.legend(loc="upper right", fontsize=8)
    save_time_figure(fig, axes, path)


def _windowed(times, values, edges):
    """Per window of ``edges`` (s): the 10th, 50th and 90th percentile of the finite ``values`` (NaN if none)."""
    out = np.full((len(edges) - 1, 3), np.nan)
    which = np.digitize(times, edges) - 1
    for k in range(len(edges) - 1):
        v = values[(which == k) & np.isfinite(values)]
        if len(v):
            out[k] = np.percentile(v, [10, 50, 90])
    return out


def overview(ax, analysis, force=None) -> None:
    """The overview of a long recording on ``ax``: per window (:data:`OVERVIEW_WINDOWS`) the median voiced
    frequency with its 10-90 % spread on an axis from 0 Hz, with ``force`` (per frame, N) the median force on a
    second axis from 0 N, and a summary of the segments and values in the title."""
    times = analysis.times_s
    edges = np.linspace(0.0, float(times[-1]), OVERVIEW_WINDOWS + 1)
    mids = (edges[:-1] + edges[1:]) / 2
    hz = _windowed(times, np.where(analysis.voiced, analysis.track_hz, np.nan), edges)
    ax.fill_between(mids, hz[:, 0], hz[:, 2], color="#5b8fc7", alpha=0.3, lw=0)
    ax.plot(mids, hz[:, 1], color="#1f4e8c", marker=".", lw=1, label="median voiced frequency (10-90 %)")
    ax.set_ylim(0, 1.15 * max(np.nanmax(hz[:, 2]) if np.isfinite(hz).any() else 1.0, analysis.band_hz[1]))
    ax.set(ylabel="frequency [Hz]")
    means = np.array([s.mean_hz for s in analysis.segments])
    summary = (f"{len(means)} segments, means {means.min():.0f}-{means.max():.0f} Hz (median {np.median(means):.0f})"
               if len(means) else "no steady segment")
    if force is not None:
        fx = ax.twinx()
        f = _windowed(times, np.asarray(force, dtype=float), edges)
        fx.plot(mids, f[:, 1], color="#c0392b", marker=".", lw=1, label="median force")
        top = np.nanmax(f[:, 2]) if np.isfinite(f).any() else 1.0
        fx.set_ylim(0, 1.15 * max(top, 1e-3))
        fx.set_ylabel("force [N]", color="#c0392b")
        finite = np.asarray(force, dtype=float)[np.isfinite(force)]
        if len(finite):
            summary += f"; force {finite.min():.2f}-{finite.max():.2f} N (median {np.median(finite):.2f})"
        fx.legend(loc="lower right", fontsize=8)
    ax.set_title(f"overview of {times[-1]:.0f} s: {summary}", fontsize=9)
    ax.legend(loc="lower left", fontsize=8)


def plot_board(tracks, path, readings=None) -> None:
    """One figure: every taxel's band (:class:`matcad.loop.board.TaxelTrack`) as spectrogram (dB) with its voiced
    track, a colour and a label per taxel; with ``readings`` ({name: Reading}) a second panel of force against
    time, one line and 95 % band per taxel."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = 2 if readings else 1
    fig, axes = plt.subplots(rows, 1, figsize=(9, 3.6 * rows + 0.8), sharex=True, squeeze=False)
    ax = axes[0, 0]
    present = [t for t in tracks if t.analysis is not None]
    levels = np.concatenate([t.analysis.plot_db.ravel() for t in present])
    vmin, vmax = np.percentile(levels, 5), levels.max()
    colours = plt.get_cmap("tab10")
    for k, t in enumerate(tracks):
        colour = colours(k % 10)
        ax.axhspan(*t.band_hz, color=colour, alpha=0.08, lw=0)
        if t.analysis is None:
            ax.text(0.01, np.mean(t.band_hz), f"{t.name}: no tone", color=colour, fontsize=8,
                    transform=ax.get_yaxis_transform())
            continue
        a = t.analysis
        ax.pcolormesh(a.plot_times_s, a.plot_freqs_hz, a.plot_db, shading="nearest", cmap="gray_r", vmin=vmin,
                      vmax=vmax)
        ax.plot(a.times_s, np.where(a.voiced, a.track_hz, np.nan), color=colour, lw=1.2,
                label=f"{t.name}: {a.mean_hz:.0f} Hz, tone {100 * a.tone_fraction:.0f} %")
    ax.set(ylabel="frequency [Hz]", title=f"{len(tracks)} taxels, one band each")
    ax.legend(loc="upper right", fontsize=7)
    if readings:
        bx = axes[1, 0]
        for k, t in enumerate(tracks):
            r = readings.get(t.name)
            if r is None or t.analysis is None:
                continue
            colour = colours(k % 10)
            times = t.analysis.times_s
            bx.fill_between(times, r.frames_interval_n[:, 0], r.frames_interval_n[:, 1], color=colour, alpha=0.25,
                            lw=0)
            bx.plot(times, r.frames_n, color=colour, lw=1, label=t.name)
        bx.set(ylabel="force [N]")
        bx.legend(loc="upper right", fontsize=7)
    save_time_figure(fig, axes, path)


def save_time_figure(fig, axes, path) -> None:
    """Label the shared time axis (s) of a column of panels and write the figure as PNG (100 dpi)."""
    import matplotlib.pyplot as plt

    axes[-1, 0].set(xlabel="time [s]")
    axes[-1, 0].set_xlim(left=0.0)  # the recording starts at 0 s, not at its first frame
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
