"""The step of the composed system each message of a recorded run belongs
to (docs/semantics.md, "Steps"), for a temporal requirement checked on it
(:mod:`.temporal_trace`): :class:`StepClock` over the topics of a
statement's cone (:func:`cone_of`: the nodes it reads and every node
upstream of them).  The states of those steps are :mod:`.trace_states`'.
"""
from __future__ import annotations

from typing import Iterable

from rclverify.lang.types import Checked
from rclverify.traces.events import Event
from rclverify.backends.monitors.deadline_topics import topic_bindings


def cone_of(checked: Checked, nodes: Iterable[str]) -> list[str]:
    """``nodes`` and every node upstream of them: a node that publishes on a
    topic (or a link part) one of them reads, and so on (the requirement's
    cone, docs/requirements.md, "Temporal requirements"), in ``checked``'s
    order."""
    binds = {n: topic_bindings(cn) for n, cn in checked.nodes.items()}
    producers: dict[str, set[str]] = {}
    for n, b in binds.items():
        for topic, keys in b.items():
            if any(k.startswith("out.") for k, _ in keys):
                producers.setdefault(topic, set()).add(n)
    cone, todo = set(nodes), list(nodes)
    while todo:
        for topic, keys in binds.get(todo.pop(), {}).items():
            if any(k.startswith("in.") for k, _ in keys):
                for p in producers.get(topic, ()):
                    if p not in cone:
                        cone.add(p)
                        todo.append(p)
    return [n for n in checked.nodes if n in cone]



class StepClock:
    """The step of the composed system each message of a run belongs to
    (docs/semantics.md, "Steps"; :mod:`.temporal_trace`'s docstring), over
    the topics and link parts of the nodes ``nodes`` (a statement's cone,
    :func:`cone_of`).

    In a step every node takes its current input and answers it or not, and
    a node reads another's output in the step after it was published
    (:mod:`rclverify.calculus.requirements.transition`).  On a run:

    * an output belongs to the step of the input its node answers (the
      latest it took), or to the current step when that is later (a late
      answer); a node answers once per step, with all its outputs: another
      output on a topic it published in that step already is the next
      step's;
    * a node reads an output of another node of ``nodes`` in the step after
      it, and an input from outside them (the environment's) in the current
      step; an input of a node that has published in that step already is
      its input of the next step (its output ended the instant); inputs of
      one node in one step are one instant: on different topics, and from
      the environment within ``skew`` seconds of the step's first; another
      message on the same topic, or one later than the skew, is the node's
      next step, and a new step of the system when it came from the
      environment;
    * a step is over when a message of a later step comes; steps never go
      back.

    So a question and its answer are one step, an answer read by another
    node and that node's answer the next, and inputs that come at once one."""

    def __init__(self, checked: Checked, nodes: Iterable[str], skew: float = 0.0) -> None:
        self.skew = skew
        self.roles: dict[str, tuple[frozenset[str], frozenset[str]]] = {}  # topic -> (producers, readers)
        roles: dict[str, tuple[set[str], set[str]]] = {}
        for n in nodes:
            for topic, keys in topic_bindings(checked.nodes[n]).items():
                prod, read = roles.setdefault(topic, (set(), set()))
                for k, _ in keys:
                    (prod if k.startswith("out.") else read).add(n)
        self.roles = {t: (frozenset(p), frozenset(r)) for t, (p, r) in roles.items()}
        self.step = -1
        self.took: dict[str, int] = {}  # node -> the step of its latest input
        self.took_topics: dict[str, set[str]] = {}
        self.took_at: dict[str, float] = {}  # node -> the time of its latest step's first input
        self.answered: dict[str, int] = {}  # node -> the step of its latest output
        self.answered_topics: dict[str, set[str]] = {}  # node -> the topics of its outputs in that step

    def tick(self, ev: Event) -> tuple[int, frozenset[str]] | None:
        """``(step, later)``: the step message ``ev`` belongs to and the
        nodes that read it as an input only from the next step on; ``None``
        when it is on no topic of the nodes (no step)."""
        topic = ev.topic.strip("/")
        roles = self.roles.get(topic)
        if roles is None:
            return None
        prod, read = roles
        t = ev.stamped
        at = max(self.step, 0)
        for p in sorted(prod):
            a = max(at, self.took.get(p, 0))
            at = a + 1 if self.answered.get(p) == a and topic in self.answered_topics[p] else a
        for p in prod:
            if self.answered.get(p) != at:
                self.answered_topics[p] = set()
            self.answered[p] = at
            self.answered_topics[p].add(topic)
        reads: dict[str, int] = {}
        for n in sorted(read - prod if prod else read):
            r, deferred = self._input_step(n, at + 1 if prod else at, topic, t, bool(prod))
            reads[n] = r
            at = max(at, r - 1 if deferred else r)
        self.step = at
        return at, frozenset(n for n, r in reads.items() if r > at)

    def _input_step(self, n: str, r: int, topic: str, t: float, fed: bool) -> tuple[int, bool]:
        """The step in which ``n`` takes an input on ``topic`` at ``t``, from step ``r`` on (``fed``: from
        another node of the clock), and whether it is deferred (read after the message's step: fed, or
        ``n`` published in that step already, or it joins a step ``n`` takes later)."""
        deferred = fed
        if self.answered.get(n, -1) >= r:
            r, deferred = self.answered[n] + 1, True
        k = self.took.get(n)
        if k is not None and k > r:
            r, deferred = k, True
        if k == r:
            joins = (topic not in self.took_topics[n]
                     and (deferred or t - self.took_at[n] < self.skew))
            if joins:
                self.took_topics[n].add(topic)
                return r, deferred
            r += 1
        self.took[n], self.took_topics[n], self.took_at[n] = r, {topic}, t
        return r, deferred


__all__ = ["StepClock", "cone_of"]
