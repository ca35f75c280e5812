"""Diagnosis records as terminal text (``rclverify explain``, ``status``)."""
from __future__ import annotations

import re
from typing import Any, Mapping, Sequence

from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.repair_rows import CexTableRow
from rclverify.records.report_record import AssuranceReport


#: Longest diagnosis sentence ``status`` prints whole (``explain`` prints it
#: whole always); a longer one is cut at a clause boundary (:func:`clause_cut`).
SENTENCE = 600


def _natural_key(text: str) -> list[Any]:
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", text)]


def natural_sorted(ids: Sequence[str]) -> list[str]:
    """``ids`` in natural order (``p1 < p2 < p10``)."""
    return sorted(ids, key=_natural_key)


def table_lines(rows: Sequence[CexTableRow], indent: str = "  ") -> list[str]:
    """A counterexample table (:func:`rclverify.diagnosis.table.counterexample_table`, decoded)
    as aligned text: node, variable, value; a function's finite table below it."""
    if not rows:
        return []
    w_node = max(len("node"), *(len(r.node) for r in rows))
    w_var = max(len("variable"), *(len(r.variable) for r in rows))
    out = [f"{indent}{'node':<{w_node}}  {'variable':<{w_var}}  value"]
    for r in rows:
        t = r.table
        if t:
            out.append(f"{indent}{r.node:<{w_node}}  {r.variable:<{w_var}}  function:")
            for args, v in t.rows:
                out.append(f"{indent}{'':<{w_node}}  {'':<{w_var}}    {args} -> {v}")
            if t.more:
                out.append(f"{indent}{'':<{w_node}}  {'':<{w_var}}    ... {t.more} more points")
            out.append(f"{indent}{'':<{w_node}}  {'':<{w_var}}    elsewhere -> {t.elsewhere}")
        else:
            out.append(f"{indent}{r.node:<{w_node}}  {r.variable:<{w_var}}  {r.value}")
    return out


def explain_lines(d: DiagnosisRow) -> list[str]:
    """One diagnosis record (decoded) as text: sentence, culprits, counterexample, repairs with their diffs
    and cost."""
    out = [f"{d.id} [{d.status}] ({d.kind})", f"  {d.sentence}"]
    if d.culprits:
        out.append("  culprits:")
        out += [f"    {c.what}" + (f"  ({c.source})" if c.source and c.source not in c.what else "")
                for c in d.culprits]
    if d.counterexample:
        out.append("  counterexample:")
        out += table_lines(d.counterexample, "    ")
    if d.related:
        out.append("  the same guarantee, found by: " + ", ".join(natural_sorted(d.related)))
    if not d.repairs:
        out.append("  repairs: none that Z3 could check")
    for k, r in enumerate(d.repairs, 1):
        out.append(f"  repair {k} ({r.kind}): {r.summary}")
        out.append(f"    Z3 ({r.checked_by}) shows: {r.proves or 'the problem no longer follows'}; "
                   f"not shown: {r.not_shown or 'that the change is safe'}")
        for c in r.checks:
            out.append(f"    checked: {c.check}: {c.status}")
        if r.cost:
            out += [f"    changes: {c.check}: {c.before} -> {c.after}" for c in r.cost]
        else:
            out.append("    changes: no other check changes status")
        out += ["    " + line for line in r.diff.rstrip("\n").splitlines()]
    for why in d.not_offered or ():
        out.append(f"  not offered: {why}")
    return out


def whole_first_sentence(text: str) -> str:
    """The first sentence of ``text``, never cut: up to a ``.`` or ``;``
    followed by white space and a capital letter, outside parentheses,
    brackets, braces and backquoted formulas (:func:`_boundaries`).  A ``;``
    inside a parenthesis before a node's name is no sentence end: REQ4's
    sentence was shown in the terminal cut after its first ``Navigation.out.at;``, inside
    its parenthesis and without a sign that it was cut."""
    text = str(text).strip()
    for k in _boundaries(text):
        if text[k - 1] in ".;" and _CAPITAL_NEXT.match(text, k):
            return text[:k]
    return text


#: White space then a capital letter: what starts a sentence after a boundary.
_CAPITAL_NEXT = re.compile(r"\s+[A-Z]")


def _boundaries(text: str) -> list[int]:
    """Where ``text`` may be cut: after a ``.``, ``;`` or ``:`` followed by a
    space, outside parentheses, brackets, braces and backquoted formulas (a
    ``:`` of ``file:line:col`` or a ``;`` inside a formula is no boundary)."""
    out: list[int] = []
    depth, quoted = 0, False
    for k, ch in enumerate(text):
        if ch == "`":
            quoted = not quoted
        elif quoted:
            continue
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth = max(0, depth - 1)
        elif ch in ".;:" and depth == 0 and text[k + 1:k + 2] == " ":
            out.append(k + 1)
    return out


def clause_cut(text: str, limit: int = SENTENCE) -> str:
    """``text`` whole when at most ``limit`` characters; otherwise cut at the
    last sentence or clause boundary (:func:`_boundaries`) within ``limit``,
    with `` ...``; whole again when it has no such boundary.  Never cuts
    inside a clause: a cut text always ends at the end of one."""
    if len(text) <= limit:
        return text
    cuts = [k for k in _boundaries(text) if k <= limit]
    return text[:cuts[-1]] + " ..." if cuts else text
def same_file_lines(culprits: Sequence[str]) -> list[str]:
    """``culprits`` with consecutive ``file:line`` entries of one file written
    once (``a.gwen:72, 74, 77``), in their order; any other entry as it is."""
    out: list[str] = []
    last_file = None
    for c in culprits:
        file, sep, line = str(c).rpartition(":")
        if sep and line.isdigit() and file == last_file:
            out[-1] += f", {line}"
            continue
        out.append(str(c))
        last_file = file if sep and line.isdigit() else None
    return out


def finding_lines(report: AssuranceReport | Mapping[str, Any], wanted: str) -> list[str]:
    """A finding of the report's problems by root cause that has no
    diagnosis record of its own (an unverified guarantee ``Node.g<k>``, a
    derived property ``Node.derived``, a requirement): its id, status and
    kind, its sentence, the row it is in (culprits or where it was found)
    and the other findings of that row; ``[]`` when ``wanted`` is none.
    ``report``: the decoded report, or its JSON object (decoded here; raises
    :class:`msgspec.ValidationError` when it does not decode)."""
    for g in AssuranceReport.of(report).problems:
        for m in g.members:
            if m.id != wanted:
                continue
            out = [f"{wanted} [{m.status}] ({m.kind})", f"  {m.sentence}"]
            # a culprit: diagnosis/'s JSON object (what, source)
            cs = [f"{c['what']} ({c['source']})" if c.get("what") else str(c.get("source", ""))
                  for c in g.culprits]
            if cs:
                out += ["  culprits:"] + [f"    {c}" for c in cs]
            elif g.where:
                out.append(f"  found at {g.where}")
            others = [x.id for x in g.members if x.id != wanted]
            if others:
                out.append("  the same root cause, found by: " + ", ".join(others))
            return out
    return []


def _short(sentence: str) -> str:
    return clause_cut(sentence)


def status_lines(data: Mapping[str, Any]) -> list[str]:
    """The overall line, then the problems of a summary
    (``artifacts/report/summary.json``): one entry per root cause, as the
    report's "What needs attention" shows them (status, culprits, the
    findings behind it, one sentence, how many repairs Z3 checked), or, for a summary
    without that grouping, each problem and diagnosis on a line."""
    s = data["summary"]
    out = [f"overall: {s['status']} -- {s['headline']}"]
    groups = data.get("problems")
    if groups:
        found = sum(len(g["members"]) for g in groups)
        out.append(f"{len(groups)} problem{'s' if len(groups) != 1 else ''} by root cause ({found} finding"
                   f"{'s' if found != 1 else ''}); `rclverify explain ID` prints a finding's diagnosis:")
        for k, g in enumerate(groups, 1):
            # no culprit Z3 showed: the problem's own location, when it has one
            cause = "; ".join(same_file_lines(g["culprits"])) or (f"at {g['where']}" if g.get("where") else "(no culprit named)")
            repairs = (f", {g['repairs']} repair{'s' if g['repairs'] != 1 else ''} (Z3 shows the problem gone, not "
                       "that the change is safe)") if g["repairs"] else ""
            out.append(f"  {k}. [{g['status']}] {cause}: {len(g['members'])} finding"
                       f"{'s' if len(g['members']) != 1 else ''}{repairs}")
            if g["sentence"]:
                out.append(f"     {_short(g['sentence'])}")
            out.append(f"     findings: {', '.join(g['members'])}")
        return out
    out += [f"  problem: {p}" for p in s["problems"]]
    for d in s.get("diagnoses", []):
        sentence = _short(d["sentence"])
        more = (f"{d['repairs']} repair{'s' if d['repairs'] != 1 else ''} Z3 checked: " if d.get("repairs") else "")
        out.append(f"  diagnosis {d['id']}: {sentence} ({more}rclverify explain {d['id']})")
    return out
