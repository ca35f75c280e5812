"""What the batch deadline judge needs of a node, and whether the node is eligible
(:mod:`.batch_deadlines`'s module docstring, "Eligible")."""
from __future__ import annotations

from typing import Any

from rclverify.core.numeric import np

from rclverify.targets.column_deadlines import Judge
from rclverify.targets.columns import ColumnCompiler, Compiled, Unsupported, io_kind
from rclverify.traces.mapping import rule_for
from rclverify.traces.sim_clock import CLOCK_TOPIC
from rclverify.backends.monitors.deadlines import DeadlineMonitor


class DeadlinePlan:
    """The input's and the output's topic, key, message field and column kind (``real`` or ``enum``),
    each enumeration's codes, the compiled assumptions, and per timed guarantee ``(k, bound in ns,
    bound in s, its compiled formula or None when no output answers it)``.  Raises
    :class:`~rclverify.targets.columns.Unsupported` for a node that is not eligible."""

    def __init__(self, m: DeadlineMonitor) -> None:
        node = m.node
        if m.tolerance is not None or node.node.links or m.state_outs or not m.timed:
            raise Unsupported("a tolerance, a link, a state output or no timed guarantee")
        if len(node.inputs) != 1 or len(node.outputs) != 1:
            raise Unsupported("not one input and one output variable")
        ends: dict[str, tuple[str, str, str, str]] = {}
        for topic, keys in m.bindings.items():
            if len(keys) != 1 or keys[0][1]:
                raise Unsupported(f"topic {topic}: not one variable of the whole message")
            key = keys[0][0]
            side = key.split(".", 1)[0]
            typ = node.inputs.get(key[3:]) if side == "in" else node.outputs.get(key[4:])
            rule = rule_for(m.rules, topic, key)
            kind = io_kind(typ)
            if side in ends or kind is None or len(rule.fields) != 1 or not rule.fields[0].isidentifier() or \
                    rule.state:
                raise Unsupported(f"topic {topic}: not one REAL/enumeration field named at the top level")
            ends[side] = (topic, key, rule.fields[0], kind)
        if set(ends) != {"in", "out"}:
            raise Unsupported("the input or the output has no topic")
        self.in_topic, self.in_key, self.in_field, self.in_kind = ends["in"]
        self.out_topic, self.out_key, self.out_field, self.out_kind = ends["out"]
        compiler = ColumnCompiler(m.checked, node)
        self.codes: dict[str, dict[str, int]] = {}
        for key, kind in ((self.in_key, self.in_kind), (self.out_key, self.out_kind)):
            typ = node.inputs.get(key[3:]) if key.startswith("in.") else node.outputs.get(key[4:])
            if kind == "enum":
                self.codes[key] = {v: compiler.codes[v] for v in getattr(typ, "values", ()) if v in compiler.codes}
        self.assumptions: list[Compiled] = [compiler.compile(f) for f in m.assumption]
        probe = {self.in_key: np.zeros(1, dtype=np.float64 if self.in_kind == "real" else np.int64)}
        try:
            for a in self.assumptions:  # an assumption that reads an output is judged on no value of it
                a(probe)
        except KeyError as exc:
            raise Unsupported("an assumption reads an output") from exc
        self.timed: list[tuple[int, int, float, Judge | None]] = []
        for k, cl, trig, outs, d in m.timed:
            if trig != self.in_key:
                raise Unsupported(f"guarantee {k}: triggered by another variable than the input")
            self.timed.append((k, m.bounds_ns[k], d, compiler.compile(cl.formula) if self.out_key in outs else None))
        #: each guarantee's place in :attr:`timed`
        self.place = {k: g for g, (k, _, _, _) in enumerate(self.timed)}

    @classmethod
    def of(cls, m: DeadlineMonitor) -> DeadlinePlan | None:
        """The plan of ``m``'s node, ``None`` when it is not eligible."""
        try:
            return cls(m)
        except (Unsupported, ValueError, KeyError):
            return None

    def kind_of(self, topic: str) -> int:
        """A row's topic as its column code: 1 the input's, -1 the output's, 0 another topic; 2 for the
        node's topic written otherwise (a leading ``/``: mapped by another rule, streamed) and for ``/clock``
        (a simulated clock the streaming monitor reads: :mod:`.deadline_clock`)."""
        if topic == self.in_topic:
            return 1
        if topic == self.out_topic:
            return -1
        return 2 if topic.lstrip("/") in (self.in_topic, self.out_topic, CLOCK_TOPIC) else 0

    def seed(self, key: str, value: Any) -> Any:
        """A value the monitor holds as a column entry (a finite float, an enumeration's code), else None."""
        codes = self.codes.get(key)
        if codes is not None:
            return codes.get(value) if type(value) is str else None
        return value if type(value) is float and np.isfinite(value) else None


__all__ = ["DeadlinePlan"]
