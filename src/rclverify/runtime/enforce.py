"""``--enforce``: the monitor as a filter between a node and its consumers
(ROSMonitoring 3's ``filter`` action).

``rclverify monitor --live --ros2 --enforce /cmd`` (or ``/cmd:=/cmd_raw``):
the node's output ``/cmd`` is remapped, when the node is started, to a
private name (``/cmd_unchecked`` unless one is given: ``ros2 run pkg node
--ros-args -r /cmd:=/cmd_unchecked``); the monitor reads the private topic
as the contract's ``/cmd`` and publishes each message under the real name
only when the node's guarantees hold on it (its bytes unchanged, with the
QoS the node's publisher offers).  A message is judged when the engine
releases it (after the reorder window), on the node's state as the engine
has it then: the latest inputs, the outputs with this message's value
(:func:`judge`), by the evaluator every verdict uses
(:func:`~rclverify.semantics.decide.decide`: direct evaluation, Z3 where that
cannot decide).  It is released only when every guarantee that reads the
topic's variable is true; ``false`` blocks it (``violated``, with the
guarantee and the values), and so does a guarantee that cannot be decided
or an input the guarantee reads that has not been received yet, or whose
latest message did not map (a NaN or an infinity, which no guarantee can
be judged on: the value in force before it is stale, and judging against
it released 0.9 after ``limit = NaN``) (``inconclusive``,
``incomplete input``): a filter lets through what is shown to hold, not what
is not shown to fail (it fails closed).  The policy is per topic:
``--enforce /cmd@open`` releases what cannot be decided (it still blocks
what is false), for a consumer that must not starve; the evidence counts
those releases apart (``released_undecided``).  The assumption is not
consulted: a message that breaks the guarantee is held back even when the
inputs broke the assumption.

Every blocked message is a line of the log (``{"topic":
"rclverify/blocked", "kind": "blocked", ...}`` with its verdict, which no
contract names) and a verdict on the verdict topic; the evidence record
counts what was released and blocked per guarded topic.  The engine still
checks every message the node produced, the blocked ones included (they are
its output); a contract that reads the guarded topic as its input sees them
too (docs/monitors.md, "Enforcement").
"""
from __future__ import annotations

from typing import Any, Callable, Mapping, Sequence

from rclverify.semantics.decide import decide
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.walk import subexpressions
from rclverify.traces.events import Event
from rclverify.traces.mapping import MappingError, TopicRule, map_value, rule_for
from rclverify.semantics.values import render
from rclverify.runtime.live import LiveRun, dumps
from rclverify.runtime.shapes import BlockVerdict, GateCounts

BLOCKED_LOG_TOPIC = "rclverify/blocked"


class EnforceUsage(ValueError):
    """A malformed ``--enforce`` argument."""


def parse_enforce(items: Sequence[str]) -> dict[str, str]:
    """``["/cmd", "/speed:=/speed_raw"]`` -> ``{"cmd": "/cmd_unchecked",
    "speed": "/speed_raw"}`` (contract topic without ``/`` -> private ROS
    name).  Raises :class:`EnforceUsage` for an empty name or a private name
    equal to the real one."""
    out: dict[str, str] = {}
    for it in items:
        real, sep, private = it.strip().removesuffix("@open").partition(":=")
        real = real.strip().strip("/")
        private = "/" + (private.strip().strip("/") if sep else real + "_unchecked")
        if not real or private == "/":
            raise EnforceUsage(f"--enforce {it!r}: write TOPIC or TOPIC:=PRIVATE, e.g. --enforce /cmd:=/cmd_unchecked")
        if private == "/" + real:
            raise EnforceUsage(f"--enforce {it!r}: the private name must differ from the topic it guards")
        out[real] = private
    return out


def fail_open(items: Sequence[str]) -> frozenset[str]:
    """The guarded topics (without ``/``) written ``TOPIC@open`` (module
    docstring): undecided messages are released there."""
    return frozenset(it.split(":=", 1)[0].strip().removesuffix("@open").strip("/") for it in items
                     if it.strip().endswith("@open"))


def _reads(formula: ast.Expr) -> set[str]:
    names: set[str] = set()
    for e in subexpressions(formula):
        if isinstance(e, ast.Var):
            names.update((e.qualified, e.name))
    return names


def judge(monitors: Sequence[Any], checked: Any, ev: Event,
          rules: Mapping[str, TopicRule]) -> tuple[bool, BlockVerdict]:
    """Whether message ``ev`` of a guarded topic may pass (module docstring),
    on the node monitors' state before it; returns ``(release, verdict)``,
    the verdict a dict (``node``, ``verdict``, ``guarantee``, ``formula``,
    ``values``, ``reason``) of the first guarantee that blocks it (``{}``
    when released)."""
    judged = False
    for m in monitors:
        outs = [(key, typ) for key, typ, is_input in m.topics.get(ev.topic, []) if not is_input]
        if not outs:
            continue
        values = {k: v for k, v in m.values.items() if v is not None}
        try:
            for key, typ in outs:
                values[key] = map_value(typ, ev.fields, rule_for(rules, ev.topic, key), m.values.get(key))
        except MappingError as exc:
            return False, {"node": m.node.name, "verdict": "inconclusive", "guarantee": 0, "formula": "",
                           "values": {}, "reason": f"the message does not map to {outs[0][0]}: {exc}"}
        wanted = {key for key, _ in outs} | {key.split(".", 1)[1] for key, _ in outs}
        for k, formula in enumerate(m.guarantees, 1):
            reads = _reads(formula)
            if not reads & wanted:
                continue
            judged = True
            shown = {n: render(v) for n, v in sorted(values.items()) if n in reads or n.split(".", 1)[1] in reads}
            missing = sorted(n for n in m.needed_inputs if n not in values and (n in reads or n[3:] in reads))
            stale = sorted(n for n in getattr(m, "invalid", {}) if n.startswith("in.") and (n in reads or n[3:] in reads))
            if stale:
                return False, {"node": m.node.name, "verdict": "inconclusive", "guarantee": k,
                               "formula": expr_to_rcl(formula), "values": shown,
                               "reason": f"{stale[0]}: {m.invalid[stale[0]]}; the value in force is stale, so "
                                         f"guarantee {k} cannot be judged (held back: the gate fails closed)"}
            if missing:
                return False, {"node": m.node.name, "verdict": "incomplete input", "guarantee": k,
                               "formula": expr_to_rcl(formula), "values": shown,
                               "reason": "no value yet for " + ", ".join(missing)}
            try:
                ok, why = decide(formula, checked, m.node, values)
            except Exception as exc:  # noqa: BLE001 - a value Z3 cannot take: undecided, so held back
                ok, why = None, f"{type(exc).__name__}: {exc}"
            if ok is not True:
                return False, {"node": m.node.name, "verdict": "violated" if ok is False else "inconclusive",
                               "guarantee": k, "formula": expr_to_rcl(formula), "values": shown,
                               "reason": (f"guarantee {k} is false on this message" if ok is False
                                          else f"guarantee {k} cannot be decided on this message: {why}")}
    if not judged:
        return False, {"node": "", "verdict": "inconclusive", "guarantee": 0, "formula": "", "values": {},
                       "reason": f"no monitored node's guarantee reads the output {ev.topic}"}
    return True, {}


class EnforcingRun(LiveRun):
    """A :class:`~.live.LiveRun` that also gates the guarded topics (module
    docstring).  ``guarded``: contract topic -> private ROS name;
    ``release(topic, raw)`` republishes a message's bytes under the real
    name.  :meth:`stash` keeps a message's bytes until the engine releases it."""

    def __init__(self, *args: Any, guarded: Mapping[str, str], release: Callable[[str, bytes], None],
                 open_topics: frozenset[str] = frozenset(), **kw: Any) -> None:
        self.guarded, self.release = dict(guarded), release
        self.open_topics = open_topics
        self._raw: dict[int, bytes] = {}
        self.gate_counts: dict[str, GateCounts] = {t: _gate(p, t in open_topics) for t, p in self.guarded.items()}
        super().__init__(*args, **kw)

    def stash(self, fields: Any, raw: bytes) -> None:
        """Keep ``raw`` for the message whose decoded fields are ``fields`` (the
        same object the engine will release)."""
        self._raw[id(fields)] = raw

    def _event(self, ev: Event) -> None:
        super()._event(ev)
        if ev.topic not in self.guarded:
            return
        raw = self._raw.pop(id(ev.fields), None)
        ok, verdict = judge(self.engine.monitors, self.engine.checked, ev, self.engine.rules)
        counts = self.gate_counts[ev.topic]
        undecided = not ok and verdict.get("verdict") in ("inconclusive", "incomplete input")
        if raw is not None and (ok or (undecided and ev.topic in self.open_topics)):
            self.release(ev.topic, raw)
            counts["released"] += 1
            if not ok:
                counts["released_undecided"] += 1
            return
        counts["blocked"] += 1
        why: BlockVerdict = verdict or {"verdict": "inconclusive", "reason": "its bytes were lost"}
        self._log.write(dumps({"topic": BLOCKED_LOG_TOPIC, "time": ev.time, "kind": "blocked", "guarded": ev.topic,
                               "where": ev.where, "verdict": why}) + "\n")
        if self.publish is not None:
            self.publish(dumps({"kind": "blocked", "topic": ev.topic, "where": ev.where, "time": ev.time, **why}))


def _gate(private: str, open_gate: bool) -> GateCounts:
    """A gate's counts before its first message (an open gate also counts what it released undecided)."""
    counts: GateCounts = {"private": private, "released": 0, "blocked": 0, "policy": "open" if open_gate else "closed"}
    if open_gate:
        counts["released_undecided"] = 0
    return counts


__all__ = ["BLOCKED_LOG_TOPIC", "EnforceUsage", "EnforcingRun", "fail_open", "judge", "parse_enforce"]
