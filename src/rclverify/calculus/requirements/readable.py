"""A refuted requirement's counterexample as a person reads it.

The requirement's query (:mod:`.check`) holds the cone's guarantees and its
environment assumptions, not the internal conjuncts of the assumptions
(those are side conditions).  So Z3 may answer with a counterexample in
which a node reads a value its assumption rules out (``dest_id = 501`` where
the node assumes ``<= 500``), which reads as a counterexample to something
else.  :func:`readable_counterexample` asks Z3 again
(:func:`rclverify.semantics.nicemodel.nicer_model`) with those conjuncts added
and for short values; when no counterexample keeps them, the record says
that it needs an input outside them, naming them.
"""
from __future__ import annotations

from typing import Any, Sequence

import z3

from rclverify.calculus.compose import split_assumption
from rclverify.semantics.nicemodel import nicer_model
from rclverify.lang.printer import expr_to_rcl


def readable_counterexample(labelled: Sequence[tuple[str, z3.BoolRef]], model: dict[str, str], cone: Sequence[str],
                            checked: Any, system: Any, enc: Any) -> tuple[dict[str, str], dict[str, Any]]:
    """``(model, fields)``: the refuting ``model`` (RCL name -> value text) of
    the query ``labelled`` asked again within the internal assumption
    conjuncts of the ``cone``'s nodes and for short values, and the record
    fields that say how: ``{}`` when the model keeps every assumption, else
    ``outside_assumptions`` (``[{node, text, source}]``, the conjuncts no
    counterexample keeps: an unsat core) and ``counterexample_note`` (one
    sentence).  ``checked``/``system`` the checked contracts and the system
    model, ``enc`` the query's encoder.  Never raises on solver trouble."""
    assume: list[tuple[str, z3.BoolRef]] = []
    where: dict[str, dict[str, Any]] = {}
    for n in cone:
        cn = checked.nodes[n]
        for k, c in enumerate(split_assumption(checked, system, n)[0], 1):
            label = f"{n} assumption conjunct {k}"
            assume.append((label, enc.formula(c, cn)))
            where[label] = {"node": n, "text": expr_to_rcl(c),
                            "source": f"{c.loc.file}:{c.loc.line}:{c.loc.col}" if c.loc else ""}
    nice = nicer_model([f for _, f in labelled], enc, model, assumptions=assume)
    if nice.within is not False:
        return nice.model, {}
    rows = [where[l] for l in nice.outside]
    named = "; ".join(f"{r['node']}: {r['text']} ({r['source']})" for r in rows)
    note = (f"No counterexample keeps every input within its node's assumption: this one needs an input outside "
            f"{named}. Those conjuncts are side conditions; the requirement fails through the failed or "
            f"undecided side conditions that should keep the input there.")
    return nice.model, {"outside_assumptions": rows, "counterexample_note": note}
