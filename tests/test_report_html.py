"""report.html: the same content as report.md, self-contained, every picture loads in a real headless Chromium;
the section is labelled and dimensioned to scale; previews are real pictures of the parts."""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.build import build
from tests.browser import broken_images, chromium, console_errors
from tests.conftest import ROOT

SVG = "{http://www.w3.org/2000/svg}"
SPECS = [ROOT / "templates" / "mat-paper.toml", ROOT / "templates" / "mat-laser-only.toml"]


@pytest.fixture(scope="module", params=SPECS, ids=lambda p: p.stem)
def kit(request, tmp_path_factory):
    spec = spec_mod.load(request.param)
    out = tmp_path_factory.mktemp("html") / spec.name
    build(spec, out)
    return spec, out, json.loads((out / "report.json").read_text())


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images, self.links, self.ids, self.headings, self.urls = [], [], set(), [], []
        self._heading = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images.append(a["src"])
        if tag == "a" and "href" in a:
            self.links.append(a["href"])
        if "id" in a:
            self.ids.add(a["id"])
        self.urls += [v for k, v in attrs if k in ("src", "href") and v and re.match(r"[a-z]+:", v)]
        if re.fullmatch(r"h[1-6]", tag):
            self._heading = ""

    def handle_data(self, data):
        if self._heading is not None:
            self._heading += data

    def handle_endtag(self, tag):
        if re.fullmatch(r"h[1-6]", tag) and self._heading is not None:
            self.headings.append(self._heading.strip())
            self._heading = None


def test_html_is_the_markdown_rendered(kit):
    spec, out, report = kit
    md = (out / "report.md").read_text()
    page = _Page()
    page.feed((out / "report.html").read_text())
    md_images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert page.images == md_images and len(md_images) == len(report["figures"])
    assert page.headings == [re.sub(r"\*\*|`", "", h) for h in re.findall(r"^#+ (.*)$", md, flags=re.M)]
    assert page.urls == [], "the page must not reach the network"
    for src in page.images:
        assert (out / src).is_file()
    for link in page.links:
        assert link.startswith("#") and link[1:] in page.ids, link
    # every part built has its picture, and the rules that name a part link to it
    parts = {f["part"] for f in report["figures"]}
    laser = {p.stem for p in out.glob("*.dxf") if not p.stem.startswith("sheet_")}  # sheet_*: parts nested per sheet
    printed = {p.stem for p in out.glob("*.stl")}
    assert laser | printed <= parts
    for f in report["findings"]:
        head = f["message"].split(":", 1)[0]
        if head in laser | printed:
            assert f"[{head}](#part-{head})" in md


def test_every_picture_loads_in_chromium_without_console_errors(kit):
    _, out, report = kit
    with chromium() as driver:
        driver.get((out / "report.html").as_uri())
        assert driver.execute_script("return document.readyState") == "complete"
        n = driver.execute_script("return document.images.length")
        assert n == len(report["figures"]) > 0
        assert broken_images(driver) == []
        widths = driver.execute_script("return [...document.images].map(i => i.naturalWidth)")
        assert min(widths) > 100
        assert console_errors(driver) == []


def test_previews_are_pictures_not_blank(kit):
    import matplotlib.image as mpimg

    _, out, report = kit
    for fig in report["figures"]:
        if not fig["file"].endswith(".png"):
            continue
        img = mpimg.imread(out / fig["file"])
        assert img.shape[0] > 150 and img.shape[1] > 300
        ink = np.mean(np.any(np.abs(img[..., :3] - 1.0) > 0.1, axis=-1))
        assert 0.01 < ink < 0.9, (fig["file"], ink)  # drawn on, but not a solid block


def _dimension_lengths(root) -> dict[str, float]:
    """Label text → length of the dimension line drawn just before its arrows (mm, drawing units)."""
    group = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "dimensions")
    found, last_line = {}, None
    for el in group:
        if el.tag == f"{SVG}line" and el.get("class") == "dimension":
            last_line = el
        elif el.tag == f"{SVG}text" and last_line is not None:
            x1, y1, x2, y2 = (float(last_line.get(k)) for k in ("x1", "y1", "x2", "y2"))
            found[el.text] = math.hypot(x2 - x1, y2 - y1)
    return found


def test_section_is_labelled_and_dimensioned_to_scale(kit):
    spec, out, _ = kit
    if not spec.outputs.assembly:
        assert not (out / "section.svg").exists()
        return
    root = ET.parse(out / "section.svg").getroot()
    texts = [t.text for t in root.iter(f"{SVG}text")]
    for name in ("neck plate", "end cap", "needle mount", "needle", "guide"):
        assert any(name in t for t in texts), name
    want = {f"D = {spec.cavity.diameter:g}": spec.cavity.diameter, f"L = {spec.cavity.length:g}": spec.cavity.length,
            f"d = {spec.neck.diameter:g}": spec.neck.diameter, f"l = {spec.neck.length:g}": spec.neck.length,
            f"cap Ø {spec.end_cap.outer_diameter:g}": spec.end_cap.outer_diameter,
            f"top {spec.end_cap.top_thickness:g}": spec.end_cap.top_thickness,
            f"gap {spec.spacer.height:g}": spec.spacer.height, f"y = {spec.needle.y:g}": spec.needle.y}
    drawn = _dimension_lengths(root)
    for label, length in want.items():
        assert drawn[label] == pytest.approx(length, abs=1e-3), label
    assert f"θ = {spec.needle.theta_deg:g}°" in texts
    # the dimensions sit on the geometry: the neck plate's section spans z = 0..l, i.e. y = -l..0 in the drawing
    plate = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "neck_plate")
    ys = [float(v) for p in plate for v in re.findall(r"[-\d.]+,([-\d.]+)", p.get("d"))]
    assert max(ys) - min(ys) == pytest.approx(spec.neck.length, abs=1e-6)


def _printed(page, tmp_path) -> tuple[Path, list[str]]:
    """``page`` (an HTML file) printed to PDF by headless Chromium on A4: (the PDF, each page's text)."""
    import shutil
    import subprocess

    from tests.browser import CHROMIUM, _missing

    if not (shutil.which("pdfinfo") and shutil.which("pdftotext") and shutil.which("pdfimages")):
        _missing("poppler-utils (pdfinfo, pdftotext, pdfimages) missing")
    if not shutil.which(CHROMIUM) and not (CHROMIUM and __import__("os").path.exists(CHROMIUM)):
        _missing("chromium missing")
    pdf = tmp_path / "report.pdf"
    subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
                    f"--user-data-dir={tmp_path / 'profile'}", f"--print-to-pdf={pdf}", page.as_uri()],
                   capture_output=True, timeout=120, check=True)
    info = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True).stdout
    pages = int(re.search(r"^Pages:\s+(\d+)", info, flags=re.M).group(1))
    return pdf, [subprocess.run(["pdftotext", "-f", str(k), "-l", str(k), "-layout", str(pdf), "-"],
                                capture_output=True, text=True, check=True).stdout for k in range(1, pages + 1)]


def test_printed_report_keeps_captions_with_their_pictures(kit, tmp_path):
    """report.html printed to PDF by headless Chromium: every raster picture lands on the page of its caption
    (no heading orphaned at a page's foot), and the pages stay few (mat-paper: 18 before the print stylesheet)."""
    import subprocess

    _, out, report = kit
    pdf, texts = _printed(out / "report.html", tmp_path)
    assert len(texts) <= 10, len(texts)
    listed = subprocess.run(["pdfimages", "-list", str(pdf)], capture_output=True, text=True, check=True).stdout
    image_pages = [int(line.split()[0]) for line in listed.splitlines()[2:]
                   if line.split() and line.split()[2] == "image"]
    raster = [f for f in report["figures"] if f["file"].endswith(".png")]
    assert len(image_pages) >= len(raster)
    for fig, page in zip(raster, image_pages):  # pictures are drawn in report order
        head = " ".join(fig["caption"].split()[:3])
        assert head in " ".join(texts[page - 1].split()), f"{fig['caption']!r} not on page {page} with its picture"


def test_printed_lines_that_introduce_a_list_or_table_stay_with_it(tmp_path):
    """A line ending in ':' before a list or a table ("Trim:", "Caliper these sheets ...:") never ends a printed
    page away from what it introduces (the board kit's report printed "Trim:" alone at a page's foot). Steps of
    growing length put such lines at many heights on the page."""
    from matcad.report.page import render_html

    md = []
    for i in range(24):
        md += [f"## Step {i}", ""] + [f"Filler line {j} of step {i}." + " word" * 8 + "\n" for j in range(i % 7)]
        md += ["Do these:", ""] + [f"- item {k}: " + "text " * 30 for k in range(4)] + [""]
        md += ["Measure these:", "", "| a | b |", "|---|---|"] + [f"| {k} | {2 * k} |" for k in range(6)] + [""]
    page = tmp_path / "steps.html"
    page.write_text(render_html("\n".join(md), "steps"), encoding="utf-8")
    _, texts = _printed(page, tmp_path)
    feet = [[line for line in text.splitlines() if line.strip()][-1].strip() for text in texts]
    assert len(feet) > 5 and not [foot for foot in feet if foot.endswith(":")], feet


def test_headline_and_band_chart_agree_on_an_invalid_chosen_model(kit, tmp_path):
    """The report's headline and the band chart's title say the same of the chosen model: nothing when it holds;
    when it fails its checks (the report data with the chosen model's check failed, as mat-sla-array's
    elastic_wall does), both carry the same "chosen model NAME invalid (check)" and the verdict is named as the
    design rules'."""
    import copy

    from matcad.render.plots import band_plot, chosen_model_status
    from matcad.report.page import render_markdown

    _, out, report = kit
    head = render_markdown(report).splitlines()[2]
    assert head.startswith("**Verdict: ") and "invalid" not in head
    bad = copy.deepcopy(report)
    p = bad["prediction"]
    chosen = p["models"].setdefault(p["model"], {"f0_hz": p["f0_hz"], "checks": {}})
    chosen.update(valid=False, checks={**chosen.get("checks", {}), "no_wall_mode_near_f": False})
    status = chosen_model_status(p)
    assert status.startswith(f"chosen model {p['model']} invalid (") and "no_wall_mode_near_f" in status
    head = render_markdown(bad).splitlines()[2]
    assert "(design rules)" in head and status in head
    from matcad import canvas

    titles = []
    real_frame = canvas.Axes.frame

    def spy(self, *args, **kw):
        titles.append(kw.get("title", ""))
        return real_frame(self, *args, **kw)

    canvas.Axes.frame = spy
    try:
        band_plot(p, tmp_path / "band.png")
    finally:
        canvas.Axes.frame = real_frame
    assert any(status in t for t in titles)
    import matplotlib.image as mpimg

    dark = (mpimg.imread(tmp_path / "band.png")[..., :3] < 0.85).any(axis=2)  # the longer title is not clipped
    assert not (dark[0].any() or dark[-1].any() or dark[:, 0].any() or dark[:, -1].any())


def test_no_picture_is_clipped_at_its_edge(kit):
    """Every PNG of the kit has a blank outer ring of pixels: no caption, title or label runs off the picture
    (figures are saved to their drawn extent, matcad.render.figure)."""
    import matplotlib.image as mpimg

    _, out, report = kit
    for fig in report["figures"]:
        if not fig["file"].endswith(".png"):
            continue
        dark = (mpimg.imread(out / fig["file"])[..., :3] < 0.85).any(axis=2)
        ring = {"top": dark[0].sum(), "bottom": dark[-1].sum(), "left": dark[:, 0].sum(), "right": dark[:, -1].sum()}
        assert not any(ring.values()), f"{fig['file']}: ink at the edge {ring}"
