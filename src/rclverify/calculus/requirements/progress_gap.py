"""A lasso that rests on a node that never answers: the missing progress, named.

Without a ``progress`` declaration a node may answer late or never
(:mod:`.transition`), so an unbounded ``eventually`` is often refuted by a
lasso in which some node's assumption holds at a step of the loop but the
node answers at none: it *could* be the run of a node that hangs, but it is
more often a declaration the user left out.  :func:`explain_idle` asks the
lasso search again over the same system with every node answering every
input it accepts at once (as if each declared ``progress( within 0 steps
)``, :meth:`.composed.ComposedSystem.synchronous`: the easiest query for
Z3, and the reading before progress could be declared), then, if that finds
none, with every node held to fairness (as if each declared ``progress(
eventually )``, :meth:`.composed.ComposedSystem.fair_everywhere`):

* a lasso there too: the goal is missed even though every node answers
  what it accepts; that lasso is the counterexample (it is a run of the
  declared system as well: fairness only removes runs);
* none (or undecided): the first lasso stands, and its idle nodes are named
  with the declaration that would exclude it (``missing_progress``, which
  the record, the roll-up's note and the diagnosis's culprit read:
  :mod:`rclverify.diagnosis.liveness`).

A lasso may also be *stuck* (:func:`stuck_in_loop`): nodes whose
assumption fails at every step of the loop, because an input they read
keeps the value its producer's output had before the run (the producer
never answers, and declares no ``initially``) -- in a loop of nodes each
waiting for the other, no node ever answers.  Those producers are named
(``missing_initially``) with the initial value to declare.

Source of the rule: fairness as the constraint that removes the runs of a
process that stops answering (Manna and Pnueli, "The Temporal Logic of
Reactive and Concurrent Systems", 1992, ch. 3; SPIN's weak fairness, NuSMV's
FAIRNESS/COMPASSION declarations).
"""
from __future__ import annotations

from typing import Any, Callable, Mapping, Sequence

from rclverify.lang.liveness import progress_words
from rclverify.lang.types import Checked
from rclverify.calculus.requirements.composed import ComposedSystem
from rclverify.calculus.requirements.tsys import TemporalVerdict, TransitionSystem
from rclverify.calculus.shapes import Gaps, IdleNode, MissingProgress, StuckProducer

_TRUE = ("True", "TRUE", "true")
#: What a lasso found with every node answering what it accepts adds to its detail.
EVEN_SO = "every node that accepts its input in the loop answers there: the goal is missed even with progress"


def idle_in_loop(trace: Sequence[Mapping[str, str]], loop: int | None, sys: ComposedSystem) -> list[IdleNode]:
    """The nodes of ``sys`` that accept their input at some step of the
    lasso's loop (steps ``loop`` .. ``len(trace) - 2``; the last state is
    the loop state again) and answer at none: ``[{"node", "accepted_at":
    [steps]}]`` in the cone's order.  ``trace`` is a verdict's (one
    ``{variable: text}`` per step)."""
    if loop is None or not trace:
        return []
    out: list[IdleNode] = []
    ring = range(loop, len(trace) - 1) or range(loop, loop + 1)
    for n in sys.cone:
        if f"{n}.answers" not in sys.variables:
            continue
        accepted = [i for i in ring if str(trace[i].get(f"{n}.accepts", "True")) in _TRUE
                    and all(str(trace[i].get(f)) in _TRUE for f in sys.pub.fed.get(n, ()))]
        if accepted and not any(str(trace[i].get(f"{n}.answers")) in _TRUE for i in ring):
            out.append({"node": n, "accepted_at": accepted})
    return out


def stuck_in_loop(trace: Sequence[Mapping[str, str]], loop: int | None, sys: ComposedSystem,
                  checked: Checked) -> list[StuckProducer]:
    """The producers that keep a lasso stuck (module docstring): a node
    whose assumption fails at every step of the loop reads an input whose
    producer answers at no step of the whole run and declares no
    ``initially``.  ``[{"node" (the producer), "source" (its header),
    "output" (``out.y``), "value" (the value it keeps), "consumer"
    (``Node.in.x``)}]``, one per producer output, in the cone's order."""
    if loop is None or not trace:
        return []
    ring = range(loop, len(trace) - 1) or range(loop, loop + 1)
    def enabled(n: str, i: int) -> bool:  # its assumption holds on inputs that were all published
        return (str(trace[i].get(f"{n}.accepts", "True")) in _TRUE
                and all(str(trace[i].get(f)) in _TRUE for f in sys.pub.fed.get(n, ())))
    stuck = {n for n in sys.cone if (f"{n}.accepts" in sys.variables or sys.pub.fed.get(n))
             and not any(enabled(n, i) for i in ring)}
    out: list[StuckProducer] = []
    seen: set[str] = set()
    for consumer, producer in sys.links:
        c_node, p_node = consumer.split(".", 1)[0], producer.split(".", 1)[0]
        if c_node not in stuck or producer in seen or f"{p_node}.answers" not in sys.variables:
            continue
        node = checked.nodes[p_node].node
        if node.initially or any(str(st.get(f"{p_node}.answers")) in _TRUE for st in trace):
            continue
        seen.add(producer)
        heard = sys.pub.heard.get(consumer)
        absent = heard is not None and not any(str(st.get(heard)) in _TRUE for st in trace)
        out.append({"node": p_node, "source": f"{node.loc.file}:{node.loc.line}:{node.loc.col}",
                    "output": producer.split(".", 1)[1],
                    "value": "none: never published" if absent else str(trace[-1].get(producer, "?")),
                    "consumer": consumer})
    order = {n: k for k, n in enumerate(sys.cone)}
    return sorted(out, key=lambda r: order.get(r["node"], 0))


def stuck_words(stuck: Sequence[StuckProducer]) -> str:
    """The stuck lasso in one sentence, naming each producer's initial value to declare."""
    parts = [(f"{r['consumer']} never has a value: {r['node']} never publishes {r['node']}.{r['output']}"
              if r["value"].startswith("none") else
              f"{r['consumer']} keeps the value {r['node']}.{r['output']} had before the run ({r['value']}), "
              f"outside its assumption, and {r['node']} never answers") for r in stuck]
    names = list(dict.fromkeys(r["node"] for r in stuck))
    return ("no node waiting on it ever has a question it owes an answer in the loop: " + "; ".join(parts)
            + f": declare the initial value of the outputs of {', '.join(names)} "
              "(initially( out.y == ... ), a value its readers accept) if the node has one before its first answer")


def missing_progress(idle: Sequence[IdleNode], checked: Checked) -> list[MissingProgress]:
    """The record's ``missing_progress`` for the ``idle`` nodes: ``[{"node",
    "source" (the node's header, file:line:col), "declared" (what it
    declares, ``none``), "accepted_at", "fix"}]``."""
    out: list[MissingProgress] = []
    for r in idle:
        node = checked.nodes[r["node"]].node
        declared = progress_words(node)
        out.append({"node": r["node"], "source": f"{node.loc.file}:{node.loc.line}:{node.loc.col}",
                    "declared": declared, "accepted_at": list(r["accepted_at"]),
                    "fix": f"declare progress( eventually ) (or within K steps) on {r['node']} if it does answer "
                           "every input its assumption accepts"})
    return out


def words(gaps: Sequence[MissingProgress]) -> str:
    """The missing progress in one sentence: ``"Base never answers in the
    loop although its assumption holds there (steps 1, 2): declare progress(
    ... ) on Base if it does"``."""
    parts = []
    for g in gaps:
        steps = ", ".join(str(i) for i in g["accepted_at"])
        parts.append(f"{g['node']} never answers in the loop although its assumption holds there (step"
                     f"{'s' if len(g['accepted_at']) != 1 else ''} {steps}; it declares no progress"
                     + ("" if g["declared"] == "none" else f" that excludes it: {g['declared']}")
                     + f"): declare progress( eventually ) or progress( within K steps ) on {g['node']} if it does")
    return "; ".join(parts)


def explain_idle(v: TemporalVerdict, sys: ComposedSystem, ts: TransitionSystem, checked: Checked,
                 search: Callable[[TransitionSystem], TemporalVerdict | None], *, tried_sync: bool = False
                 ) -> tuple[TemporalVerdict, Gaps]:
    """The verdict to report for lasso ``v`` found over ``ts`` (module
    docstring) and what it says is missing: ``{"missing_progress": [...],
    "missing_initially": [...]}`` (empty lists when nothing is).
    ``search(ts2)`` searches a lasso over ``ts2`` the way ``v`` was found
    (``None``: none found or undecided); ``tried_sync``: the synchronous
    system was searched already (and had none).  Any other verdict is
    returned unchanged."""
    none: Gaps = {"missing_progress": [], "missing_initially": []}
    if v.status != "refuted" or v.method != "lasso":
        return v, none
    idle = idle_in_loop(v.trace, v.loop, sys)
    if idle:
        again = None if tried_sync else search(sys.synchronous(ts))
        if again is None or again.status != "refuted":
            again = search(sys.fair_everywhere(ts))
        if again is None or again.status != "refuted":
            gaps = missing_progress(idle, checked)
            return TemporalVerdict(v.status, v.method, k=v.k, bound=v.bound, trace=v.trace, loop=v.loop,
                                   deadlock=v.deadlock, detail=f"{v.detail}; {words(gaps)}"), {**none, "missing_progress": gaps}
        v = TemporalVerdict(again.status, again.method, k=again.k, bound=again.bound, trace=again.trace,
                            loop=again.loop, deadlock=again.deadlock, detail=f"{again.detail}; {EVEN_SO}")
    stuck = stuck_in_loop(v.trace, v.loop, sys, checked)
    if not stuck:
        return v, none
    return TemporalVerdict(v.status, v.method, k=v.k, bound=v.bound, trace=v.trace, loop=v.loop, deadlock=v.deadlock,
                           detail=f"{v.detail}; {stuck_words(stuck)}"), {**none, "missing_initially": stuck}
