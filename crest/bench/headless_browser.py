"""A headless Chromium driven by Selenium, for the view's bench and tests (no download, no network).

Debian's chromium and chromium-driver (/usr/bin/chromium, /usr/bin/chromedriver) are used as
installed: the Service is given chromedriver's path, so selenium-manager never tries to fetch
a browser. The flags keep Chromium off the network (no background requests, updates or sync)
and a fresh profile directory makes each start independent.
"""
from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage", "--window-size=1200,1000")

SCRIPT_TIMEOUT_S = 120.0
"""Page loads and scripts may take long on a loaded machine; a hang still ends."""


class BrowserMissing(RuntimeError):
    """No headless browser here; the message says what to install."""


def browser_missing() -> str | None:
    """Why no headless browser can be started here, or None when one can."""
    if not CHROMIUM.exists() or not CHROMEDRIVER.exists():
        return (f"no headless Chromium: {CHROMIUM} or {CHROMEDRIVER} is missing "
                "(apt-get install chromium chromium-driver)")
    try:
        import selenium  # noqa: F401  (only asks whether it is installed)
    except ImportError:
        return "selenium is not installed (pip install '.[test]')"
    return None


@contextmanager
def headless_chromium() -> Iterator:
    """A selenium WebDriver on a headless Chromium; quit and its profile removed on exit."""
    reason = browser_missing()
    if reason is not None:
        raise BrowserMissing(reason)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="crest-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for flag in FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    try:
        driver = webdriver.Chrome(service=Service(executable_path=str(CHROMEDRIVER)), options=options)
        driver.set_script_timeout(SCRIPT_TIMEOUT_S)
        driver.set_page_load_timeout(SCRIPT_TIMEOUT_S)
        try:
            yield driver
        finally:
            driver.quit()
    finally:
        shutil.rmtree(profile, ignore_errors=True)
