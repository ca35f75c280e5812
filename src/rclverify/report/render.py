"""Render the assurance report (HTML, Markdown, JSON) from the report dict.

The report dict is the plain, JSON-serialisable roll-up of the pipeline
(system model, calculus, contract health, obligations, evidence) that traces
requirement -> node -> guarantee -> obligation -> evidence (shared design,
"Evidence"; the paper's five steps, lines 368-437).  This module does no
verification: it lays that dict out so that a genuine problem (a failed,
erroneous, stale or inconclusive item, a refuted side condition, a contract
health problem) comes first and cannot be missed.

Templates: ``templates/assurance.html.j2`` (autoescaped) and
``templates/assurance.md.j2`` (not autoescaped; the ``md``/``code`` filters
escape Markdown).  Output is deterministic: nothing in it depends on the time
of rendering; evidence records show their own start times.
"""
from __future__ import annotations

import re
from collections import defaultdict
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence, TypeVar
from urllib.parse import quote

import jinja2
from markupsafe import Markup, escape

from rclverify.records.records import SEVERITY
from rclverify.records.published import write_published
from rclverify.records.store import dumps
from rclverify.core.cache.memo import last_call
from rclverify.report import diagram
from rclverify.report.fragments import FragmentCache, cached_dumps
from rclverify.report.culprits import culprit_nodes
from rclverify.report.problems import group_problems
from rclverify.report import htmlfilters
from rclverify.report.textfmt import FOLD_CHARS, breakable, formula_html, formula_lines, natural_key, natural_sorted, natural_within

_T = TypeVar("_T")

#: Top-level keys every report dict carries.
REPORT_KEYS: tuple[str, ...] = (
    "meta", "summary", "system", "requirements", "nodes", "side_conditions",
    "derived_properties", "findings", "obligations", "evidence",
    "environment_assumptions", "pending", "lint",
)

#: Status word -> badge style.  Evidence statuses map to themselves; contract
#: health and solver words map to the evidence status they stand for.
STATUS_STYLE: Mapping[str, str] = {
    "discharged": "discharged",
    "pending": "pending",
    "unverified": "unverified",
    "inconclusive": "inconclusive",
    "stale": "stale",
    "error": "error",
    "failed": "failed",
    "ok": "discharged",
    "problem": "failed",
    "proved": "discharged",
    "refuted": "failed",
    "unknown": "inconclusive",
    # derivation status of a derived property (report/build.py)
    "derived": "discharged",
    "not derived": "failed",
    "undecided": "inconclusive",
    "warning": "warning",  # a health warning: its own colour, never a pass (report/severity.py)
}

#: Severity of a status word for ordering the attention list (larger is
#: worse).  A word outside the vocabulary ranks as an error: the report cannot
#: vouch for what it does not understand.
_RANK: Mapping[str, int] = {**SEVERITY, "ok": 0, "proved": 0, "problem": SEVERITY["failed"],
                            "refuted": SEVERITY["failed"], "unknown": SEVERITY["inconclusive"], "derived": 0,
                            "not derived": SEVERITY["failed"], "undecided": SEVERITY["inconclusive"], "warning": 1}
_UNKNOWN_RANK = SEVERITY["error"]

#: Marker shown in Markdown next to a status (no colours there).
_MD_MARK: Mapping[str, str] = {
    "discharged": "\u2705",
    "pending": "\u23f3",
    "unverified": "\u2754",
    "inconclusive": "\u26a0\ufe0f",
    "stale": "\U0001f7e3",
    "error": "\u26d4",
    "failed": "\u274c",
}

#: Order in which status counts are listed: worst first, then any other key.
_COUNT_ORDER = sorted(SEVERITY, key=lambda s: -SEVERITY[s])


def rank(status: str) -> int:
    """Severity of ``status`` (0 = fine ... ``SEVERITY["failed"]`` = failed/problem)."""
    return _RANK.get(status, _UNKNOWN_RANK)


def style(status: str) -> str:
    """CSS class suffix for ``status`` (``other`` for an unknown word)."""
    return STATUS_STYLE.get(status, "other")


# ---------------------------------------------------------------------------
# filters


_ANCHOR_BAD = re.compile(r"[^A-Za-z0-9_.\-]")


def anchor(*parts: Any) -> str:
    """A fragment id built from ``parts`` joined by ``-``.

    Characters other than letters, digits, ``_ . -`` are hex-encoded as
    ``_xx``, so any user text gives a valid, quote-free HTML id.
    """
    text = "-".join(str(p) for p in parts)
    return _ANCHOR_BAD.sub(lambda m: "".join(f"_{b:02x}" for b in m.group(0).encode("utf-8")), text)


def html_badge(status: Any) -> Markup:
    """``<span class="badge st-...">status</span>`` (status text escaped)."""
    s = str(status)
    return Markup('<span class="badge st-%s">%s</span>') % (style(s), escape(s))


_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>|&#])")
_WS = re.compile(r"\s*[\r\n]+\s*")


def md_text(value: Any) -> str:
    """Escape ``value`` for inline Markdown (also inside a table cell).

    Markdown punctuation, ``<``, ``>``, ``&`` and ``|`` are backslash-escaped,
    so no HTML or table structure can come from user text; line breaks
    become spaces.
    """
    return _MD_SPECIAL.sub(r"\\\1", _WS.sub(" ", str(value)).strip())


def md_code(value: Any, cell: bool = True) -> str:
    """``value`` as an inline code span.

    The fence is longer than any backtick run inside; with ``cell`` (the
    default) ``|`` is escaped so the span can sit in a table cell.  An empty
    value gives ``''``.
    """
    text = _WS.sub(" ", str(value)).strip()
    if not text:
        return ""
    runs = [len(m) for m in re.findall(r"`+", text)]
    fence = "`" * (max(runs, default=0) + 1)
    if text.startswith("`") or text.endswith("`"):
        text = f" {text} "
    if cell:
        text = text.replace("|", "\\|")
    return f"{fence}{text}{fence}"


def md_fence(value: Any, lang: str = "") -> str:
    """``value`` as a fenced code block (fence longer than any backtick run)."""
    text = str(value).rstrip("\n")
    runs = [len(m) for m in re.findall(r"`{3,}", text)]
    fence = "`" * max(3, max(runs, default=0) + 1)
    return f"{fence}{lang}\n{text}\n{fence}"


def md_badge(status: Any) -> str:
    """A status for Markdown: a marker and the word, bold unless fine."""
    s = str(status)
    mark = _MD_MARK.get(style(s), "\u2753")
    word = md_text(s)
    return f"{mark} {word}" if rank(s) == 0 else f"{mark} **{word}**"


def seconds(value: Any) -> str:
    """A duration in seconds as ``'1.23 s'`` (``'-'`` when absent)."""
    if value is None or value == "":
        return "-"
    return f"{float(value):.2f} s"


def comment_safe(value: Any) -> str:
    """Text safe inside an HTML comment (no ``--``, one line)."""
    text = _WS.sub(" ", str(value))
    while "--" in text:
        text = text.replace("--", "- -")
    return text


def link_maker(prefix: str) -> Callable[[str], str]:
    """Return a function mapping a workspace-relative path to an href.

    ``prefix`` is the path from the report's directory to the workspace root
    (``'../'`` for the standard ``reports/`` folder).  The path is
    percent-encoded, so ``:`` cannot start a URL scheme.
    """
    def href(path: str) -> str:
        return prefix + quote(str(path), safe="/._-~")
    return href


#: Longest model value shown in the reports (characters); the JSON report and
#: the artifacts keep every value whole.
CLIP_CHARS = 2000


def clip(value: Any, limit: int = CLIP_CHARS) -> str:
    """``str(value)``, cut to ``limit`` characters with a note of how much
    was left out: a function-table model of a nested quantifier can run to
    hundreds of thousands of characters, which no reader scrolls through."""
    text = str(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit]} ... ({len(text) - limit} more characters in the JSON report)"


def model_text(model: Mapping[str, Any] | None) -> str:
    """``name = value, ...`` of a model or counterexample, sorted by name,
    each value clipped (:func:`clip`); ``""`` for none.  For the one-line
    messages of SARIF and JUnit."""
    return ", ".join(f"{k} = {clip(v)}" for k, v in sorted((model or {}).items()))


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    """The report's jinja2 environment.

    ``*.html.j2`` templates are autoescaped, ``*.md.j2``/``*.dot.j2`` are
    not; undefined names raise (``StrictUndefined``).
    """
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("rclverify.report", "templates"),
        autoescape=jinja2.select_autoescape(
            enabled_extensions=("html.j2", "html"),
            disabled_extensions=("md.j2", "dot.j2"),
            default_for_string=True,
            default=True,
        ),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters.update(
        anchor=anchor, badge=html_badge, md=md_text, code=md_code, fence=md_fence,
        mdbadge=md_badge, secs=seconds, comment_safe=comment_safe, style=style, clip=clip,
        formula=formula_html, lines=formula_lines, wbr=breakable,
    )
    env.globals.update(anchor=anchor, rank=rank)
    htmlfilters.register(env)  # prose, natsort, readable_svg, reqbadges, latex_frame
    return env


def use_bytecode_cache(directory: Path | None) -> None:
    """Keep the report's compiled templates in ``directory`` (jinja2's
    ``FileSystemBytecodeCache``, keyed by template name and source checksum;
    ``None``: compile in memory only).  Compiling the report's templates is
    about 0.3 s of every report run.  The files are code: the report run
    keeps them in the user's cache, never in a workspace
    (:func:`rclverify.core.cache.keys.user_cache_dir`).  Raises ``OSError`` when
    ``directory`` cannot be created."""
    if directory is None:
        environment().bytecode_cache = None
        return
    Path(directory).mkdir(parents=True, exist_ok=True)
    environment().bytecode_cache = jinja2.FileSystemBytecodeCache(str(directory))


# ---------------------------------------------------------------------------
# view model


def validate(report: Mapping[str, Any]) -> None:
    """Check the top-level shape of ``report``.

    Raises ``ValueError`` naming every missing top-level key (the templates
    themselves raise ``jinja2.UndefinedError`` for a missing inner key).
    """
    missing = [k for k in REPORT_KEYS if k not in report]
    if missing:
        raise ValueError("report dict lacks key(s): " + ", ".join(missing))


def _by(items: Sequence[Mapping[str, Any]], key: str) -> dict[str, list[Mapping[str, Any]]]:
    out: dict[str, list[Mapping[str, Any]]] = defaultdict(list)
    for it in items:
        out[str(it[key])].append(it)
    return out


def _attention(report: Mapping[str, Any], ev_anchor: Sequence[str]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Items needing attention: (problems, outstanding).

    Problems are everything worse than pending (failed, error, stale,
    inconclusive evidence; refuted or undecided side conditions; contract
    health problems; derived properties that do not hold; lint errors);
    outstanding are the pending items with their reason.  Each item is
    ``{"status", "kind", "ref", "anchor", "where", "message", "formula"}``
    (``formula`` is RCL text to show as code, or ''); both lists
    are sorted worst first, then by kind and reference.
    """
    items: list[dict[str, Any]] = []

    def add(status: str, kind: str, ref: str, anchor_id: str, where: str, message: str,
            formula: str = "") -> None:
        items.append({"status": status, "kind": kind, "ref": ref, "anchor": anchor_id,
                      "where": where, "message": message, "formula": formula})

    reasons: dict[str, list[str]] = defaultdict(list)
    for p in report["pending"]:
        reasons[str(p["obligation"])].append(str(p["reason"]))
    evidenced: set[str] = set()
    for ev, aid in zip(report["evidence"], ev_anchor):
        ob = str(ev["obligation"])
        evidenced.add(ob)
        if rank(ev["status"]) == 0:
            continue
        msg = str(ev["explanation"])
        if ev["status"] == "pending" and reasons.get(ob):
            msg = " ".join(dict.fromkeys([*reasons[ob], msg] if msg else reasons[ob]))
        add(ev["status"], "evidence", ob, aid, f"{ev['backend']} ({ev['kind']})", msg)
    for p in report["pending"]:
        ob = str(p["obligation"])
        if ob not in evidenced:
            add("pending", "obligation", ob, anchor("ob", ob), str(p["backend"]), str(p["reason"]))
            evidenced.add(ob)
    for o in report["obligations"]:
        if o["id"] not in evidenced and rank(o["status"]) > 0:
            add(o["status"], "obligation", o["id"], anchor("ob", o["id"]), str(o["backend"]),
                "No evidence record for this obligation.")
    for u in report.get("unverified") or ():  # a guarantee no obligation covers (report/unverified.py)
        add(str(u["status"]), "guarantee", str(u["id"]), anchor("g", u["node"], u["guarantee"]), str(u["source"]),
            f"Unverified: {u['reason']}.")
    for sc in report["side_conditions"]:
        if rank(sc["status"]) > 0:
            add(sc["status"], "side condition", sc["id"], anchor("sc", sc["id"]),
                f"{sc['node']}, {sc['rule']}, {sc['source']}",
                str(sc["explanation"]) or "Assumption conjunct not established:", str(sc["conjunct"]))
    for f in report["findings"]:
        if rank(f["status"]) > 0 and not f.get("acknowledged"):  # an accepted risk is listed with its reason
            where = str(f["node"]) + (f", guarantee {f['guarantee']}" if f["guarantee"] is not None else "")
            msg = str(f["message"]) + (f" {f['explanation']}" if f["explanation"] else "")
            add(f["status"], f"contract health: {f['check']}", f["id"], anchor("finding", f["id"]), where, msg)
    for d in report["derived_properties"]:
        if rank(d["status"]) > SEVERITY["pending"]:
            add(d["status"], "derived property", d["node"], anchor("derived", d["node"]),
                ", ".join(d["rules"]), f"Derived property {d.get('derivation', 'not established')} "
                "(a side condition of its cone is not discharged):", str(d["property"]))
    for a in report.get("acknowledgements") or ():  # a stale or refused acknowledgement (model/plan/acknowledged.py)
        if a.get("status") != "ok":
            add(str(a["status"]), "acknowledgement", str(a["warning"]), "acknowledged", str(a["at"]), str(a["message"]))
    for k, lint in enumerate(report["lint"]):
        if str(lint["severity"]).lower() == "error":
            add("error", "lint", str(lint["location"]), anchor("lint", k + 1), str(lint["location"]),
                str(lint["message"]))

    kind_order = {"evidence": 0, "obligation": 1, "guarantee": 1, "side condition": 2, "derived property": 4, "lint": 5}
    items.sort(key=lambda it: (-rank(it["status"]), kind_order.get(it["kind"], 3), it["kind"], natural_key(it["ref"])))
    problems = [it for it in items if rank(it["status"]) > SEVERITY["pending"]]
    outstanding = [it for it in items if rank(it["status"]) <= SEVERITY["pending"]]
    return problems, outstanding


_NUMBERS = re.compile(r"\d+")


def group_items(items: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Attention items grouped when they say the same thing: equal status,
    kind and backend (``where``), and a message that is equal once its
    numbers are left out (39 AJPF instances pending for one reason are one
    group).  Each group is ``{"status", "kind", "where", "message" (the
    first item's), "items" (in order)}``; groups keep the order of their
    first items."""
    groups: dict[tuple[str, str, str, str], dict[str, Any]] = {}
    for it in items:
        key = (it["status"], it["kind"], it["where"], _NUMBERS.sub("#", it["message"]))
        g = groups.get(key)
        if g is None:
            g = groups[key] = {"status": it["status"], "kind": it["kind"], "where": it["where"],
                               "message": it["message"], "items": []}
        g["items"].append(it)
    return list(groups.values())


def evidence_anchors(report: Mapping[str, Any]) -> list[str]:
    """One fragment id per evidence record of ``report``, in order:
    ``ev-<obligation>``, then ``ev-<obligation>-2`` ... for further records
    of the same obligation."""
    seen: dict[str, int] = defaultdict(int)
    out = []
    for ev in report["evidence"]:
        ob = str(ev["obligation"])
        seen[ob] += 1
        out.append(anchor("ev", ob) if seen[ob] == 1 else anchor("ev", ob, seen[ob]))
    return out


def problem_items(report: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The attention items of ``report`` that are problems (worse than
    pending), worst first (see :func:`_attention`)."""
    return _attention(report, evidence_anchors(report))[0]


def problem_groups(report: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The report's problems grouped by root cause
    (:func:`rclverify.report.problems.group_problems`): the report dict's
    ``problems`` when it has them, else computed from ``report``."""
    if report.get("problems") is not None:
        return list(report["problems"])
    return group_problems(report, problem_items(report), anchor)


#: The techniques of the dashboard's columns, in order: contract health, the
#: calculus' side conditions, then the backends (docs/reading-the-report.md).
#: A backend outside this list gets a column after them when it has evidence.
TECHNIQUES: tuple[str, ...] = ("health", "side conditions", "hoare", "dafny", "ajpf", "property_tests",
                               "monitors", "experiment", "review")


#: A contract health status as the evidence status the dashboard ranks it by.
#: A warning stays ``warning`` (ranked with pending): it changes no node's
#: status (report/build.py) but it is no pass either; it fails ``--strict``
#: as in every other output (report/severity.py).
_HEALTH_AS: Mapping[str, str] = {"ok": "discharged", "problem": "failed", "unknown": "inconclusive"}


def dashboard(report: Mapping[str, Any], evidence_of: Mapping[str, Sequence[tuple[str, Any]]],
              groups: Sequence[Mapping[str, Any]] | None = None) -> dict[str, Any]:
    """The dashboard's matrix of nodes (rows) against techniques (columns).

    Each cell is the WORST status of the node's items of that technique
    (evidence severity: failed > error > stale > inconclusive > pending >
    discharged, :data:`rclverify.records.records.SEVERITY`): for a backend,
    the statuses of the node's obligations of that backend (an obligation's
    status is that of its evidence, pending when it has none); for
    ``no evidence`` (only when there is one), the node's guarantees no
    obligation covers (``unverified``); for
    ``health``, the node's contract health checks (ok counts as
    discharged, a problem as failed, unknown as inconclusive); for ``side
    conditions``, the side conditions the node's assumptions give rise to.
    A cell is ``None`` when the node has no item of that technique, else
    ``{"status", "worst" (how many items have it), "total", "counts"
    ([(status, n)] worst first), "anchor"}``: ``anchor`` is the fragment id
    of the first item with the worst status (its first evidence record,
    else its obligation row; the health finding; the side condition).
    Returns ``{"columns": [technique], "rows": [{"node", "status",
    "cells": [cell], "culprit" (a problem's culprit is its guarantee or
    contract, :func:`culprit_nodes`)}]}``."""
    items: dict[tuple[str, str], list[tuple[str, str]]] = defaultdict(list)
    for o in report["obligations"]:
        evs = evidence_of.get(str(o["id"]), [])
        items[(str(o["node"]), str(o["backend"]))].append(
            (str(o["status"]), evs[0][0] if evs else anchor("ob", o["id"])))
    for f in report["findings"]:
        items[(str(f["node"]), "health")].append((_HEALTH_AS.get(str(f["status"]), str(f["status"])),
                                                  anchor("finding", f["id"])))
    for sc in report["side_conditions"]:
        items[(str(sc["node"]), "side conditions")].append((str(sc["status"]), anchor("sc", sc["id"])))
    for u in report.get("unverified") or ():  # no obligation at all: a column of its own, after the techniques
        items[(str(u["node"]), "no evidence")].append((str(u["status"]), anchor("g", u["node"], u["guarantee"])))
    culprits = culprit_nodes(groups if groups is not None else report.get("problems") or ())
    extra = sorted({b for _, b in items} - set(TECHNIQUES) - {"no evidence"})
    extra += ["no evidence"] if any(b == "no evidence" for _, b in items) else []
    columns = [*TECHNIQUES, *extra]
    rows = []
    for n in report["nodes"]:
        name = str(n["name"])
        cells: list[dict[str, Any] | None] = []
        for col in columns:
            got = items.get((name, col))
            if not got:
                cells.append(None)
                continue
            worst_rank = max(rank(st) for st, _ in got)
            first = next((st, a) for st, a in got if rank(st) == worst_rank)
            tally: dict[str, int] = defaultdict(int)
            for st, _ in got:
                tally[st] += 1
            counts = sorted(tally.items(), key=lambda kv: (-rank(kv[0]), kv[0]))
            cells.append({"status": first[0], "worst": tally[first[0]], "total": len(got), "counts": counts,
                          "anchor": first[1]})
        rows.append({"node": name, "status": n["status"], "cells": cells, "culprit": name in culprits})
    return {"columns": columns, "rows": rows}




def view(report: Mapping[str, Any]) -> dict[str, Any]:
    """Derived lookups the templates need (pure function of ``report``).

    Keys: ``dashboard`` (:func:`dashboard`), ``problem_groups`` (the
    problems grouped by root cause, :func:`problem_groups`), ``diagnosis``
    (diagnosis id -> record), ``counts`` (``[(status, n)]`` worst first), ``problems`` and
    ``outstanding`` (see :func:`_attention`), ``unmet_requirements``,
    ``ev_anchor`` (one fragment id per evidence record, in order),
    ``evidence_of`` (obligation id -> ``[(anchor, record)]``), ``obligation``
    (id -> obligation), ``trace`` (requirement rows with ``rowspan`` and the
    evidence of each supporting obligation), ``sections`` (per node: the node,
    its rule instances/derived property, side conditions, findings and
    ``ob_status``, the status of each obligation its guarantees list),
    ``finding_runs``, ``obligation_runs`` (rows ``{"obligation", "evidence":
    [anchor]}``) and ``evidence_runs`` (``{"anchor", "record"}``): the rows of
    the health table, the obligations table and the evidence records, in
    report order, cut into runs of one node each (:func:`runs`).
    """
    validate(report)
    ev_anchor = evidence_anchors(report)
    evidence_of: dict[str, list[tuple[str, Mapping[str, Any]]]] = defaultdict(list)
    for aid, ev in zip(ev_anchor, report["evidence"]):
        evidence_of[str(ev["obligation"])].append((aid, ev))
    obligation = {str(o["id"]): o for o in report["obligations"]}

    counts_in = report["summary"]["counts"]
    counts = [(s, counts_in[s]) for s in _COUNT_ORDER if s in counts_in]
    counts += [(s, counts_in[s]) for s in sorted(counts_in) if s not in SEVERITY]

    trace = []
    for req in report["requirements"]:
        rows = []
        for sup in req["support"]:
            obs = []
            for oid in sup["obligations"]:
                o = obligation.get(str(oid))
                obs.append({
                    "id": oid,
                    "known": o is not None,
                    "status": o["status"] if o is not None else "pending",
                    "backend": o["backend"] if o is not None else "",
                    "evidence": evidence_of.get(str(oid), []),
                })
            rows.append({"support": sup, "obligations": obs})
        trace.append({"req": req, "rows": rows, "rowspan": max(1, len(rows))})

    derived = _by(report["derived_properties"], "node")
    sides = _by(natural_sorted(report["side_conditions"], key=lambda sc: sc["id"]), "node")
    findings = _by(natural_sorted(report["findings"], key=lambda f: f["id"]), "node")
    sections = []
    named = [str(n["name"]) for n in report["nodes"]]
    for n in report["nodes"]:
        name = str(n["name"])
        sections.append({"name": name, "node": n, "derived": derived.get(name, []),
                         "side": sides.get(name, []), "findings": findings.get(name, [])})
    for name in sorted((set(derived) | set(sides)) - set(named)):
        sections.append({"name": name, "node": None, "derived": derived.get(name, []),
                         "side": sides.get(name, []), "findings": findings.get(name, [])})

    for sec in sections:
        ids = [str(oid) for g in (sec["node"] or {}).get("guarantees", []) for oid in g["obligations"]]
        sec["ob_status"] = {oid: obligation[oid]["status"] for oid in ids if oid in obligation}

    def node_of_evidence(item: Mapping[str, Any]) -> str:
        o = obligation.get(str(item["record"]["obligation"]))
        return str(o["node"]) if o is not None else ""

    problems, outstanding = _attention(report, ev_anchor)
    outstanding_groups = group_items(outstanding)
    pending_groups: dict[tuple[str, str], dict[str, Any]] = {}  # the same reason, numbers aside: one row
    for p in natural_sorted(report["pending"], key=lambda p: p["obligation"]):
        key = (str(p["backend"]), _NUMBERS.sub("#", str(p["reason"])))
        pending_groups.setdefault(key, {"backend": p["backend"], "reason": p["reason"], "items": []})["items"].append(p)
    unmet = [r for r in report["requirements"] if rank(r["status"]) > 0]
    groups = (list(report["problems"]) if report.get("problems") is not None
              else group_problems(report, problems, anchor))
    return {
        "dashboard": dashboard(report, evidence_of, groups), "problem_groups": groups,
        "diagnosis": {str(d["id"]): d for d in report.get("diagnoses") or []},
        "counts": counts, "problems": problems, "outstanding": outstanding, "outstanding_groups": outstanding_groups,
        "pending_groups": list(pending_groups.values()),
        "unmet_requirements": unmet, "ev_anchor": ev_anchor, "evidence_of": evidence_of,
        "obligation": obligation, "trace": trace, "sections": sections,
        "lint_errors": sum(1 for x in report["lint"] if str(x["severity"]).lower() == "error"),
        "finding_runs": runs(natural_within(report["findings"], lambda f: str(f["node"]), lambda f: f["id"]),
                             lambda f: str(f["node"])),
        "obligation_runs": runs([{"obligation": o, "evidence": [aid for aid, _ in evidence_of.get(str(o["id"]), [])]}
                                 for o in natural_within(report["obligations"], lambda o: str(o["node"]),
                                                         lambda o: o["id"])], lambda row: str(row["obligation"]["node"])),
        "evidence_runs": runs(natural_within([{"anchor": aid, "record": ev} for aid, ev in zip(ev_anchor, report["evidence"])],
                                             node_of_evidence, lambda it: it["record"]["obligation"]), node_of_evidence),
    }


def runs(items: Sequence[_T], key: Callable[[_T], str]) -> list[list[_T]]:
    """``items`` cut into runs of consecutive items with equal ``key``, in
    order (the report lists rows node by node, so a run is usually one
    node's rows: the unit a report piece is rendered and kept by)."""
    out: list[list[_T]] = []
    last: object = object()
    for it in items:
        k = key(it)
        if not out or k != last:
            out.append([])
            last = k
        out[-1].append(it)
    return out


def _header(report: Mapping[str, Any]) -> str:
    meta = report["meta"]
    contracts = ", ".join(str(c) for c in meta["contracts"])
    return (f"assurance report of {meta['workspace']} from {meta['plan']} ({contracts}), "
            f"generated by {meta['tool']} {meta['version']}")


def _context(report: Mapping[str, Any], link_prefix: str, fragments: FragmentCache | None) -> dict[str, Any]:
    return {"r": report, "v": view(report), "header": _header(report), "href": link_maker(link_prefix),
            "part": part_renderer(fragments if fragments is not None else FragmentCache(), link_prefix)}


def part_renderer(fragments: FragmentCache, link_prefix: str) -> Callable[..., str]:
    """The templates' ``part(name, **data)``: the text of
    ``templates/parts/<name>.j2`` rendered with ``data`` (and ``href`` for
    ``link_prefix``) and nothing else, taken from ``fragments`` when that
    data was rendered before.  HTML parts come back as ``Markup`` (they are
    escaped inside)."""
    href = link_maker(link_prefix)

    def part(name: str, **data: Any) -> str:
        template = f"parts/{name}.j2"

        def render() -> str:
            return environment().get_template(template).render(**data, href=href)
        text = fragments.text(template, {"data": data, "link_prefix": link_prefix}, render)
        return Markup(text) if name.endswith(".html") else text
    return part


#: Stand-in layout where only the argument's DOT source is shown (Markdown).
_NO_LAYOUT = diagram.Rendering(None, "the Markdown report gives the argument as DOT source")


def _argument(report: Mapping[str, Any], rendering: diagram.Rendering | None,
              fragments: FragmentCache | None) -> dict[str, Any]:
    """The assurance argument's view for the templates (GSN goal structure
    built from ``report``, see :mod:`rclverify.report.argument`); ``rendering`` of
    the system diagram, when given, stands in for its layout too."""
    from rclverify.report.argument.export import argument_view
    return argument_view(report, rendering, fragments)


@last_call  # the HTML report's layout and page both show it
def _system_dot(report: Mapping[str, Any]) -> str:
    """The system diagram with the problems' culprit nodes and the failing connections marked (issue 48)."""
    from rclverify.diagnosis.repairs import link_pairs
    failing = {(p, c) for sc in report.get("side_conditions") or () if sc.get("status") in ("failed", "inconclusive", "error")
               for p, _, c, _ in link_pairs(sc)}
    culprits = culprit_nodes(problem_groups(report))
    return diagram.system_dot(report["system"], title=f"system model of {report['meta']['workspace']}",
                              culprits=culprits, failing=failing)


def render_html(report: Mapping[str, Any], link_prefix: str = "../",
                rendering: diagram.Rendering | None = None, fragments: FragmentCache | None = None,
                system: diagram.Rendering | None = None, argument: diagram.Rendering | None = None) -> str:
    """The assurance report as one self-contained HTML page.

    ``report`` is the report dict (see :data:`REPORT_KEYS`); ``link_prefix``
    the path from the report's directory to the workspace root, prepended to
    the workspace-relative artifact paths it links to.  The system diagram is
    laid out with Graphviz (:func:`diagram.render_dot`) unless ``rendering``
    is given; without Graphviz the page says so and shows the DOT source.
    Every value from the report is HTML-escaped; only the SVG produced by
    ``dot`` is inlined as markup.  ``fragments`` keeps rendered pieces
    between runs (:mod:`rclverify.report.fragments`; the text is the same
    with or without it).  ``system`` and ``argument``, when given, are the
    two layouts already made (:func:`render_all` makes them in threads);
    ``rendering`` stands in for both.  Raises
    ``ValueError`` for a missing top-level key and ``jinja2.UndefinedError``
    for a missing inner key.
    """
    dot = _system_dot(report)
    drawn = rendering if rendering is not None else system if system is not None else diagram.render_dot(dot)
    return environment().get_template("assurance.html.j2").render(
        **_context(report, link_prefix, fragments), dot=dot, svg=drawn.svg, diagram_note=drawn.note,
        argument=_argument(report, rendering if rendering is not None else argument, fragments),
    )


def render_markdown(report: Mapping[str, Any], link_prefix: str = "../", fragments: FragmentCache | None = None) -> str:
    """The assurance report as Markdown (GitHub-flavoured tables).

    Same sections and order as :func:`render_html`; the system diagram is
    given as DOT source.  User text is Markdown-escaped (:func:`md_text`,
    :func:`md_code`).  ``fragments`` and errors as for :func:`render_html`.
    """
    dot = _system_dot(report)
    return environment().get_template("assurance.md.j2").render(**_context(report, link_prefix, fragments), dot=dot,
                                                                 argument=_argument(report, _NO_LAYOUT, fragments))


def render_json(report: Mapping[str, Any], fragments: FragmentCache | None = None) -> str:
    """The report dict as deterministic JSON (sorted keys, indent 2, final newline).

    With ``fragments``, the indented text of each element of the top-level
    lists is kept between runs (:func:`rclverify.report.fragments.cached_dumps`;
    same text).  Raises ``ValueError`` for a missing top-level key and
    ``TypeError`` for a value that is not JSON-serialisable.
    """
    validate(report)
    return dumps(report) if fragments is None else cached_dumps(report, fragments)


#: The report files :func:`render_files` writes, in this order.
REPORT_FILES = ("assurance.html", "assurance.md", "assurance.json")


def render_all(report: Mapping[str, Any], out_dir: Path, link_prefix: str = "../",
               fragments: FragmentCache | None = None) -> list[Path]:
    """Write ``assurance.html``, ``assurance.md`` and ``assurance.json`` to
    ``out_dir`` (:func:`render_files` with every file; same arguments,
    errors and return value)."""
    return render_files(report, out_dir, REPORT_FILES, link_prefix, fragments)


def render_files(report: Mapping[str, Any], out_dir: Path, names: Sequence[str] = REPORT_FILES,
                 link_prefix: str = "../", fragments: FragmentCache | None = None,
                 argument: Callable[[], diagram.Rendering] | None = None) -> list[Path]:
    """Write the report files of :data:`REPORT_FILES` named in ``names`` to ``out_dir``.

    All the texts are rendered before anything is written, so a rendering
    error leaves the previous files untouched; for the HTML, the system
    diagram and the argument are laid out by Graphviz in two threads while
    the other texts are rendered (the layouts are subprocesses); each file
    is then written atomically (and left alone when unchanged).
    ``link_prefix`` as in :func:`render_html`.  ``fragments`` keeps the
    rendered pieces between runs (:mod:`rclverify.report.fragments`; the
    caller saves it); the files are the same with or without it.
    ``argument`` lays the argument out (default
    :func:`rclverify.report.argument.export.argument_layout`).  Returns the paths
    in :data:`REPORT_FILES` order.  Raises
    ``ValueError``/``TypeError``/``jinja2.UndefinedError`` for a malformed
    report and ``OSError`` when ``out_dir`` cannot be written.
    """
    from concurrent.futures import Future, ThreadPoolExecutor

    from rclverify.report.argument.export import argument_layout
    texts = {}
    # The two Graphviz layouts (seconds each on a large system) run as subprocesses beside the
    # other rendering; a thread only waits for its `dot`, so the GIL is not in the way.
    with ThreadPoolExecutor(max_workers=2, thread_name_prefix="rclverify-dot") as pool:
        layouts: tuple[Future[diagram.Rendering], Future[diagram.Rendering]] | None = None
        if "assurance.html" in names:
            layouts = (pool.submit(diagram.render_dot, _system_dot(report)),
                       pool.submit(argument if argument is not None else argument_layout(report, fragments)))
        if "assurance.md" in names:
            texts["assurance.md"] = render_markdown(report, link_prefix, fragments=fragments)
        if "assurance.json" in names:
            texts["assurance.json"] = render_json(report, fragments)
        if layouts is not None:
            texts["assurance.html"] = render_html(report, link_prefix, fragments=fragments,
                                                  system=layouts[0].result(), argument=layouts[1].result())
    paths = []
    for name in REPORT_FILES:
        if name in texts:
            path = Path(out_dir) / name
            write_published(path, texts[name])
            paths.append(path)
    return paths
