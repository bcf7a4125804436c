"""Pictures of the recording loop: the band's spectrogram kept while tracking (max-pooled in time, bounded memory)
and the figures drawn from it — one taxel's track and segments, a board's taxels, forces against time. PNG;
frequencies Hz, times s, forces N. matplotlib is imported only when a figure is drawn."""

from __future__ import annotations

import numpy as np

PLOT_COLUMNS = 1200


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

    rows = 2 if forces is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 3.2 * rows + 0.8), sharex=True, squeeze=False)
    ax = axes[0, 0]
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
        bx = axes[1, 0]
        bx.fill_between(analysis.times_s, low, high, alpha=0.3, label="95 % interval")
        bx.plot(analysis.times_s, force, "k.", ms=2, label="force per voiced frame")
        bx.set(ylabel="force [N]")
        bx.legend(loc="upper right", fontsize=8)
    save_time_figure(fig, axes, path)


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
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
