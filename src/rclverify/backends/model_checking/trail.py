"""A SPIN counterexample mapped back to the explored graph and the Gwendolen source.

``spin -T -t -p`` replays a trail of the model of :mod:`.promela`; the
model prints ``@T <k>`` when it takes transition ``k`` of the graph and
``@S <s>`` when final state ``s`` stutters, and SPIN prints
``<<<<<START OF CYCLE>>>>>`` where the accepting cycle of a lasso begins
(a trail without it is a finite bad prefix: the claim reached its end).

The counterexample (:func:`counterexample`) is a lasso over the graph: the
``prefix`` from the initial state and the ``cycle`` repeated for ever, each
step the transition's label, its Gwendolen source line and reasoning-cycle
stage, and the state it leads to with the propositions true there.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Sequence

from rclverify.backends.model_checking.graph import StateGraph
from rclverify.backends.model_checking.ltl import Propositions, atom_text
from rclverify.backends.shapes import Lasso, LassoStep

_STEP = re.compile(r"^\s*@([TS])\s+(\d+)\s*$")
CYCLE_MARK = "START OF CYCLE"


@dataclass(frozen=True)
class Replay:
    """What a replay printed: ``steps`` as ``("T", transition)`` or
    ``("S", state)`` in order, and ``cycle_start`` the index in ``steps``
    where the cycle begins (``None``: no cycle)."""

    steps: tuple[tuple[str, int], ...]
    cycle_start: int | None


def read_replay(text: str) -> Replay:
    """Parse ``spin -T -t -p`` output (see the module docstring); never raises."""
    steps: list[tuple[str, int]] = []
    start = None
    for line in text.splitlines():
        if CYCLE_MARK in line and start is None:
            start = len(steps)
            continue
        m = _STEP.match(line)
        if m:
            steps.append((m.group(1), int(m.group(2))))
    return Replay(tuple(steps), start)


def counterexample(graph: StateGraph, replay: Replay, props: Propositions | None = None) -> Lasso:
    """The replay as a JSON-ready lasso over ``graph`` (evidence ``details["lasso"]``).

    ``{"kind": "lasso" | "prefix", "source": file, "initial": {state...},
    "prefix": [step, ...], "cycle": [step, ...], "trace": [line, ...]}``;
    each step is ``{"transition", "from", "to", "label", "line", "stage",
    "where", "holds"}`` (``where`` is ``file:line`` or ``""`` for an
    environment step; ``holds`` the propositions true in ``to``, in AJPF's
    syntax), and a stutter step ``{"stutter": state, ...}``.  ``trace`` is
    the same as readable lines.  Raises ``ValueError`` when the replay names
    a transition or state the graph does not have, or its steps do not
    form a path from state 0 (the model was not made from this graph).
    """
    atoms = [a for _, a in (props or Propositions()).atoms()]
    memo: dict[int, list[str]] = {}

    def holds(state: int) -> list[str]:  # only the states on the path are evaluated
        if state not in memo:
            memo[state] = [atom_text(a) for a in atoms if graph.holds(state, a)]
        return memo[state]

    steps: list[LassoStep] = []
    at = 0
    for kind, k in replay.steps:
        if kind == "T":
            if not 0 <= k < len(graph.transitions):
                raise ValueError(f"the trail names transition {k}; the graph has {len(graph.transitions)}")
            tr = graph.transitions[k]
            if tr.src != at:
                raise ValueError(f"the trail takes transition {k} from state {tr.src}, but is in state {at}")
            at = tr.dst
            steps.append({"transition": k, "from": tr.src, "to": tr.dst, "label": tr.label, "line": tr.line,
                          "stage": tr.stage, "where": f"{graph.source}:{tr.line}" if tr.line else "",
                          "holds": holds(tr.dst)})
        else:
            if k != at:
                raise ValueError(f"the trail stutters in state {k}, but is in state {at}")
            steps.append({"stutter": k, "from": k, "to": k, "label": f"state {k} is final: it stutters",
                          "line": None, "stage": "", "where": "", "holds": holds(k)})
    cut = len(steps) if replay.cycle_start is None else replay.cycle_start
    prefix, cycle = steps[:cut], steps[cut:]
    trace = [f"state 0 (initial): {', '.join(holds(0)) or 'no proposition holds'}"]
    for i, st in enumerate(steps):
        if i == cut and cycle:
            trace.append("-- the cycle, repeated for ever, starts here --")
        trace.append(_line(st))
    return {"kind": "lasso" if cycle else "prefix", "source": graph.source,
            "initial": {"state": 0, "holds": holds(0)}, "prefix": prefix, "cycle": cycle, "trace": trace}


def _line(st: LassoStep) -> str:
    where = f" [{st['where']}, stage {st['stage']}]" if st["where"] else (
        f" [stage {st['stage']}]" if st["stage"] else "")
    true = ", ".join(st["holds"]) or "no proposition holds"
    if "stutter" in st:
        return f"state {st['from']} stutters (final state): {true}"
    return f"{st['from']} -> {st['to']}: {st['label']}{where}; then {true}"


def summary(cex: Lasso) -> str:
    """One sentence: the lasso's size and the source lines it passes through."""
    steps: Sequence[LassoStep] = [*cex["prefix"], *cex["cycle"]]
    lines = sorted({ln for s in steps if (ln := s.get("line"))})
    where = (f"; Gwendolen line{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))} of {cex['source']}"
             if lines else "")
    if cex["kind"] == "lasso":
        return f"a lasso of {len(cex['prefix'])} steps then a cycle of {len(cex['cycle'])}{where}"
    return f"a path of {len(cex['prefix'])} steps after which the property cannot hold{where}"
