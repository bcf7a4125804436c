"""Headless Chromium for the page tests (Debian's chromium + chromium-driver through selenium).

Never lets a tool download a browser: the system binaries are named explicitly. With MATCAD_REQUIRE_CLIENTS=1
(.ci/run) a missing browser is a failure; elsewhere the tests skip with that reason.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager

from tests.conftest import missing_client

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--window-size=1200,900")


def _missing(why: str):
    missing_client(why, "apt-get install chromium chromium-driver, pip install selenium (the dev extra)",
                   ".ci/run installs chromium and chromium-driver")


@contextmanager
def chromium():
    """A selenium WebDriver on headless Chromium with a fresh profile; console messages kept for get_log."""
    if not (os.path.exists(CHROMIUM) and os.path.exists(CHROMEDRIVER)):
        _missing("chromium / chromedriver missing")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        _missing("selenium missing")
    profile = tempfile.mkdtemp(prefix="matcad-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def console_errors(driver) -> list[dict]:
    """Console and network messages at level SEVERE since the last call."""
    return [entry for entry in driver.get_log("browser") if entry["level"] == "SEVERE"]


def broken_images(driver) -> list[str]:
    """src of every <img> on the page that did not load (naturalWidth 0 once complete), and of every shown <img>
    with nothing to show (no src: a broken-picture icon)."""
    return driver.execute_script(
        "return [...document.images].filter(i => (i.getAttribute('src') || !i.hidden)"
        " && !(i.complete && i.naturalWidth > 0)).map(i => i.src)")
