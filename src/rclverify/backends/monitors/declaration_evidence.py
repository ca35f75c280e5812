"""A node's declaration rows and their fold into the record's status.

The rows :class:`~.declarations.DeclarationMonitor` judges on a run (and
the rows of the periods in time, :func:`add_periods`) are a
:class:`DeclarationResult`.  Each row's status is its verdict's
(:data:`STATUS`: ``true`` discharged, ``false`` failed, ``inconclusive``,
``pending``) and names the declaration's source, so a requirement resting
on it (calculus/requirements/rollup.py) can read it.  The node's record
folds them in by the rule of evidence (docs/semantics.md, "Verdicts and
evidence"; :func:`declaration_status`, :func:`with_declarations`): a
declaration pending or undecided never leaves the record ``discharged``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rclverify.lang import ast
from rclverify.lang.liveness import period_seconds
from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.periods import PeriodResult

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import DeclarationsPart
    from rclverify.backends.shapes import DeclarationRow

#: declaration verdict -> evidence status
STATUS = {"true": "discharged", "false": "failed", "inconclusive": "inconclusive", "pending": "pending"}


@dataclass
class DeclarationResult:
    """The verdict rows of one node's declarations on one run."""

    node: str
    declarations: list[DeclarationRow] = field(default_factory=list)
    #: the labels of the rows no run can decide (an ``initially`` whose first published value came after
    #: an input: the property tests' to show): listed in the record's explanation, not folded into its status
    unobservable: set[str] = field(default_factory=set)

    def rows(self) -> list[DeclarationRow]:
        """``[{"declaration", "premise", "index", "source", "verdict", "status", "reason"}]``:
        ``premise`` the kind of premise the requirement check makes of it
        (``"initial value"``, ``"progress"``, ``""`` for a period in time)."""
        return [r.copy() for r in self.declarations]


def source_text(loc: ast.Loc) -> str:
    """``"file:line:col"``: where a declaration stands, as a row names it."""
    return f"{loc.file}:{loc.line}:{loc.col}"


def declaration_row(label: str, premise: str, index: int, source: str, text: str, verdict: str,
                    reason: str) -> DeclarationRow:
    """One row of :attr:`DeclarationResult.declarations`: ``label`` (e.g.
    ``"initially 1"``), the ``premise`` kind, the declaration's 1-based
    ``index`` among its kind (0 for progress and periods), its ``source``
    (``file:line:col``) and ``text``, its ``verdict`` (a key of
    :data:`STATUS`, else ``KeyError``) with the status it gives, and the
    ``reason``."""
    return {"declaration": label, "premise": premise, "index": index, "source": source, "text": text,
            "verdict": verdict, "status": STATUS[verdict], "reason": reason}


def add_periods(res: DeclarationResult, node: CheckedNode, periods: PeriodResult | None) -> DeclarationResult:
    """``res`` with a row per period in time of ``node``, from the run's
    :class:`~.periods.PeriodResult` (``None``: not checked, ``pending``)."""
    for per in node.node.periodic:
        if period_seconds(per) is not None:
            res.declarations.append(declaration_row(
                f"periodic out.{per.output.name}", "", 0, source_text(per.loc),
                f"periodic( out.{per.output.name}, {per.amount} {per.unit} )",
                *_period_verdict(periods, f"out.{per.output.name}")))
    return res


def _period_verdict(res: PeriodResult | None, key: str) -> tuple[str, str]:
    if res is None or key not in res.periods:
        return "pending", "the period was not checked"
    late = res.late.get(key)
    n = res.messages.get(key, 0)
    rate = res.clocks.get(key)
    clock = (f" (in the node's clock: its stamps, set aside in another clock, run at {rate:.3f} s per s of the "
             "run's)") if rate is not None else ""
    if late is not None:
        after = "" if late["to"] is not None else ", until the run's end"
        return "false", (f"a gap of {late['gap'] * 1000:.0f} ms after the message at {late['from']:.3f} s "
                         f"({late['where']}){after}, over the period of {late['period'] * 1000:.0f} ms{clock}")
    if n == 0:
        return "pending", "no message of the output: its period was not checked"
    if key in res.undecided:
        return "inconclusive", f"not decided in simulated time: {res.undecided[key]}"
    if n == 1:
        return "inconclusive", ("a single message and the run ends within the period: too short to show a gap"
                                if key not in res.unrated else
                                "a single message stamped in another clock: too short to show a gap, and its "
                                "clock's rate unknown, so the run's end was not carried into it")
    if key in res.unrated:
        return "inconclusive", (f"{n} messages, no gap over {res.periods[key] * 1000:.0f} ms{clock}, but the run "
                                "goes on past the period after the last at that rate and no later stamp of its "
                                "simulated clock shows the clock got there: it may have slowed or paused, so the "
                                "run's end was not carried into it")
    return "true", f"{n} messages, no gap over {res.periods[key] * 1000:.0f} ms{clock}"


def declaration_status(res: DeclarationResult, trace: str) -> tuple[str, str]:
    """``(status, explanation)`` the declarations of ``res`` give on
    ``trace``, by the rule of evidence (docs/semantics.md, "Verdicts and
    evidence"): a ``false`` row -> ``failed`` (named, a declaration of the
    contract before a period in time); else an ``inconclusive`` row, or a
    ``pending`` row beside a ``true`` one -> ``inconclusive``; else every row
    ``pending`` (or none) -> ``pending``; else ``discharged``.  A row no run
    can decide (:attr:`DeclarationResult.unobservable`) is listed apart and
    left out of the status.  The explanation lists the rows that held, those
    not decided and those no run shows, each with its reason."""
    status, words = _fold(res, trace)
    return status or "pending", words


def _fold(res: DeclarationResult, trace: str) -> tuple[str | None, str]:
    """:func:`declaration_status`, with ``None`` for a status when every row
    is one no run can decide (nothing for the record's status)."""
    rows = [r for r in res.declarations if r["declaration"] not in res.unobservable]
    bad = sorted((r for r in rows if r["verdict"] == "false"), key=lambda r: not r["premise"])
    if bad:
        r = bad[0]
        return "failed", f"{res.node} declares {r['text']} ({r['source']}) but in {trace}: {r['reason']}"
    open_ = [f"{r['text']}: {r['verdict']} ({r['reason']})" for r in rows if r["verdict"] not in ("true", "false")]
    done = [r["text"] for r in rows if r["verdict"] == "true"]
    apart = [f"{r['text']}: {r['verdict']} ({r['reason']})" for r in res.declarations
             if r["declaration"] in res.unobservable]
    words = "; ".join((["held: " + ", ".join(done)] if done else [])
                      + (["not decided: " + "; ".join(open_)] if open_ else [])
                      + (["not shown by a run (its first published value answers an input; the property tests "
                          "show it): " + "; ".join(apart)] if apart else [])) or "none judged"
    if not rows and res.declarations:
        return None, words
    if any(r["verdict"] == "inconclusive" for r in rows) or (open_ and done):
        return "inconclusive", words
    if not done:
        return "pending", words
    return "discharged", words


def with_declarations(res: DeclarationResult, trace: str, status: str,
                      explanation: str) -> tuple[str, str, DeclarationsPart]:
    """The record's status from the other checks' ``status`` (with its
    ``explanation``) and the node's declarations on the same run
    (:func:`declaration_status`), by the rule of evidence (docs/semantics.md,
    "Verdicts and evidence"): a false declaration fails the record (it is a
    claim of the node's contract); a declaration pending or undecided keeps
    a ``discharged`` record from ``discharged`` (``inconclusive``) and makes
    a ``pending`` one ``inconclusive`` when one was undecided; ``failed``,
    ``error``, ``stale`` and ``inconclusive`` stand; a row no run can decide
    changes nothing but the explanation.  Returns ``(status, explanation,
    {"declarations": rows})``."""
    dstatus, dexpl = _fold(res, trace)
    part: DeclarationsPart = {"declarations": res.rows()}
    if dstatus == "failed":
        late_period = not any(r["verdict"] == "false" and r["premise"] for r in res.declarations
                              if r["declaration"] not in res.unobservable)
        if late_period and status == "failed":  # a late period fails the record through periods.py: not said twice
            return status, f"{explanation}; declarations: {dexpl}", part
        return "failed", f"declarations: {dexpl}; {explanation}", part
    if status == "discharged" and dstatus not in (None, "discharged"):
        return "inconclusive", (f"{explanation}; but a declaration is not decided on this run, so the record is "
                                f"not discharged (docs/semantics.md, \"Verdicts and evidence\"); declarations: "
                                f"{dexpl}"), part
    if status == "pending" and dstatus == "inconclusive":
        return "inconclusive", f"{explanation}; declarations: {dexpl}", part
    return status, f"{explanation}; declarations: {dexpl}", part
