"""Headless Debian chromium driven by selenium through the system chromedriver, for the browser
tests of the HTML viewer and the live app. Nothing is downloaded: without /usr/bin/chromium,
/usr/bin/chromedriver or selenium the tests skip and say how to install them."""

from __future__ import annotations

import os
import shutil

import pytest

#: Set (e.g. by CI) to make a missing browser a failure instead of a skip.
REQUIRED = bool(os.environ.get("SOFTARM_REQUIRE_BROWSER"))

INSTALL = ("browser tests need Debian's chromium and its driver: apt-get install -y chromium "
           "chromium-driver, and pip install selenium")


def _find(*names: str) -> str | None:
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def chromium():
    """A headless chromium WebDriver (1200 × 800), or pytest.skip with how to install it
    (pytest.fail if the environment variable SOFTARM_REQUIRE_BROWSER is set, as in CI)."""
    missing = pytest.fail if REQUIRED else pytest.skip
    try:
        from selenium import webdriver
    except ImportError:
        missing(INSTALL)
    browser = os.environ.get("SOFTARM_CHROMIUM") or _find("chromium", "chromium-browser")
    driver_path = os.environ.get("SOFTARM_CHROMEDRIVER") or _find("chromedriver")
    if browser is None or driver_path is None:
        missing(INSTALL)
    options = webdriver.ChromeOptions()
    options.binary_location = browser
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1200,800",
                 "--disable-dev-shm-usage", "--enable-unsafe-swiftshader"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    from selenium.webdriver.chrome.service import Service

    return webdriver.Chrome(service=Service(executable_path=driver_path), options=options)


def severe_console_messages(driver) -> list[str]:
    """The page's console errors (level SEVERE) so far."""
    return [entry["message"] for entry in driver.get_log("browser")
            if entry["level"] == "SEVERE"]


def png_pixels(data: bytes):
    """(height, width, 3) uint8 array of a PNG screenshot (decoded by Pillow, which matplotlib
    in the test extra brings)."""
    import io

    import numpy as np

    image = pytest.importorskip("PIL.Image", reason="pip install pillow")
    return np.asarray(image.open(io.BytesIO(data)).convert("RGB"))
