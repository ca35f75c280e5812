"""The one-screen summary that ends ``doit verify`` and ``rclverify verify``.

Per node: obligations by status, side conditions proved, contract health,
the node's rolled-up status; a total row; then the requirements, deadlines,
problems by root cause, the ROS grounding's and the NoDL documents' errors
at their ``file:line:col``, the near misses, the warnings answered in the
plan and the clauses a failed ``--strict`` names; the path of the report.
Built from
the report dict of :func:`rclverify.report.build.build_report` with ``rich``
tables.  On a terminal the table has colours; otherwise it is plain ASCII
(no escape codes), so CI logs stay readable.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Iterable, Literal, Mapping, Sequence, TypeVar

if TYPE_CHECKING:  # rich is imported where a table is drawn: doit imports this module on every run
    from rich.table import Table
from rclverify.records.findings import FindingRow
from rclverify.records.node_rows import UnverifiedRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import ProblemRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.shapes import GroundingBrief, NodeSummaryRow, ProblemBrief, SummaryData
from rclverify.records.records import SEVERITY
from rclverify.report.strict import grounding_brief, strict_reasons

#: At most this many node rows (worst first); the rest are summed in one row.
MAX_ROWS = 15

#: A report row that names its node (an obligation, side condition, health finding, unverified guarantee).
_Row = TypeVar("_Row", ObligationRow, SideConditionRow, UnverifiedRow, FindingRow)

#: The counts of a node's summary row that a merged row sums.
_Count = Literal["sc_proved", "sc_total", "health_problems", "health_open", "health_total", "health_warnings"]

_COLOUR = {"discharged": "green", "pending": "yellow", "unverified": "dark_orange", "inconclusive": "yellow",
           "stale": "magenta", "error": "red", "failed": "red"}


def _rank(status: str) -> int:
    return SEVERITY.get(status, SEVERITY["error"])


def node_rows(report: AssuranceReport) -> list[NodeSummaryRow]:
    """One row per node of ``report`` (decoded once): ``{"node", "status", "obligations"
    (status -> count), "sc_proved", "sc_total", "health_problems",
    "health_open", "health_total", "health_warnings", "unverified" (``["g<k>"]``: the node's
    guarantees no obligation covers), "culprit" (its guarantee or contract is a problem's culprit,
    :mod:`.culprits`)}``, worst status first, then report order."""
    def by_node(items: Sequence[_Row]) -> dict[str, list[_Row]]:
        # one pass per kind: a scan of every item per node was quadratic in the system size
        out: dict[str, list[_Row]] = {}
        for it in items:
            out.setdefault(it.node, []).append(it)
        return out
    obligations, sides = by_node(report.obligations), by_node(report.side_conditions)
    findings, unverified = by_node(report.findings), by_node(report.unverified)
    from rclverify.report.culprits import culprit_nodes  # deferred: start-up (loads rclverify.report.culprits only when called)
    blamed = culprit_nodes(report.problems)
    rows: list[NodeSummaryRow] = []
    for k, n in enumerate(report.nodes):
        obs: dict[str, int] = {}
        for o in obligations.get(n.name, []):
            obs[o.status] = obs.get(o.status, 0) + 1
        scs = sides.get(n.name, [])
        fs = findings.get(n.name, [])
        rows.append({"node": n.name, "status": n.status, "obligations": obs, "order": k,
                     "sc_proved": sum(sc.status == "discharged" for sc in scs), "sc_total": len(scs),
                     "health_problems": sum(f.status in ("problem", "error") for f in fs),
                     "health_open": sum(f.status == "inconclusive" for f in fs), "health_total": len(fs),
                     "health_warnings": sum(f.status == "warning" for f in fs),
                     "unverified": [f"g{u.guarantee}" for u in unverified.get(n.name, [])],
                     "culprit": n.name in blamed})
    rows.sort(key=lambda r: (-_rank(r["status"]), r["order"]))
    return rows


def _counts(obs: Mapping[str, int], colour: bool) -> str:
    if not obs:
        return "none"
    parts = []
    for s in sorted(obs, key=lambda s: -_rank(s)):
        text = f"{obs[s]} {s}"
        parts.append(f"[{_COLOUR.get(s, 'red')}]{text}[/]" if colour else text)
    return ", ".join(parts)


def _health(r: NodeSummaryRow) -> str:
    if not r["health_total"]:
        return "-"
    words = []
    if r["health_problems"]:
        words.append(f"{r['health_problems']} problem")
    if r["health_open"]:
        words.append(f"{r['health_open']} undecided")
    warned = int(r.get("health_warnings", 0) or 0)  # a warning fails --strict: never counted as ok (report/severity.py)
    if warned and not words:
        words.append(f"{r['health_total'] - warned} ok")
    if warned:
        words.append(f"{warned} warning{'s' if warned != 1 else ''}")
    return ", ".join(words) or f"{r['health_total']} ok"


def _merge(rows: list[NodeSummaryRow], label: str) -> NodeSummaryRow:
    def total(key: _Count) -> int:
        return sum(int(r.get(key, 0) or 0) for r in rows)
    out: NodeSummaryRow = {
        "node": label, "status": max((r["status"] for r in rows), key=_rank, default="discharged"), "obligations": {},
        "sc_proved": total("sc_proved"), "sc_total": total("sc_total"), "health_problems": total("health_problems"),
        "health_open": total("health_open"), "health_total": total("health_total"),
        "health_warnings": total("health_warnings"),
        "unverified": [f"{r['node']}.{g}" for r in rows for g in r.get("unverified", [])]}
    for r in rows:
        for s, c in r["obligations"].items():
            out["obligations"][s] = out["obligations"].get(s, 0) + c
    return out


def _culprit(c: Mapping[str, Any]) -> str:
    """A root culprit as ``what (file:line:col)``; a program line has only its source."""
    what, source = c.get("what") or "", c.get("source") or ""
    return f"{what} ({source})" if what and source else what or source or "?"


def _problem(g: ProblemRow) -> ProblemBrief:
    """A problem row as the summary keeps it; a consequence says of what (one row per cause, its
    consequences under it)."""
    return {"status": g.status, "sentence": group_sentence(g), "culprits": [_culprit(c) for c in g.culprits],
            "where": g.where,
            "members": [m.id + (f" (a consequence of {', '.join(m.consequence_of)})" if m.consequence_of else "")
                        for m in g.members],
            "repairs": len(g.repairs)}


def summary_data(report: AssuranceReport | Mapping[str, Any]) -> SummaryData:
    """What ``doit verify`` prints at its end, taken from ``report`` (the
    report, or its JSON object: decoded here once into
    :class:`~rclverify.records.report_record.AssuranceReport`, which raises
    :class:`msgspec.ValidationError` for a report of another shape):
    ``{"meta": {"workspace", "strict_ok"}, "summary": the report's summary,
    "rows": node_rows(report), "requirements": [[id, verdict, status], ...],
    "problems": [{"status", "sentence", "culprits": ["what (file:line:col)"],
    "members": [finding ids], "repairs": int}, ...], "unverified", "deadlines",
    "grounding", "nodl", "strict", "acknowledged", "near_misses"}`` (the problems grouped by
    root cause, :mod:`rclverify.report.problems`).  The report task writes it next to the
    report (``artifacts/report/summary.json``), so ``verify`` reads a few
    kilobytes instead of the whole JSON report (6 MB at 1000 nodes)."""
    r = AssuranceReport.of(report)
    from rclverify.report.near_misses import summary_lines  # deferred: start-up (loads rclverify.report.near_misses only when called)
    return {"meta": {"workspace": r.meta.workspace, "strict_ok": r.meta.strict_ok},
            "summary": r.summary.to_json(), "rows": node_rows(r),
            "unverified": [u.id for u in r.unverified],
            "requirements": [[q.id, q.verdict, q.status] for q in r.requirements],
            "deadlines": [[d.requirement, d.verdict, _text(d.total) or "?", d.within or "?", _text(d.evidence_status)]
                          for d in r.deadlines],
            "problems": [_problem(g) for g in r.problems],
            "grounding": grounding_brief(r.grounding), "nodl": _nodl(r), "strict": strict_reasons(r),
            # warnings answered in the plan (model/plan/acknowledged.py): named, so an accepted risk is never silent
            "acknowledged": [f"{m} ({a.at}: {a.reason})" for a in r.acknowledgements if a.status == "ok"
                             for m in a.matched],
            # guarantees held by less than the plan's near-miss threshold (report/near_misses.py)
            "near_misses": summary_lines(r.near_misses)}


def _text(value: object) -> str:
    """A text field that may be unset (``""``) as the summary's cell."""
    return value if isinstance(value, str) else ""


def group_sentence(group: ProblemRow) -> str:
    """The first sentence of a problem group (its row, decoded), whole (:func:`whole_sentence`)."""
    return whole_sentence(group.sentence, [m.sentence for m in group.members])


def whole_sentence(short: str, members: Iterable[str]) -> str:
    """The first sentence of a problem group whose row says ``short``, whole, found among its ``members``'
    sentences: the report's row (report/problems.py) cuts it to a length; the terminal cuts it only at
    a clause boundary (:func:`rclverify.report.diagnosis_text.clause_cut`).  ``short`` when none has it."""
    from rclverify.report.diagnosis_text import whole_first_sentence  # deferred: start-up (loads rclverify.report.diagnosis_text only when called)
    stem = short[:-4] if short.endswith(" ...") else None
    for sentence in members:
        whole = whole_first_sentence(sentence)
        if whole == short or (stem and whole.startswith(stem)):
            return whole
    return short


def _nodl(report: AssuranceReport) -> GroundingBrief | None:
    """The NoDL check as the terminal shows it (:func:`rclverify.report.nodl.terminal_brief`)."""
    if report.nodl is None:
        return None
    from rclverify.report.nodl import terminal_brief  # deferred: start-up (loads rclverify.report.nodl only when NoDL documents were checked)
    return terminal_brief(report.nodl)


def status_text(data: SummaryData) -> list[str]:
    """The overall line and the problems of the summary ``data``
    (:func:`rclverify.report.diagnosis_text.status_lines`), with the ROS grounding
    errors and the NoDL errors (a stale NoDL check too): counted on the overall
    line and listed one a line, each at its file:line:col (they change no
    verdict, docs/ros.md, docs/nodl.md, but fail ``--strict``)."""
    from rclverify.report.diagnosis_text import status_lines  # deferred: start-up (loads rclverify.report.diagnosis_text only when called)
    g, nd = data.get("grounding"), data.get("nodl")
    errors = int(g.get("error", 0) or 0) if g is not None else 0
    nodl_lines = list(nd.get("errors", [])) if nd is not None else []
    nodl_errors = int(nd.get("error", 0) or 0) if nd is not None else 0
    drop = (("Grounding: ",) if errors else ()) + (("NoDL ",) if nodl_lines else ())
    if drop:  # listed below one a line, not as the report's summary problems
        data = {**data, "summary": {**data["summary"], "problems": [
            p for p in data["summary"]["problems"] if not str(p).startswith(drop)]}}
    lines = status_lines(data)
    if errors:
        plural = "s" if errors != 1 else ""
        lines[0] = lines[0].rstrip(".") + f"; {errors} ROS grounding error{plural}."
        lines.append(f"{errors} ROS grounding error{plural}: the contracts do not match the ROS software "
                     f"(no verdict changes; `--strict` fails; `rclverify ros check`, docs/ros.md):")
        lines += [f"  {e}" for e in (g.get("errors", []) if g is not None else [])]
    if nodl_lines:
        plural = "s" if nodl_errors != 1 else ""
        if nodl_errors:
            lines[0] = lines[0].rstrip(".") + f"; {nodl_errors} NoDL error{plural}."
        lines.append(f"{nodl_errors} NoDL error{plural}: the node interface documents disagree with the contracts "
                     f"or each other (no verdict changes; `--strict` fails; `rclverify nodl check`, docs/nodl.md):"
                     if nodl_errors else "NoDL (`--strict` fails; `doit verify` checks the current documents):")
        lines += [f"  {e}" for e in nodl_lines]
    return lines


def summary_table(report: AssuranceReport | SummaryData, colour: bool, rows: list[NodeSummaryRow] | None = None) -> Table:
    """The summary table of ``report`` (the report decoded, or the summary made of one,
    :func:`summary_data`; at most :data:`MAX_ROWS` node rows + total); ``rows`` are its
    :func:`node_rows` when already made (a summary's must be given: ``KeyError`` otherwise)."""
    from rich import box  # deferred: start-up (loads rich only when called)
    from rich.markup import escape  # deferred: start-up (loads rich and more only when called)
    from rich.table import Table  # deferred: start-up (loads rich and more only when called)
    if rows is None:  # a summary's rows are given (print_last_run); a report is made into them
        if not isinstance(report, AssuranceReport):
            raise KeyError("nodes")
        rows = node_rows(report)
    workspace = report.meta.workspace if isinstance(report, AssuranceReport) else report["meta"]["workspace"]
    shown, rest = rows[:MAX_ROWS], rows[MAX_ROWS:]
    if rest:
        shown = shown + [_merge(rest, f"(+{len(rest)} more nodes)")]
    table = Table(title=escape(f"rclverify: {workspace}"), box=box.SIMPLE_HEAD if colour else box.ASCII,
                  show_footer=True, title_justify="left")
    total = _merge(rows, "total")
    cols = [("node", total["node"]), ("status", total["status"]), ("obligations", _counts(total["obligations"], colour)),
            ("side conditions", f"{total['sc_proved']}/{total['sc_total']} proved"), ("health", _health(total))]
    # guarantees no obligation covers: a column only when there are any (report/unverified.py)
    gaps = bool(total["unverified"])
    if gaps:
        cols.append(("unverified", f"{len(total['unverified'])} guarantee{'s' if len(total['unverified']) != 1 else ''}"))
    for head, foot in cols:
        table.add_column(head, footer=foot, overflow="fold", no_wrap=head in ("node", "status"))
    for r in shown:
        st = f"[{_COLOUR.get(r['status'], 'red')}]{r['status']}[/]" if colour else r["status"]
        # a node whose guarantee or contract is a problem's culprit: where the repair goes
        cells = [r["node"] + (" (culprit)" if r.get("culprit") else ""), st, _counts(r["obligations"], colour),
                 f"{r['sc_proved']}/{r['sc_total']} proved" if r["sc_total"] else "-", _health(r)]
        if gaps:
            own = r.get("unverified", [])
            cells.append(", ".join(own) if 0 < len(own) <= 4 else f"{len(own)} guarantees" if own else "-")
        table.add_row(*cells)
    return table


def is_terminal() -> bool:
    """Is the process's standard output a terminal?"""
    out = sys.__stdout__
    return bool(out is not None and out.isatty())


def print_summary(report: AssuranceReport | SummaryData, report_path: str, file: IO[str] | None = None,
                  terminal: bool | None = None, rows: list[NodeSummaryRow] | None = None) -> None:
    """Print the summary table of ``report`` and the report's path to ``file``
    (default: the current ``sys.stdout``).  ``terminal`` (default
    :func:`is_terminal`) selects colours and box drawing; otherwise plain
    ASCII, at most 120 columns wide.  ``rows`` as for :func:`summary_table`."""
    from rich.console import Console  # deferred: start-up (loads rich and more only when called)
    tty = is_terminal() if terminal is None else terminal
    console = Console(file=file or sys.stdout, force_terminal=tty, no_color=not tty, highlight=False,
                      width=None if tty else 120, soft_wrap=False)
    console.print(summary_table(report, tty, rows))
    console.print(f"report: {report_path}", markup=False)


def requirements_line(rows: Sequence[Sequence[str]]) -> str:
    """``requirements: 1 met, 1 refuted (STOP), 1 informal`` from the summary's
    ``[id, verdict, status]`` rows (docs/requirements.md), verdicts in order of
    first appearance; the ids of those that are not met, informal or
    outstanding are named."""
    by: dict[str, list[str]] = {}
    for rid, verdict, _ in rows:
        by.setdefault(verdict or "traced", []).append(rid)
    named = ("refuted", "proved from an inconsistency", "proved vacuously", "inconclusive", "stale", "error")
    return "requirements: " + ", ".join(f"{len(ids)} {v}" + (f" ({', '.join(ids[:5])}{', ...' if len(ids) > 5 else ''})"
                                                            if v in named else "") for v, ids in by.items())


def deadlines_line(rows: Sequence[Sequence[str]]) -> str:
    """``deadlines: STOP proved (250 ms <= 300 ms; evidence of its chain unverified)``
    from the summary's ``[requirement, verdict, chain total, bound, evidence status]``
    rows (rule D3, calculus/deadlines.py; docs/requirements.md)."""
    parts = []
    for rid, verdict, total, within, evidence in rows:
        cmp = "<=" if verdict == "proved" else ">" if verdict == "refuted" else "vs"
        ev = f"; evidence of its chain {evidence}" if evidence and evidence != "discharged" else ""
        parts.append(f"{rid} {verdict} ({total} {cmp} {within}{ev})")
    return "deadlines: " + ", ".join(parts)


def read_summary(root: Path) -> SummaryData:
    """What ``status`` and ``verify`` print, from the workspace ``root``:
    ``artifacts/report/summary.json`` when it is there (of any shape: a
    broken one is an error, not silently replaced), else made from
    ``reports/assurance.json``.  Raises
    :class:`~rclverify.lang.errors.RclError` (one located line) as
    :func:`rclverify.report.lastrun.read_checked` does."""
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.report.lastrun import SUMMARY_SHAPE, SUMMARY_SOURCE_SHAPE, located, read_checked  # deferred: start-up (loads rclverify.lang, rclverify.lang.ast and more only when called)
    from rclverify.records.sealed import read_sealed  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    path = root / Workspace.SUMMARY
    if path.exists():
        # sealed: a summary altered outside rclverify is said so and never shown (docs/integrity.md)
        _, problem = read_sealed(path, "summary record")
        if problem:
            raise located(path, f"{problem}; run `rclverify verify` (or `doit verify`) to write it again")
        data: SummaryData = read_checked(path, SUMMARY_SHAPE, "an rclverify summary")
        return data
    report = read_checked(root / "reports/assurance.json", SUMMARY_SOURCE_SHAPE, "an rclverify report")
    try:
        return summary_data(report)
    except (KeyError, TypeError, AttributeError, ValueError) as exc:  # a deeper field of another shape
        raise located(root / "reports/assurance.json", f"not an rclverify report: cannot summarise it ({exc!r})") from None


def print_last_run(root: Path) -> SummaryData:
    """Print what ``doit verify`` ends with, from the last run's files in the
    workspace ``root``: the overall line and the problems by root cause
    (:func:`rclverify.report.diagnosis_text.status_lines`), the requirements line
    and the summary table.  Read from ``artifacts/report/summary.json``
    (written with the report), else from ``reports/assurance.json``.
    Returns the summary data (:func:`summary_data`).  Raises
    :class:`~rclverify.lang.errors.RclError` (one located line) when neither
    file can be read or the one read is of another shape
    (:mod:`rclverify.report.lastrun`)."""
    data = read_summary(root)
    print("\n".join(status_text(data)))
    if data.get("requirements"):
        print(requirements_line(data["requirements"]))
    if data.get("deadlines"):
        print(deadlines_line(data["deadlines"]))
    acks = list(data.get("acknowledged") or [])
    if acks:
        print(f"accepted risks: {len(acks)} warning{'s' if len(acks) != 1 else ''} acknowledged in the plan: "
              + "; ".join(acks[:3]) + ("; ..." if len(acks) > 3 else ""))
    for line in data.get("near_misses") or ():
        print(line)
    print_summary(data, "reports/assurance.html", rows=data["rows"])
    return data
