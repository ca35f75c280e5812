"""The monitor's records: one verdict, one node's result on one run, who is blamed.

Kept apart from the engine (:mod:`.engine`) so that every transport and the
evidence builder read them without the engine; docs/monitors.md,
"Semantics and verdicts", and docs/semantics.md give what they mean.
"""
from __future__ import annotations

import bisect
import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast
from rclverify.lang.walk import names, reads  # re-exported: the engine and its mixins import them from here
from rclverify.lang.types import Checked, CheckedNode
from rclverify.model.system.services import peers

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import (AssumptionVerdict, AssumptionViolation, Inconclusive, Inexact,
                                                     NodeResultJson, VerdictJson, Violation)

#: Verdicts of one node's events: per output message (``satisfied``,
#: ``violated``, ``inconclusive``), per question (``assumption violated``,
#: ``incomplete input``, ``superseded``, ``inconclusive`` when unanswered
#: within the horizon, ``before first answer`` when that was before any
#: output of the node was heard (not counted: docs/semantics.md, "Steps"),
#: ``open`` when the run ended first; ``satisfied`` or ``violated`` when its
#: inputs alone decide the guarantees).
VERDICTS = ("satisfied", "violated", "open", "assumption violated", "inconclusive", "incomplete input",
            "superseded", "before first answer")
#: Topic suffixes of a service's or action's parts, in the order of ``Link.parts``
#: (a service ``s`` is observed as ``s/request`` and ``s/response`` events, an
#: action ``a`` as actionlib's ``a/goal``, ``a/feedback`` and ``a/result``).
#: How far an arithmetic is from exact (the weakest one a verdict rests on is shown; semantics/floatsem.py).
WEAK = {"exact": 0, "double": 1, "tolerance": 2}
#: Violations kept per node and run (each a few hundred bytes; the count is exact beyond it).
KEPT_VIOLATIONS = 200
#: How many of each guarantee's smallest margins a run keeps (a margin target counts the answers below its
#: margin from them; docs/statistics.md, "Margin targets")
KEPT_MARGINS = 256
LINK_TOPICS = {"service": ("request", "response"), "action": ("goal", "feedback", "result")}


@dataclass(frozen=True)
class Verdict:
    """The verdict of one event of one node, as soon as it is decided.

    ``verdict`` one of :data:`VERDICTS`; ``event``/``time``/``where``/``topic``
    identify the message it is about: the output message for a verdict on
    an output, the input message that raised the question otherwise; ``guarantee`` the 1-based guarantee that failed (0 when
    none or for the assumption); ``decided_at`` the time (s, trace clock)
    when it was decided; ``values`` the rendered values of the first failure
    (inputs and the outputs that failed), ``reason`` one sentence;
    ``semantics`` the arithmetic that decided it (:mod:`rclverify.semantics.floatsem`):
    ``exact``, ``double`` or ``tolerance`` for a ``satisfied`` (the weakest
    its assumption and guarantees needed), the semantics that all agreed for
    a ``violated`` or ``assumption violated`` (``exact, double``), else ``""``;
    ``question`` where the question an output verdict answers was raised
    (``""`` for a verdict on a question itself or on a node without inputs);
    ``margin`` the message's space margin (the least of the judged
    guarantees' margins, :func:`rclverify.semantics.robustness.margin`;
    docs/semantics.md, "Margins") when the run was judged with margins and
    the verdict is ``satisfied`` or ``violated`` on values that have one,
    else ``None`` (``inf``/``-inf`` when only atoms without a distance
    decided); ``provisional`` True for a verdict a live monitor gave before
    every writer (topic) of the node had been heard past ``decided_at``: it
    went on once a writer had been silent for longer than the lateness
    bound, or had not been heard at all, so a message of that writer still
    to come may replace it (docs/semantics.md, "Provisional verdicts").
    """

    node: str
    verdict: str
    event: int
    time: float
    where: str
    topic: str
    decided_at: float
    guarantee: int = 0
    values: Mapping[str, str] = field(default_factory=dict)
    reason: str = ""
    semantics: str = ""
    question: str = ""
    margin: float | None = None
    provisional: bool = False

    def to_json(self) -> VerdictJson:
        """A JSON-ready dict (the live monitor's verdict message); ``margin``
        only when there is one, an infinite one as ``null`` (JSON has no infinity);
        ``provisional`` only when true."""
        out: VerdictJson = {"node": self.node, "verdict": self.verdict, "event": self.event, "time": self.time,
                            "where": self.where, "topic": self.topic, "decided_at": self.decided_at,
                            "guarantee": self.guarantee, "values": dict(self.values), "reason": self.reason,
                            "semantics": self.semantics}
        if self.question:
            out["question"] = self.question
        if self.margin is not None:
            out["margin"] = self.margin if math.isfinite(self.margin) else None
        if self.provisional:
            out["provisional"] = True
        return out


@dataclass
class GuaranteeMargin:
    """The smallest space margin of one guarantee over a run's judged answers.

    ``guarantee`` 1-based, ``formula`` its text; ``value`` the smallest
    margin (``inf``/``-inf``: only atoms without a distance decided it),
    in ``unit`` (``""``: none declared), decided by the comparison ``atom``
    in ``arithmetic`` (``exact`` or ``double``); ``event``/``time``/``where``
    the output message it was judged on and ``question`` where that
    message's question was raised (``""``: none); ``answers`` how many judged
    answers gave the guarantee a margin, ``undefined`` how many had none
    (docs/semantics.md, "Margins"); ``lowest`` the :data:`KEPT_MARGINS`
    smallest of those margins, ascending (all of them on a shorter run)."""

    guarantee: int
    formula: str
    value: float
    unit: str
    atom: str
    arithmetic: str
    event: int
    time: float
    where: str
    question: str = ""
    answers: int = 1
    undefined: int = 0
    lowest: list[float] = field(default_factory=list)

    def keep(self, values: Any) -> None:
        """Keep the smallest of ``lowest`` and ``values`` (floats), at most :data:`KEPT_MARGINS`."""
        low = self.lowest
        if len(values) == 1:  # the engine's one answer at a time: an insertion, not a sort
            v = values[0]
            if len(low) < KEPT_MARGINS or v < low[-1]:
                bisect.insort(low, v)
                del low[KEPT_MARGINS:]
            return
        if len(low) >= KEPT_MARGINS and not any(v < low[-1] for v in values):
            return
        self.lowest = sorted([*low, *values])[:KEPT_MARGINS]

    def to_json(self, trace: str = "") -> dict[str, Any]:
        """A JSON-ready dict: ``margin`` the value, ``null`` when infinite (then
        ``holds`` says on which side: true for ``+inf``) or when no answer had
        one (``answers`` 0; ``holds`` is ``null`` but for an infinite margin),
        ``trace`` the run when given."""
        out: dict[str, Any] = {"guarantee": self.guarantee, "formula": self.formula,
                               "margin": self.value if math.isfinite(self.value) else None,
                               "holds": self.value > 0 if math.isinf(self.value) else None,
                               "unit": self.unit, "atom": self.atom,
                               "arithmetic": self.arithmetic, "event": self.event, "time": self.time,
                               "where": self.where, "question": self.question, "answers": self.answers,
                               "undefined": self.undefined,
                               # -inf (decided by an atom without a distance, violated) as null
                               "lowest": [v if math.isfinite(v) else None for v in self.lowest if v != math.inf]}
        if trace:
            out["trace"] = trace
        return out


@dataclass
class NodeResult:
    """Verdicts of one node on one trace.

    ``counts`` verdict -> number of verdicts (on output messages and on
    questions, :data:`VERDICTS`); ``first_violation`` and
    ``first_assumption_violation`` are dicts (event index, time, where,
    guarantee, formula, values, reason) or ``None``; ``events`` is the
    number of events on the node's topics; ``accepted`` the input events
    whose assumption held; ``semantics`` the ``satisfied`` verdicts per the
    arithmetic that decided them (``exact``, ``double``, ``tolerance``);
    ``first_inexact`` the first formula that held only in double arithmetic
    or within the tolerance (event, where, time, semantics, formula, values);
    ``unowed`` the input events that met the assumption and that no
    guarantee answers (each is ``triggered by`` another input): no verdict,
    nothing was checked for them; ``unasked`` the output messages published
    before the node had any question (only their output-only guarantees are
    judged); ``violations`` every ``violated`` verdict of the run (the first
    :data:`KEPT_VIOLATIONS`, in the order decided; ``violations_dropped``
    counts the rest), each as ``first_violation`` is.
    ``evaluation`` how each formula was evaluated (debug; not in :meth:`to_json`).
    ``margins`` guarantee -> its smallest space margin on the run
    (:class:`GuaranteeMargin`), filled only when the run is judged with
    margins (:func:`.check.check_trace`); not compared, so a run judged with
    and without margins gives equal results.
    """

    node: str
    counts: dict[str, int] = field(default_factory=lambda: {v: 0 for v in VERDICTS})
    events: int = 0
    first_violation: Violation | None = None
    first_assumption_violation: AssumptionViolation | None = None
    first_inconclusive: Inconclusive | None = None
    accepted: int = 0
    semantics: dict[str, int] = field(default_factory=lambda: {"exact": 0, "double": 0, "tolerance": 0})
    first_inexact: Inexact | None = None
    unowed: int = 0
    unasked: int = 0
    violations: list[Violation] = field(default_factory=list)
    violations_dropped: int = 0
    #: a debug field, in no evidence record: how each formula was evaluated
    #: (``assumption 1`` / ``guarantee 2`` -> ``compiled``, or why the
    #: straight-line code left it to the evaluator; semantics/judges.py)
    evaluation: dict[str, str] = field(default_factory=dict, compare=False)
    margins: dict[int, GuaranteeMargin] = field(default_factory=dict, compare=False)

    @property
    def assumption(self) -> AssumptionVerdict:
        """The assumption monitor's verdict on the run: ``violated`` when an
        input event violated it (the node is not at fault: the blame names the
        producer), ``held`` when every evaluated input event met it, ``not
        evaluated`` when none was evaluated."""
        n = self.counts["assumption violated"]
        verdict = "violated" if n else "held" if self.accepted else "not evaluated"
        return {"verdict": verdict, "violations": n, "accepted": self.accepted,
                "first": self.first_assumption_violation}

    def to_json(self) -> NodeResultJson:
        return {"node": self.node, "counts": dict(self.counts), "events": self.events,
                "first_violation": self.first_violation,
                "first_assumption_violation": self.first_assumption_violation,
                "first_inconclusive": self.first_inconclusive, "accepted": self.accepted,
                "semantics": dict(self.semantics), "first_inexact": self.first_inexact, "unowed": self.unowed,
                "unasked": self.unasked, "violations": list(self.violations),
                "violations_dropped": self.violations_dropped}

    def note_margin(self, k: int, formula: str, value: float | None, unit: str, atom: str, arithmetic: str,
                    at: tuple[int, float, str, str]) -> None:
        """Count guarantee ``k``'s margin ``value`` (``None``: it has none on these
        values) on the answer ``at`` (event index, time, where, the question's
        where), keeping the smallest (the first of equals)."""
        kept = self.margins.get(k)
        if value is None:
            if kept is not None:
                kept.undefined += 1
            else:
                self.margins[k] = GuaranteeMargin(k, formula, math.nan, "", "", "", -1, 0.0, "", "", 0, 1)
            return
        if kept is None:
            self.margins[k] = GuaranteeMargin(k, formula, value, unit, atom, arithmetic, *at, lowest=[value])
            return
        kept.keep((value,))
        kept.answers += 1
        if kept.answers == 1 or value < kept.value:  # answers == 1: the first after only undefined ones
            kept.value, kept.unit, kept.atom, kept.arithmetic = value, unit, atom, arithmetic
            kept.event, kept.time, kept.where, kept.question = at

    def note_margins(self, k: int, formula: str, value: float, unit: str, atom: str, arithmetic: str,
                     at: tuple[int, float, str, str], answers: int, lowest: Any = ()) -> None:
        """Count ``answers`` margins of guarantee ``k`` at once (the batch path),
        ``value`` the smallest of them, on the answer ``at``, ``lowest`` the
        smallest of them (at least :data:`KEPT_MARGINS`, or all): as that many
        :meth:`note_margin` calls in order would."""
        kept = self.margins.get(k)
        if kept is None:
            self.margins[k] = kept = GuaranteeMargin(k, formula, value, unit, atom, arithmetic, *at, answers=answers)
            kept.keep(lowest)
            return
        kept.keep(lowest)
        first = not kept.answers
        kept.answers += answers
        if first or value < kept.value:
            kept.value, kept.unit, kept.atom, kept.arithmetic = value, unit, atom, arithmetic
            kept.event, kept.time, kept.where, kept.question = at

    def margins_json(self, trace: str = "") -> list[dict[str, Any]]:
        """The smallest margin of every guarantee judged with margins, by guarantee
        (:meth:`GuaranteeMargin.to_json`; one whose answers had none: ``answers`` 0, ``margin`` null)."""
        return [m.to_json(trace) for _, m in sorted(self.margins.items())]

    def withdraw_violation(self, event: int) -> None:
        """Withdraw the ``violated`` verdict of message ``event`` (a revision
        replaced it, late.py): its record leaves :attr:`violations` (or the
        count of those dropped), and :attr:`first_violation` is the next kept."""
        kept = [v for v in self.violations if v["event"] != event]
        if len(kept) == len(self.violations) and self.violations_dropped:
            self.violations_dropped -= 1
        self.violations = kept
        if self.first_violation is not None and self.first_violation["event"] == event:
            self.first_violation = kept[0] if kept else None

    def add_violation(self, record: Violation) -> None:
        """Keep ``record`` (one ``violated`` verdict) in :attr:`violations`
        (bounded) and as :attr:`first_violation` when it is the first."""
        if self.first_violation is None:
            self.first_violation = record
        if len(self.violations) < KEPT_VIOLATIONS:
            self.violations.append(record)
        else:
            self.violations_dropped += 1


def producers(checked: Checked, node: CheckedNode, var: str) -> list[str]:
    """Other nodes whose output has the input's name or is matched to the
    input's topic, or feeds it through a service or action link (rule S1,
    :func:`rclverify.model.system.services.peers`: a client's response comes from
    the server, a server's request from its clients)."""
    topics = {t.field for t in node.node.topics if t.match is not None and t.match.name == var}
    out = {m for m, _ in peers(checked, node.name, var)} if node.node.links else set()
    for other in checked.nodes.values():
        if other.name == node.name:
            continue
        if var in other.outputs or any(t.field in topics and t.match is not None and t.match.name in other.outputs
                                       for t in other.node.topics):
            out.add(other.name)
    return sorted(out)


def link_of(node: CheckedNode, var: str) -> str:
    """``service estop`` when input ``var`` of ``node`` is a part of a service
    or action link (its response, feedback, result, or a server's request),
    else ``""``."""
    for lk in node.node.links:
        if any(v.prefix == "in" and v.name == var for v in lk.parts):
            return f"{lk.kind} {lk.name}"
    return ""


def in_all(semantics: str) -> str:
    """`` (false in exact and double arithmetic)`` for a failure that every
    float semantics agreed on, ``""`` when only exact arithmetic applied."""
    names = [s for s in semantics.split(", ") if s]
    if len(names) < 2:
        return ""
    words = {"exact": "exact", "double": "double", "tolerance": "within the tolerance"}
    said = [words.get(n, n) for n in names]
    arith = [w for w in said if w in ("exact", "double")]
    text = " and ".join(arith) + " arithmetic" + (" and " + said[-1] if "within the tolerance" in said else "")
    return f" (false in {text})"


__all__ = ["GuaranteeMargin", "KEPT_VIOLATIONS", "LINK_TOPICS", "WEAK", "VERDICTS", "NodeResult", "Verdict", "in_all", "link_of", "producers", "reads", "names"]
