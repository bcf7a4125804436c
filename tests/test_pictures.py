"""Pictures of the commands that make numbers: design's plot read back, a long recording's overview and summary."""

from __future__ import annotations


import matplotlib.image as mpimg
import numpy as np
from scipy.io import wavfile

from tests.conftest import ROOT, run_cli

LASER = ROOT / "matcad" / "templates" / "mat-laser-only.toml"


def test_design_plot_marks_target_and_solution(tmp_path):
    """plot_design.png: the f0 curve crosses the target where the solved value is (from the data the picture is
    drawn from, recomputed), and the picture is drawn (not blank) with nothing touching its edge."""
    from matcad import spec as spec_mod
    from matcad.design.picture import solution_plot
    from matcad.design.solve import parse_vary, solve

    spec = spec_mod.load(LASER)
    result = solve(spec, 5500.0, parse_vary(spec, ["cavity.length"]))
    name = solution_plot(spec, result, tmp_path)
    image = mpimg.imread(tmp_path / name)[..., :3]
    assert image.shape[1] > 600 and (image < 0.5).mean() > 0.005
    dark = (image < 0.85).any(axis=2)
    assert not dark[0].any() and not dark[-1].any() and not dark[:, 0].any() and not dark[:, -1].any()


def _steps(path, seconds, rate=4000):
    t = np.arange(int(rate * seconds)) / rate
    f = 1500 + 100 * (np.floor(t / 2) % 4) / 3
    x = 0.3 * np.sin(2 * np.pi * np.cumsum(f) / rate) * (np.modf(t / 2)[0] < 0.8)
    x += 0.01 * np.random.default_rng(0).normal(size=t.size)
    wavfile.write(path, rate, (x * 32767).astype(np.int16))


def test_long_recording_overview_and_summary(tmp_path):
    """A 70 s recording (35 presses): stdout lists the first and last 5 segments and one summary line, the CSV
    keeps all 35; the spectrogram gets an overview panel above it (a taller picture than a 20 s recording's)."""
    rec = tmp_path / "long.wav"
    _steps(rec, 70.0)
    code, out, err = run_cli("analyze", rec, "--band", "1300", "1800", "--out", tmp_path / "a")
    assert code == 0, err
    segments = (tmp_path / "a" / "segments.csv").read_text().strip().splitlines()[1:]
    assert len(segments) >= 30
    lines = [line for line in out.splitlines() if line.strip().endswith(")") and " s " in line]
    assert len(lines) == 10  # 5 + 5 segment lines
    summary = [line for line in out.splitlines() if "more segments" in line]
    assert len(summary) == 1 and f"{len(segments) - 10} more segments" in summary[0]
    assert "every segment in segments.csv" in summary[0]
    short = tmp_path / "short.wav"
    _steps(short, 20.0)
    assert run_cli("analyze", short, "--band", "1300", "1800", "--out", tmp_path / "b")[0] == 0
    tall = mpimg.imread(tmp_path / "a" / "spectrogram.png").shape[0]
    assert tall > 1.5 * mpimg.imread(tmp_path / "b" / "spectrogram.png").shape[0]  # the overview panel


def test_segment_list_is_summarised_past_twelve():
    """segments_text: 12 segments print as they are; 40 print 5 + a summary + 5, the summary's range and count
    from the hidden ones."""
    from matcad.loop.analysis import Analysis, SEGMENTS_END, SEGMENTS_SHOWN
    from matcad.loop.segments import Segment

    def analysis(n):
        segs = tuple(Segment(2.0 * i, 2.0 * i + 1.5, 16, 1500.0 + i, 1500.0 + i, 0.1) for i in range(n))
        a = Analysis.__new__(Analysis)
        object.__setattr__(a, "segments", segs)
        return a

    assert len(analysis(SEGMENTS_SHOWN).segments_text()) == SEGMENTS_SHOWN + 1
    lines = analysis(40).segments_text()
    assert len(lines) == 1 + 2 * SEGMENTS_END + 1
    assert "30 more segments" in lines[SEGMENTS_END + 1] and "1505.00-1534.00 Hz" in lines[SEGMENTS_END + 1]


def test_overview_axes_start_at_zero():
    """The overview's frequency and force axes start at 0 (Hz, N) and its time axis at 0 s, whatever the first
    frame's time; its title sums up the segments and the forces (read back from the drawn picture's axes)."""
    from types import SimpleNamespace

    from matcad.canvas import Canvas
    from matcad.loop.plots import SPECTROGRAM_BOX, overview
    from matcad.loop.segments import Segment

    times = np.arange(0.05, 90.0, 0.1)
    track = 1500.0 + 50.0 * np.sin(times / 7.0)
    a = SimpleNamespace(times_s=times, voiced=np.ones(times.size, bool), track_hz=track, band_hz=(1300.0, 1800.0),
                        segments=(Segment(1.0, 2.0, 10, 1510.0, 1510.0, 0.1), Segment(5.0, 6.0, 10, 1540.0, 1540.0, 0.1)))
    canvas = Canvas(800, 365)
    ax, fx, title = overview(canvas, SPECTROGRAM_BOX, a, force=2.0 + np.cos(times / 5.0))
    assert ax.ylim[0] == 0.0 and ax.ylim[1] > track.max() and fx.ylim[0] == 0.0 and fx.ylim[1] > 3.0
    assert ax.xlim[0] == 0.0 and fx.xlim == ax.xlim
    assert "2 segments, means 1510-1540 Hz" in title and "force 1.00-3.00 N" in title


def test_a_long_title_widens_the_picture_instead_of_being_clipped(tmp_path):
    """A laser part with a long name: its cut plan's title is wider than the 660 px picture. The picture widens
    and its outer ring stays blank (at a fixed width the title ran off both edges, the start of the name cut
    away)."""
    import dataclasses

    from matcad import spec as spec_mod
    from matcad.parts.coupon import coupon_sheets, laser_coupon
    from matcad.parts.flat import cut_plan
    from matcad.render.previews import flat_preview

    spec = spec_mod.load(LASER)
    flat = dataclasses.replace(laser_coupon(spec, coupon_sheets(spec)[1]),
                               name="coupon_guide_with_a_long_descriptive_name")
    flat_preview(cut_plan(flat, True), tmp_path / "p.png")
    image = mpimg.imread(tmp_path / "p.png")[..., :3]
    dark = (image < 0.85).any(axis=2)
    assert image.shape[1] > 660  # wider than the default picture: the whole title is in
    assert not (dark[0].any() or dark[-1].any() or dark[:, 0].any() or dark[:, -1].any())


def _picture(colour: str):
    from matcad.canvas import Canvas

    canvas = Canvas(120, 80)
    ax = canvas.axes((10, 10, 110, 70), (0, 1), (0, 1))
    ax.line([0, 1], [0, 1], colour, 2)
    return canvas


def test_pictures_saved_together_are_written_at_the_end_with_the_same_bytes(tmp_path):
    """Inside ``saved_together`` a save writes nothing until the block ends; then every picture (more than the
    threads, nested blocks too) is the file a plain save writes, byte for byte."""
    from matcad.canvas import saved_together

    colours = ["red", "blue", "green", "black", "orange"]
    for k, colour in enumerate(colours):
        _picture(colour).save(tmp_path / f"plain{k}.png")
    with saved_together():
        for k, colour in enumerate(colours[:3]):
            _picture(colour).save(tmp_path / f"held{k}.png")
        with saved_together():
            for k, colour in enumerate(colours[3:], 3):
                _picture(colour).save(tmp_path / f"held{k}.png")
        assert not list(tmp_path.glob("held*.png"))
    for k in range(len(colours)):
        assert (tmp_path / f"held{k}.png").read_bytes() == (tmp_path / f"plain{k}.png").read_bytes()
    assert len({(tmp_path / f"plain{k}.png").read_bytes() for k in range(len(colours))}) == len(colours)


def test_pictures_held_by_a_failed_block_are_never_written_and_a_failed_write_is_raised(tmp_path):
    import pytest

    from matcad.canvas import saved_together

    with pytest.raises(RuntimeError, match="drawing failed"):
        with saved_together():
            _picture("red").save(tmp_path / "a.png")
            raise RuntimeError("drawing failed")
    assert not (tmp_path / "a.png").exists()
    with pytest.raises(OSError):
        with saved_together():
            _picture("red").save(tmp_path / "b.png")
            _picture("blue").save(tmp_path / "missing" / "c.png")
    _picture("red").save(tmp_path / "d.png")  # the thread's state is back to writing at once
    assert (tmp_path / "d.png").is_file()
