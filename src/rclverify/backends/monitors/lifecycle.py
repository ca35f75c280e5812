"""Managed (lifecycle) nodes judged by their state (docs/monitors.md, "Lifecycle nodes"): the gate a live run, a
recorded run (``rclverify monitor TRACE``) and the pipeline's monitors backend ask.

A managed node (ROS 2 design, "Managed nodes"; ``rclcpp_lifecycle``, ``rclpy.lifecycle``)
publishes each transition it completes on ``<node>/transition_event``
(``lifecycle_msgs/msg/TransitionEvent``: ``timestamp`` in ns of the node's clock, ``transition``,
``start_state``, ``goal_state``, each state an ``id`` and a ``label``).  A contract declares its node managed by naming that topic with
that type and no ``matches`` (``lifecycle_msgs/TransitionEvent battery/transition_event``: the node
``/battery``; under an instance's namespace the name resolves as every other, docs/plan.md
"Instances"): :func:`managed_of`.  Its guarantees hold in their scope (``guarantee(...) while
active``, one scope per node, an unscoped guarantee's ``active``: :func:`scope_ids`,
:mod:`rclverify.lang.lifecycle`):

* a managed node is ``unconfigured`` until its first transition event (every managed node starts
  so); its state then is the ``goal_state`` of its latest event, in force from the event's
  ``timestamp`` (the node's clock, seconds: on one machine the clock the monitor receives by);
* an **input** heard while every monitored node reading it is managed and not in a state of its
  scope (the latest event heard) is no question: it is held back from the guarantees' judge and
  counted;
* an **output** of a managed node published outside ``active`` violates the lifecycle contract:
  it is judged against the node's states within :attr:`LifecycleGate.skew` of its time (the
  time the live run places it at: its source time, else its receipt), and is red only when none
  of them is ``active`` or a transition into or out of it (``activating``, ``deactivating``: a
  managed publisher is enabled in ``on_activate``), so a message published just before a
  deactivation is not red; it is decided once :attr:`LifecycleGate.settle` seconds have passed
  after it (a transition event heard after the output, on its own topic, still counts), and at
  the end of the run for the rest.  Each violation names the node, the topic, the time and the
  state it was published in;
* the transition events are the gate's, counted as heard (:attr:`LifecycleGate.heard`, what the
  run's "not judged" list reads); the guarantees' judge never sees them.

* a **transition deadline** (``deadlines``, per managed node: transition -> seconds, e.g.
  ``{"Battery": {"activate": 0.2}}``; the contract's ``ready within 200 ms of activate``,
  :func:`stated_deadlines`, read by :func:`gate_of`, so a live run judges it) bounds each of the node's transitions of that name from the
  event into its transition state to the event into the state it leads to (:data:`TRANSITIONS`:
  ``activate`` from ``activating`` to ``active``): ``met`` within it, ``missed`` when the goal
  came later, the transition ended elsewhere (a failed ``on_activate``: ``inactive``, or
  ``errorprocessing``) or the run ended more than the deadline after its start with no end,
  ``open`` when the run ended sooner.  A missed transition fails the node, as a violation does.

:class:`LifecycleGate` is the gate a live run (:class:`rclverify.runtime.live.LiveRun`,
``gate``, made by :func:`gate_of` from the monitored nodes) asks for every message before its
judge, in its engine's release order (the transition topics ordered with the rest,
:attr:`rclverify.backends.monitors.online.OnlineEngine.gate_topics`), after the message's log line; its :meth:`~LifecycleGate.record` is the run's ``lifecycle`` record.  The transport reads
the transition topic as any topic a contract names, and a bag the run records (``--record``) holds
it.  :func:`rclverify.cli.lifecycle_runs.judge_recorded` judges a recorded run (a bag, or a log holding the transition events:
:mod:`rclverify.traces.lifecycle_events`) as the live run judges it: its messages, in the order
read and at their recorded times, through the same gate and the same judge.
"""
from __future__ import annotations

import bisect
from dataclasses import dataclass, field
from typing import Any, Iterable, Iterator, Mapping, Sequence

from rclverify.lang.lifecycle import DEFAULT_SCOPE, scope_of, transition_topic
from rclverify.lang.timing import seconds
from rclverify.lang.types import CheckedNode

#: The message type a managed node publishes its transitions in.
TRANSITION_TYPE = "lifecycle_msgs/msg/TransitionEvent"
#: lifecycle_msgs/msg/State's ids: the primary states and the transition states.
STATES = {0: "unknown", 1: "unconfigured", 2: "inactive", 3: "active", 4: "finalized", 10: "configuring",
          11: "cleaningup", 12: "shuttingdown", 13: "activating", 14: "deactivating", 15: "errorprocessing"}
ACTIVE = 3
#: The states an output may be published in: ``active``, and the transitions into and out of it (a
#: managed publisher is enabled in ``on_activate``, while the node is ``activating``).
ACTIVE_LIKE = frozenset({3, 13, 14})
#: A transition's name -> (its transition state, the primary state it leads to) (ROS 2 design,
#: "Managed nodes"; lifecycle_msgs/msg/Transition's names).
TRANSITIONS = {"configure": (10, 2), "activate": (13, 3), "deactivate": (14, 2), "cleanup": (11, 1),
               "shutdown": (12, 4)}


def event_topic(fqn: str) -> str:
    """The topic a managed node of fully qualified name ``fqn`` publishes its transitions on, as the
    judge keys topics (no leading ``/``): ``/r1/battery`` -> ``r1/battery/transition_event``."""
    return f"{fqn.strip('/')}/transition_event"


def managed_of(nodes: Sequence[CheckedNode]) -> dict[str, str]:
    """The managed nodes among ``nodes``: ``{contract node: fully qualified ROS name}`` of each whose
    contract names a ``lifecycle_msgs/TransitionEvent`` topic ``<ros node>/transition_event`` with no
    ``matches`` (module docstring; ``battery/transition_event`` -> ``/battery``)."""
    out: dict[str, str] = {}
    for n in nodes:
        t = transition_topic(n.node)
        if t is not None:
            out[n.name] = "/" + t.key[: -len("/transition_event")]
    return out


def scope_ids(node: CheckedNode) -> frozenset[int]:
    """The state ids (:data:`STATES`) a managed node's questions are asked in: its guarantees' one scope
    (``while active``; unscoped: ``active``; :func:`rclverify.lang.lifecycle.scope_of`, one per node by
    the type checker's rule)."""
    scope = next((scope_of(node.node, cl) for cl in node.node.guarantees), None) or DEFAULT_SCOPE
    return frozenset(k for k, name in STATES.items() if name in scope)


def stated_deadlines(nodes: Sequence[CheckedNode]) -> dict[str, dict[str, tuple[float, str]]]:
    """The transition deadlines the contracts of ``nodes`` state (``ready within 200 ms of activate``):
    ``{node: {transition: (seconds, "file:line:col")}}``."""
    out: dict[str, dict[str, tuple[float, str]]] = {}
    for n in nodes:
        for td in n.node.transitions:
            secs = seconds(td.deadline)
            if secs is not None:
                out.setdefault(n.name, {})[td.transition] = (float(secs), str(td.loc))
    return out


def gate_of(nodes: Sequence[CheckedNode], deadlines: Mapping[str, Mapping[str, float]] | None = None
            ) -> "LifecycleGate | None":
    """The lifecycle gate of a run monitoring ``nodes``, ``None`` when none is managed: the transition
    deadlines the contracts state (:func:`stated_deadlines`) and ``deadlines`` (per node, transition ->
    seconds: the command line's, which replace a contract's for the same transition)
    (:class:`LifecycleGate`)."""
    managed = managed_of(nodes)
    if not managed:
        return None
    stated = stated_deadlines(nodes)
    merged: dict[str, dict[str, float]] = {n: {t: v[0] for t, v in per.items()} for n, per in stated.items()}
    for n, per in (deadlines or {}).items():
        merged.setdefault(n, {}).update(per)
    where = {n: {t: v[1] for t, v in per.items() if (deadlines or {}).get(n, {}).get(t) is None}
             for n, per in stated.items()}
    return LifecycleGate(managed, nodes, deadlines=merged, where=where)


def _get(fields: Mapping[str, object], *path: str) -> object:
    """A field of a message read nested (``{"goal_state": {"id": 3}}``) or flattened as the log
    writes it (``{"goal_state.id": 3}``)."""
    flat = fields.get(".".join(path))
    if flat is not None:
        return flat
    cur: object = fields
    for p in path:
        cur = cur.get(p) if isinstance(cur, Mapping) else None
    return cur


@dataclass
class _Managed:
    """One managed node: its contract's name, its topics (judge keys), its states over time."""

    node: str
    fqn: str
    outputs: set[str]
    inputs: set[str]
    scope: frozenset[int] = frozenset({ACTIVE})
    times: list[float] = field(default_factory=lambda: [float("-inf")])
    states: list[int] = field(default_factory=lambda: [1])
    transitions: int = 0
    judged: int = 0

    def states_within(self, lo: float, hi: float) -> list[int]:
        """The states in force at some time of ``[lo, hi]``, the one at ``lo`` first."""
        return self.states[bisect.bisect_right(self.times, lo) - 1: bisect.bisect_right(self.times, hi)]

    def now(self) -> int:
        return self.states[-1]


class LifecycleGate:
    """The lifecycle gate of a live run (module docstring).

    ``managed`` maps each managed node's contract name to its fully qualified ROS name; ``nodes``
    are the monitored nodes (their topics say which topics are a node's inputs and outputs).
    ``skew`` and ``settle`` in seconds; ``deadlines``: per managed node, transition name
    (:data:`TRANSITIONS`) -> seconds (module docstring); ``where``: per node, transition -> the
    contract clause stating that deadline (``file:line:col``, given in its rows as ``stated``).  Raises :class:`ValueError` for a managed
    node that is not monitored, a deadline of a node that is not managed, of an unknown transition
    or not a positive number.  Not thread safe: the live run calls it under its lock.
    """

    def __init__(self, managed: Mapping[str, str], nodes: Sequence[CheckedNode], *, skew: float = 0.05,
                 settle: float = 0.5, deadlines: Mapping[str, Mapping[str, float]] | None = None,
                 where: Mapping[str, Mapping[str, str]] | None = None) -> None:
        by_name = {n.name: n for n in nodes}
        unknown = sorted(set(managed) - set(by_name))
        if unknown:
            raise ValueError(f"managed node {unknown[0]!r} is not monitored (nodes: {', '.join(by_name)})")
        for node, per in (deadlines or {}).items():
            if node not in managed:
                raise ValueError(f"a transition deadline for {node!r}, which is not a managed node "
                                 f"(managed: {', '.join(managed) or 'none'})")
            for name, secs in per.items():
                if name not in TRANSITIONS:
                    raise ValueError(f"{node}: no transition {name!r} (transitions: {', '.join(TRANSITIONS)})")
                if isinstance(secs, bool) or not isinstance(secs, (int, float)) or not 0 < secs < float("inf"):
                    raise ValueError(f"{node}: the {name} deadline must be a positive number of seconds, not {secs!r}")
        self.deadlines = {n: dict(per) for n, per in (deadlines or {}).items() if per}
        #: per node, transition -> the contract clause that states its deadline (``file:line:col``)
        self.where = {n: dict(per) for n, per in (where or {}).items()}
        self.last = float("-inf")  # the latest time a message was heard (s): where the run ends
        self.skew, self.settle = skew, settle
        self.managed: dict[str, _Managed] = {}
        self.readers: dict[str, list[str]] = {}  # input topic -> every monitored node reading it
        for n in nodes:
            for t in n.node.topics:
                if t.match is not None and (t.match.prefix == "in" or (t.match.prefix is None and t.match.name in n.inputs)):
                    self.readers.setdefault(t.key, []).append(n.name)
        for name, fqn in managed.items():
            n = by_name[name]
            outs = {t.key for t in n.node.topics if t.match is not None
                    and (t.match.prefix == "out" or (t.match.prefix is None and t.match.name not in n.inputs))}
            ins = {t.key for t in n.node.topics if name in self.readers.get(t.key, ())}
            self.managed[name] = _Managed(name, fqn, outs, ins, scope_ids(n))
        self.events = {event_topic(m.fqn): m for m in self.managed.values()}
        self.pending: list[tuple[float, str, _Managed]] = []  # (received, topic, node): outputs not yet decided
        self.violations: list[dict[str, Any]] = []
        #: violations a transition event heard late withdrew, each with why (:meth:`_rejudge`)
        self.withdrawn: list[dict[str, Any]] = []
        self.outputs_judged = 0
        self.not_questions: dict[str, int] = {}
        #: transition topic -> events heard on it
        self.heard: dict[str, int] = {}

    def topics(self) -> dict[str, str]:
        """The transition topics to read (judge keys) and their message type."""
        return {t: TRANSITION_TYPE for t in self.events}

    def admit(self, topic: str, fields: Mapping[str, object], received: float) -> bool:
        """Whether the message goes on to the guarantees' judge (module docstring); a transition
        event updates its node's state; outputs older than ``settle`` are decided."""
        self._decide(received - self.settle)
        self.last = max(self.last, received)
        m = self.events.get(topic)
        if m is not None:
            goal, stamp = _get(fields, "goal_state", "id"), _get(fields, "timestamp")
            if isinstance(goal, int):
                at = stamp / 1e9 if isinstance(stamp, (int, float)) and stamp > 0 else received
                k = bisect.bisect_right(m.times, at)
                m.times.insert(k, at)
                m.states.insert(k, goal)
                m.transitions += 1
            self.heard[topic] = self.heard.get(topic, 0) + 1
            return False
        for m in self.managed.values():
            if topic in m.outputs:
                self.pending.append((received, topic, m))
        readers = self.readers.get(topic)
        if readers and all(r in self.managed and self.managed[r].now() not in self.managed[r].scope for r in readers):
            self.not_questions[topic] = self.not_questions.get(topic, 0) + 1
            return False
        return True

    def _decide(self, before: float) -> None:
        keep = []
        for received, topic, m in self.pending:
            if received > before:
                keep.append((received, topic, m))
                continue
            self.outputs_judged += 1
            m.judged += 1
            states = m.states_within(received - self.skew, received + self.skew)
            state = states[0]
            if not ACTIVE_LIKE & set(states):
                self.violations.append({"node": m.node, "ros_node": m.fqn, "topic": topic, "time": received,
                                        "state": STATES.get(state, str(state)),
                                        "reason": f"{m.fqn} published on /{topic} while {STATES.get(state, state)}, "
                                                  f"not active: its guarantees hold only while active"})
        self.pending = keep

    def _rejudge(self) -> None:
        """Each violation judged again on the node's whole state history: a transition event heard
        more than :attr:`settle` after its own time (a loaded machine, a writer later than the
        bound) reached the gate after the outputs it decides were judged.  A violation whose output
        that late event places in ``active`` or a transition into or out of it is withdrawn, with
        why (a late message never adds a violation: docs/semantics.md, "Event time"); the rest
        stand, since the states they were judged on were all heard in time."""
        kept = []
        for v in self.violations:
            m = self.managed[v["node"]]
            t = float(v["time"])
            states = m.states_within(t - self.skew, t + self.skew)
            if ACTIVE_LIKE & set(states):
                k = bisect.bisect_right(m.times, t + self.skew) - 1
                self.withdrawn.append({**v, "reason": (
                    f"withdrawn: {m.fqn}'s output on /{v['topic']} at {t:.3f} s was judged {v['state']}, but a "
                    f"transition event stamped {m.times[k]:.3f} s, heard after that output was judged, puts it "
                    f"in {STATES.get(states[-1], states[-1])}")})
            else:
                kept.append(v)
        self.violations = kept

    def counted(self, heard: Mapping[str, int]) -> dict[str, int]:
        """``heard`` (messages per topic key the judge was fed) with the messages the gate kept from
        it: the transition events and the inputs held back as no question, each heard."""
        out = dict(heard)
        for extra in (self.heard, self.not_questions):
            for topic, k in extra.items():
                out[topic] = out.get(topic, 0) + k
        return out

    def state(self, node: str) -> str:
        """The latest state heard of managed node ``node`` (its contract's name), in words."""
        s = self.managed[node].now()
        return STATES.get(s, str(s))

    def transitions(self, node: str) -> list[dict[str, Any]]:
        """The transitions of managed node ``node`` its deadlines bound, each judged (module
        docstring): ``transition``, ``start`` and ``end`` (s; ``None``: none heard), ``seconds``,
        ``within`` (s), ``status`` (``met``, ``missed``, ``open``) and ``reason``, in time order."""
        m = self.managed[node]
        out: list[dict[str, Any]] = []
        for name, within in self.deadlines.get(node, {}).items():
            into, goal = TRANSITIONS[name]
            for k, (t, st) in enumerate(zip(m.times, m.states)):
                if st != into or (k and m.states[k - 1] == into):
                    continue
                end = next(((t2, s2) for t2, s2 in zip(m.times[k + 1:], m.states[k + 1:]) if s2 != into), None)
                row: dict[str, Any] = {"transition": name, "start": t, "end": None, "seconds": None, "within": within,
                                       **({"stated": self.where[node][name]} if name in self.where.get(node, {}) else {})}
                label = f"{m.fqn}'s {name} from {t:.3f} s"
                if end is None:
                    late = self.last - t > within
                    row.update(status="missed" if late else "open",
                               reason=f"{label}: no end heard, {'more' if late else 'less'} than {within:g} s "
                                      f"before the run's end")
                else:
                    secs = end[0] - t
                    row.update(end=end[0], seconds=round(secs, 6))
                    if end[1] != goal:
                        row.update(status="missed", reason=f"{label} ended in {STATES.get(end[1], end[1])}, not "
                                                           f"{STATES[goal]}, after {secs:.3f} s")
                    else:
                        row.update(status="met" if secs <= within else "missed",
                                   reason=f"{label} reached {STATES[goal]} after {secs:.3f} s "
                                          f"({'within' if secs <= within else 'over'} its {within:g} s)")
                out.append(row)
        return sorted(out, key=lambda r: r["start"])

    def record(self, verdicts: Sequence[dict[str, Any]] = ()) -> dict[str, Any]:
        """Every pending output decided; the run's ``lifecycle`` record: per managed node its latest
        state, transitions heard, outputs judged and violations, its ``status`` ``failed`` with a
        violation, ``inconclusive`` with no output heard (silence is not green), else
        ``discharged``; and the inputs held back as no question, per topic.  Each of ``verdicts`` (the
        run's node records: ``node``, ``status``, ``explanation``) whose managed node has a violation
        is made ``failed``, its explanation saying so first: the lifecycle contract is part of the node's.
        A node with deadlines has its transitions judged (:meth:`transitions`) as ``deadlines``; one
        missed fails it as a violation does."""
        self._decide(float("inf"))
        self._rejudge()
        nodes = []
        for m in self.managed.values():
            mine = [v for v in self.violations if v["node"] == m.node]
            timed = self.transitions(m.node)
            missed = [t for t in timed if t["status"] == "missed"]
            nodes.append({"node": m.node, "ros_node": m.fqn, "state": self.state(m.node),
                          "scope": [STATES[k] for k in sorted(m.scope)],
                          "transitions": m.transitions, "outputs_judged": m.judged, "violations": mine,
                          **({"withdrawn": [v for v in self.withdrawn if v["node"] == m.node]}
                             if any(v["node"] == m.node for v in self.withdrawn) else {}),
                          **({"deadlines": timed} if m.node in self.deadlines else {}),
                          "status": "failed" if mine or missed else "discharged" if m.judged else "inconclusive"})
            for v in verdicts:
                if v.get("node") == m.node and (mine or missed):
                    v["status"] = "failed"
                    said = [f"{len(mine)} output(s) published outside active (lifecycle); the first: "
                            f"{mine[0]['reason']} (t = {mine[0]['time']:.3f} s)."] if mine else []
                    said += [f"{len(missed)} transition deadline(s) missed (lifecycle); the first: "
                             f"{missed[0]['reason']}."] if missed else []
                    v["explanation"] = " ".join([*said, str(v.get("explanation", ""))])
        return {"outputs_judged": self.outputs_judged, "not_questions": dict(sorted(self.not_questions.items())),
                "nodes": nodes}


def gated(events: Iterable[Any], gate: LifecycleGate) -> Iterator[Any]:
    """The events of a recorded run (:class:`rclverify.traces.events.Event`, in the order read) the
    ``gate`` admits, each asked at its recorded time: the pipeline's monitors backend judges a managed
    node's run through the gate the live run asks (docs/monitors.md, "Lifecycle nodes in the
    pipeline")."""
    for ev in events:
        if gate.admit(ev.topic, ev.fields, ev.time):
            yield ev


def with_lifecycle(gate: LifecycleGate | None, node: str, status: str, explanation: str
                   ) -> tuple[str, str, dict[str, Any]]:
    """A recorded run's verdict on managed node ``node`` (``status``, ``explanation``: the untimed
    check's) combined with its lifecycle record (:meth:`LifecycleGate.record`): ``failed``, its
    explanation first saying why, for an output outside ``active`` or a missed transition
    deadline; returns ``(status, explanation, {"lifecycle": record})``, the verdict unchanged and
    ``{}`` without a ``gate`` (a node that is not managed)."""
    if gate is None:
        return status, explanation, {}
    entry: dict[str, Any] = {"node": node, "status": status, "explanation": explanation}
    record = gate.record([entry])
    return str(entry["status"]), str(entry["explanation"]), {"lifecycle": record}


__all__ = ["ACTIVE", "LifecycleGate", "STATES", "TRANSITIONS", "TRANSITION_TYPE", "event_topic", "gate_of",
           "gated", "managed_of", "scope_ids", "stated_deadlines", "with_lifecycle"]
