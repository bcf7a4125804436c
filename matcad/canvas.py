"""Charts as PNG without the plotting stack: a Pillow canvas with axes in data units, ticks, text, lines, bars,
markers, images and a legend. The commands that draw a picture on their fast path (`analyze`'s spectrogram, a
laser-only `build`'s previews and plots) use it instead of matplotlib, whose import alone costs several times
numpy's. Deterministic: no timestamps, one font file (:func:`font`), same data → same bytes. Pixels; data units are
whatever the chart's axes say.
"""

from __future__ import annotations

import contextlib
import functools
import math
import threading

MAGMA = ((0.0, (0, 0, 4)), (0.13, (28, 16, 68)), (0.25, (79, 18, 123)), (0.38, (129, 37, 129)),
         (0.5, (181, 54, 122)), (0.63, (229, 80, 100)), (0.75, (251, 135, 97)), (0.88, (254, 194, 135)),
         (1.0, (252, 253, 191)))
"""matplotlib's 'magma' colour map at nine stops (linear between them)."""
VIRIDIS = ((0.0, (68, 1, 84)), (0.0625, (72, 24, 106)), (0.125, (71, 45, 123)), (0.1875, (66, 64, 134)),
           (0.25, (59, 82, 139)), (0.3125, (51, 99, 141)), (0.375, (44, 114, 142)), (0.4375, (38, 130, 142)),
           (0.5, (33, 145, 140)), (0.5625, (31, 160, 136)), (0.625, (40, 174, 128)), (0.6875, (63, 188, 115)),
           (0.75, (94, 201, 98)), (0.8125, (132, 212, 75)), (0.875, (173, 220, 48)), (0.9375, (216, 226, 25)),
           (1.0, (253, 231, 37)))
"""matplotlib's 'viridis' colour map (van der Walt & Smith 2015: perceptually uniform, legible in grey and to
colour-blind readers) at 17 stops, linear between them: within 6/255 of matplotlib's 256 entries."""
GREYS_R = ((0.0, (255, 255, 255)), (1.0, (0, 0, 0)))
TAB10 = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
         "#17becf")
_FONTS: dict = {}
_HELD = threading.local()


def font(size: float):
    """DejaVu Sans at ``size`` px: the TrueType file matplotlib ships (found without importing matplotlib; the same
    face its figures used, with ×, Ø, –, θ, ≤), else Pillow's embedded font (which lacks those: they are spelled
    in ASCII then, see :func:`ascii_text`)."""
    from PIL import ImageFont

    size = round(size)
    if size not in _FONTS:
        path = dejavu_path()
        _FONTS[size] = ImageFont.truetype(path, size) if path else ImageFont.load_default(size)
    return _FONTS[size]


@functools.cache
def dejavu_path() -> str | None:
    """matplotlib's DejaVuSans.ttf (a dependency: always there after the README's set-up), or None."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.find_spec("matplotlib")
    for folder in (spec.submodule_search_locations or []) if spec else []:
        ttf = Path(folder) / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
        if ttf.is_file():
            return str(ttf)
    return None


ASCII = {"×": "x", "Ø": "dia ", "–": "-", "θ": "theta", "≤": "<=", "≥": ">=", "µ": "u", "Δ": "d", "²": "^2",
         "³": "^3"}


def ascii_text(s: str) -> str:
    """``s`` as the fallback font can draw it (no DejaVu): :data:`ASCII`'s spellings."""
    return s if dejavu_path() else "".join(ASCII.get(ch, ch) for ch in s)


def nice_ticks(lo: float, hi: float, count: int = 6) -> list[float]:
    """Round tick values (1, 2, 5 × 10^k apart) inside [lo, hi], about ``count`` of them."""
    if not hi > lo:
        return [lo]
    raw = (hi - lo) / max(count, 1)
    step = 10 ** math.floor(math.log10(raw))
    step *= next(m for m in (1, 2, 5, 10) if m * step >= raw)
    first = math.ceil(lo / step - 1e-9)
    return [k * step for k in range(first, math.floor(hi / step + 1e-9) + 1)]


def tick_label(v: float, ticks: list[float]) -> str:
    step = abs(ticks[1] - ticks[0]) if len(ticks) > 1 else 1.0
    digits = max(0, -math.floor(math.log10(step) + 1e-9)) if step > 0 else 0
    return f"{v + 0.0:.{digits}f}"


def tint(colour: str, alpha: float) -> tuple[int, int, int]:
    """``colour`` (#rrggbb) laid over white at opacity ``alpha``."""
    rgb = (int(colour[k:k + 2], 16) for k in (1, 3, 5))
    return tuple(round(255 - alpha * (255 - c)) for c in rgb)


def colour_map(values, lo: float, hi: float, stops=MAGMA):
    """RGB (uint8, values' shape × 3) of ``values`` scaled from ``lo`` to ``hi`` on the colour map ``stops``."""
    import numpy as np

    t = np.clip((np.asarray(values, dtype=float) - lo) / max(hi - lo, 1e-12), 0.0, 1.0)
    at = np.array([s for s, _ in stops])
    rgb = np.array([c for _, c in stops], dtype=float)
    return np.stack([np.interp(t, at, rgb[:, k]) for k in range(3)], axis=-1).round().astype(np.uint8)


class Canvas:
    """A white picture ``width`` × ``height`` px; :meth:`axes` places a plot in it, :meth:`save` writes the PNG."""

    def __init__(self, width: int, height: int):
        from PIL import Image, ImageDraw

        self.image = Image.new("RGB", (int(width), int(height)), "white")
        self.draw = ImageDraw.Draw(self.image)

    def text(self, x, y, s: str, size: float = 11, colour="black", anchor: str = "la") -> None:
        """``s`` at pixel (x, y); ``anchor`` as Pillow's (l/m/r, a/m/s/d), lines split on newlines."""
        self.draw.multiline_text((x, y), ascii_text(s), fill=colour, font=font(size), anchor=anchor, align="center"
                                 if anchor[0] == "m" else "left")

    def text_width(self, s: str, size: float = 11) -> float:
        return self.draw.textlength(ascii_text(s), font=font(size))

    def vertical_text(self, x, y, s: str, size: float = 11, colour="black") -> None:
        """``s`` turned 90° (read bottom to top), centred at pixel (x, y)."""
        from PIL import Image, ImageDraw

        w = int(self.text_width(s, size)) + 4
        h = int(size * 1.4) + 2
        tile = Image.new("RGB", (w, h), "white")
        ImageDraw.Draw(tile).text((w / 2, h / 2), ascii_text(s), fill=colour, font=font(size), anchor="mm")
        tile = tile.transpose(Image.Transpose.ROTATE_90)
        self.image.paste(tile, (int(x - h / 2), int(y - w / 2)))

    def axes(self, box, xlim, ylim, equal: bool = False) -> "Axes":
        """A plot in the pixel box (left, top, right, bottom) showing ``xlim`` × ``ylim`` (data units); with
        ``equal`` one unit is as many pixels across as up (the box shrinks to fit, centred)."""
        return Axes(self, box, xlim, ylim, equal)

    def save(self, path, text: dict[str, str] | None = None) -> None:
        """The picture as a PNG file at ``path``, ``text`` as its text chunks (key: value); inside
        :func:`saved_together`, written at that block's end. A name ending in .png is left to Pillow to recognise:
        it then loads its PNG writer alone, where ``format="PNG"`` loads four other formats' plugins first (BMP,
        GIF, JPEG, PPM; ~10 ms)."""
        info = None
        if text:
            from PIL.PngImagePlugin import PngInfo

            info = PngInfo()
            for key, value in text.items():
                info.add_text(key, value)
        png = str(path).lower().endswith(".png")
        options = {"format": None if png else "PNG", "compress_level": 1,  # 3x faster than 6, 10 % larger
                   "pnginfo": info}
        held = getattr(_HELD, "pictures", None)
        if held is None:
            self.image.save(path, **options)
        else:
            held.append((self.image, path, options))


@contextlib.contextmanager
def saved_together(threads: int = 2):
    """Inside the block, :meth:`Canvas.save` holds its picture (this thread's canvases); when the block ends
    without an exception, the held pictures are encoded to their PNG files on ``threads`` threads at once (this
    one among them). Pillow's PNG encoder releases the GIL, so pictures encode in parallel once the drawing, which
    holds it, is done: a laser-only build's 7 pictures ~19 → ~10 ms on 2 cores (encoding beside the drawing
    gained nothing)."""
    if getattr(_HELD, "pictures", None) is not None:  # nested: the outer block writes them
        yield
        return
    _HELD.pictures = held = []
    try:
        yield
    finally:
        _HELD.pictures = None
    errors = []

    def encode(share):
        try:
            for image, path, options in share:
                image.save(path, **options)
        except BaseException as exc:  # noqa: BLE001 - raised again on this thread below
            errors.append(exc)

    others = [threading.Thread(target=encode, args=(held[k::threads],)) for k in range(1, threads)]
    for thread in others:
        thread.start()
    encode(held[::threads])
    for thread in others:
        thread.join()
    if errors:
        raise errors[0]


class Axes:
    """Data → pixels in one box of a :class:`Canvas`; y grows upward as in a plot."""

    def __init__(self, canvas: Canvas, box, xlim, ylim, equal: bool):
        self.c, self.d = canvas, canvas.draw
        left, top, right, bottom = box
        (x0, x1), (y0, y1) = xlim, ylim
        if equal:
            k = min((right - left) / (x1 - x0), (bottom - top) / (y1 - y0))
            cx, cy = (left + right) / 2, (top + bottom) / 2
            left, right = cx - k * (x1 - x0) / 2, cx + k * (x1 - x0) / 2
            top, bottom = cy - k * (y1 - y0) / 2, cy + k * (y1 - y0) / 2
        self.box = (left, top, right, bottom)
        self.xlim, self.ylim = (x0, x1), (y0, y1)

    def x(self, v: float) -> float:
        left, _, right, _ = self.box
        return left + (v - self.xlim[0]) / (self.xlim[1] - self.xlim[0]) * (right - left)

    def y(self, v: float) -> float:
        _, top, _, bottom = self.box
        return bottom - (v - self.ylim[0]) / (self.ylim[1] - self.ylim[0]) * (bottom - top)

    def scale(self) -> float:
        """Pixels per x unit."""
        return (self.box[2] - self.box[0]) / (self.xlim[1] - self.xlim[0])

    def image(self, rgb, extent=None) -> None:
        """An RGB array (rows from the top down) stretched over the whole box, or over ``extent`` (x0, x1, y0, y1 in
        data units, clipped to the box)."""
        from PIL import Image

        left, top, right, bottom = (round(v) for v in self.box)
        if extent is not None:
            x0, x1, y0, y1 = extent
            left, right = max(left, round(self.x(x0))), min(right, round(self.x(x1)))
            top, bottom = max(top, round(self.y(y1))), min(bottom, round(self.y(y0)))
            if right <= left or bottom <= top:
                return
        tile = Image.fromarray(rgb, "RGB").resize((right - left, bottom - top), Image.Resampling.NEAREST)
        self.c.image.paste(tile, (left, top))

    def cells(self, x_edges, y_edges, rgb, blank=None, hatch=None, hatch_colour=(255, 255, 255)) -> None:
        """A heat map: cell (i, j), the data rectangle [x_edges[j], x_edges[j + 1]] × [y_edges[i], y_edges[i + 1]]
        (edges ascending, any spacing), filled with ``rgb[i, j]`` (uint8); each pixel of the box takes the cell its
        centre falls in. Cells where ``blank`` (bool, cells' shape) are left as they were; cells where ``hatch``
        get diagonal lines 6 px apart in ``hatch_colour``."""
        import numpy as np
        from PIL import Image

        left, top, right, bottom = (round(v) for v in self.box)
        if right <= left or bottom <= top:
            return
        (x0, x1), (y0, y1), (bl, bt, br, bb) = self.xlim, self.ylim, self.box
        xs = x0 + (np.arange(left, right) + 0.5 - bl) / (br - bl) * (x1 - x0)
        ys = y0 + (bb - np.arange(top, bottom) - 0.5) / (bb - bt) * (y1 - y0)
        j = np.searchsorted(np.asarray(x_edges, dtype=float), xs, side="right") - 1
        i = np.searchsorted(np.asarray(y_edges, dtype=float), ys, side="right") - 1
        inside = ((i >= 0) & (i < len(y_edges) - 1))[:, None] & ((j >= 0) & (j < len(x_edges) - 1))[None, :]
        rows, cols = np.clip(i, 0, len(y_edges) - 2), np.clip(j, 0, len(x_edges) - 2)

        def per_pixel(cell_values, dtype):  # each pixel's cell's value, by two takes (a map's cells: 6 -> 2.3 ms)
            return np.asarray(cell_values, dtype=dtype).take(rows, axis=0).take(cols, axis=1)

        show = inside if blank is None else inside & ~per_pixel(blank, bool)
        paint = per_pixel(rgb, np.uint8)
        if hatch is not None:
            diagonal = (np.arange(left, right)[None, :] + np.arange(top, bottom)[:, None]) % 6 == 0
            paint = np.where((per_pixel(hatch, bool) & diagonal)[..., None], np.asarray(hatch_colour, np.uint8), paint)
        tile = np.where(show[..., None], paint, np.asarray(self.c.image.crop((left, top, right, bottom))))
        self.c.image.paste(Image.fromarray(tile, "RGB"), (left, top))

    def line(self, xs, ys, colour, width: float = 1, dash: float = 0) -> None:
        """A polyline through (xs, ys); non-finite points break it; ``dash`` px dashes when > 0."""
        run: list = []
        for a, b in zip(list(xs) + [math.nan], list(ys) + [math.nan]):
            if math.isfinite(a) and math.isfinite(b):
                run.append((self.x(a), self.y(b)))
                continue
            if len(run) > 1 and dash:
                self._dashed(run, colour, width, dash)
            elif len(run) > 1:
                self.d.line(run, fill=colour, width=round(width), joint="curve")
            run = []

    def _dashed(self, points, colour, width, dash) -> None:
        for (ax, ay), (bx, by) in zip(points, points[1:]):
            n = max(1, int(math.hypot(bx - ax, by - ay) / dash))
            for k in range(0, n, 2):
                t0, t1 = k / n, min(k + 1, n) / n
                self.d.line([(ax + t0 * (bx - ax), ay + t0 * (by - ay)), (ax + t1 * (bx - ax), ay + t1 * (by - ay))],
                            fill=colour, width=round(width))

    def rect(self, x0, y0, x1, y1, fill=None, outline=None, width: float = 1, hatch: str | None = None) -> None:
        """The data rectangle [x0, x1] × [y0, y1]; ``hatch`` a colour of diagonal lines 6 px apart."""
        px = sorted((self.x(x0), self.x(x1)))
        py = sorted((self.y(y0), self.y(y1)))
        box = (px[0], py[0], max(px[1], px[0] + 1), max(py[1], py[0] + 1))
        if fill is not None:
            self.d.rectangle(box, fill=fill)
        if hatch:
            w, h = box[2] - box[0], box[3] - box[1]
            k = -h
            while k < w:
                a, b = max(k, 0.0), min(k + h, w)
                if b > a:
                    self.d.line([(box[0] + a, box[3] - (a - k)), (box[0] + b, box[3] - (b - k))], fill=hatch)
                k += 6
        if outline is not None:
            self.d.rectangle(box, outline=outline, width=round(width))

    def circle(self, x, y, r, outline, width: float = 1) -> None:
        """A circle of radius ``r`` (x units) round (x, y)."""
        cx, cy, pr = self.x(x), self.y(y), max(r * self.scale(), 0.5)
        self.d.ellipse((cx - pr, cy - pr, cx + pr, cy + pr), outline=outline, width=round(width))

    def rounded(self, x0, y0, x1, y1, r, outline, width: float = 1) -> None:
        """A rounded rectangle, corner radius ``r`` (x units)."""
        px0, px1 = sorted((self.x(x0), self.x(x1)))
        py0, py1 = sorted((self.y(y0), self.y(y1)))
        self.d.rounded_rectangle((px0, py0, px1, py1), radius=max(r * self.scale(), 0), outline=outline,
                                 width=round(width))

    def polygon(self, points, fill) -> None:
        self.d.polygon([(self.x(a), self.y(b)) for a, b in points], fill=fill)

    def marker(self, x, y, kind: str, colour="black", size: float = 4) -> None:
        """'o' disc, 'x' cross, '|' vertical tick at (x, y); ``size`` px half width."""
        px, py, s = self.x(x), self.y(y), size
        if kind == "o":
            self.d.ellipse((px - s, py - s, px + s, py + s), fill=colour)
        elif kind == "x":
            self.d.line([(px - s, py - s), (px + s, py + s)], fill=colour, width=2)
            self.d.line([(px - s, py + s), (px + s, py - s)], fill=colour, width=2)
        else:
            self.d.line([(px, py - 2 * s), (px, py + 2 * s)], fill=colour, width=2)

    def text(self, x, y, s: str, size: float = 10, colour="black", anchor: str = "la") -> None:
        self.c.text(self.x(x), self.y(y), s, size, colour, anchor)

    def frame(self, xlabel: str = "", ylabel: str = "", title: str = "", xticks=None, yticks=None,
              grid: str = "", size: float = 11, title_colour="black") -> None:
        """Box, ticks with labels (``xticks``/``yticks``: values, or (value, label) pairs; None: round values),
        light grid lines ('x', 'y' or 'xy'), axis labels and the title."""
        left, top, right, bottom = self.box
        xt = self._ticks(xticks, self.xlim)
        yt = self._ticks(yticks, self.ylim)
        for v, label in xt:
            px = self.x(v)
            if "x" in grid:
                self.d.line([(px, top), (px, bottom)], fill="#e4e4e4")
            self.d.line([(px, bottom), (px, bottom + 4)], fill="black")
            self.c.text(px, bottom + 6, label, size - 1, anchor="ma")
        widest = 0.0
        for v, label in yt:
            py = self.y(v)
            if "y" in grid:
                self.d.line([(left, py), (right, py)], fill="#e4e4e4")
            self.d.line([(left - 4, py), (left, py)], fill="black")
            self.c.text(left - 6, py, label, size - 1, anchor="rm")
            widest = max(widest, self.c.text_width(label, size - 1))
        self.d.rectangle((left, top, right, bottom), outline="black")
        if xlabel:
            self.c.text((left + right) / 2, bottom + 8 + 1.4 * size, xlabel, size, anchor="ma")
        if ylabel:
            self.c.vertical_text(left - 14 - widest - 0.7 * size, (top + bottom) / 2, ylabel, size)
        if title:
            self.c.text((left + right) / 2, top - 6, title, size + 1, title_colour, anchor="md")

    def _ticks(self, given, lim):
        lo, hi = sorted(lim)
        if given is None:
            values = nice_ticks(lo, hi)
            return [(v, tick_label(v, values)) for v in values]
        return [(t if isinstance(t, tuple) else (t, tick_label(t, list(given)))) for t in given
                if lo - 1e-9 <= (t[0] if isinstance(t, tuple) else t) <= hi + 1e-9]

    def legend(self, entries, size: float = 9, corner: str = "upper right", outside: bool = False) -> None:
        """A box of (label, colour, kind) entries, kind 'line', 'bar', 'hatch', 'x' (a cross) or 'o' (a disc); in
        the box's ``corner``, or right of the box when ``outside``."""
        if not entries:
            return
        left, top, right, bottom = self.box
        h = size * 1.5
        w = max(self.c.text_width(label, size) for label, _, _ in entries) + 34
        x0 = right + 8 if outside else (right - w - 6 if "right" in corner else left + 6)
        y0 = top + 6
        self.d.rectangle((x0, y0, x0 + w, y0 + h * len(entries) + 6), fill="white", outline="#bbbbbb")
        for k, (label, colour, kind) in enumerate(entries):
            cy = y0 + 3 + h * (k + 0.5)
            if kind == "line":
                self.d.line([(x0 + 5, cy), (x0 + 25, cy)], fill=colour, width=2)
            elif kind in ("bar", "hatch"):
                self.d.rectangle((x0 + 5, cy - 4, x0 + 25, cy + 4), fill=None if kind == "hatch" else colour,
                                 outline=colour)
                if kind == "hatch":
                    for k6 in range(0, 20, 5):
                        self.d.line([(x0 + 5 + k6, cy + 4), (x0 + 5 + min(k6 + 8, 20), cy - 4)], fill=colour)
            elif kind == "x":
                self.d.line([(x0 + 11, cy - 3), (x0 + 17, cy + 3)], fill=colour, width=2)
                self.d.line([(x0 + 11, cy + 3), (x0 + 17, cy - 3)], fill=colour, width=2)
            else:
                self.d.ellipse((x0 + 11, cy - 3, x0 + 17, cy + 3), fill=colour)
            self.c.text(x0 + 30, cy, label, size, anchor="lm")
