"""Whether some run exercises a temporal proof: the vacuity of a temporal requirement.

A state requirement ``P -> Q`` proved only because ``P`` never holds with
the premises of its cone is *proved vacuously* (:mod:`.check`, the vacuity
query).  A temporal statement has the same failure over runs: its state
formula is evaluated on published values only (:mod:`.published`), so
``always F`` holds at every state where a value ``F`` reads was never
published, and a proof over a cone in which that value never gets one
rests on no message at all.  The statement *demands* something at a state:

=============================  ============================================
statement                      demanded at a state where
=============================  ============================================
``always F``                   every value ``F`` reads is published and,
                               for ``F`` = ``forall(bs | P -> Q)`` or
                               ``P -> Q``, ``exists(bs | P)`` holds
``always next F``              the same, from step 1 on
``always (P -> eventually[<=   every value ``P`` reads is published and
N] Q)``, ``always (P ->        ``P`` holds (the trigger)
eventually Q)``, ``always (P
-> next Q)``
=============================  ============================================

The other shapes (``eventually``, ``next``, ``until``) are proved only by
reaching their goal, which some state of every run then exercises; they
get no vacuity field.  A proved statement is ``vacuous`` when no reachable
state is one where it demands something, decided in two steps:

1. by the connections (:meth:`.published.Publication.silent`): a value
   ``F`` reads whose node, or whose producer, publishes on no run (a loop
   of nodes each answering only the others' messages, none declaring an
   initial value) keeps ``F`` from ever being demanded; the reason names
   those nodes and the value;
2. else as the safety property ``always not D`` of the demanding
   condition ``D`` (:func:`.safety.prove_always`, with the plan's
   ``invariant:`` as for the proof): proved is ``vacuous``; a run reaching
   ``D`` is ``non-vacuous``; undecided is ``undecided`` with the reason,
   never met (docs/requirements.md, "Status").

Rule: docs/requirements.md, "A proof no run exercises" (Beer, Ben-David,
Eisner and Rodeh's vacuity of temporal formulas, CAV 1997, read over the
published values of the composed contracts).
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable, Sequence, cast

import z3

from rclverify.calculus.requirements.published import Publication
from rclverify.calculus.requirements.safety import Hint, prove_always
from rclverify.calculus.requirements.tsys import Pred, TemporalVerdict, TransitionSystem, with_flag
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.model.plan.formal import Formal
from rclverify.model.plan.temporal import Temporal, shape
from rclverify.semantics.connectives import conj
from rclverify.calculus.shapes import Vacuity

NON_VACUOUS, VACUOUS, UNDECIDED = "non-vacuous", "vacuous", "undecided"


def antecedent(e: ast.Expr) -> ast.Expr | None:
    """``exists(bs | P)`` for ``forall(bs | P -> Q)``, ``P`` for ``P -> Q``;
    ``None`` for a formula of another shape (it demands something wherever
    it is evaluated)."""
    bindings: list[ast.Binding] = []
    while isinstance(e, ast.Quant) and e.kind == "forall":
        bindings.extend(e.bindings)
        e = e.body
    if not (isinstance(e, ast.Binary) and e.op == "->"):
        return None
    return ast.Quant("exists", tuple(bindings), e.left, e.loc) if bindings else e.left


def demands(t: Temporal) -> tuple[Formal, bool, bool] | None:
    """What statement ``t`` demands (module table): ``(F, split, later)``
    with ``F`` the state formula read, ``split`` whether its antecedent is
    the condition (``always``) or ``F`` itself is (a response's trigger),
    ``later`` whether only steps from 1 on count; ``None`` for a shape
    proved by reaching its goal."""
    kind = shape(t, None)
    if kind == "always":
        return cast(Formal, t.args[0]), True, False
    if kind == "always next":
        return cast(Formal, cast(Temporal, t.args[0]).args[0]), True, True
    if kind == "response":
        return cast(Formal, cast(Temporal, t.args[0]).args[0]), False, False
    return None


def blocked(pub: Publication, f: Formal) -> tuple[list[str], str] | None:
    """``(nodes, value)``: the first value ``f`` reads (``Node.out.y`` or a
    fed ``Node.in.x``) that never has one, because its node or producer
    publishes on no run, and the nodes that never publish behind it (that
    one and, to a fixpoint, the silent producers of the inputs each reads),
    in the system's order; ``None`` when every value ``f`` reads can be
    published."""
    silent = set(pub.silent())
    if not silent:
        return None
    by_flag = {flag: pub.producer[c] for c, flag in pub.heard.items()}
    for n, kind, var in f.mentions:
        flag = pub.published.get(n) if kind == "out" else pub.heard.get(f"{n}.in.{var}") if kind == "in" else None
        who = None if flag is None else n if kind == "out" else by_flag[flag]
        if who is None or who not in silent:
            continue
        behind = [who]
        for m in behind:  # grows while read: the silent producers of what each reads
            behind += [p for p in (by_flag[x] for x in pub.fed.get(m, ())) if p in silent and p not in behind]
        return [x for x in pub.published if x in behind], f"{n}.{kind}.{var}"
    return None


def _names(nodes: Sequence[str]) -> str:
    return nodes[0] if len(nodes) == 1 else ", ".join(nodes[:-1]) + f" and {nodes[-1]}"


def silent_words(nodes: Sequence[str], value: str) -> str:
    """The reason of a proof over values nothing publishes, in one sentence."""
    one = len(nodes) == 1
    return (f"{_names(nodes)} never publish{'es' if one else ''}: {'it answers' if one else 'each answers'} only "
            f"once the inputs it reads from other nodes have been published, and no node of the loop "
            f"{'it waits' if one else 'they wait'} in declares an initial value, so {value} never has a value and "
            f"no run exercises the proof (declare initially( ... ) on a node of that loop)")


def vacuity(t: Temporal, ts: TransitionSystem, pub: Publication, raw: Callable[[Formal], Pred], *, max_k: int,
            timeout_ms: int, hint: Hint | None = None) -> Vacuity:
    """The vacuity fields of a proved statement ``t`` over ``ts`` (module
    docstring): ``{}`` for a shape that reaches its goal, else ``vacuity``
    (``non-vacuous``/``vacuous``/``undecided``) with, when not
    ``non-vacuous``, ``vacuity_reason`` (one sentence) and ``vacuity_core``
    (``[]``: an induction has no core), and ``never_publish`` (the silent
    nodes) when the connections decided it.  ``pub`` is the system's
    publication, ``raw(F)`` F as a predicate over one state (without the
    published guard); ``max_k``, ``timeout_ms`` and ``hint`` as for
    :func:`.safety.prove_always`.  Never raises on solver trouble."""
    d = demands(t)
    if d is None:
        return {}
    f, split, later = d
    stop = blocked(pub, f)
    if stop is not None:
        return {"vacuity": VACUOUS, "vacuity_core": [], "vacuity_reason": silent_words(*stop),
                "never_publish": stop[0]}
    ante = antecedent(f.expr) if split else f.expr
    flags = pub.flags_of(f.mentions)
    if ante is None and not flags:  # demanded at every state: the premises have a run (consistency, no run stops)
        return {"vacuity": NON_VACUOUS}
    cond = raw(replace(f, expr=ante)) if ante is not None else None

    def demanded(s: Any) -> z3.BoolRef:
        return conj(pub.defined(f.mentions, s), *([cond(s)] if cond is not None else []),
                    *([s["<started>"]] if later else []))
    ts2 = with_flag(ts, "<started>", lambda s: z3.BoolVal(False), lambda s, u: z3.BoolVal(True)) if later else ts
    try:
        v = prove_always(ts2, lambda s: z3.Not(demanded(s)), max_k=max_k, timeout_ms=timeout_ms, hint=hint)
    except z3.Z3Exception as exc:  # undecided, never non-vacuous
        v = TemporalVerdict("inconclusive", "k-induction", detail=f"the solver failed ({exc})")
    shown = ", ".join(_values(pub, f))
    what = (f"{'its premise' if split else 'its trigger'} {' '.join(expr_to_rcl(ante).split())}"
            + (f" with {shown} published" if flags else "") if ante is not None else
            f"a state where {shown} {'all have a value' if len(flags) > 1 else 'has a value'}")
    if v.status == "refuted":
        return {"vacuity": NON_VACUOUS}
    if v.status in ("proved", "met"):
        how = f"{v.method}" + (f", k = {v.k}" if v.k is not None else "")
        return {"vacuity": VACUOUS, "vacuity_core": [],
                "vacuity_reason": f"{what} holds on no run of the system{' from step 1 on' if later else ''} "
                                  f"({how}), so no run exercises the proof"}
    why = (f"no run of up to {v.bound} steps reaches it, and no invariant found excludes it" if v.bound is not None
           else v.detail.split("; ")[0] or v.method)
    return {"vacuity": UNDECIDED, "vacuity_core": [], "vacuity_reason": f"whether {what} holds on some run is undecided: {why}"}


def _values(pub: Publication, f: Formal) -> list[str]:
    """The values ``f`` reads that hold one only once published (outputs of
    answering nodes, fed inputs), as ``Node.out.y`` / ``Node.in.x``."""
    return list(dict.fromkeys(f"{n}.{k}.{v}" for n, k, v in f.mentions
                              if (k == "out" and n in pub.published) or (k == "in" and f"{n}.in.{v}" in pub.heard)))


__all__ = ["antecedent", "blocked", "demands", "silent_words", "vacuity"]
