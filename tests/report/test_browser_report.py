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
that exists; and it reads well (issue 30, item 6): no backtick outside
``<code>``/``<pre>``, every badge inside its cell, obligation ids in natural
order, the diagrams' text at least 9 px, no word broken inside itself, the
LaTeX appendix one document with one preamble and no ``<string>``.

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

from rclverify.app.pipeline import (
    Workspace,
    stage_check,
    stage_compose,
    stage_health,
    stage_report,
)
from rclverify.report.render import render_files
from rclverify.report.templating import anchor
from rclverify.report.textfmt import natural_key

REPO = Path(__file__).resolve().parents[2]
#: Tallest the case study's HTML report may be at 1400 px (CSS px): 40% of the 79,000 px of issue 24.
MAX_HEIGHT = 31_600
#: The system diagram starts within the first three screens (CSS px): "What needs attention"
#: above it now has nine rows (the model checker's instances are rows of their own, not members of the
#: guarantee-3 row), which put the diagram at 2,081 px; eleven since the Radiation Sensor's recorded runs
#: are inconclusive (one row for the three), at 2,262 px; twelve since the Agent's contract is found
#: unrealizable (a row of its own), at 2,353 px; the margins part (the guarantees held by the smallest
#: margins over the recorded runs, four rows) above it since the stored report was regenerated with it, at
#: 2,755 px. Still within three screens of 1,000 px.
MAX_DIAGRAM_TOP = 2_800
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
    assert "guarantee( 0 <= out.speed and out.speed <= 1.5 )" in repair.text
    row.find_element("css selector", "details.found > summary").click()
    details = driver.find_element("id", "diagnosis-Controller-sc2")
    details.find_element("tag name", "summary").click()
    assert "guarantee( 0 <= out.speed and out.speed <= 1.5 )" in details.text
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


#: Text nodes of the page (not in code, pre, script, style or a drawing) that hold a backtick.
_STRAY_BACKTICKS = """
    const out = [], w = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    for (let n; (n = w.nextNode());) {
      if (n.data.includes('`') && !n.parentElement.closest('code, pre, script, style, svg')) out.push(n.data.trim());
    }
    return out;"""

#: Badges shown that stick out of their table cell (CSS px, half a pixel allowed).
_BADGES_OUTSIDE = """
    const out = [];
    for (const b of document.querySelectorAll('td .badge, th .badge')) {
      const r = b.getBoundingClientRect();
      if (!r.width) continue;  // not shown
      const c = b.closest('td, th').getBoundingClientRect();
      if (r.left < c.left - .5 || r.right > c.right + .5 || r.top < c.top - .5 || r.bottom > c.bottom + .5)
        out.push(b.textContent + ' in ' + b.closest('tr').textContent.slice(0, 60));
    }
    return out;"""

#: The smallest text of the drawings, in CSS px as shown: each label's font size times its scale on screen.
_SMALLEST_DIAGRAM_TEXT = """
    let least = Infinity, n = 0;
    for (const t of document.querySelectorAll('.diagram svg text')) {
      const m = t.getScreenCTM();
      least = Math.min(least, parseFloat(getComputedStyle(t).fontSize) * Math.hypot(m.a, m.b)); n++;
    }
    return [least, n];"""

#: Words shown on two lines broken inside themselves: a line ends inside a run of non-space characters of
#: one text node after a character that is not a sensible break (- / . _ , and the like; <wbr> after . / _
#: splits the text node, so a break there is between nodes).
_BROKEN_WORDS = """
    const ok = new Set(['-', '/', '.', '_', ',', '(', ')', '|', ':', ';', '=', '>', '<', '&', '+', '*']);
    const out = [], w = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    for (let n; (n = w.nextNode());) {
      const p = n.parentElement;
      if (p.closest('pre, svg, script, style') || !p.getClientRects().length) continue;
      for (const m of n.data.matchAll(/\\S{2,}/g)) {
        const r = document.createRange();
        r.setStart(n, m.index); r.setEnd(n, m.index + m[0].length);
        if (Array.from(r.getClientRects()).filter(x => x.width > 0).length < 2) continue;
        let top = null;
        for (let i = 0; i < m[0].length; i++) {
          r.setStart(n, m.index + i); r.setEnd(n, m.index + i + 1);
          const cr = r.getClientRects();
          if (!cr.length) continue;
          if (top !== null && cr[0].top > top + 2 && !ok.has(m[0][i - 1])) {
            out.push(m[0].slice(0, i) + '|' + m[0].slice(i)); break;
          }
          top = cr[0].top;
        }
      }
    }
    return out;"""


def _case_study_page(tmp_path: Path, driver: Any) -> dict[str, Any]:
    """Open the case study's report (rendered from the stored report dict); returns the dict."""
    with gzip.open(REPO / "tests" / "data" / "case-study-report.json.gz", "rt", encoding="utf-8") as f:
        report: dict[str, Any] = json.load(f)
    report.pop("problems", None)
    out = tmp_path / "reports"
    out.mkdir()
    render_files(report, out, ("assurance.html",))
    driver.get((out / "assurance.html").as_uri())
    return report


def test_the_case_study_report_reads_well(tmp_path: Path, driver: Any) -> None:
    report = _case_study_page(tmp_path, driver)
    assert driver.execute_script(_STRAY_BACKTICKS) == []
    assert driver.execute_script("return document.querySelectorAll('code').length") > 100
    # the drawings' text is at least 9 px as shown at 1400 px (the argument scrolls in its box)
    least, labels = driver.execute_script(_SMALLEST_DIAGRAM_TEXT)
    print(f"smallest diagram text: {least:.1f} px of {labels} labels")
    assert labels > 50 and least >= 9
    # the obligations: one folded table per node, ids in natural order (p1_i0 < p2_i1 < p10_i9)
    tables = driver.execute_script("""
        return Array.from(document.querySelectorAll('details.obligations')).map(d => [d.open,
          Array.from(d.querySelectorAll('tr[id] > td:first-child > code')).map(c => c.textContent)]);""")
    assert len(tables) == len({o["node"] for o in report["obligations"]})
    assert not any(is_open for is_open, _ in tables)
    ids = [i for _, t in tables for i in t]
    assert sorted(ids) == sorted(o["id"] for o in report["obligations"])
    for _, t in tables:
        assert t == sorted(t, key=natural_key)
    agent = next(t for _, t in tables if "Agent.g1.ajpf.p1_i0" in t)
    assert agent.index("Agent.g1.ajpf.p2_i1") < agent.index("Agent.g1.ajpf.p10_i9")
    # a link to an obligation opens its node's table
    driver.execute_script("document.querySelector('a[href=\"#ob-Agent.g1.ajpf.p10_i9\"]').click()")
    assert driver.execute_script("return document.getElementById('ob-Agent.g1.ajpf.p10_i9')"
                                 ".closest('details').open")
    # the requirement proved vacuously is one warning badge; a proved one shows its evidence apart
    row = driver.find_element("xpath", "//table[contains(@class,'requirements')]//tr[td/a[text()='REQ1']]")
    assert [b.text for b in row.find_elements("css selector", ".badge")] == ["proved vacuously"]
    row = driver.find_element("xpath", "//table[contains(@class,'requirements')]//tr[td/a[text()='REQ2']]")
    assert [b.text for b in row.find_elements("css selector", ".badge")] == ["proved", "evidence: failed"]
    # the LaTeX appendix is one document: one preamble, each node's block, one end; no <string>
    appendix = driver.find_element("id", "appendix").get_attribute("textContent")
    assert appendix.count("\\documentclass") == appendix.count("\\begin{document}") == 1
    assert appendix.count("\\end{document}") == 1 and appendix.count("\\paragraph{") == len(report["nodes"])
    assert "% node Agent (contracts/remote_inspection.rcl:" in appendix
    assert "<string>" not in driver.execute_script("return document.body.textContent")
    # with every fold open: no badge sticks out of its cell, no word is broken inside itself, no
    # sideways scrolling of the page
    driver.execute_script("document.querySelectorAll('details').forEach(d => d.open = true)")
    assert driver.execute_script(_BADGES_OUTSIDE) == []
    assert driver.execute_script(_BROKEN_WORDS) == []
    assert driver.execute_script("return document.documentElement.scrollWidth <= window.innerWidth")
    driver.execute_script("document.getElementById('argument').scrollIntoView()")
    _screenshot(driver, tmp_path, "assurance-case-study-argument.png")


def _first_screen(driver: Any, tmp_path: Path, stored: str, regroup: bool = False) -> int:
    """Open the HTML report of the stored report dict ``tests/data/<stored>`` at 1400x900 and return
    the window's inner height; ``regroup``: its problems grouped again by the current code."""
    with gzip.open(REPO / "tests" / "data" / stored, "rt", encoding="utf-8") as f:
        report = json.load(f)
    if regroup:
        report.pop("problems", None)
    out = tmp_path / "reports"
    out.mkdir()
    render_files(report, out, ("assurance.html",))
    driver.set_window_size(1400, 900)
    driver.get((out / "assurance.html").as_uri())
    return int(driver.execute_script("return window.innerHeight"))


def test_the_first_screen_says_what_to_fix(tmp_path: Path, driver: Any) -> None:
    """Issue 48: at 1400x900 the first screen holds the overall status with the refuted
    requirements counted and the first problem to fix with its culprit (before, the
    node-by-technique dashboard pushed the problems below the fold)."""
    height = _first_screen(driver, tmp_path, "case-study-report.json.gz", regroup=True)
    lead = driver.find_element("css selector", "header p.lead").get_attribute("textContent")
    assert "1 requirement refuted (REQ4)" in lead and "problems to fix" in lead
    first = driver.find_element("css selector", "#problem-1")
    bottom = driver.execute_script("return arguments[0].getBoundingClientRect().bottom", first)
    assert bottom <= height, (bottom, height)
    assert "contracts/remote_inspection.rcl:72:3" in first.get_attribute("textContent")  # its culprit
    # the culprit nodes are marked in the dashboard (a guarantee or the contract of each is a culprit)
    marked = driver.execute_script("return [...document.querySelectorAll('table.matrix th span.culprit')]"
                                   ".map(s => s.closest('th').querySelector('a').textContent)")
    assert "Agent" in marked and "Localisation" not in marked, marked
    # and in the system diagram: the culprit's box has a thick red border and says so
    drawn = driver.execute_script("return [...document.querySelectorAll('svg g.node.culprit title')]"
                                  ".map(t => t.textContent)")
    assert "Agent" in drawn and "Localisation" not in drawn, drawn
    _screenshot(driver, tmp_path, "assurance-first-screen.png")


def test_the_warehouse_first_screen_says_what_to_fix(tmp_path: Path, driver: Any) -> None:
    """Issue 48, on examples/warehouse (``tests/data/warehouse-report.json.gz``: its
    ``reports/assurance.json`` after ``doit verify``, gzipped): at 1400x900 the first screen
    holds the overall status with the refuted requirements and deadline counted, and the
    first problem with its culprit and its first repair; the culprit node is marked in the
    dashboard and the system diagram, a node no problem blames is not."""
    height = _first_screen(driver, tmp_path, "warehouse-report.json.gz")
    status = driver.find_element("css selector", "header p.banner")
    assert "failed" in status.get_attribute("textContent")
    lead = driver.find_element("css selector", "header p.lead").get_attribute("textContent")
    assert "3 requirements refuted (STOP, DOCK, ARRIVE)" in lead and "1 end-to-end deadline refuted" in lead, lead
    first = driver.find_element("css selector", "#problem-1")
    text = first.get_attribute("textContent")
    assert "contracts/lidar_driver.rcl:15:3" in text  # the culprit: LidarDriver's guarantee, not the consumer
    assert "rescale-producer" in text  # its first repair
    top = driver.execute_script("return arguments[0].getBoundingClientRect().top", first)
    assert top < height, (top, height)  # the first problem starts on the first screen
    marked = driver.execute_script("return [...document.querySelectorAll('table.matrix th span.culprit')]"
                                   ".map(s => s.closest('th').querySelector('a').textContent)")
    assert "LidarDriver" in marked, marked
    drawn = driver.execute_script("return [...document.querySelectorAll('svg g.node.culprit title')]"
                                  ".map(t => t.textContent)")
    # the deadline's chain blames Controller's guarantee 1 too; Localiser and MissionManager are no culprit
    assert "LidarDriver" in drawn and "Localiser" not in drawn and "MissionManager" not in drawn, drawn
    failing = driver.execute_script("return [...document.querySelectorAll('svg g.edge.failing title')]"
                                    ".map(t => t.textContent)")
    assert any("LidarDriver" in t and "Controller" in t for t in failing), failing
    _screenshot(driver, tmp_path, "assurance-warehouse-first-screen.png")


def test_the_standards_section_maps_every_clause_of_the_case_study(tmp_path: Path, driver: Any) -> None:
    """The case study's plan maps its evidence onto IEC 61508-3 at SIL 2 and UL 4600 (docs/standards.md):
    in the browser, one compliance matrix per standard, one row per clause of its profile, each showing
    what covers it (or none), who checked it, its status and why, the status never "covered" while an
    item in the clause's scope is not, and never "partial" with nothing covered."""
    with gzip.open(REPO / "tests" / "data" / "case-study-report.json.gz", "rt", encoding="utf-8") as f:
        report = json.load(f)
    report.pop("problems", None)
    out = tmp_path / "reports"
    out.mkdir()
    render_files(report, out, ("assurance.html",))
    driver.get((out / "assurance.html").as_uri())
    standards = {s["profile"]: s for s in report["standards"]}
    assert set(standards) == {"iec61508-3", "ul4600"} and standards["iec61508-3"]["level"] == "2"
    for profile, s in standards.items():
        rows = driver.find_elements("css selector", f"#{anchor('standard', profile)} + p + table.standard tr[id]")
        assert len(rows) == len(s["clauses"]) > 0, profile
        for row, clause in zip(rows, s["clauses"]):
            cells = row.find_elements("tag name", "td")
            assert cells[0].text == clause["id"] and cells[6].text == clause["status"]
            covered = [x for x in clause["scope"] if x["covered"]]
            assert cells[4].text == (", ".join(clause["covered_by"]) if clause["covered_by"] else "none")
            assert cells[7].text.startswith(clause["why"][:40])
            assert clause["status"] != "covered" or len(covered) == len(clause["scope"]) > 0
            assert clause["status"] != "partial" or (covered and clause["covered_by"])
            links = cells[7].find_elements("css selector", "a")
            assert len(links) == sum(1 for e in clause["evidence"] if not e["counts"])
    assert driver.execute_script(_BROKEN_LINKS, "table.standard a") == []
    driver.execute_script(f"document.getElementById('{anchor('standard', 'iec61508-3')}').scrollIntoView()")
    _screenshot(driver, tmp_path, "assurance-standards.png")
