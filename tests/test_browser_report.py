"""The HTML report in a real browser: headless Chromium (Debian's
``chromium`` and ``chromium-driver``) driven by Selenium opens the report
of a small workspace from its file, and there are no console errors, every
in-page link (``#anchor``) resolves, the diagrams render (an ``<svg>`` with
nodes), and a screenshot is saved (docs/reading-the-report.md).

The screenshot goes to the test's temporary directory, and also to
``reports/screenshots/`` of the repository when the environment variable
``RCLVERIFY_SCREENSHOTS`` is set (CI keeps that directory as an artifact).
Skipped, with the reason, only when no browser or driver is installed.
"""
from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.pipeline import Workspace, stage_check, stage_compose, stage_health, stage_report

REPO = Path(__file__).resolve().parents[1]
#: The browser flags: no sandbox (containers), no GPU, nothing fetched from the network.
FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--no-first-run", "--disable-sync", "--window-size=1400,1000")


def _browser() -> tuple[str, str] | str:
    """(chromium binary, chromedriver) or the reason there is none."""
    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if binary is None or driver is None:
        return "no Chromium and chromedriver installed (Debian: apt-get install chromium chromium-driver)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install selenium)"
    return binary, driver


@pytest.fixture()
def driver(tmp_path: Path) -> Any:
    found = _browser()
    if isinstance(found, str):
        pytest.skip(found)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    binary, chromedriver = found
    opts = webdriver.ChromeOptions()
    opts.binary_location = binary
    for f in FLAGS:
        opts.add_argument(f)
    opts.add_argument(f"--user-data-dir={tmp_path / 'profile'}")  # a fresh profile
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(options=opts, service=Service(chromedriver))
    d.set_page_load_timeout(15)
    d.set_script_timeout(10)
    try:
        yield d
    finally:
        d.quit()


def test_the_html_report_renders_in_chromium(tmp_path: Path, driver: Any) -> None:
    root = tmp_path / "ws"
    shutil.copytree(REPO / "tests" / "data" / "newcomer", root)
    ws = Workspace(root)
    stage_check(ws)
    for n in ws.node_names():
        stage_compose(ws, n)
        stage_health(ws, n)
    stage_report(ws)
    page = root / "reports" / "assurance.html"
    driver.get(page.as_uri())
    assert driver.title
    errors = [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]
    assert errors == [], errors
    broken = driver.execute_script("""
        const out = [];
        for (const a of document.querySelectorAll('a[href^="#"]')) {
          const id = decodeURIComponent(a.getAttribute('href').slice(1));
          if (!document.getElementById(id) && document.getElementsByName(id).length === 0) out.push(id);
        }
        return out;""")
    assert broken == []
    links = driver.execute_script("return document.querySelectorAll('a[href^=\"#\"]').length")
    assert links > 5
    # the system diagram: an inline SVG with one drawn node per contract node
    nodes = driver.execute_script("return Array.from(document.querySelectorAll('svg g.node title'))"
                                  ".map(t => t.textContent)")
    assert {"Planner", "Controller", "Motor"} <= set(nodes)
    # the diagnosis of the speed mismatch opens and shows its checked repair
    details = driver.find_element("id", "diagnosis-Controller-sc2")
    details.find_element("tag name", "summary").click()
    assert "guarantee( out.speed <= 1.5 )" in details.text
    shot = tmp_path / "assurance.png"
    assert driver.save_screenshot(str(shot)) and shot.stat().st_size > 1000
    if os.environ.get("RCLVERIFY_SCREENSHOTS"):
        dest = REPO / "reports" / "screenshots"
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, dest / "assurance-newcomer.png")
