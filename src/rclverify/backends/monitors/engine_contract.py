"""What the verdict engine (:mod:`.engine`) reads from a node's contract before
its first message: the formulas, triggers and texts, the variables an input
question needs and those no topic carries, and which guarantees are asked
of a question, which judged alone, and which a message on each topic
touches (docs/semantics.md, "Questions")."""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import CheckedNode
from rclverify.traces.mapping import TopicRule
from rclverify.backends.monitors.engine_state import EngineState
from rclverify.backends.monitors.first_messages import FirstMessages
from rclverify.backends.monitors.verdicts import names, reads

_NO_RULE = TopicRule()  # the rule of a topic the mapping does not name


class ContractReading(EngineState):
    """The contract-reading part of :class:`~.engine.NodeMonitor`: called once,
    by its constructor, after the topics and values are set."""

    topics: dict[str, list[tuple[str, Any, bool]]]
    has_inputs: bool

    def _read_contract(self, node: CheckedNode) -> None:
        """The contract's formulas, triggers and texts, and the variables it
        reads: those an input question needs and those no topic carries."""
        self.assumption = tuple(c.formula for c in node.node.assumes)
        self.guarantees = tuple(c.formula for c in node.node.guarantees)
        #: guarantee k -> ``in.x`` for ``triggered by in.x``: it answers the messages of that input only
        self._trigger = {k: f"in.{c.trigger.name}" for k, c in enumerate(node.node.guarantees, 1)
                         if c.trigger is not None}
        self._triggers = frozenset(self._trigger.values())
        #: ``first(in.x)`` of the contract: its value per message (first_messages.py)
        self.first = FirstMessages(self.assumption + self.guarantees)
        self.values.update(dict.fromkeys(self.first.keys))
        self._texts = {k: expr_to_rcl(f) for k, f in enumerate(self.guarantees, 1)}
        self._renders: dict[int, tuple[Any, str]] = {}
        needed: set[str] = set()
        for f in self.assumption + self.guarantees:
            names(f, needed)
        self.needed_inputs = sorted(k for k in self.values if k.startswith("in.") and
                                    (k in needed or k[3:] in needed))
        #: variables the contract reads that no topic or link part carries: no run gives them a value
        self.unbound = sorted(f"{p}.{v}" for p, names_ in (("in", node.inputs), ("out", node.outputs))
                              for v in names_ if f"{p}.{v}" not in self.values and (v in needed or f"{p}.{v}" in needed))

    def _sort_guarantees(self, rules: Mapping[str, TopicRule]) -> None:
        """Which variables each formula reads, which guarantees are asked of a
        question and which judged alone, and per topic those a message on it touches."""
        outputs = sorted(k for k in self.values if k.startswith("out."))
        event_outs = {key for topic, vs in self.topics.items() for key, _, inp in vs
                      if not inp and not rules.get(topic, _NO_RULE).state}
        #: outputs on state topics: their current value stands in for every question
        self._state_outs = [k for k in outputs if k not in event_outs]
        self._state_set = frozenset(self._state_outs)
        self._in_keys = [k for k in self.values if k.startswith("in.")] + list(self.first.keys)
        self._deps: dict[Any, tuple[str, ...]] = {}
        for k, f in [(("A", j), f) for j, f in enumerate(self.assumption)] + list(enumerate(self.guarantees, 1)):
            mentioned: set[str] = set()
            reads(f, mentioned)
            self._deps[k] = tuple(v for v in sorted(self.values) if v in mentioned or v.split(".", 1)[1] in mentioned
                                  or v in self.first.keys)
        ks = range(1, len(self.guarantees) + 1)
        #: guarantees judged against a question (they read an input or answer a trigger) and those judged alone
        self._asked = [k for k in ks if self.has_inputs and (k in self._trigger or
                                                            any(d.startswith("in.") for d in self._deps[k]))]
        self._alone = [k for k in ks if k not in self._asked]
        gouts = {k: {d for d in self._deps[k] if d.startswith("out.")} for k in ks}
        #: per topic: the guarantees a message on it touches (they read an output it sets)
        self._touch = {topic: ([k for k in self._asked if gouts[k] & set(outs)],
                               [k for k in self._alone if gouts[k] & set(outs)])
                       for topic, (_, outs) in self._topic_io.items()}
        self._reads_out = {k: bool(gouts[k]) for k in ks}
        #: per topic, the one guarantee a message on it touches when that is all there is to judge (no
        #: trigger, no output-only guarantee): the engine's fast path (0: none)
        self._single = {topic: (asked[0] if len(asked) == 1 and not alone and not self._trigger else 0)
                        for topic, (asked, alone) in self._touch.items()}
        #: the guarantees an answered question must see decided (they read an output)
        self._need = [k for k in self._asked if gouts[k]]


__all__ = ["ContractReading"]
