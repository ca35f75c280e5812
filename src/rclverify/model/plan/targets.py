"""Statistical targets, environment tags and run origins in the plan (docs/statistics.md).

A ``monitors`` or ``experiment`` evidence entry may state

``target``       ``violation probability <= 1e-3 at 95 % per run`` (or
                 ``per answer``; ``of guarantee K`` for one guarantee): the
                 runs of the entry must bound the probability of a violation
                 by it (:mod:`rclverify.records.statistics`);
``environment``  the operating conditions its runs cover, a tag
                 (``warehouse_day``); runs under different tags are never
                 pooled into one bound;
``origin``       (``monitors`` only) ``operation`` (the default: runs of the
                 system in its operating conditions), ``simulation``, or
                 ``harness`` (runs a test harness drove, like the property
                 tests' examples: shown, never counted as operation).

A requirement may state a ``target`` too, counted per run over the recorded
runs it is checked on (docs/plan.md, "Traces of a temporal requirement");
``per answer`` means nothing there (a run gives the requirement one
verdict) and is refused.
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic
from rclverify.lang.types import Checked
from rclverify.model.plan.errors import plan_error
from rclverify.model.plan.model import EvidenceEntry, Plan

if TYPE_CHECKING:
    from rclverify.model.plan.target_text import Target

#: The tag of runs whose entry names no environment.
UNSTATED = "unstated"
#: Where a run set comes from; only ``operation`` and ``simulation`` runs are counted.
ORIGINS = ("operation", "simulation", "harness")
_TAG = re.compile(r"^[A-Za-z][A-Za-z0-9_.-]{0,63}$")
#: The backends whose entries may state a target (their evidence counts runs or trials).
COUNTING = ("monitors", "experiment")


def entry_target(config: Mapping[str, Any]) -> Target | None:
    """The parsed ``target`` of an entry's ``config`` (``None``: none or
    unreadable; :func:`check_targets` reports the latter)."""
    text = config.get("target")
    if not isinstance(text, str):
        return None
    from rclverify.model.plan.target_text import parse_target  # deferred: start-up (loaded only by a plan that states a target)
    try:
        return parse_target(text)
    except ValueError:
        return None


def entry_environment(config: Mapping[str, Any]) -> str:
    """The entry's environment tag, :data:`UNSTATED` when it names none."""
    tag = config.get("environment")
    return tag if isinstance(tag, str) and tag else UNSTATED


def entry_origin(config: Mapping[str, Any]) -> str:
    """The entry's ``origin`` (``operation`` when not given)."""
    o = config.get("origin")
    return o if isinstance(o, str) and o in ORIGINS else "operation"


def requirement_target(text: Any, loc: ast.Loc) -> Target | None:
    """A requirement's ``target`` (``None`` when absent).  Raises a located
    :class:`~.errors.PlanError` for one that does not read, or that counts
    per answer."""
    if text is None:
        return None
    from rclverify.model.plan.target_text import parse_target  # deferred: start-up (loaded only by a plan that states a target)
    try:
        t = parse_target(str(text))
    except ValueError as exc:
        raise plan_error(loc.file, loc.line, loc.col, str(exc)) from None
    if t.per != "run":
        raise plan_error(loc.file, loc.line, loc.col, "a requirement's target counts per run (a run gives the "
                                                      "requirement one verdict), not per answer")
    if t.margin is not None:
        raise plan_error(loc.file, loc.line, loc.col, "a requirement's target counts violating runs: a margin "
                                                      "target belongs on a node's monitors entry")
    if t.guarantee:
        raise plan_error(loc.file, loc.line, loc.col, "a requirement's target is about the requirement: 'of "
                                                      "guarantee K' belongs on a node's evidence entry")
    return t


def _entry_problems(e: EvidenceEntry, at: Any, guarantees: int | None) -> list[Diagnostic]:
    out: list[Diagnostic] = []

    def bad(key: str, msg: str) -> None:
        l = at(key)
        out.extend(plan_error(l.file, l.line, l.col, msg).diagnostics)
    c = e.config
    if e.backend not in COUNTING:  # another backend's entry: its unknown keys are reported by the loader
        return out
    if "target" in c:
        if not isinstance(c["target"], str):
            bad("target", f"a target is a text such as 'violation probability <= 1e-3 at 95 % per run', not "
                          f"{c['target']!r}")
        else:
            from rclverify.model.plan.target_text import parse_target  # deferred: start-up (loaded only by a plan that states a target)
            try:
                t = parse_target(c["target"])
            except ValueError as exc:
                bad("target", str(exc))
            else:
                if e.backend == "experiment" and t.margin is not None:
                    bad("target", "an experiment entry's target counts trials that miss its criterion: a margin "
                                  "target belongs on a monitors entry (its runs' answers have margins)")
                elif e.backend == "experiment" and t.guarantee:
                    bad("target", "an experiment entry's target is about the entry's guarantee: leave out "
                                  "'of guarantee K'")
                elif guarantees is not None and t.guarantee > guarantees:
                    bad("target", f"{e.node} has {guarantees} guarantee(s); there is no guarantee {t.guarantee}")
    if "environment" in c and not (isinstance(c["environment"], str) and _TAG.match(c["environment"])):
        bad("environment", f"an environment tag is a name of letters, digits, '_', '.' or '-' (at most 64), not "
                           f"{c['environment']!r}")
    if "origin" in c and c["origin"] not in ORIGINS:
        bad("origin", f"a run set's origin is one of {', '.join(ORIGINS)}, not {c['origin']!r}")
    return out


def check_targets(plan: Plan, checked: Checked | None = None) -> list[Diagnostic]:
    """Located errors for every evidence entry's ``target``,
    ``environment`` and ``origin`` that does not read, and (with the
    ``checked`` contracts) a target's guarantee the node does not have
    (module docstring)."""
    out: list[Diagnostic] = []
    for node, entries in plan.evidence.items():
        n = checked.nodes.get(node) if checked is not None else None
        for e in entries:
            def at(key: str, e: EvidenceEntry = e) -> ast.Loc:
                return plan.locs.get(("nodes", node, "evidence", e.index, key), e.loc)
            out.extend(_entry_problems(e, at, len(n.node.guarantees) if n is not None else None))
    return out


__all__ = ["COUNTING", "ORIGINS", "UNSTATED", "check_targets", "entry_environment", "entry_origin",
           "entry_target", "requirement_target"]
