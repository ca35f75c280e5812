"""The text of the deadline monitor's verdicts (:mod:`.deadlines`): durations
as its reasons show them (:func:`ms`, :func:`ms_ns`), the verdicts an
obligation gets when its deadline expires or an answer comes
(:class:`VerdictWords`, the batch deadline judge's too), why an output did
not answer one (:func:`rejected`), and the evidence status and explanation
of one node's deadline verdicts on a trace (:func:`deadline_status`;
docs/monitors.md).
"""
from __future__ import annotations

from typing import Mapping

from rclverify.semantics.floatsem import Judgement
from rclverify.lang.types import CheckedNode
from rclverify.traces.events import Event
from rclverify.backends.monitors.deadline_records import DeadlineResult, DeadlineVerdict, Pending


def ms(x: float) -> str:
    """A duration of ``x`` seconds as reports show it: whole milliseconds under 10 s, else seconds to the ms."""
    return f"{x * 1000:.0f} ms" if abs(x) < 10 else f"{x:.3f} s"


def ms_ns(ns: int) -> str:
    """A duration of ``ns`` integer nanoseconds as :func:`ms` shows it; a late
    answer less than half a millisecond past shows its microseconds (never
    "0 ms past the deadline")."""
    if 0 < abs(ns) < 500_000:
        return f"{ns / 1000:.0f} us" if abs(ns) >= 500 else f"{ns} ns"
    return ms(ns / 1e9)


def rejected(k: int, out: Event, j: Judgement) -> str:
    """Why output ``out`` did not answer an obligation of guarantee ``k``, judged ``j`` on its inputs."""
    return f"the output at {out.where} did not satisfy guarantee {k}" + (
        f" (false in {j.semantics} arithmetic)" if j.truth is False and "double" in j.semantics else
        f" ({j.reason})" if j.truth is None and j.reason else "")


class VerdictWords:
    """The verdicts of :class:`~.deadlines.DeadlineMonitor`'s obligations, in its words (its ``node``)."""

    node: CheckedNode

    def expired_verdict(self, p: Pending, now_ns: int) -> DeadlineVerdict:
        """Obligation ``p``'s ``false``: the clock passed its deadline at ``now_ns`` unanswered."""
        return DeadlineVerdict(self.node.name, p.k, "false", p.trigger.where, p.stamp, p.due, None, "",
                               f"no answer within the deadline of {ms_ns(p.bound_ns)} "
                               f"(clock at {now_ns / 1e9:.3f} s)" + (f"; {p.rejected}" if p.rejected else ""))

    def answered_verdict(self, p: Pending, ns: int, ev: Event, d: float, semantics: str = "exact") -> DeadlineVerdict:
        """Open obligation ``p`` answered by output ``ev`` stamped ``ns``: ``true`` within the deadline ``d``
        (s; at it is in time, integer ns), else ``false`` with the answer."""
        if ns <= p.due_ns:
            return DeadlineVerdict(self.node.name, p.k, "true", p.trigger.where, p.stamp, p.due, ns / 1e9,
                                   ev.where, f"answered after {ms_ns(ns - p.stamp_ns)} (deadline {ms(d)})",
                                   semantics=semantics, time_margin=(p.due_ns - ns) / 1e9)
        return DeadlineVerdict(self.node.name, p.k, "false", p.trigger.where, p.stamp, p.due, ns / 1e9,
                               ev.where, f"answered after {ms_ns(ns - p.stamp_ns)}, "
                               f"{ms_ns(ns - p.due_ns)} past the deadline of {ms(d)}",
                               semantics=semantics, time_margin=(p.due_ns - ns) / 1e9)

    def late_verdict(self, p: Pending, ns: int, ev: Event) -> DeadlineVerdict:
        """Expired obligation ``p``'s late answer ``ev`` stamped ``ns`` (an update of its ``false``)."""
        return DeadlineVerdict(self.node.name, p.k, "false", p.trigger.where, p.stamp, p.due, ns / 1e9,
                               ev.where, f"answered after {ms_ns(ns - p.stamp_ns)}, "
                               f"{ms_ns(ns - p.due_ns)} past the deadline of "
                               f"{ms_ns(p.bound_ns)}", update=True,
                               time_margin=(p.due_ns - ns) / 1e9)


def deadline_status(res: DeadlineResult, trace: str) -> tuple[str, str]:
    """Evidence status and explanation of one node's deadline verdicts on a
    trace: any ``false`` -> ``failed`` (the first named with its stamps);
    any ``currently_false`` (a trigger unanswered and within its deadline
    when the run ended: not decided, as an untimed question still open at
    the end) -> ``inconclusive``; else ``discharged``, or ``pending`` when
    no trigger event was seen."""
    c = res.counts
    f = res.first_false
    u = res.unaccepted
    refused = ""
    if any(u.values()):
        first: Mapping[str, object] = res.first_unaccepted or {}
        words = {"assumption violated": "whose inputs violated the assumption",
                 "incomplete input": "with inputs not all observed yet", "undecided": "whose assumption or verdict was undecided"}
        refused = ("; no deadline verdict for " + ", ".join(f"{n} trigger event(s) {words[k]}"
                                                            for k, n in u.items() if n)
                   + f" (first at {first.get('where')}: {first.get('reason')})")
    if c["false"] and f is not None:
        late = (f"answered at {f.answer:.3f} s ({f.answer_where})" if f.answer is not None else
                "never answered as guaranteed" if "did not satisfy" in f.reason else "never answered")
        return "failed", (f"{c['false']} trigger event(s) of {trace} missed {res.node}'s deadline; the first: "
                          f"guarantee {f.guarantee}, triggered at {f.trigger_where} (stamp {f.trigger_stamp:.3f} s), "
                          f"due {f.due:.3f} s, {late}: {f.reason}{refused}")
    if u["undecided"]:
        return "inconclusive", (f"{u['undecided']} trigger event(s) could not be decided (their assumption, or their "
                                f"answer's time: the transport skew, the clock they are kept in)"
                                f"{refused}")
    if c["currently_false"]:
        met = f"; {c['true']} other(s) were answered within their deadline" if c["true"] else ""
        return "inconclusive", (f"{c['currently_false']} trigger event(s) were unanswered and within their "
                                f"deadline when {trace} ended: not decided{met}{refused}")
    if not c["true"]:
        return "pending", f"{trace} has no accepted trigger event of {res.node}'s timed guarantees: nothing was checked{refused}"
    return "discharged", f"all {c['true']} accepted trigger event(s) were answered within their deadline{refused}"
