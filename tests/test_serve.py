"""`matcad serve`: the design page end to end in headless Chromium, and the server's contract over HTTP."""

from __future__ import annotations

import base64
import glob
import io
import json
import os
import tempfile
import threading
import urllib.error
import urllib.request
import zipfile
from concurrent.futures import ThreadPoolExecutor

import pytest

from matcad import spec as spec_mod
from matcad.prediction import predict
from matcad.serve import MAX_BODY_BYTES, make_server
from tests.browser import broken_images, chromium, console_errors
from tests.conftest import ROOT

LASER_ONLY = ROOT / "templates" / "mat-laser-only.toml"


@pytest.fixture(scope="module")
def url():
    server = make_server(0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def _post(url, path, body: bytes):
    req = urllib.request.Request(url + path, data=body, headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def _spec_json(**neck):
    import tomllib

    data = tomllib.loads(LASER_ONLY.read_text())
    data["neck"] |= neck
    return data


def test_binds_localhost_only():
    server = make_server(0)
    try:
        assert server.server_address[0] == "127.0.0.1"
    finally:
        server.server_close()


def test_predict_matches_the_library_under_concurrent_requests(url):
    diameters = [1.0 + 0.1 * i for i in range(12)]

    def one(d):
        return _post(url, "/predict", json.dumps({"spec": _spec_json(diameter=d)}).encode())

    with ThreadPoolExecutor(8) as pool:
        answers = list(pool.map(one, diameters))
    for d, (status, data) in zip(diameters, answers):
        assert status == 200
        want = predict(spec_mod.from_dict(_spec_json(diameter=d)))
        assert data["f0_hz"] == pytest.approx(want.f0_hz, rel=1e-12)
        assert data["band_hz"] == pytest.approx(list(want.band_hz), rel=1e-12)


def test_bad_requests_are_refused_with_the_field(url):
    status, data = _post(url, "/predict", json.dumps({"spec": _spec_json(diameter=-1)}).encode())
    assert status == 422 and data["error"]["field"] == "neck.diameter" and "-1" in data["error"]["message"]
    status, data = _post(url, "/predict", b"{not json")
    assert status == 422 and data["error"]["message"]
    status, data = _post(url, "/predict", b"x" * (MAX_BODY_BYTES + 1))
    assert status == 413
    status, data = _post(url, "/nowhere", b"{}")
    assert status == 404


def test_build_leaves_no_state(url, tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # the in-process server's temporary folders land here
    status, data = _post(url, "/build", json.dumps({"spec": _spec_json()}).encode())
    assert status == 200
    names = zipfile.ZipFile(io.BytesIO(base64.b64decode(data["zip"]))).namelist()
    assert "mat-laser-only/neck_plate.dxf" in names and "mat-laser-only/report.html" in names
    assert glob.glob(os.path.join(tmp_path, "*")) == []


def test_design_page_end_to_end_in_chromium(url):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    with chromium() as driver:
        wait = WebDriverWait(driver, 120)
        driver.get(url + "/?template=mat-laser-only")
        f0 = lambda: driver.find_element(By.ID, "f0").text  # noqa: E731
        wait.until(lambda d: f0().startswith("f0 ="))
        first = f0()
        want = predict(spec_mod.load(LASER_ONLY)).f0_hz
        assert first == f"f0 = {want:.0f} Hz"
        # a longer cavity sings lower: the prediction follows the field
        length = driver.find_element(By.ID, "in-cavity.length")
        length.clear()
        length.send_keys("9.5")
        wait.until(lambda d: f0() not in (first, "…") and f0().startswith("f0 ="))
        assert int(f0().split()[2]) < int(first.split()[2])
        # a neck wider than the cavity: the message appears next to that field
        neck = driver.find_element(By.ID, "in-neck.diameter")
        neck.clear()
        neck.send_keys("5")
        error = lambda: driver.find_element(By.ID, "err-neck.diameter").text  # noqa: E731
        wait.until(lambda d: "neck.diameter" in error())
        assert "cavity.diameter" in error() and "bad" in neck.get_attribute("class")
        neck.clear()
        neck.send_keys("2.1")
        wait.until(lambda d: error() == "" and f0().startswith("f0 ="))
        # build: a zip to download and the previews shown
        driver.find_element(By.ID, "build").click()
        wait.until(lambda d: d.find_element(By.ID, "download").is_displayed())
        zipped = driver.execute_async_script(
            "const done = arguments[0]; fetch(document.getElementById('download').href)"
            ".then(r => r.arrayBuffer()).then(b => { let s = ''; for (const x of new Uint8Array(b)) "
            "s += String.fromCharCode(x); done(btoa(s)); }).catch(e => done('failed: ' + e));")
        kit = zipfile.ZipFile(io.BytesIO(base64.b64decode(zipped)))
        report = json.loads(kit.read("mat-laser-only/report.json"))
        assert report["spec"]["cavity"]["length"] == 9.5
        assert {"mat-laser-only/neck_plate.dxf", "mat-laser-only/preview_neck_plate.png"} <= set(kit.namelist())
        n = driver.execute_script("return document.querySelectorAll('#previews img').length")
        assert n == len(report["figures"]) > 0
        assert broken_images(driver) == []
        errors = console_errors(driver)
        refused = [e for e in errors
                   if e["source"] == "network" and "/predict" in e["message"] and "422" in e["message"]]
        assert refused and [e for e in errors if e not in refused] == []  # only the wide neck we typed on purpose
