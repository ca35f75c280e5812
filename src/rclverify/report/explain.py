"""``rclverify explain ID``: any id an output of rclverify shows, looked up
in the last report.

The ids are those of the terminal (``status``, ``requirements``, the
summary table), the reports and the CI files: requirements (``REQ1``),
nodes (``FlightController``, also ``flight_controller``), guarantees
(``Agent.g3``, ``Agent g3``, ``Agent guarantee 3``), obligations, side
conditions, health findings, diagnoses, the problems ``status`` numbers
(``1``), SARIF rule ids (``RCL-OBL-FAILED``), ROS grounding codes
(``ROS-NODE-NOT-IN-GRAPH``), lint codes (``W-unused-bound``) and the
assurance argument's elements (``G-system``).  An exact id wins; then the
same id up to case, ``_`` and the separator between a node and its
guarantee.  :func:`explain` gives the lines to print, :func:`near_ids` the
closest ids (``difflib``) when nothing matches.

The report is decoded once into its record
(:class:`~rclverify.records.report_record.AssuranceReport`; a JSON object given
is decoded here) and read as the attributes mypy checks: its requirements,
nodes (their guarantees), side conditions, findings, obligations, evidence,
lint, diagnoses and problems.  A requirement check's record is decoded into
:class:`~rclverify.records.requirement_check.RequirementCheckRow`, a ROS
grounding finding into
:class:`~rclverify.records.grounding_findings.GroundingFindingRow`, the SARIF log
into :mod:`.sarif_view`'s runs and the argument's elements into
:class:`~rclverify.report.argument.model.ElementRecord` (files of their own: an
element, rule or result of another shape is left out).  A monitored run's
violations (the monitors' payload) by :class:`~rclverify.records.monitored_run.MonitoredRun`.  A finding, an obligation and a problem are printed by
:mod:`.explain_items`: each field is printed or named in the record's
``INTERNAL_TO["explain"]`` with the reason (tests/records/test_record_shapes.py).
A report that does not decode raises :class:`msgspec.ValidationError` (a
``ValueError``).
"""
from __future__ import annotations

import difflib
import re
from typing import Any, Iterable, Mapping, Sequence

import msgspec

from rclverify.records.grounding_findings import GroundingFindingRow, PlaceRow
from rclverify.records.lint_rows import LintRow
from rclverify.records.node_rows import CulpritOf, GuaranteeRow, NodeRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_rows import RequirementRow
from rclverify.report.argument.model import ElementRecord
from rclverify.report.diagnosis_text import clause_cut, explain_lines as diagnosis_lines, natural_sorted
from rclverify.report.explain_items import (finding_lines, obligation_lines, problem_lines, side_condition_lines,
                                            violation_id_lines, violation_lines)
from rclverify.report.explain_items import requirement_lines as requirement_lines  # rclverify requirements prints it
from rclverify.records.monitored_run import MonitoredRun
from rclverify.records.records import SEVERITY
from rclverify.report.sarif_view import ResultView, RuleView, runs_of

#: At most this many obligations of one guarantee are listed one a line; more are counted.
SHOWN_OBLIGATIONS = 6


def _rank(status: str) -> int:
    return SEVERITY.get(status, SEVERITY["error"])


_GUARANTEE = re.compile(r"^(?P<node>[A-Za-z_]\w*)\s*(?:[.:/#-]\s*|\s+)(?:g|guarantee\s*)(?P<k>\d+)$", re.IGNORECASE)
_PROBLEM = re.compile(r"^(?:problem\s*|p)?(?P<k>\d+)\.?$", re.IGNORECASE)


def _fold(text: str) -> str:
    """An id up to case, ``_``/``-`` and spaces (``battery_monitor`` ~ ``BatteryMonitor``)."""
    return re.sub(r"[\s_-]+", "", str(text)).lower()


def _elements(argument: object) -> dict[str, ElementRecord]:
    """The elements of ``argument`` (the parsed ``reports/argument.json``, or ``None``) by id; an element
    of another shape is left out."""
    out: dict[str, ElementRecord] = {}
    items = argument.get("elements") if isinstance(argument, Mapping) else None
    for e in items if isinstance(items, list) else []:
        try:
            el = msgspec.convert(e, ElementRecord)
        except msgspec.ValidationError:
            continue
        out[el.id] = el
    return out


class _Index:
    """The report's items by id (see the module docstring)."""

    def __init__(self, report: AssuranceReport, sarif: Any = None, argument: Any = None) -> None:
        self.diagnoses = {d.id: d for d in report.diagnoses}
        self.nodes = {n.name: n for n in report.nodes}
        self.requirements = {r.id: r for r in report.requirements}
        self.findings = {f.id: f for f in report.findings}
        self.sides = {x.id: x for x in report.side_conditions}
        self.obligations = {o.id: o for o in report.obligations}
        self.items: dict[str, str] = {}  # id -> what it is, a later kind's winning as in the report's order
        for kind, ids in (("health check", self.findings), ("side condition", self.sides),
                          ("obligation", self.obligations)):
            self.items.update(dict.fromkeys(ids, kind))
        self.evidence = {e.obligation: e for e in report.evidence}
        self.problems = report.problems
        self.ros: dict[str, list[GroundingFindingRow]] = {}  # a grounding finding: ros/ground's record
        for ros_finding in report.grounding.findings if report.grounding is not None else []:
            rf = GroundingFindingRow.of(ros_finding)
            self.ros.setdefault(rf.code, []).append(rf)
        self.lint: dict[str, list[LintRow]] = {}
        for w in report.lint:
            self.lint.setdefault(w.code, []).append(w)
        self.rules: dict[str, RuleView] = {}
        self.results: dict[str, list[ResultView]] = {}
        for run in runs_of(sarif):  # the SARIF log and the argument are optional: of another shape, left out
            for rule in run.rules:
                self.rules[str(rule.id)] = rule
            for res in run.results:
                self.results.setdefault(str(res.rule_id), []).append(res)
        self.argument = _elements(argument)

    def ids(self) -> list[str]:
        """Every id this index answers to, for suggestions."""
        out = list(self.requirements) + list(self.nodes)
        out += [f"{n}.g{g.index}" for n, node in self.nodes.items() for g in node.guarantees]
        out += list(self.diagnoses) + list(self.items) + list(self.rules) + list(self.results)
        out += [f"{ob}#{k}" for ob, e in self.evidence.items() if ob
                for k in range(1, len(MonitoredRun.of(e.monitoring).violations) + 1)]
        out += [c for c in self.ros if c] + [c for c in self.lint if c] + list(self.argument)
        return list(dict.fromkeys(out))

    # -- lookups, exact first ----------------------------------------------------
    def find(self, wanted: str) -> list[str] | None:
        for exact in (True, False):
            for finder in (self._requirement, self._node, self._guarantee, self._item, self._problem,
                           self._rule, self._argument, self._violation):
                lines = finder(wanted, exact)
                if lines is not None:
                    return lines
        return None

    def _match(self, wanted: str, keys: Iterable[str], exact: bool) -> str | None:
        for k in keys:
            if (k == wanted) if exact else (_fold(k) == _fold(wanted)):
                return k
        return None

    def _with_diagnosis(self, key: str, lines: list[str]) -> list[str]:
        d = self.diagnoses.get(key)
        return lines + (["", "diagnosis:"] + diagnosis_lines(d) if d else [])

    def _requirement(self, wanted: str, exact: bool) -> list[str] | None:
        key = self._match(wanted, self.requirements, exact)
        if key is None:
            return None
        first, *rest = requirement_lines(self.requirements[key])
        return self._with_diagnosis(key, [f"requirement {first}", *rest])

    def _node(self, wanted: str, exact: bool) -> list[str] | None:
        key = self._match(wanted, self.nodes, exact)
        return None if key is None else self.node_lines(key)

    def _guarantee(self, wanted: str, exact: bool) -> list[str] | None:
        m = _GUARANTEE.match(wanted.strip())
        if not m:
            return None
        key = self._match(m["node"], self.nodes, exact)
        if key is None:
            return None
        if int(m["k"]) == 0:  # "guarantee 0" of obligation ids (Agent.g0.dafny.contract): the whole contract
            return self.node_lines(key)
        for g in self.nodes[key].guarantees:
            if g.index == int(m["k"]):
                return self.guarantee_lines(key, g)
        return None

    def _item(self, wanted: str, exact: bool) -> list[str] | None:
        key = self._match(wanted, self.diagnoses, exact)  # a diagnosis says all an item row says, and more
        if key is not None:
            return diagnosis_lines(self.diagnoses[key]) + self._violation_ids(key)
        key = self._match(wanted, self.items, exact)
        return None if key is None else self.item_lines(key)

    def _problem(self, wanted: str, exact: bool) -> list[str] | None:
        m = _PROBLEM.match(wanted.strip())
        if not exact or not m or not 1 <= int(m["k"]) <= len(self.problems):
            return None
        return problem_lines(m["k"], self.problems[int(m["k"]) - 1])

    def _rule(self, wanted: str, exact: bool) -> list[str] | None:
        key = self._match(wanted, list(dict.fromkeys(list(self.rules) + list(self.results))), exact)
        if key is not None:
            rule = self.rules.get(key, RuleView())
            results = self.results.get(key, [])
            out = [f"{key} ({rule.name}): {rule.description()}".rstrip(": "),
                   f"  {len(results)} result{'s' if len(results) != 1 else ''} in reports/assurance.sarif"
                   + (":" if results else "")]
            for res in results:
                out.append(f"  {_sarif_place(res)}{clause_cut(_first_line(res.message.text))}")
            return out
        key = self._match(wanted, [c for c in self.ros if c], exact)
        if key is not None:
            return [f"{key}: {len(self.ros[key])} ROS grounding finding(s) (`rclverify ros check`, docs/ros.md):"] + [
                f"  {_place(f.rcl or f.ros)}{f.severity}: {f.message}" for f in self.ros[key]]
        key = self._match(wanted, [c for c in self.lint if c], exact)
        if key is not None:
            return [f"{key}: {len(self.lint[key])} lint warning(s):"] + [
                f"  {w.location}: {w.message}" for w in self.lint[key]]
        return None

    def _argument(self, wanted: str, exact: bool) -> list[str] | None:
        key = self._match(wanted, self.argument, exact)
        if key is None:
            return None
        e = self.argument[key]
        out = [f"{key} [{e.status or '-'}] (argument {e.type})", f"  {e.text}"]
        if e.supported_by:
            out.append("  supported by: " + ", ".join(e.supported_by))
        if e.in_context_of:
            out.append("  in context of: " + ", ".join(e.in_context_of))
        return out

    # -- what is printed ---------------------------------------------------------
    def item_lines(self, key: str) -> list[str]:
        kind, diagnosed = self.items[key], key in self.diagnoses
        if kind == "health check":
            return finding_lines(self.findings[key], diagnosed)
        if kind == "obligation":
            return obligation_lines(self.obligations[key], self.evidence.get(key), self._violation_ids(key),
                                    diagnosed)
        return side_condition_lines(key, self.sides[key], diagnosed)

    def _violation_ids(self, key: str) -> list[str]:
        """The lines naming every violation a monitored run of obligation ``key`` kept."""
        return violation_id_lines(key, self._monitoring(key))

    def _monitoring(self, key: str) -> MonitoredRun:
        """The monitored run of obligation ``key``'s evidence (backends/monitors), empty without."""
        ev = self.evidence.get(key)
        return MonitoredRun.of(ev.monitoring if ev is not None else {})

    def _violation(self, wanted: str, exact: bool) -> list[str] | None:
        """``OBLIGATION#N``: the N-th violation a monitored run kept (1-based)."""
        ob, sep, n = wanted.strip().rpartition("#")
        if not sep or not n.isdigit():
            return None
        key = self._match(ob, [str(e) for e in self.evidence if e], exact)
        return violation_lines(key, int(n), self._monitoring(key)) if key else None

    def guarantee_lines(self, node: str, g: GuaranteeRow, indent: str = "") -> list[str]:
        k = g.index
        obs = [o for o in self.obligations.values() if o.node == node and o.guarantee == k]
        status = "unverified" if not obs and not g.obligations else g.status  # no obligation covers it
        if g.culprit_of:  # a problem's culprit reads that problem's status (report/culprits.py)
            status = g.status
        out = [f"{indent}{node}.g{k} [{status}] (guarantee {k} of {node}, {g.source})",
               f"{indent}  {g.text}"]
        if not obs and not g.obligations:
            out.append(f"{indent}  evidence: none: no evidence entry of the plan covers it (`unverified`; docs/plan.md)")
        if len(obs) <= SHOWN_OBLIGATIONS:
            out += [f"{indent}  evidence: {o.id} [{o.status}] ({o.backend})" for o in obs]
        else:  # many instances (AJPF's one per waypoint): counted, the bad ones named
            groups: dict[tuple[str, str], int] = {}
            for o in obs:
                groups[(o.status, o.backend)] = groups.get((o.status, o.backend), 0) + 1
            out.append(f"{indent}  evidence: {len(obs)} obligations: " + ", ".join(
                f"{n} {st} ({be})" for (st, be), n in sorted(groups.items(), key=lambda kv: -_rank(kv[0][0]))))
            out += [f"{indent}    {o.id} [{o.status}]" for o in obs if o.status not in ("discharged", "pending")]
        supports = self._supporting(node, k)
        if supports:
            out.append(f"{indent}  supports: {', '.join(supports)}")
        for f in self.findings.values():
            if f.node == node and f.guarantee == k and f.status not in ("ok", "warning"):
                out.append(f"{indent}  health: {f.id} [{f.status}]: {clause_cut(f.message, 300)}")
        problems = [d for d in natural_sorted(list(self.diagnoses)) if d.startswith(f"{node}.g{k}.")]
        if problems:
            out.append(f"{indent}  problems: {', '.join(problems)} (`rclverify explain ID`)")
        out += [f"{indent}  culprit of a problem [{c.status}]: {clause_cut(c.sentence, 300)}" for c in _culprit_of(g)]
        return out

    def _supporting(self, node: str, k: int) -> list[str]:
        """The requirements traced to guarantee ``k`` of ``node``, once per trace."""
        out: list[str] = []
        r: RequirementRow
        for r in self.requirements.values():
            out += [r.id for s in r.support if s.node == node and s.guarantee == k]
        return out

    def node_lines(self, node: str) -> list[str]:
        n: NodeRow = self.nodes[node]
        out = [f"{node} [{n.status}] (node, {n.source})"]
        for label, vs in (("inputs", n.inputs), ("outputs", n.outputs)):
            if vs:
                out.append(f"  {label}: " + ", ".join(f"{v.name} : {v.type}" for v in vs))
        out += [f"  assumption: {a.text}  ({a.source})" for a in n.assumptions]
        whole = [o for o in self.obligations.values() if o.node == node and o.guarantee == 0]
        out += [f"  evidence for the whole contract: {o.id} [{o.status}] ({o.backend})" for o in whole]
        for g in n.guarantees:
            out += self.guarantee_lines(node, g, "  ")
        sides = [x for x in self.sides.values() if x.node == node]
        if sides:
            proved = sum(x.status == "discharged" for x in sides)
            out.append(f"  side conditions: {proved}/{len(sides)} proved"
                       + "".join(f"; {x.id} [{x.status}]" for x in sides if x.status != "discharged"))
        health = [f for f in self.findings.values() if f.node == node]
        bad = [f for f in health if f.status not in ("ok", "warning")]
        if health:
            out.append(f"  health: {len(health) - len(bad)}/{len(health)} ok" + "".join(f"; {f.id} [{f.status}]" for f in bad))
        problems = [d for d in natural_sorted(list(self.diagnoses)) if d.split(".", 1)[0] == node]
        out.append(f"  problems: {', '.join(problems)} (`rclverify explain ID`)" if problems else "  problems: none")
        out += [f"  culprit of a problem [{c.status}]: {clause_cut(c.sentence, 300)}"
                for c in _culprit_of(n)]  # report/culprits.py
        for f in (g for fs in self.ros.values() for g in fs):
            if f.node == node:
                out.append(f"  ROS grounding {f.severity}: {f.message} ({f.code})")
        return out


def _culprit_of(item: NodeRow | GuaranteeRow) -> list[CulpritOf]:
    """The problems ``item`` is the culprit of (report/culprits.py), none when the pass left it unset."""
    return [] if item.culprit_of is msgspec.UNSET else item.culprit_of


def _place(at: PlaceRow | None) -> str:
    return f"{at.text()}: " if at is not None and at.file else ""


def _sarif_place(res: ResultView) -> str:
    place = res.place()
    return f"{place[0]}:{place[1].start_line}:{place[1].start_column}: " if place else ""


def _first_line(text: str) -> str:
    return str(text).strip().splitlines()[0] if str(text).strip() else ""


def explain(report: AssuranceReport | Mapping[str, Any], wanted: str, sarif: Any = None,
            argument: Any = None) -> list[str] | None:
    """The lines ``rclverify explain wanted`` prints from ``report`` (the
    decoded report, or its JSON object as :mod:`rclverify.report.lastrun`
    reads it, decoded here), the parsed ``reports/assurance.sarif`` and
    ``reports/argument.json`` (either may be ``None``); ``None`` when no id
    matches.  Raises :class:`msgspec.ValidationError` for a report that does
    not decode."""
    return _Index(AssuranceReport.of(report), sarif, argument).find(wanted)


def near_ids(report: AssuranceReport | Mapping[str, Any], wanted: str, sarif: Any = None, argument: Any = None,
             n: int = 5) -> list[str]:
    """At most ``n`` ids of ``report`` (as :func:`explain` takes it) close to
    ``wanted``: ``difflib``'s closest (case-folded), then those containing it."""
    ids = _Index(AssuranceReport.of(report), sarif, argument).ids()
    folded: dict[str, str] = {}
    for i in ids:
        folded.setdefault(i.lower(), i)
    close = [folded[c] for c in difflib.get_close_matches(wanted.lower(), list(folded), n=n, cutoff=0.6)]
    contains = [i for i in ids if wanted and _fold(wanted) in _fold(i)]
    return list(dict.fromkeys(close + contains))[:n]


def id_kinds(report: AssuranceReport | Mapping[str, Any]) -> str:
    """A few ids of each kind of ``report`` (as :func:`explain` takes it), for the message when nothing
    matches."""
    typed = AssuranceReport.of(report)
    reqs = [r.id for r in typed.requirements]
    nodes = [n.name for n in typed.nodes]
    parts: list[tuple[str, Sequence[str]]] = [("requirements", reqs), ("nodes", nodes)]
    if nodes and typed.nodes[0].guarantees:
        parts.append(("guarantees", [f"{nodes[0]}.g1"]))
    parts.append(("problems", natural_sorted([d.id for d in typed.diagnoses])))
    shown = [f"{what} {', '.join(list(xs)[:4])}{', ...' if len(xs) > 4 else ''}" for what, xs in parts if xs]
    return "; ".join(shown)
