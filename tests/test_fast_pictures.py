"""The pictures and filters of the fast paths (issue 25): numpy filters give scipy.ndimage's numbers exactly; the
spectrogram drawn without matplotlib still shows the track where it is (pixels read back and mapped to Hz)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from PIL import Image
from scipy.ndimage import maximum_filter1d, median_filter

from matcad.loop.spectrum import running_max, running_median_rows


@pytest.mark.parametrize("shape", [(5, 1), (5, 2), (3, 7), (31, 410), (2, 1000)])
def test_numpy_filters_equal_scipy_ndimage(shape):
    """running_max (reflect and constant edges) and running_median_rows against scipy.ndimage on random rows, with
    -inf holes (the tracker's 'no line'). Catches an off-by-one window, a wrong edge mode, an even-width slip."""
    r = np.random.default_rng(sum(shape))
    x = r.standard_normal(shape)
    x[x > 1.2] = -np.inf
    for size in (3, 5, 7, 9):
        assert np.array_equal(running_max(x, size), maximum_filter1d(x, size, axis=1))
        u = (x > 0).astype(np.uint8)
        assert np.array_equal(running_max(u, size, "constant"), maximum_filter1d(u, size, axis=1, mode="constant"))
    p = np.abs(r.standard_normal(shape))
    for width in (3, 63):
        half = width // 2
        padded = np.pad(p, ((0, 0), (half, half)), mode="edge")
        ref = median_filter(padded.ravel(), size=width, mode="nearest").reshape(padded.shape)[:, half:-half]
        assert np.array_equal(running_median_rows(p, width), ref)


def test_spectrogram_shows_the_track_where_it_is(tmp_path):
    """analyze's spectrogram.png read back: its size, the magma image filling the axes, and the cyan track's pixels
    mapped through the axes back to Hz within 1.5 % of the band of the tracked frequency at their time. Catches
    a flipped image or axis, a track drawn in the wrong place, a blank picture."""
    from matcad.loop.analyze import analyze
    from matcad.loop.plots import SPECTROGRAM_BOX, SPECTROGRAM_PX, plot

    fs = 44100
    t = np.arange(int(4.0 * fs)) / fs
    x = 0.3 * np.sin(2 * np.pi * (4700 * t - 40 / (2 * np.pi * 0.5) * np.cos(2 * np.pi * 0.5 * t)))
    x += 0.02 * np.random.default_rng(0).standard_normal(len(t))
    a = analyze(x, fs, (3900.0, 5600.0))
    plot(a, tmp_path / "s.png")
    rgb = np.asarray(Image.open(tmp_path / "s.png").convert("RGB")).astype(int)
    assert rgb.shape[1] == SPECTROGRAM_PX[0] and rgb.shape[0] > SPECTROGRAM_PX[1]
    left, top, right, bottom = SPECTROGRAM_BOX
    inside = rgb[top + 2:bottom - 2, left + 2:right - 2]
    assert (inside.sum(axis=2) < 200).mean() > 0.2  # mostly dark magma background, not white
    cyan = (rgb[..., 0] < 60) & (rgb[..., 1] > 200) & (rgb[..., 2] > 200)
    ys, xs = np.nonzero(cyan[top:bottom, left:right])
    assert len(xs) > 100
    f0, f1 = a.plot_freqs_hz[0], a.plot_freqs_hz[-1]
    t0, t1 = 0.0, a.plot_times_s[-1]  # the time axis starts at 0 s
    hz = f1 - (ys + 0.5) / (bottom - top) * (f1 - f0)
    sec = t0 + (xs + 0.5) / (right - left) * (t1 - t0)
    voiced = a.voiced & np.isfinite(a.track_hz)
    expected = np.interp(sec, a.times_s[voiced], a.track_hz[voiced])
    assert np.median(np.abs(hz - expected)) < 0.015 * (f1 - f0)


def test_spectrogram_with_forces_has_a_second_panel(tmp_path):
    """With forces, the picture grows by one panel and draws the force points (black) in it."""
    from matcad.loop.analyze import analyze
    from matcad.loop.plots import SPECTROGRAM_BOX, SPECTROGRAM_PX, plot

    fs = 44100
    t = np.arange(int(2.0 * fs)) / fs
    a = analyze(0.3 * np.sin(2 * np.pi * 4700 * t), fs, (3900.0, 5600.0))
    n = len(a.times_s)
    force = np.linspace(1, 5, n)
    plot(a, tmp_path / "f.png", forces=(force, force - 0.5, force + 0.5))
    rgb = np.asarray(Image.open(tmp_path / "f.png").convert("RGB")).astype(int)
    assert rgb.shape[0] == 2 * SPECTROGRAM_PX[1] + 45
    left, top, right, bottom = SPECTROGRAM_BOX
    panel = rgb[top + SPECTROGRAM_PX[1] + 2:bottom + SPECTROGRAM_PX[1] - 2, left + 2:right - 2]
    black = panel.sum(axis=2) < 60
    ys, xs = np.nonzero(black)
    assert len(xs) > 20 and np.corrcoef(xs, -ys)[0, 1] > 0.9  # force rises with time: points go up to the right


@pytest.mark.parametrize("height", [0.6, 1.0, 2.5, 4.0, 6.0])
def test_engraving_table_draws_what_matplotlib_draws(height):
    """glyphs.json (outlines and spacing tabulated from matplotlib) gives the same outlines as matplotlib's own
    TextPath for labels and random printable text, to 1e-9 mm, at every height (taller than GLYPH_TABLE_MAX_MM
    matplotlib draws them). Catches a stale table, a kerning pair applied to the wrong glyph, a scale or baseline
    slip, a table limit set where the table no longer holds."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    from matcad.parts.flat import CAP_HEIGHT_PER_SIZE, Engraving, engraving_outlines

    r = np.random.default_rng(round(10 * height))
    chars = [chr(c) for c in range(33, 127)]
    texts = ["PLATE d2.1", "t1", "AVATAR To Wa", "neck 2.10 mm", "Ty.,;:", "1/4-20 UNC"]
    texts += ["".join(r.choice(chars + [" "], 12)) for _ in range(20)]
    for text in texts:
        got = engraving_outlines(Engraving(1.5, -2.0, height, text))
        path = TextPath((0.0, 0.0), text, size=height / CAP_HEIGHT_PER_SIZE, prop=FontProperties(family="DejaVu Sans"))
        want = [[(1.5 + float(x), -2.0 + float(y)) for x, y in poly[:-1]]
                for poly in path.to_polygons(closed_only=True) if len(poly) > 3]
        assert [len(p) for p in got] == [len(p) for p in want], text
        assert np.allclose(np.concatenate(got), np.concatenate(want), atol=1e-9, rtol=0), text


def test_analyze_loads_neither_matplotlib_nor_scipy_ndimage(tmp_path):
    """`analyze --band` in a fresh interpreter, twice into one folder: the spectrogram is written and neither the
    plotting stack nor scipy.ndimage (nor the spec package: --band needs no spec) is loaded, nor Pillow's other
    image formats (the PNG is saved by its name), nor subprocess (the second run swaps the folders through the C
    library already loaded, not ctypes.util.find_library), nor numpy.ma (numpy's median and percentile load it:
    matcad.loop.stats) (issue 25: analyze near its tracker)."""
    import subprocess
    import sys
    import wave

    fs = 44100
    t = np.arange(int(1.0 * fs)) / fs
    rec = tmp_path / "tone.wav"
    with wave.open(str(rec), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(fs)
        w.writeframes(np.round(0.3 * np.sin(2 * np.pi * 4700 * t) * 30000).astype("<i2").tobytes())
    code = ("import sys; from matcad.cli import main; argv = ['analyze', %r, '--band', '3900', '5600', '--out', %r];"
            " assert main(argv) == 0 and main(argv) == 0; bad = [m for m in ('matplotlib', 'scipy.ndimage', "
            "'matcad.spec', 'PIL.JpegImagePlugin', 'PIL.GifImagePlugin', 'subprocess', 'numpy.ma') if m in "
            "sys.modules]; assert not bad, bad" % (str(rec), str(tmp_path / "a")))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "a" / "spectrogram.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("template", ["mat-laser-only.toml", "mat-paper.toml", "mat-array-4.toml"])
def test_dxf_writer_writes_ezdxfs_bytes(template, tmp_path):
    """write_dxf (no ezdxf import) against ezdxf itself: the same bytes for every laser part and nested sheet of a
    template, and the template document rebuilt from ezdxf equals the shipped one. Catches a group code or float
    format slip, a handle off by one, an ezdxf upgrade that changes its document (rebuild the template:
    benchmarks/dxf_template.py)."""
    from pathlib import Path

    from matcad.export.dxf_svg import TEMPLATE, dxf_template, write_dxf, write_dxf_ezdxf
    from matcad.export.sheets import kit_sheets
    from matcad.parts.catalogue import laser_parts
    from matcad.parts.flat import cut_plan
    from matcad.spec import load

    root = Path(__file__).resolve().parents[1] / "templates"
    spec = load(root / template)
    plans = [cut_plan(f, spec.outputs.reference_square) for f in laser_parts(spec)]
    plans += list(kit_sheets(spec, plans).values())
    assert plans
    for plan in plans:
        write_dxf(plan, tmp_path / "fast.dxf")
        write_dxf_ezdxf(plan, tmp_path / "ezdxf.dxf")
        assert (tmp_path / "fast.dxf").read_bytes() == (tmp_path / "ezdxf.dxf").read_bytes(), plan.flat.name
    with_hole = next(p for p in plans if p.circles)
    assert dxf_template(with_hole, tmp_path) == TEMPLATE.read_text(encoding="utf-8")


def test_loop_median_and_percentile_are_numpys():
    """matcad.loop.stats against numpy's median, percentile (its default, linear method) and nanmedian along rows on
    random arrays of 1-80 values over seven decades, odd and even counts, NaN included (rows of NaN only too): the
    same numbers, bit for bit."""
    from matcad.loop.stats import median, nanmedian_rows, percentile

    rng = np.random.default_rng(3)
    for n in range(1, 81):
        x = rng.standard_normal(n) * 10 ** rng.uniform(-3, 4)
        if n % 7 == 0:
            x[rng.integers(n)] = np.nan
        assert np.array_equal(median(x), np.median(x), equal_nan=True)
        for q in (0, 5, 37.3, 100, [10, 50, 90]):
            assert np.array_equal(percentile(x, q), np.percentile(x, q), equal_nan=True)
        rows = rng.standard_normal((5, n)) * 10 ** rng.uniform(-3, 4)
        rows[rng.uniform(size=rows.shape) < n / 80] = np.nan
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # numpy's "All-NaN slice"
            assert np.array_equal(nanmedian_rows(rows), np.nanmedian(rows, axis=1), equal_nan=True)
