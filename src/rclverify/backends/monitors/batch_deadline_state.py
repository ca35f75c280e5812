"""What the batch deadline judge's chunk side (:mod:`.batch_deadline_chunk`) asks of
the deadline monitor it judges for (:class:`~.batch_deadlines.BatchDeadlines`): a
message's mapped value, the streaming monitor's words for a rejected output (its
verdicts it builds as the streaming monitor does: :class:`~.deadlines.DeadlineMonitor`), and
the state a clean chunk leaves (docs/semantics.md, "Deadlines")."""
from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Callable, Mapping

from rclverify.semantics.floatsem import judge
from rclverify.traces.events import Event
from rclverify.traces.mapping import rule_for, value_mapper
from rclverify.backends.monitors.deadline_records import Pending
from rclverify.backends.monitors.deadlines import DeadlineMonitor, rejected

if TYPE_CHECKING:
    from rclverify.backends.monitors.batch_deadline_plan import DeadlinePlan


class ChunkSide(DeadlineMonitor):
    """The deadline monitor as the chunk judge reads and updates it; ``plan``
    is the node's :class:`~.batch_deadline_plan.DeadlinePlan`."""

    plan: "DeadlinePlan"
    #: (topic, key) -> that variable's mapper on that topic (traces/mapping.py ``value_mapper``), made once
    _mappers: dict[tuple[str, str], Callable[[Mapping[str, object], object], object]] | None = None

    # -- what the chunk judge gives the monitor ---------------------------------------------
    def mapped(self, ev: Event, key: str) -> object:
        """The value variable ``key`` takes from message ``ev`` as :meth:`feed` maps it (``value_mapper``:
        ``map_value``'s values and errors, its rule read once per topic)."""
        mappers = self._mappers
        if mappers is None:
            mappers = self._mappers = {}
        mapper = mappers.get((ev.topic, key))
        if mapper is None:
            typ = self.node.inputs[key[3:]] if key.startswith("in.") else self.node.outputs[key[4:]]
            mapper = mappers[(ev.topic, key)] = value_mapper(typ, rule_for(self.rules, ev.topic, key))
        fields = ev.fields
        if "header" in fields:
            fields = {k: v for k, v in fields.items() if k != "header"}
        return mapper(fields, None)

    def rejection(self, k: int, inputs: Mapping[str, object], out_key: str, out: Event) -> str:
        """Why output ``out`` did not answer an obligation of guarantee ``k`` on ``inputs``
        (:meth:`~.deadlines.DeadlineMonitor._try`'s words)."""
        cl = self.node.node.guarantees[k - 1]
        values = {**inputs, out_key: self.mapped(out, out_key)}
        return rejected(k, out, judge(cl.formula, self.checked, self.node, values, self.tolerance))

    def take_state(self, pending: list[Pending], expired: list[Pending], values: Mapping[str, object],
                   heard: list[tuple[int, Event, set[str], dict[str, object]]], now_ns: int) -> None:
        """The state a clean chunk leaves: open and expired obligations, the latest values, the last
        outputs heard, the clock."""
        self.pending = pending
        self.expired = deque(expired, maxlen=self.expired.maxlen)
        for key, v in values.items():
            self.values[key] = v
            self.invalid.pop(key, None)
        self.heard.extend(heard)
        if self.now_ns is None or now_ns > self.now_ns:
            self.now_ns = now_ns
            self.now = now_ns / 1e9


__all__ = ["ChunkSide"]
