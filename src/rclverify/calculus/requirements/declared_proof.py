"""Declarations that follow from the node's other declarations.

A declaration a requirement's proof uses needs evidence (calculus/requirements/rollup.py);
where it follows from other declarations of the same node, their evidence is
its evidence:

* ``initially( F )`` follows from the node's other ``initially`` clauses
  when Z3 shows they entail F (their conjunction and ``not F`` unsatisfiable,
  with the typing axioms of the outputs): F rests on the clauses of the
  unsat core (none: F holds of every value of the outputs' types, nothing to
  verify).  Entailment here is the calculus's (a formula over one node's
  outputs encoded as the side conditions are, semantics/encode.py).
* The premise ``progress`` of a node is its least step bound
  (rcl/liveness.step_bound): ``progress( within K steps )`` and
  ``periodic( out.y, N steps )`` (within ``N - 1``); ``eventually`` follows
  from any bound, a bound K from any bound at most K.  So the premise rests
  only on the declarations that give the least bound (``eventually`` alone
  when no bound is declared); the others follow from them by arithmetic.
"""
from __future__ import annotations

from typing import Any

import z3

from rclverify.semantics.encode import Encoder, EncodingError
from rclverify.semantics.query import satisfiable
from rclverify.lang.liveness import STEP_WORDS, _steps
from rclverify.lang.types import Checked, CheckedNode

#: The budget of one entailment query (ms).
TIMEOUT_MS = 2_000


def initial_support(checked: Checked, node: CheckedNode, index: int) -> list[int] | None:
    """The indices (1-based) of the other ``initially`` clauses of ``node``
    that entail clause ``index`` (an unsat core; ``[]``: it holds of every
    value of the outputs' types), or ``None`` when they do not (or Z3 could
    not decide, or a clause cannot be encoded)."""
    clauses = node.node.initially
    if not 1 <= index <= len(clauses):
        return None
    enc = Encoder(checked.env)
    try:
        goal = enc.formula(clauses[index - 1].formula, node)
        others = [(f"initially {k}", enc.formula(c.formula, node)) for k, c in enumerate(clauses, 1) if k != index]
    except (EncodingError, z3.Z3Exception):
        return None
    r = satisfiable([*others, ("goal", z3.Not(goal))], enc, timeout_ms=TIMEOUT_MS, comment="initially entailed",
                    retry=False)
    if r.status != "unsat" or r.core is None:
        return None
    return sorted(int(c.split()[1]) for c in r.core if c != "goal")


def progress_labels(node: CheckedNode) -> list[str]:
    """The labels of the declarations the premise ``progress`` of ``node``
    rests on (module docstring): those with the least step bound, as
    backends/monitors/declarations.py names them (``progress``,
    ``periodic out.y``)."""
    bounds: list[tuple[float, str]] = []
    for p in node.node.progress:
        k = _steps(p.bound) if p.bound is not None else None
        bounds.append((float("inf") if k is None else float(k), "progress"))
    for per in node.node.periodic:
        n = _steps(per.amount) if per.unit in STEP_WORDS else None
        if n:
            bounds.append((float(n - 1), f"periodic out.{per.output.name}"))
    if not bounds:
        return []
    least = min(b for b, _ in bounds)
    return [label for b, label in bounds if b == least]


def node_of(checked: Any, name: str) -> CheckedNode | None:
    """``checked.nodes[name]`` (``None`` without a checked system or node)."""
    nodes = getattr(checked, "nodes", None)
    return nodes.get(name) if nodes is not None else None
