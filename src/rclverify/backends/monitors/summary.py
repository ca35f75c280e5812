"""What ``rclverify monitor`` and the monitors' evidence say of one node's verdicts on a run.

The summary line, the status and its explanation, and the details block of
a node's :class:`~.verdicts.NodeResult` (docs/monitors.md), shared by the
offline command (:mod:`.cli`), the evidence builder (:mod:`.backend`) and
the live monitors.  Standard library only, so the offline command imports
none of the evidence builder's dependencies (templates, bag readers).
"""
from __future__ import annotations

import os
import re
import sys
from typing import Any, Mapping

from rclverify.backends.monitors.verdicts import NodeResult


def tool_versions() -> str:
    """``rclverify X, rosbags Y`` (the libraries the verdicts depend on): rclverify's the running
    code's ``__version__``, rosbags' its distribution's (:func:`distribution_version`)."""
    from rclverify import __version__  # deferred: start-up (the package's own version, only where it is written)
    found = distribution_version("rosbags")
    return f"rclverify {__version__}, rosbags {found or '(not installed)'}"


def _normal(name: str) -> str:
    """A distribution's name as the binary distribution format compares it: runs of ``-``, ``_``
    and ``.`` one ``_``, lower case (``PyYAML`` and a wheel's ``pyyaml-6.0.4.dist-info`` alike)."""
    return re.sub(r"[-_.]+", "_", name).lower()


def distribution_version(name: str) -> str | None:
    """The version of the installed distribution ``name``, ``None`` when none is: from the first
    ``sys.path`` entry holding its metadata, names compared normalised (:func:`_normal`), as
    :func:`importlib.metadata.version` searches: a ``<name>-<version>.dist-info`` folder gives the
    version (how a wheel names it, the Python Packaging Authority's binary distribution format);
    an egg's metadata there, or none on any entry, is left to :func:`importlib.metadata.version`
    itself, whose import and search cost about 0.04 CPU s of the command's start-up, paid only then."""
    want = _normal(name)
    for entry in sys.path:
        try:
            names = os.listdir(entry or ".")
        except OSError:  # not a folder (a zip), or gone
            continue
        for n in names:
            stem, dot, kind = n.rpartition(".")
            dist, dash, ver = stem.partition("-")
            if dot and dash and kind in ("dist-info", "egg-info") and _normal(dist) == want:
                if kind == "dist-info" and "-" not in ver:
                    return ver
                break  # an egg's metadata: importlib.metadata reads it
        else:
            continue
        break
    from importlib.metadata import PackageNotFoundError, version  # deferred: start-up (the distributions' search, only where no dist-info folder named it)
    try:
        return version(name)
    except PackageNotFoundError:
        return None


def monitoring_details(res: NodeResult, trace: str, events: int, sha: str, versions: str,
                       horizon: float, tolerance: Any = None, duration_s: float | None = None) -> dict[str, Any]:
    """The evidence ``details["monitoring"]`` block (also printed by ``rclverify monitor``):
    beside the counts and first violations, the assumption monitor's verdict
    (``assumption``), the ``satisfied`` verdicts per semantics that decided
    them (``semantics``: exact, double, tolerance), the first formula that
    held only outside exact arithmetic (``first_inexact``) and the declared
    ``tolerance`` (``None``: none), and every violation of the run
    (``violations``: the first :data:`~.verdicts.KEPT_VIOLATIONS`, each with
    its time, message, guarantee, values and the question it answered;
    ``violations_dropped`` the count beyond them), which ``rclverify explain
    OBLIGATION#N`` prints one by one; ``duration_s``: the run's span in trace
    time, seconds from its first event to its last (``None``: not measured);
    ``margins``: per guarantee its smallest space margin on the run, the
    message and the time (:meth:`.verdicts.NodeResult.margins_json`, each
    naming ``trace``; empty when the run was judged without margins;
    docs/semantics.md, "Margins")."""
    return {"trace": trace, "sha256": sha, "events_read": events, "node_events": res.events,
            "horizon_s": horizon, "counts": dict(res.counts), "first_violation": res.first_violation,
            "first_assumption_violation": res.first_assumption_violation,
            "first_inconclusive": res.first_inconclusive, "assumption": res.assumption,
            "semantics": dict(res.semantics), "first_inexact": res.first_inexact,
            "tolerance": tolerance.to_json() if tolerance else None, "tools": versions,
            "violations": list(res.violations), "violations_dropped": res.violations_dropped,
            "unasked": res.unasked, "duration_s": duration_s, "margins": res.margins_json(trace)}


def summary_line(res: NodeResult) -> str:
    """``Node: 3 satisfied, 1 violated, ...`` (non-zero counts only)."""
    parts = [f"{n} {v}" for v, n in res.counts.items() if n]
    if res.unowed:
        parts.append(f"{res.unowed} owed no answer (its guarantees answer other inputs)")
    return f"{res.node}: " + (", ".join(parts) if parts else "no event on its topics")


def semantics_note(res: NodeResult) -> str:
    """``; 2 satisfied event(s) hold only in the node's double arithmetic
    (first at run.jsonl:4: guarantee 1 (...))``: which semantics decided what
    exact arithmetic alone would have called false (docs/monitors.md,
    "Numbers on the wire"); ``""`` when exact arithmetic decided everything."""
    f = res.first_inexact
    if f is None:
        return ""
    words = {"double": "only in the node's double arithmetic", "tolerance": "only within the declared tolerance"}
    counts = [f"{n} {words[k]}" for k, n in res.semantics.items() if n and k in words]
    head = (f"; satisfied event(s) that hold {', '.join(counts)}" if counts
            else f"; a formula held {words.get(f['semantics'], f['semantics'])}")
    return f"{head} (first at {f['where']}: {f['formula']})"


def verdict_status(res: NodeResult, trace: str) -> tuple[str, str]:
    """Evidence status and explanation for one node's verdicts on a trace:
    any ``violated`` -> ``failed``; else any ``inconclusive`` or ``open`` ->
    ``inconclusive``; else nothing satisfied -> ``pending``; else
    ``discharged``.  Assumption violations are added to the explanation
    (blamed upstream or on the environment), whatever the status."""
    c = res.counts
    blame = ""
    if c["assumption violated"]:
        a: Mapping[str, object] = res.first_assumption_violation or {}
        blame = (f"; the assumption monitor's verdict is violated: {c['assumption violated']} question(s) "
                 f"violated the assumption (first at {a.get('where')}, blamed on the {a.get('blame')}), so the node "
                 f"is not at fault for them")
    blame += semantics_note(res)
    if c["violated"]:
        v: Mapping[str, object] = res.first_violation or {}
        which = f"guarantee {v['guarantee']} ({v.get('formula', '')})" if v.get("guarantee") else "the guarantees"
        return "failed", (f"{c['violated']} message(s) of {trace} violated {res.node}'s contract; the first "
                          f"violation is at {v.get('where')} (t = {v.get('time')} s): {which}: {v.get('reason')}"
                          + (f" (every violation: `rclverify explain OBLIGATION#N`, N = 1..{len(res.violations)})"
                             if len(res.violations) > 1 else ""))
    if c["before first answer"] and not c["satisfied"]:
        return "inconclusive", (f"no output of {res.node} was heard in {trace}: {c['before first answer']} "
                                "question(s) came before any answer, and a node that never answers and a reader "
                                f"that never matched look the same (docs/semantics.md, \"Steps\"){blame}")
    if c["inconclusive"]:
        i: Mapping[str, object] = res.first_inconclusive or {}
        return "inconclusive", (f"{c['inconclusive']} event(s) could not be decided; first at {i.get('where')}: "
                                f"{i.get('reason')}{blame}")
    if c["open"]:
        i = res.first_inconclusive or {}
        why = f"; first at {i.get('where')}: {i.get('reason')}" if i else ""
        return "inconclusive", f"{c['open']} question(s) were still unanswered when the trace ended{why}{blame}"
    if not c["satisfied"]:
        unowed = (f"; {res.unowed} met it but no guarantee answers them (each is triggered by another input)"
                  if res.unowed else "")
        return "pending", (f"{trace} has no input event of {res.node} that meets its assumption and that a "
                           f"guarantee answers ({c['assumption violated']} violated it{unowed}): nothing was checked")
    return "discharged", f"all {c['satisfied']} judged answer(s) met the guarantees{blame}"


__all__ = ["monitoring_details", "semantics_note", "summary_line", "tool_versions", "verdict_status"]
