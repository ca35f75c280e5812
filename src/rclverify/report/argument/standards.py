"""The argument's strategies linked to the standard clauses they address (docs/standards.md).

For each standard the plan names (the report's ``standards`` rows,
report/standards_rows.py), every clause with supporting evidence becomes
one GSN *context* (``C``) naming the standard, where its profile comes
from (built-in, or the workspace file and its sha256), the clause, its
own short title, its recommendation at the chosen level, its status and
why.  A strategy
addresses a clause when a solution under it (through ``supported_by``)
stands for an evidence row that supports the clause; the strategy then
carries the clause's context in ``in_context_of``.  Contexts have no
status: the links are a traceability aid and change no status.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Mapping

from rclverify.records.report_record import AssuranceReport
from rclverify.report.argument.model import Element
from rclverify.report.standards_rows import origin_text


def _solutions_under(els: Mapping[str, Element], start: str) -> set[str]:
    """The ``ref`` of every solution reachable from ``start`` through ``supported_by`` (iterative)."""
    seen, out, stack = {start}, set(), [start]
    while stack:
        e = els.get(stack.pop())
        if e is None:
            continue
        if e.type == "solution":
            out.add(e.ref)
        for child in e.supported_by:
            if child not in seen:
                seen.add(child)
                stack.append(child)
    return out


def add_standard_links(els: dict[str, Element], report: AssuranceReport, ident: Any) -> None:
    """Add one context per standard clause with supporting evidence to ``els``
    (changed in place) and put it in the context of every strategy that
    addresses the clause (the module docstring); ``ident`` makes element
    ids.  A report without ``standards`` rows changes nothing."""
    clauses: list[tuple[str, set[str]]] = []
    for row in report.standards:
        level = f" {row.level_name.upper()} {row.level}" if row.level is not None else ""
        for c in row.clauses:
            obligations = {e.obligation for e in c.evidence}
            if not obligations:
                continue
            cid = ident("C", "std", row.profile, c.id)
            els[cid] = Element(cid, "context", f"{row.edition}{level} ({origin_text(row.origin)}), "
                               f"{c.id}: {c.title} (recommendation {c.recommendation}; {c.status}: "
                               f"{c.why}; a traceability aid, not a compliance claim)",
                               ref=f"{row.profile}:{c.id}")
            clauses.append((cid, obligations))
    if not clauses:
        return
    for sid in [i for i, e in els.items() if e.type == "strategy"]:
        under = _solutions_under(els, sid)
        links = tuple(cid for cid, obligations in clauses if obligations & under)
        if links:
            els[sid] = replace(els[sid], in_context_of=(*els[sid].in_context_of, *links))


__all__ = ["add_standard_links"]
