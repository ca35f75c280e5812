"""Counterexamples cut to the cone that matters.

The records keep every value Z3 gave (a side condition decided in context
holds a model of its whole upstream cone; a temporal requirement's lasso
holds every variable and flag of every node of its cone at every step, 34
of them in the issue's delivery robot).  The report shows what a person
needs to follow the failure:

* a side condition: the values of the consumer, of the producers it reads
  on the conjunct's links, and of the nodes whose assumption the
  counterexample violates (:func:`side_condition_view`); one that failed
  in context keeps its whole cone (the counterexample traced back through
  the premises that allow it);
* a temporal trace (:func:`trace_view`): at every step, the variables the
  statement (or its ``assuming:``) names and those whose value changes along
  the run; of a node the lasso rests on (a missing progress or initial
  value), every input and output and its ``accepts``/``answers`` flags.
  Values that never change on a node the statement does not name are left
  out, and counted.

Nothing is recomputed: a view is a subset of the record's values, so it
shows a counterexample exactly when the record holds one.
"""
from __future__ import annotations

import re
from typing import Any, Mapping, Sequence

import msgspec

from rclverify.records.side_condition_rows import SideConditionRow

_NAMED = re.compile(r"\b([A-Za-z_]\w*)\.(in|out|state)\.([A-Za-z_]\w*)")
#: The flags of a node's run that say whether it answers (calculus/requirements/published.py).
_ANSWER_FLAGS = ("accepts", "answers")


def named_variables(texts: Sequence[str | None]) -> set[tuple[str, str]]:
    """``{(node, "in.x")}`` of every ``Node.in.x``/``Node.out.y``/``Node.state.v``
    the statement texts name."""
    out: set[tuple[str, str]] = set()
    for t in texts:
        for n, p, v in _NAMED.findall(t or ""):
            out.add((n, f"{p}.{v}"))
    return out


def trace_view(temporal: Mapping[str, Any], texts: Sequence[str | None]) -> tuple[list[dict[str, Any]], int]:
    """``(steps, hidden)``: the record's ``temporal["trace"]`` (``[{"step", "nodes":
    [{"node", "values"}]}]``) cut as the module docstring says, in the same
    shape and order, and how many node variables were left out (per
    variable, not per step).  ``texts`` the statement and its ``assuming:``
    texts.  A trace of one step keeps the named variables and the culprit
    nodes' (nothing changes in one step)."""
    trace = list(temporal.get("trace") or [])
    named = named_variables(texts)
    culprits = {str(m.get("node")) for key in ("missing_progress", "missing_initially")
                for m in temporal.get(key) or () if isinstance(m, Mapping)}
    seen: dict[tuple[str, str], set[str]] = {}
    for st in trace:
        for row in st.get("nodes", []):
            for k, v in row.get("values", {}).items():
                seen.setdefault((row["node"], k), set()).add(str(v))

    def shown(node: str, var: str) -> bool:
        if (node, var) in named:
            return True
        if node in culprits:
            return var.startswith(("in.", "out.", "state.")) or var in _ANSWER_FLAGS
        if not var.startswith(("in.", "out.", "state.")):
            return False  # a node's run flags (published, heard.x): the culprit's only
        return len(seen.get((node, var), ())) > 1

    keep = {key for key in seen if shown(*key)}
    steps = []
    for st in trace:
        rows = []
        for row in st.get("nodes", []):
            values = {k: v for k, v in row.get("values", {}).items() if (row["node"], k) in keep}
            if values:
                rows.append({"node": row["node"], "values": values})
        steps.append({"step": st.get("step"), "nodes": rows})
    return steps, len(seen) - len(keep)


def with_trace_view(check: Mapping[str, Any]) -> Mapping[str, Any]:
    """``check`` (a requirement's check record) with ``temporal["shown"]``
    (the cut trace) and ``temporal["hidden"]`` (the count left out) when it
    has a temporal trace; unchanged otherwise."""
    t = check.get("temporal")
    if not isinstance(t, Mapping) or not t.get("trace"):
        return check
    steps, hidden = trace_view(t, [check.get("formal"), *(check.get("assuming") or [])])
    return {**check, "temporal": {**t, "shown": steps, "hidden": hidden}}


def side_condition_view(sc: SideConditionRow) -> SideConditionRow:
    """``sc`` (a side-condition row of the calculus, decoded) with its ``model``
    (``{"Node.in.x": value}``) cut to the nodes its conjunct involves: the
    consumer, the producers of its ``links`` (``"P.out.v -> C.in.w (...)"``)
    and, decided in context, the nodes whose assumption the counterexample
    violates (``context["violated"]``); ``model_hidden`` counts the values
    left out.  Unchanged without a model or links, or when nothing would be
    left; unchanged, too, for a side condition that failed *in context*: its
    counterexample is traced back through the upstream cone whose premises
    allowed it, every value of which is part of why it fails."""
    model = sc.model
    if model is None or not sc.links or sc.variant == "in context":
        return sc
    nodes = {sc.node} | {link.split(".", 1)[0] for link in sc.links}
    if sc.context is not None:  # calculus/compose.py's record of the in-context check
        nodes |= {str(n) for n in sc.context.get("violated") or ()}
    kept = {k: v for k, v in model.items() if str(k).split(".", 1)[0] in nodes}
    if not kept or len(kept) == len(model):
        return sc
    return msgspec.structs.replace(sc, model=kept, model_hidden=len(model) - len(kept))
