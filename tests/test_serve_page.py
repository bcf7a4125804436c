"""The design page for boards and before building (issue 23): every [[taxel]] kept, predicted and built; the
geometry preview, the model and budget tables, TOML save/load, the share link and build progress. Over HTTP and
in headless Chromium against an in-process server."""

from __future__ import annotations

import base64
import io
import json
import re
import threading
import tomllib
import urllib.error
import urllib.request
import xml.etree.ElementTree as ET
import zipfile

import pytest

from matcad import spec as spec_mod
from matcad.prediction.board import predict_board
from matcad.render.plots import chosen_models_status
from matcad.serve import make_server
from matcad.serve.builds import STAGES, stage_of
from tests.browser import chromium, console_errors
from tests.conftest import ROOT

BOARD = ROOT / "templates" / "mat-array-4.toml"
LASER_ONLY = ROOT / "templates" / "mat-laser-only.toml"
NO_CAD = {"end_cap_mold": False, "needle_mount": False, "assembly": False}
"""[outputs] that leave a board's kit laser-only: built in seconds, no CAD kernel."""


@pytest.fixture(scope="module")
def server():
    srv = make_server(0)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    yield srv
    srv.shutdown()
    srv.server_close()


@pytest.fixture(scope="module")
def url(server):
    return f"http://127.0.0.1:{server.server_address[1]}"


def _raw(path: str) -> dict:
    return tomllib.loads(path.read_text())


def _post(url, path, payload, timeout=300):
    req = urllib.request.Request(url + path, data=json.dumps(payload).encode(),
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def _get(url, path):
    try:
        with urllib.request.urlopen(url + path, timeout=30) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


# ---- over HTTP ---------------------------------------------------------------------------------------------------

def test_board_prediction_is_predict_boards(url):
    """The page's prediction of the board template is `matcad predict`'s (predict_board): every taxel, its
    unloaded and loaded band, the same conflicts; one taxel's override changes that taxel's band only."""
    raw = _raw(BOARD)
    status, data = _post(url, "/predict", {"spec": raw})
    assert status == 200 and data["board"] is True
    want = predict_board(spec_mod.from_dict(raw))
    assert [t["name"] for t in data["taxels"]] == [b.name for b in want.bands] == ["t1", "t2", "t3", "t4"]
    for got, b in zip(data["taxels"], want.bands):
        assert got["unloaded_hz"] == pytest.approx(list(b.unloaded_hz), rel=1e-12)
        assert got["loaded_hz"] == pytest.approx(list(b.loaded_hz), rel=1e-12)
        assert (got["x_mm"], got["y_mm"]) == (b.x_mm, b.y_mm)
        assert got["budget"] and got["models"][got["model"]]["f0_hz"] == pytest.approx(b.f0_hz, rel=1e-12)
    assert data["conflicts"] == want.summary["conflicts"] and data["layout"] == []  # its taxels fit the plate
    raw["taxel"][1]["neck_diameter"] = 2.2  # a narrower neck sings lower (Helmholtz: f ~ d)
    _, edited = _post(url, "/predict", {"spec": raw})
    assert edited["taxels"][1]["f0_hz"] < data["taxels"][1]["f0_hz"]
    for i in (0, 2, 3):
        assert edited["taxels"][i]["f0_hz"] == data["taxels"][i]["f0_hz"]


def test_a_board_without_its_caps_mechanics(url):
    """"mechanics": false: the same taxels and unloaded bands, each loaded band the unloaded one and the rise said
    to follow (rise_pending); a value other than true or false is refused naming the field."""
    raw = _raw(BOARD)
    _, full = _post(url, "/predict", {"spec": raw})
    status, quick = _post(url, "/predict", {"spec": raw, "mechanics": False})
    assert status == 200 and quick["rise_pending"] is True and full["rise_pending"] is False
    for q, f in zip(quick["taxels"], full["taxels"]):
        assert q["unloaded_hz"] == f["unloaded_hz"] and q["loaded_hz"] == q["unloaded_hz"] != f["loaded_hz"]
        assert q["rise_source"].startswith("not computed")
    status, bad = _post(url, "/predict", {"spec": raw, "mechanics": "no"})
    assert status == 422 and bad["error"]["field"] == "mechanics"


def test_an_array_grid_is_predicted_too(url):
    """[array] columns x rows on a single-taxel template (refused by the page's prediction before): one band per
    grid position, at the grid's positions (mm)."""
    raw = _raw(LASER_ONLY) | {"array": {"columns": 2, "rows": 1, "pitch_x": 12.0}}
    raw["plate"] = raw.get("plate", {}) | {"width": 40.0}
    status, data = _post(url, "/predict", {"spec": raw})
    assert status == 200, data
    assert [(t["name"], t["x_mm"], t["y_mm"]) for t in data["taxels"]] == [("t1", -6.0, 0.0), ("t2", 6.0, 0.0)]


def test_a_taxel_placed_badly_is_told_with_the_prediction(url):
    """A fifth taxel 7 mm below t4 (where the page's "add taxel" puts it): the reply carries the board rules'
    errors (its flange over t4's, past the plate's edge, on a bolt hole) as `matcad check` gives them."""
    from matcad.rules import check

    raw = _raw(BOARD)
    raw["taxel"].append({k: v for k, v in raw["taxel"][-1].items() if k != "name"} | {"y": -17.5})
    status, data = _post(url, "/predict", {"spec": raw})
    assert status == 200 and len(data["taxels"]) == 5
    want = [f.to_dict() for f in check(spec_mod.from_dict(raw)) if f.id.startswith("board.") and f.level != "info"]
    assert sorted(data["layout"], key=str) == sorted(want, key=str)
    assert {f["id"] for f in data["layout"] if f["level"] == "error"} == {"board.outside", "board.on_fastener",
                                                                           "board.spacing"}


def test_a_bad_taxel_field_is_named(url):
    raw = _raw(BOARD)
    raw["taxel"][2]["neck_diameter"] = -1
    status, data = _post(url, "/predict", {"spec": raw})
    assert status == 422 and data["error"]["field"] == "taxel[3].neck_diameter"


def test_toml_round_trip(url):
    """Save: the spec as TOML reads back to the same spec; load: a template's text gives its values; a syntax
    error is told with its line; a bad spec is not saved."""
    raw = _raw(BOARD)
    status, data = _post(url, "/toml", {"spec": raw})
    assert status == 200 and tomllib.loads(data["toml"]) == raw
    status, data = _post(url, "/parse", {"toml": BOARD.read_text()})
    assert status == 200 and data["spec"] == raw
    status, data = _post(url, "/parse", {"toml": "name = 'x'\n[cavity\n"})
    assert status == 422 and "line 2" in data["error"]["message"]
    raw["cavity"]["length"] = 0
    status, data = _post(url, "/toml", {"spec": raw})
    assert status == 422 and data["error"]["field"] == "cavity.length"


def test_build_stages_from_the_files_written():
    """The stage is the furthest one whose files have appeared; the finished kit is the last."""
    assert STAGES[stage_of(set(), False)][0] == "starting"
    assert STAGES[stage_of({"neck_plate.dxf", "neck_plate.svg"}, False)][0] == "laser"
    assert STAGES[stage_of({"neck_plate.dxf", "end_cap.stl", "end_cap.step"}, False)][0] == "solids"
    assert STAGES[stage_of({"neck_plate.dxf", "end_cap.stl", "section.svg"}, False)][0] == "assembly"
    assert STAGES[stage_of({"a.dxf", "b.stl", "section.svg", "plot.png", "report.json"}, False)][0] == "report"
    assert STAGES[stage_of(set(), True)][0] == "zip"


def test_progress_of_unknown_or_badly_named_builds(url):
    """A build not running (not started, finished, never) is no error: the page's polls cross the build's start and
    end (a 404 was a console error in the browser); an id no build can have is refused, naming the parameter."""
    status, data = _get(url, "/progress?build=nosuchbuild123")
    assert status == 200 and data == {"running": False}
    status, data = _get(url, "/progress?build=../../etc")
    assert status == 422 and data["error"]["field"] == "build"
    status, data = _post(url, "/build", {"spec": _raw(LASER_ONLY), "build_id": "../../etc"})
    assert status == 422 and data["error"]["field"] == "build_id"


def test_preview_section_and_mesh(url, server):
    """The section is the report's drawing of the fields sent (its dimension labels follow an edit); the mesh
    holds the plate, the cap and the mold, the plate as wide (x) and thick (z) as the spec says (mm). The kernel
    lives in the preview process, never in the server's."""
    import sys

    raw = _raw(ROOT / "templates" / "mat-paper.toml")
    status, data = _post(url, "/preview", {"spec": raw})
    assert status == 200, data
    texts = {t.text for t in ET.fromstring(data["svg"]).iter("{http://www.w3.org/2000/svg}text")}
    assert f"D = {raw['cavity']['diameter']:g}" in texts
    raw["cavity"]["diameter"] = 3.5
    _, edited = _post(url, "/preview", {"spec": raw})
    assert "D = 3.5" in {t.text for t in ET.fromstring(edited["svg"]).iter("{http://www.w3.org/2000/svg}text")}
    status, mesh = _post(url, "/preview", {"spec": raw, "what": "mesh"})
    assert status == 200
    parts = {p["name"]: p for p in mesh["parts"]}
    assert {"neck_plate", "end_cap", "end_cap_mold_base", "end_cap_mold_lid"} <= set(parts)
    v = parts["neck_plate"]["vertices"]
    xs, zs = v[0::3], v[2::3]
    spec = spec_mod.from_dict(raw)
    assert max(xs) - min(xs) == pytest.approx(spec.plate.width, abs=0.01)
    assert max(zs) - min(zs) == pytest.approx(spec.neck.length, abs=0.01)
    assert max(parts["end_cap"]["triangles"]) < len(parts["end_cap"]["vertices"]) // 3
    _, assembly = _post(url, "/preview", {"spec": raw, "what": "assembly"})  # the page's two steps: the same parts
    _, molds = _post(url, "/preview", {"spec": raw, "what": "molds"})
    assert [p["name"] for p in molds["parts"]] == ["end_cap_mold_base", "end_cap_mold_lid"]
    assert assembly["parts"] + molds["parts"] == mesh["parts"]
    assert "build123d" not in sys.modules or server.preview.proc is not None  # the kernel is the child's
    status, bad = _post(url, "/preview", {"spec": raw, "what": "everything"})
    assert status == 422 and bad["error"]["field"] == "what"


def test_the_preview_process_ends_with_the_server():
    srv = make_server(0)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    port = srv.server_address[1]
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=30) as r:
        assert r.status == 200
    warmed = srv.preview.proc  # opening the page starts the child: it loads the kernel while the page predicts
    assert warmed is not None
    status, _ = _post(f"http://127.0.0.1:{port}", "/preview", {"spec": _raw(LASER_ONLY)})
    proc = srv.preview.proc
    assert status == 200 and proc is warmed and proc.poll() is None
    srv.shutdown()
    srv.server_close()
    assert proc.wait(timeout=10) is not None


# ---- in Chromium -------------------------------------------------------------------------------------------------

def _bands(driver) -> dict[str, tuple[float, float, float]]:
    return {g["taxel"]: (float(g["f0"]), float(g["low"]), float(g["high"])) for g in driver.execute_script(
        "return [...document.querySelectorAll('#bandchart g.band')].map(g => ({...g.dataset}))")}


def _risen(driver) -> bool:
    """Whether the band chart shows the bands with their rise under load (a board's second reply)."""
    return driver.execute_script("return document.querySelector('#bands-svg')?.dataset.rise === 'done'")


def _kit(driver) -> zipfile.ZipFile:
    zipped = driver.execute_async_script(
        "const done = arguments[0]; fetch(document.getElementById('download').href)"
        ".then(r => r.arrayBuffer()).then(b => { let s = ''; for (const x of new Uint8Array(b)) "
        "s += String.fromCharCode(x); done(btoa(s)); }).catch(e => done('failed: ' + e));")
    return zipfile.ZipFile(io.BytesIO(base64.b64decode(zipped)))


def _type(driver, element_id: str, text: str) -> None:
    from selenium.webdriver.common.by import By

    box = driver.find_element(By.ID, element_id)
    box.clear()
    box.send_keys(text)


def test_board_template_on_the_page(url):
    """mat-array-4 opens with its four taxels in the table and four bands on the chart, each predict_board's;
    editing t2's neck moves t2's band alone; a bad taxel field is told next to the table; adding and removing a
    taxel adds and removes a band, and the added one's overlap with t4 is told under the table; moving one moves
    it on the plan."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    want = predict_board(spec_mod.load(BOARD))
    with chromium() as driver:
        wait = WebDriverWait(driver, 180)
        driver.get(url + "/?template=mat-array-4")
        wait.until(lambda d: len(_bands(d)) == 4 and _risen(d))
        shown_ms, risen_ms = driver.execute_script("return [window.matcad.bandsShownMs, window.matcad.riseShownMs]")
        print(f"\nopening the page to a board's bands: {shown_ms:.0f} ms, with their rise under load {risen_ms:.0f} ms")
        assert len(driver.find_elements(By.CSS_SELECTOR, "#taxels tbody tr")) == 4
        first = _bands(driver)
        for b in want.bands:
            assert first[b.name] == pytest.approx((b.f0_hz, b.unloaded_hz[0], b.loaded_hz[1]), abs=0.06)
        _type(driver, "in-taxel[2].neck_diameter", "2.2")
        wait.until(lambda d: len(_bands(d)) == 4 and _bands(d)["t2"] != first["t2"] and _risen(d))
        edited = _bands(driver)
        assert edited["t2"][0] < first["t2"][0]
        assert all(edited[n] == first[n] for n in ("t1", "t3", "t4"))
        _type(driver, "in-taxel[3].cavity_length", "-2")
        error = lambda: driver.find_element(By.ID, "err-taxel").text  # noqa: E731
        wait.until(lambda d: "taxel[3].cavity_length" in error())
        assert "bad" in driver.find_element(By.ID, "in-taxel[3].cavity_length").get_attribute("class")
        _type(driver, "in-taxel[3].cavity_length", "2.3")
        wait.until(lambda d: error() == "" and len(_bands(d)) == 4 and _risen(d))
        layout = lambda: driver.find_element(By.ID, "layout").text  # noqa: E731
        assert layout() == ""
        driver.find_element(By.ID, "add-taxel").click()
        wait.until(lambda d: len(_bands(d)) == 5)
        wait.until(lambda d: "error board.spacing: t4 and t5" in layout())  # told at once, not at the build
        driver.find_elements(By.CSS_SELECTOR, "#taxels .remove-taxel")[4].click()
        wait.until(lambda d: len(_bands(d)) == 4 and layout() == "")
        circle = "return document.querySelector('#plan g[data-taxel=t1] circle').getAttribute('cx')"
        assert float(driver.execute_script(circle)) == -7.5
        _type(driver, "in-taxel[1].x", "-8.5")
        assert float(driver.execute_script(circle)) == -8.5
        rows = driver.execute_script("return document.querySelectorAll('#models tr').length")
        assert rows == 1 + len(want.predictions["t1"].models)
        assert driver.execute_script("return document.querySelectorAll('#budget tr').length") > 2
        errors = [e for e in console_errors(driver)
                  if not (e["source"] == "network" and "/predict" in e["message"] and "422" in e["message"])]
        assert errors == []


def test_a_boards_bands_come_before_its_caps_mechanics(url, monkeypatch):
    """The cap mechanics of a cap not yet cached take a FElupe run each (minutes for the template's four on a
    cold cache): the page shows every taxel's unloaded band at once and the rises when they come. Here the rise
    is held until the bands are on the chart; then each loaded band is predict_board's."""
    import threading as th

    from matcad.prediction import bands as bands_mod
    from selenium.webdriver.support.ui import WebDriverWait

    held, real = th.Event(), bands_mod.mechanics_rise

    def slow_rise(*args, **kw):
        held.wait(120)
        return real(*args, **kw)

    want = predict_board(spec_mod.load(BOARD))
    monkeypatch.setattr(bands_mod, "mechanics_rise", slow_rise)
    with chromium() as driver:
        wait = WebDriverWait(driver, 180)
        driver.get(url + "/?template=mat-array-4")
        try:
            wait.until(lambda d: len(_bands(d)) == 4)
            assert not _risen(d := driver) and "rise under load" in d.find_element("id", "status").text
            for b in want.bands:  # each unloaded band, its top not yet raised
                assert _bands(d)[b.name] == pytest.approx((b.f0_hz, b.unloaded_hz[0], b.unloaded_hz[1]), abs=0.06)
        finally:
            held.set()
        wait.until(_risen)
        for b in want.bands:
            assert _bands(driver)[b.name] == pytest.approx((b.f0_hz, b.unloaded_hz[0], b.loaded_hz[1]), abs=0.06)
        assert console_errors(driver) == []


def test_board_kit_built_from_the_page_with_progress(url, server):
    """The board, laser parts only (fast): the kit's report carries all four taxels and their bands, the neck
    plate its four necks; the page showed the build's stages while it ran, and says after the verdict which
    taxels' chosen models fail their checks, as the report's headline does. While another build holds the slot
    the page says it waits, and its polls of a build not yet started raise no console error."""
    import time

    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    raw = _raw(BOARD)
    raw["outputs"] = NO_CAD
    link = "/#spec=" + base64.urlsafe_b64encode(json.dumps(raw).encode()).decode().rstrip("=")
    with chromium() as driver:
        wait = WebDriverWait(driver, 300)
        driver.get(url + link)  # the share link's form: the spec in the fragment
        wait.until(lambda d: len(_bands(d)) == 4)
        assert not driver.find_element(By.ID, "in-outputs.assembly").is_selected()
        server.build_slot.acquire()  # another build runs: this one waits (the page polls every 0.4 s)
        try:
            driver.find_element(By.ID, "build").click()
            time.sleep(2.0)
            assert driver.find_element(By.ID, "build-stage").text == "waiting for the build slot"
        finally:
            server.build_slot.release()
        wait.until(lambda d: d.find_element(By.ID, "download").is_displayed())
        kit = _kit(driver)
        stages = driver.execute_script("return window.matcad.stages")
        built = driver.find_element(By.ID, "build-status").text
        assert console_errors(driver) == []
    report = json.loads(kit.read("mat-array-4/report.json"))
    status = chosen_models_status(report)
    assert status.startswith("t1: chosen model")
    assert re.fullmatch(rf"\d+ files, verdict {report['verdict']} \(design rules\); {re.escape(status)}", built)
    assert [t["name"] for t in report["taxels"]] == ["t1", "t2", "t3", "t4"]
    assert len(report["bands"]["taxels"]) == 4
    assert [(t["x_mm"], t["y_mm"]) for t in report["taxels"]] == [(e["x"], e["y"]) for e in raw["taxel"]]
    assert "mat-array-4/neck_plate.dxf" in kit.namelist()
    assert stages and stages[0] in ("starting", "laser"), stages


@pytest.mark.slow
def test_full_board_kit_from_the_page(url):
    """The whole board kit (CAD parts, mold for four caps) from the page, its stages shown in order."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    with chromium() as driver:
        wait = WebDriverWait(driver, 900)
        driver.get(url + "/?template=mat-array-4")
        wait.until(lambda d: len(_bands(d)) == 4)
        driver.find_element(By.ID, "build").click()
        wait.until(lambda d: d.find_element(By.ID, "download").is_displayed())
        kit = _kit(driver)
        stages = driver.execute_script("return window.matcad.stages")
    names = set(kit.namelist())
    assert {"mat-array-4/end_cap_mold_base.stl", "mat-array-4/section.svg", "mat-array-4/plot_taxel_bands.png"} <= names
    order = [key for key, _, _ in STAGES]
    assert "solids" in stages and [order.index(s) for s in stages] == sorted(order.index(s) for s in stages)


def test_share_link_save_and_load_in_chromium(url, tmp_path):
    """An edit survives the share link (a fresh page from the URL shows it); Save TOML gives the spec the page
    predicts; Load TOML replaces the form with the file's spec, taxels included."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    with chromium() as driver:
        wait = WebDriverWait(driver, 120)
        driver.get(url + "/?template=mat-laser-only")
        f0 = lambda: driver.find_element(By.ID, "f0").text  # noqa: E731
        wait.until(lambda d: f0().startswith("f0 ="))
        before = f0()
        _type(driver, "in-cavity.length", "9.5")
        wait.until(lambda d: f0().startswith("f0 =") and f0() != before)  # a longer cavity sings lower
        shown = f0()
        driver.find_element(By.ID, "share").click()
        link = driver.find_element(By.ID, "share-url").get_attribute("value")
        assert "#spec=" in link
        driver.find_element(By.ID, "save").click()
        wait.until(lambda d: d.execute_script("return window.matcad.savedToml"))
        saved = tomllib.loads(driver.execute_script("return window.matcad.savedToml"))
        assert saved == driver.execute_script("return collect()") and saved["cavity"]["length"] == 9.5
        driver.get("about:blank")
        driver.get(link)
        wait.until(lambda d: f0().startswith("f0 ="))
        assert driver.find_element(By.ID, "in-cavity.length").get_attribute("value") == "9.5" and f0() == shown
        path = tmp_path / "board.toml"
        path.write_text(BOARD.read_text())
        driver.find_element(By.ID, "load").send_keys(str(path))
        wait.until(lambda d: len(_bands(d)) == 4)
        assert driver.find_element(By.ID, "in-name").get_attribute("value") == "mat-array-4"
        assert driver.execute_script("return collect().taxel") == _raw(BOARD)["taxel"]
