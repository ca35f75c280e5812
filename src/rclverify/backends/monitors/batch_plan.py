"""What the offline batch path needs of a node's monitor, and whether the
node is eligible (:func:`batch_plan`; the rule is :mod:`.batch`'s module
docstring, "Eligible"; windows: :mod:`.batch_window`)."""
from __future__ import annotations

from typing import Mapping

from rclverify.traces.mapping import TopicRule
from rclverify.semantics.robustness import atom_words
from rclverify.targets.column_margins import ColumnMargin
from rclverify.targets.column_windows import WindowCompiler, WindowMargins, is_window
from rclverify.targets.columns import Unsupported, io_kind
from rclverify.backends.monitors.batch_window import answer_only, mappers
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.backends.monitors.needs_answer import answer_decides


class BatchPlan:
    """What the batch path needs of an eligible node's monitor ``m``: its input
    topics (topic -> (key, field, kind)), its output topic and key, the
    compiled assumptions and guarantees; ``widths``: each window variable's offsets read, ``mapped``: its
    message's value as the engine maps it (:mod:`.batch_window`)."""

    def __init__(self, m: NodeMonitor, rules: Mapping[str, TopicRule], compiler: WindowCompiler) -> None:
        self.m = m
        self.inputs: dict[str, tuple[str, str, str]] = {}
        self.output: tuple[str, str, str, str] = ("", "", "", "")
        for topic, vs in m.topics.items():
            (key, typ, is_input), = vs
            rule = rules.get(topic)
            kind = io_kind(typ) or ("window" if is_window(typ) else None)
            if rule is None or len(rule.fields) != 1 or not rule.fields[0].isidentifier() or rule.state or \
                    kind is None:  # a field path is read by the general mapper: every message would be streamed
                raise Unsupported(f"topic {topic}: not one REAL/enumeration/window field named at the top level")
            if is_input:
                self.inputs[topic] = (key, rule.fields[0], kind)
            elif self.output[0]:
                raise Unsupported("more than one output topic")
            else:
                self.output = (topic, key, rule.fields[0], kind)
        self.keys = [k for k, _, _ in self.inputs.values()]
        #: the message fields the columns read (a log read in blocks decodes them: rows.py)
        self.fields = [f for _, f, _ in self.inputs.values()] + [self.output[2]]
        if not self.output[0] or not self.inputs or len(set(self.keys)) != len(self.keys) or \
                sorted(self.keys) != sorted(m._in_keys) or not set(m.needed_inputs) <= set(self.keys):
            raise Unsupported("inputs and output not one topic each")
        #: enumeration-valued keys -> the code of each value of their type (a value of no other type)
        self.enums = {key: {v: compiler.codes[v] for v in typ.values if v in compiler.codes}
                      for vs in m.topics.values() for key, typ, _ in vs if io_kind(typ) == "enum"}
        self.codes = compiler.codes
        self.formulas = [compiler.compile(f) for f in m.assumption + m.guarantees]
        self.mapped = mappers(m.node, m.topics, rules)
        #: window keys -> the offsets their column holds (every window variable is read: else the engine's)
        self.widths = dict(compiler.widths)
        if set(self.widths) != set(self.mapped):
            raise Unsupported("a window variable no formula reads at an offset")
        #: ``triggered by``: the one input every triggered guarantee answers, when one input triggers them all, else ""
        self.trigger = ""
        #: ``triggered by``: guarantee -> its trigger input (several inputs may trigger: a question owes a guarantee
        #: its own message triggers, any other only as carried, which the engine decides: batch.py)
        self.triggers: dict[int, str] = dict(m._trigger)
        if m._trigger:
            tks = set(m._trigger.values())
            if not tks <= set(self.keys):
                raise Unsupported("a guarantee triggered by no input of its own topic")
            if len(tks) == 1:
                self.trigger = next(iter(tks))
        #: the question's evaluation decides nothing (needs_answer.py's Z3 answer, or batch_window.answer_only);
        #: the engine evaluates a triggered node's questions without asking Z3: asked here (a trigger only
        #: narrows which guarantees a question owes, so no input deciding any of them decides none it owes)
        if m._ask_at_question and not (self.widths and all(answer_only(m.guarantees[k - 1], m.node)
                                                            for k in m._asked)) and \
                not (self.triggers and not self.widths and answer_decides(m.checked, m.node, m.guarantees)):
            raise Unsupported("a question's inputs may decide a guarantee")
        self.asked = set(m._asked)
        #: with margins: each guarantee's margin over the columns, and the (text, unit) of each deciding comparison
        self.margins: list[ColumnMargin] = []
        #: the same margins without their deciding atoms (``None``): the runs of pairs read a row's atom only
        #: where they note it (column_margins.RowAtoms)
        self.margin_values: list[ColumnMargin] = []
        self.atoms: list[tuple[str, str]] = []
        if m.margins:
            margins = WindowMargins(compiler)
            self.margins = [margins.compile(g) for g in m.guarantees]
            self.atoms = [atom_words(m.checked, m.node, e, i) for e, i in margins.atoms]
            values = WindowMargins(compiler, track=False)
            self.margin_values = [values.compile(g) for g in m.guarantees]


def batch_plan(m: NodeMonitor, rules: Mapping[str, TopicRule]) -> BatchPlan | None:
    """The batch plan of monitor ``m`` when its node is eligible (module docstring), else ``None``."""
    node = m.node
    ks = range(1, len(m.guarantees) + 1)
    if node.node.links or m._state_outs or not m.has_inputs or m.unbound or \
            any(len(vs) != 1 for vs in m.topics.values()) or \
            any(not m._reads_out[k] for k in ks) or sorted(m._asked + m._alone) != list(ks):
        return None
    try:
        plan = BatchPlan(m, rules, WindowCompiler(m.checked, node))
    except (Unsupported, ValueError):
        return None
    return plan


__all__ = ["BatchPlan", "batch_plan"]
