"""The assurance report as JUnit XML (``reports/assurance.junit.xml``).

CI systems show JUnit XML in their test view.  This module lays out the
report of :func:`rclverify.report.build.build_report`, its rows decoded
into their records and read as the attributes mypy checks; it verifies
nothing itself.  Layout (decisions in ``docs/ci.md``):

* one ``<testsuite>`` per node (in the report's node order), named after
  the node;
* in it one ``<testcase>`` per obligation (``classname`` ``<Node>.obligation``,
  name the obligation id), per side condition of the calculus
  (``<Node>.side_condition``) and per contract health check
  (``<Node>.health``), each with the RCL ``file`` and ``line`` of its clause;
* outcome from the status: ``discharged``/``ok`` passes (a side condition
  ``discharged in context`` passes with its verdict and the upstream
  premises its proof used in ``<system-out>``); ``failed`` and
  ``problem`` are a ``<failure>`` whose text carries the explanation and the
  counterexample (or unsat core); ``stale`` is a ``<failure>`` of type
  ``stale`` (the evidence no longer vouches for the current inputs);
  ``error`` is an ``<error>``; ``pending`` and ``inconclusive`` are
  ``<skipped>`` with the reason;
* one ``<testcase>`` per guarantee no obligation covers (``classname``
  ``<Node>.guarantee``, name ``<Node>.g<k>``, at the guarantee): a
  ``<failure>`` of type ``unverified`` with the reason (nothing was planned
  to establish it, and ``--strict`` fails on it; report/unverified.py);
* after the nodes, when the plan has requirements, one ``<testsuite>``
  named ``requirements`` with one ``<testcase>`` per requirement
  (``classname`` ``requirement``, name its id, at its formal statement):
  it passes only when the requirement is ``met``; a refuted one (or one
  proved from an inconsistency) is a ``<failure>`` with the counterexample
  node by node; outstanding evidence and inconclusive are ``<skipped>``
  (a ``<failure>`` when evidence the proof rests on failed), informal
  ones ``<skipped>``;
* when the plan has end-to-end deadlines, a ``deadlines`` ``<testsuite>``
  with one ``<testcase>`` per deadline (:func:`.deadlines.junit_suite`);
* when the contracts have lint diagnostics, a ``lint`` ``<testsuite>`` with
  one failing ``<testcase>`` per diagnostic (:func:`_lint_suite`);
* when the runs nearly missed a guarantee, a ``near_misses`` ``<testsuite>``
  with one failing ``<testcase>`` per near miss (:func:`.near_misses.junit_suite`);
* when the plan names a design, a ``design`` ``<testsuite>``, one case per monitoring field
  (:func:`.design.junit_suite`; docs/nodl.md, "The design stage");
* when the workspace has NoDL documents, a ``nodl`` ``<testsuite>`` with one
  failing ``<testcase>`` per NoDL error, or one passing case for a check
  without one (:func:`.nodl.junit_suite`; docs/nodl.md).  The ROS grounding
  has no suite: its errors are in the terminal summary, the report and SARIF.

Every outcome is the item's one severity (:mod:`.severity`, docs/ci.md):
an ``error`` is a ``<failure>`` (``<error>`` for a record not believed), a
``warning`` a ``<failure>`` or, when undecided or not run yet, a
``<skipped>``; a ``note`` (an informal requirement) ``<skipped>``.

``time`` is the recorded duration of the check in seconds (0 when the
record has none).  The XML is built with :mod:`xml.etree.ElementTree`, so
every text is escaped; it is deterministic for a given report dict.
"""
from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from typing import Any, Mapping, cast

import msgspec

from rclverify.report.fragments import FragmentCache
from rclverify.records.sarif import split_location
from rclverify.report.templating import model_text
from rclverify.records.findings import rows_of
from rclverify.records.node_rows import NodeRow, UnverifiedRow
from rclverify.records.obligations import rows_of as obligation_rows_of
from rclverify.records.evidence_rows import rows_of as evidence_rows_of
from rclverify.records.report_record import AssuranceReport
from rclverify.records.report_schema import Report
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.records.row import decode_rows
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.severity import junit_outcome
from rclverify.report.junit_suite import closed


def _case(suite: ET.Element, classname: str, name: str, where: str, seconds: Any) -> ET.Element:
    attrs = {"classname": classname, "name": name, "time": f"{float(seconds or 0.0):.3f}"}
    loc = split_location(where)
    if loc is not None:
        attrs["file"], attrs["line"] = loc[0], str(loc[1])
    return ET.SubElement(suite, "testcase", attrs)


def _outcome(case: ET.Element, status: str, summary: str, detail: str, kind: str = "obligation") -> str:
    """Attach the child element for an item of ``kind`` with ``status`` (its
    one severity, :func:`.severity.junit_outcome`); return the counter it
    bumps (``failures``, ``errors``, ``skipped``) or '' for a pass."""
    if status == "acknowledged":  # a warning accepted in the plan with a reason (model/plan/acknowledged.py)
        ET.SubElement(case, "skipped", {"message": f"acknowledged warning: {summary}"}).text = detail or None
        return "skipped"
    how = junit_outcome(kind, status)
    if how == "pass":
        return ""
    if how == "skipped":
        ET.SubElement(case, "skipped", {"message": f"{status}: {summary}"}).text = detail or None
        return "skipped"
    if how == "error":
        ET.SubElement(case, "error", {"type": "error", "message": summary}).text = detail or None
        return "errors"
    failure = "failed" if status in ("failed", "problem") else status
    ET.SubElement(case, "failure", {"type": failure, "message": summary}).text = detail or None
    return "failures"


def _properties(rows: list[tuple[str, str]], case: str, props: Mapping[str, str]) -> None:
    """Add ``props`` of test case ``case`` to ``rows``, named ``<case>.<property>``:
    the JUnit XML schema has properties per suite, not per test case."""
    rows.extend((f"{case}.{k}", str(v)) for k, v in props.items())


def _put_properties(suite: ET.Element, rows: list[tuple[str, str]]) -> None:
    """``rows`` as the suite's ``<properties>``, its first child (JUnit XML schema)."""
    if rows:
        el = ET.Element("properties")
        for k, v in rows:
            ET.SubElement(el, "property", {"name": k, "value": v})
        suite.insert(0, el)


def _lines(*parts: str) -> str:
    return "\n".join(p for p in parts if p)


def _both(report: Report | AssuranceReport) -> tuple[AssuranceReport, Report]:
    """``report`` decoded once, and as its JSON object (the node suites' kept fragments are keyed by their
    JSON, :func:`_suite_data`)."""
    typed = AssuranceReport.of(report)
    return typed, report if isinstance(report, Mapping) else cast(Report, typed.to_json())


def junit_tree(report: Report | AssuranceReport) -> ET.Element:
    """The ``<testsuites>`` element of ``report`` (see the module docstring).

    Raises :class:`msgspec.ValidationError` for a report dict that is not
    of the report's shape (:class:`~rclverify.records.report_record.AssuranceReport`).
    """
    typed, report = _both(report)
    root = ET.Element("testsuites", {"name": f"rclverify: {typed.meta.workspace}"})
    totals = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    total_time = 0.0
    for node, data in _suite_data(report):
        suite, counts, time = _suite(node, data)
        root.append(suite)
        for k, v in counts.items():
            totals[k] += v
        total_time += time
    from rclverify.report.deadlines import junit_suite  # deferred: start-up (loads rclverify.lang.errors, rclverify.report.deadlines and more only when called)
    from rclverify.report.near_misses import junit_suite as near_misses_suite  # deferred: start-up (only when called)
    from rclverify.report.nodl import junit_suite as nodl_suite  # deferred: start-up (only when called)
    from rclverify.report.design import junit_suite as design_suite  # deferred: start-up (only when called)
    for req in (_requirements_suite(typed), junit_suite(typed, _case, _outcome), _lint_suite(typed),
                near_misses_suite(typed, _case, _outcome), nodl_suite(typed, _case, _outcome),
                design_suite(typed, _case, _outcome)):
        if req is None:
            continue
        root.append(req[0])
        for k, v in req[1].items():
            totals[k] += v
        total_time += req[2]
    for k, v in totals.items():
        root.set(k, str(v))
    root.set("time", f"{total_time:.3f}")
    return root


def _requirements_suite(report: AssuranceReport) -> tuple[ET.Element, dict[str, int], float] | None:
    """The ``requirements`` ``<testsuite>`` (module docstring), its counts and
    time; ``None`` when the report has no requirements."""
    if not report.requirements:
        return None
    suite = ET.Element("testsuite", {"name": "requirements"})
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    props: list[tuple[str, str]] = []  # the test cases' strength and confidence (docs/confidence.md)
    time = 0.0
    for r in report.requirements:
        c = RequirementCheckRow.of(r.check)  # the requirement check's record (calculus/requirements/check.py)
        secs = float(c.duration_s)
        case = _case(suite, "requirement", r.id, c.source or "", secs)
        cex = "; ".join(f"{row.node}: " + ", ".join(f"{k} = {v}" for k, v in row.values.items())
                        for row in c.counterexample)
        used = "; ".join(f"{p.label} ({p.source})" for p in c.used)
        prevent = "; ".join(f"{p.label}: {p.text} ({p.source})" for p in c.failed_to_prevent)
        counts["tests"] += 1
        time += secs
        limited = r.limited_by
        if r.confidence is not None and limited:
            sentence = "" if limited.sentence is msgspec.UNSET else limited.sentence
            _properties(props, r.id, {"confidence": f"{r.confidence:.6g}", "limited_by": sentence})
        bumped = _outcome(case, r.status, f"{r.verdict}: {r.note}",
                          _lines(f"requirement {r.id}: {r.text}",
                                 f"formal: {c.formal}" if c.formal else "",
                                 f"verdict: {r.verdict}", r.note,
                                 f"used: {used}" if used else "", f"counterexample: {cex}" if cex else "",
                                 f"not prevented by: {prevent}" if prevent else ""))
        if bumped:
            counts[bumped] += 1
    for k, v in counts.items():
        suite.set(k, str(v))
    suite.set("time", f"{time:.3f}")
    _put_properties(suite, props)
    return suite, counts, time


def _lint_suite(report: AssuranceReport) -> tuple[ET.Element, dict[str, int], float] | None:
    """The ``lint`` ``<testsuite>``: one ``<testcase>`` per lint diagnostic
    (``classname`` ``lint``, name its code and location, at its location), a
    ``<failure>`` of type ``warning`` or ``error`` (its one severity,
    :mod:`.severity`: ``--strict`` fails on it); ``None`` without lint."""
    rows = report.lint
    if not rows:
        return None
    suite = ET.Element("testsuite", {"name": "lint"})
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for x in rows:
        sev = x.severity.lower()
        case = _case(suite, "lint", f"{x.code or 'lint'} {x.location}", x.location, 0.0)
        counts["tests"] += 1
        ack = x.acknowledged
        bumped = _outcome(case, "acknowledged" if ack else sev,
                          x.message + (f" (acknowledged at {ack.at}: {ack.reason})" if ack else ""),
                          f"{x.location}: {sev}: {x.message}", kind="lint")
        if bumped:
            counts[bumped] += 1
    return closed(suite, counts)


def _suite_data(report: Report) -> list[tuple[Mapping[str, Any], dict[str, Any]]]:
    """Per node of ``report``, in order: the node and exactly what its
    ``<testsuite>`` is made from (its obligations, side conditions and
    findings, the evidence records and pending reasons of its obligations)."""
    evidence = {str(e["obligation"]): e for e in report["evidence"]}  # JSON: the suite's fragment is keyed by it
    reasons: dict[str, str] = {}
    for p in report["pending"]:
        reasons.setdefault(str(p["obligation"]), str(p["reason"]))
    by_node: dict[Any, dict[str, list[Mapping[str, Any]]]] = {}  # node -> kind -> items, in report order
    for kind in ("obligations", "side_conditions", "findings"):
        for item in report[kind]:
            by_node.setdefault(item["node"], {}).setdefault(kind, []).append(item)
    for u in report.get("unverified") or ():
        by_node.setdefault(u["node"], {}).setdefault("unverified", []).append(u)
    out: list[tuple[Mapping[str, Any], dict[str, Any]]] = []
    for node in report["nodes"]:
        items = by_node.get(str(node["name"]), {})
        ids = [str(o["id"]) for o in items.get("obligations", ())]
        out.append((node, {"items": items, "evidence": {i: evidence[i] for i in ids if i in evidence},
                           "reasons": {i: reasons[i] for i in ids if i in reasons}}))
    return out


def _suite(node_json: Mapping[str, Any], data: Mapping[str, Any]) -> tuple[ET.Element, dict[str, int], float]:
    """The ``<testsuite>`` of one node from :func:`_suite_data` (its JSON, the kept fragment's key), its rows
    decoded, its counts (``tests``, ``failures``, ``errors``, ``skipped``) and its time in seconds."""
    node = NodeRow.of(node_json)
    name = node.name
    items, reasons = data["items"], data["reasons"]
    evidence = {e.obligation: e for e in evidence_rows_of(data["evidence"].values())}
    suite = ET.Element("testsuite", {"name": name})
    counts = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    props: list[tuple[str, str]] = []  # the test cases' strength and confidence (docs/confidence.md)
    time = 0.0

    def tally(case: ET.Element, status: str, summary: str, detail: str, seconds: Any) -> None:
        nonlocal time
        counts["tests"] += 1
        time += float(seconds or 0.0)
        bumped = _outcome(case, status, summary, detail)
        if bumped:
            counts[bumped] += 1

    for o in obligation_rows_of(items.get("obligations", ())):
        ev = evidence.get(o.id)
        secs = ev.duration_s if ev is not None else 0.0
        case = _case(suite, f"{name}.obligation", o.id, o.source, secs)
        expl = ev.explanation if ev is not None else reasons.get(o.id, "no evidence record yet")
        cex = model_text(ev.counterexample) if ev is not None else ""
        if ev is not None and ev.strength is not None:  # the evidence's kind (docs/confidence.md)
            _properties(props, o.id, {"strength": ev.strength.kind,
                                      "strength.detail": ev.strength.detail or ""})
        tally(case, o.status, expl.splitlines()[0] if expl else o.status,
              _lines(f"obligation ({o.backend}, {o.kind}) of guarantee {o.guarantee}: {o.statement}",
                     f"source: {o.source}", f"artifact: {o.artifact}" if o.artifact else "", expl,
                     f"counterexample: {cex}" if cex else ""), secs)
    for sc in decode_rows(SideConditionRow, items.get("side_conditions", ())):
        case = _case(suite, f"{name}.side_condition", sc.id, sc.source, sc.duration_s)
        model = model_text(sc.model)
        verdict = sc.verdict or sc.status
        if sc.strength:
            solvers = 1 if sc.strength.solvers is msgspec.UNSET else sc.strength.solvers
            _properties(props, sc.id, {"strength": sc.strength.kind, "solvers": str(solvers)})
        tally(case, sc.status, sc.explanation or sc.status,
              _lines(f"side condition ({sc.rule}): {sc.conjunct}", f"source: {sc.source}",
                     f"verdict: {verdict}", sc.explanation,
                     f"counterexample: {model}" if model else ""),
              sc.duration_s)
        if sc.status == "discharged" and verdict != sc.status:  # a pass that rests on the upstream cone
            ET.SubElement(case, "system-out").text = _lines(
                f"verdict: {verdict}", "upstream premises used: " + "; ".join(sc.hypotheses))
    for f in rows_of(items.get("findings", ())):
        case = _case(suite, f"{name}.health", f.id, _source_of(node, f.guarantee), f.duration_s)
        core = "; ".join(f.core or [])
        model = model_text(f.model)
        ack = f.acknowledged
        _properties(props, f.id, {"check": f.check, **({"solvers": f.solvers.agreement} if f.solvers else {})})
        tally(case, "acknowledged" if ack else f.status,
              f.message + (f" (acknowledged at {ack.at}: {ack.reason})" if ack else ""),
              _lines(f.message, f.explanation, f"unsat core: {core}" if core else "",
                     f"counterexample: {model}" if model else ""), f.duration_s)
    for u in decode_rows(UnverifiedRow, items.get("unverified", ())):
        case = _case(suite, f"{name}.guarantee", u.id, u.source, 0.0)
        tally(case, u.status, f"unverified: {u.reason}",
              _lines(f"guarantee {u.guarantee} of {name}: {u.text}", f"source: {u.source}",
                     f"unverified: {u.reason}"), 0.0)
    for k, v in counts.items():
        suite.set(k, str(v))
    suite.set("time", f"{time:.3f}")
    _put_properties(suite, props)
    return suite, counts, time


def _source_of(node: NodeRow, guarantee: int | None) -> str:
    for g in node.guarantees:
        if guarantee is not None and g.index == guarantee:
            return g.source
    return node.source


_DECLARATION = '<?xml version="1.0" encoding="utf-8"?>\n'


def render_junit(report: Report | AssuranceReport, fragments: FragmentCache | None = None) -> str:
    """:func:`junit_tree` as indented UTF-8 XML text with a declaration.

    With ``fragments``, each node's ``<testsuite>`` (its indented text, its
    counts and time) is kept between runs, keyed by the data it is made
    from (:func:`_suite_data`; :mod:`rclverify.report.fragments`): the same
    text, without building and serialising the XML of unchanged nodes."""
    typed, report = _both(report)
    if fragments is None or not typed.nodes:
        root = junit_tree(typed)
        ET.indent(root)
        return _DECLARATION + ET.tostring(root, encoding="unicode") + "\n"
    texts: list[str] = []
    totals = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    total_time = 0.0
    for node, data in _suite_data(report):
        def render(node: Mapping[str, Any] = node, data: dict[str, Any] = data) -> str:
            suite, counts, time = _suite(node, data)
            ET.indent(suite, level=1)  # as ET.indent(root) indents a child of the root
            return json.dumps({"xml": ET.tostring(suite, encoding="unicode"), "counts": counts, "time": time})
        piece = json.loads(fragments.text("junit-testsuite", {"node": node, **data}, render))
        texts.append(piece["xml"])
        for k, v in piece["counts"].items():
            totals[k] += v
        total_time += piece["time"]
    from rclverify.report.deadlines import junit_suite  # deferred: start-up (loads rclverify.lang.errors, rclverify.report.deadlines and more only when called)
    from rclverify.report.near_misses import junit_suite as near_misses_suite  # deferred: start-up (only when called)
    from rclverify.report.nodl import junit_suite as nodl_suite  # deferred: start-up (only when called)
    from rclverify.report.design import junit_suite as design_suite  # deferred: start-up (only when called)
    for req in (_requirements_suite(typed), junit_suite(typed, _case, _outcome), _lint_suite(typed),
                near_misses_suite(typed, _case, _outcome), nodl_suite(typed, _case, _outcome),
                design_suite(typed, _case, _outcome)):
        if req is None:
            continue
        ET.indent(req[0], level=1)
        texts.append(ET.tostring(req[0], encoding="unicode"))
        for k, v in req[1].items():
            totals[k] += v
        total_time += req[2]
    root = ET.Element("testsuites", {"name": f"rclverify: {typed.meta.workspace}"})
    for k, v in totals.items():
        root.set(k, str(v))
    root.set("time", f"{total_time:.3f}")
    root.text = _MARK  # the root's tags as ElementTree writes them, around the suites' kept texts
    head, tail = ET.tostring(root, encoding="unicode").rsplit(_MARK, 1)
    return _DECLARATION + head + "\n  " + "\n  ".join(texts) + "\n" + tail + "\n"


#: Stands in for the root's children while its tags are serialised (no escaped text contains it).
_MARK = "\ue000rclverify-junit-suites\ue000"
