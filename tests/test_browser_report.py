"""The HTML report in a real browser: headless Chromium (Debian's
``chromium`` and ``chromium-driver``) driven by Selenium opens the report
of a small workspace from its file, and there are no console errors, every
in-page link (``#anchor``) resolves, the diagrams render (an ``<svg>`` with
nodes), and a screenshot is saved (docs/reading-the-report.md).

The case study's report is rendered from its report dict
(``tests/data/case-study-report.json.gz``: ``reports/assurance.json`` of
``doit verify`` in a copy of the repository root, gzipped; regenerate it
when the report dict changes shape) and measured at 1400 px: at most
31,600 px tall (40% of the 79,000 px of issue 24), the system diagram within
the first two screens, every cell of the dashboard linked to an element
that exists.

The screenshot goes to the test's temporary directory, and also to
``reports/screenshots/`` of the repository when the environment variable
``RCLVERIFY_SCREENSHOTS`` is set (CI keeps that directory as an artifact).
Skipped, with the reason, only when no browser or driver is installed.
"""
from __future__ import annotations

import gzip
import json
import os
import shutil
from pathlib import Path
from typing import Any

import pytest

from rclverify.pipeline import (
    Workspace,
    stage_check,
    stage_compose,
    stage_health,
    stage_report,
)
from rclverify.report.render import render_files

REPO = Path(__file__).resolve().parents[1]
#: Tallest the case study's HTML report may be at 1400 px (CSS px): 40% of the 79,000 px of issue 24.
MAX_HEIGHT = 31_600
#: The system diagram starts within the first two screens (CSS px).
MAX_DIAGRAM_TOP = 2_000
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


_BROKEN_LINKS = """
    const out = [];
    for (const a of document.querySelectorAll(arguments[0])) {
      const id = decodeURIComponent(a.getAttribute('href').slice(1));
      if (!document.getElementById(id) && document.getElementsByName(id).length === 0) out.push(id);
    }
    return out;"""


def _screenshot(driver: Any, tmp_path: Path, name: str) -> None:
    """Save the page as ``name``: it must be a real image; with
    RCLVERIFY_SCREENSHOTS set it is kept in reports/screenshots/ (a CI artifact)."""
    shot = tmp_path / name
    assert driver.save_screenshot(str(shot)) and shot.stat().st_size > 1000
    if os.environ.get("RCLVERIFY_SCREENSHOTS"):
        dest = REPO / "reports" / "screenshots"
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, dest / name)


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
    broken = driver.execute_script(_BROKEN_LINKS, 'a[href^="#"]')
    assert broken == []
    links = driver.execute_script("return document.querySelectorAll('a[href^=\"#\"]').length")
    assert links > 5
    # the system diagram: an inline SVG with one drawn node per contract node
    nodes = driver.execute_script("return Array.from(document.querySelectorAll('svg g.node title'))"
                                  ".map(t => t.textContent)")
    assert {"Planner", "Controller", "Motor"} <= set(nodes)
    # the speed mismatch is a row of "What needs attention" whose repair opens to the diff Z3 checked,
    # and whose findings open to the side condition's diagnosis
    row = driver.find_element("xpath", "//table[contains(@class,'problems')]//tr[.//code[text()='Controller.sc2']]")
    repair = row.find_element("css selector", "details.repair")
    repair.find_element("tag name", "summary").click()
    assert "guarantee( out.speed <= 1.5 )" in repair.text
    row.find_element("css selector", "details.found > summary").click()
    details = driver.find_element("id", "diagnosis-Controller-sc2")
    details.find_element("tag name", "summary").click()
    assert "guarantee( out.speed <= 1.5 )" in details.text
    # the dashboard: one row per node, and Controller's side conditions cell is failed
    cell = driver.find_element("xpath", "//table[contains(@class,'matrix')]//tr[th/a[text()='Controller']]/td[2]")
    assert "failed" in cell.text
    _screenshot(driver, tmp_path, "assurance-newcomer.png")


def test_the_case_study_report_is_short_and_its_dashboard_links_resolve(tmp_path: Path, driver: Any) -> None:
    with gzip.open(REPO / "tests" / "data" / "case-study-report.json.gz", "rt", encoding="utf-8") as f:
        report = json.load(f)
    report.pop("problems", None)  # grouped again by the code under test
    out = tmp_path / "reports"
    out.mkdir()
    render_files(report, out, ("assurance.html",))
    driver.get((out / "assurance.html").as_uri())
    errors = [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]
    assert errors == [], errors
    height = driver.execute_script("return document.documentElement.scrollHeight")
    top = driver.execute_script("return document.querySelector('#system svg').getBoundingClientRect().top"
                                " + window.scrollY")
    print(f"case study report: {height} px tall at 1400 px, system diagram at {top:.0f} px")
    assert height <= MAX_HEIGHT
    assert top <= MAX_DIAGRAM_TOP
    # every cell of the matrix that has items links to an element that exists; one row per node
    cells = driver.execute_script("return document.querySelectorAll('table.matrix td.cell a').length")
    assert cells >= len(report["nodes"])
    assert driver.execute_script(_BROKEN_LINKS, "table.matrix a") == []
    assert driver.execute_script(_BROKEN_LINKS, 'a[href^="#"]') == []
    # the Agent's guarantee 3 is one row: its vacuity problems, the requirement REQ1, monitor and tests
    row = driver.find_element("xpath", "//table[contains(@class,'problems')]//tr[.//code[text()='REQ1']]")
    text = row.get_attribute("textContent")
    assert "contracts/remote_inspection.rcl:72:3" in text and "Agent.g2.non-vacuous" in text
    assert "Agent.g0.monitors.nominal_jsonl" in text
    _screenshot(driver, tmp_path, "assurance-case-study.png")
