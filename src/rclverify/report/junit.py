"""The assurance report as JUnit XML (``reports/assurance.junit.xml``).

CI systems show JUnit XML in their test view.  This module lays out the
report dict of :func:`rclverify.report.build.build_report`; it verifies
nothing itself.  Layout (decisions in ``docs/ci.md``):

* one ``<testsuite>`` per node (in the report's node order), named after
  the node;
* in it one ``<testcase>`` per obligation (``classname`` ``<Node>.obligation``,
  name the obligation id), per side condition of the calculus
  (``<Node>.side_condition``) and per contract health check
  (``<Node>.health``), each with the RCL ``file`` and ``line`` of its clause;
* outcome from the status: ``discharged``/``ok`` passes; ``failed`` and
  ``problem`` are a ``<failure>`` whose text carries the explanation and the
  counterexample (or unsat core); ``stale`` is a ``<failure>`` of type
  ``stale`` (the evidence no longer vouches for the current inputs);
  ``error`` is an ``<error>``; ``pending`` and ``inconclusive`` are
  ``<skipped>`` with the reason.

``time`` is the recorded duration of the check in seconds (0 when the
record has none).  The XML is built with :mod:`xml.etree.ElementTree`, so
every text is escaped; it is deterministic for a given report dict.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any, Mapping

from .sarif import split_location
from .render import model_text


def _case(suite: ET.Element, classname: str, name: str, where: str, seconds: Any) -> ET.Element:
    attrs = {"classname": classname, "name": name, "time": f"{float(seconds or 0.0):.3f}"}
    loc = split_location(where)
    if loc is not None:
        attrs["file"], attrs["line"] = loc[0], str(loc[1])
    return ET.SubElement(suite, "testcase", attrs)


def _outcome(case: ET.Element, status: str, summary: str, detail: str) -> str:
    """Attach the child element for ``status``; return the counter it bumps
    (``failures``, ``errors``, ``skipped``) or '' for a pass."""
    if status in ("discharged", "ok"):
        return ""
    if status in ("pending", "inconclusive"):
        ET.SubElement(case, "skipped", {"message": f"{status}: {summary}"}).text = detail or None
        return "skipped"
    if status == "error":
        ET.SubElement(case, "error", {"type": "error", "message": summary}).text = detail or None
        return "errors"
    kind = "failed" if status in ("failed", "problem") else status
    ET.SubElement(case, "failure", {"type": kind, "message": summary}).text = detail or None
    return "failures"


def _lines(*parts: str) -> str:
    return "\n".join(p for p in parts if p)


def junit_tree(report: Mapping[str, Any]) -> ET.Element:
    """The ``<testsuites>`` element of ``report`` (see the module docstring).

    Raises ``KeyError`` for a report dict without the keys ``nodes``,
    ``obligations``, ``evidence``, ``pending``, ``side_conditions``,
    ``findings`` and ``meta``.
    """
    evidence = {str(e["obligation"]): e for e in report["evidence"]}
    reasons: dict[str, str] = {}
    for p in report["pending"]:
        reasons.setdefault(str(p["obligation"]), str(p["reason"]))
    by_node: dict[Any, dict[str, list[Mapping[str, Any]]]] = {}  # node -> kind -> items, in report order
    for kind in ("obligations", "side_conditions", "findings"):
        for item in report[kind]:
            by_node.setdefault(item["node"], {}).setdefault(kind, []).append(item)
    root = ET.Element("testsuites", {"name": f"rclverify: {report['meta']['workspace']}"})
    totals = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    total_time = 0.0
    for node in report["nodes"]:
        name = str(node["name"])
        suite = ET.SubElement(root, "testsuite", {"name": name})
        counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
        time = 0.0

        def tally(case: ET.Element, status: str, summary: str, detail: str, seconds: Any) -> None:
            nonlocal time
            counts["tests"] += 1
            time += float(seconds or 0.0)
            bumped = _outcome(case, status, summary, detail)
            if bumped:
                counts[bumped] += 1

        for o in by_node.get(name, {}).get("obligations", ()):
            ev = evidence.get(str(o["id"]))
            secs = ev["duration_s"] if ev is not None else 0.0
            case = _case(suite, f"{name}.obligation", str(o["id"]), str(o["source"]), secs)
            expl = str(ev["explanation"]) if ev is not None else reasons.get(str(o["id"]), "no evidence record yet")
            cex = model_text(ev.get("counterexample")) if ev is not None else ""
            tally(case, str(o["status"]), expl.splitlines()[0] if expl else str(o["status"]),
                  _lines(f"obligation ({o['backend']}, {o['kind']}) of guarantee {o['guarantee']}: {o['statement']}",
                         f"source: {o['source']}", expl, f"counterexample: {cex}" if cex else ""), secs)
        for sc in by_node.get(name, {}).get("side_conditions", ()):
            case = _case(suite, f"{name}.side_condition", str(sc["id"]), str(sc["source"]), sc.get("duration_s"))
            model = model_text(sc.get("model"))
            tally(case, str(sc["status"]), str(sc.get("explanation") or sc["status"]),
                  _lines(f"side condition ({sc['rule']}): {sc['conjunct']}", f"source: {sc['source']}",
                         str(sc.get("explanation") or ""), f"counterexample: {model}" if model else ""),
                  sc.get("duration_s"))
        for f in by_node.get(name, {}).get("findings", ()):
            case = _case(suite, f"{name}.health", str(f["id"]), _source_of(node, f), f.get("duration_s"))
            core = "; ".join(str(c) for c in f.get("core") or [])
            model = model_text(f.get("model"))
            tally(case, str(f["status"]), str(f["message"]),
                  _lines(str(f["message"]), str(f.get("explanation") or ""), f"unsat core: {core}" if core else "",
                         f"counterexample: {model}" if model else ""), f.get("duration_s"))
        for k, v in counts.items():
            suite.set(k, str(v))
            totals[k] += v
        suite.set("time", f"{time:.3f}")
        total_time += time
    for k, v in totals.items():
        root.set(k, str(v))
    root.set("time", f"{total_time:.3f}")
    return root


def _source_of(node: Mapping[str, Any], finding: Mapping[str, Any]) -> str:
    for g in node["guarantees"]:
        if finding["guarantee"] is not None and g["index"] == finding["guarantee"]:
            return str(g["source"])
    return str(node["source"])


def render_junit(report: Mapping[str, Any]) -> str:
    """:func:`junit_tree` as indented UTF-8 XML text with a declaration."""
    root = junit_tree(report)
    ET.indent(root)
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
