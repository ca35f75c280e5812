"""The composition calculus, applied automatically (paper lines 556-768).

For each node ``n`` of the system model:

* its assumption is split into top-level conjuncts; a conjunct that mentions
  an internally produced input is *internal*, the rest are *environment
  assumptions* left to the user;
* each internal conjunct is a **side condition**: the guarantees of ``n``'s
  producers must entail it (the premise after the turnstile in R1 and R3,
  lines 564-590 and 664-690; R2, lines 612-640, when a producer feeds
  several consumers).  Producers' outputs and ``n``'s inputs are the same Z3
  symbol.  Each side condition is a recorded Z3 validity query;
* the rules it instantiates: R1 (one producer), R3 (several producers), R2
  (a producer of ``n`` branches to several consumers) and R4 (``n`` lies on
  a loop, lines 717-768, with the extra assumption that rule rests on);
* the rule instance's conclusion, ``A_p1 and ... and A_pk => <> G_n``
  (for the Agent this is the paper's derivation D1, lines 1183-1250); and
* the **derived property** of ``n`` over its whole upstream cone:
  ``(environment assumptions of the cone) => <> G_n``.

A side condition is ``discharged`` (Z3 proved it), ``failed`` (Z3 found a
model of the producers' guarantees violating the conjunct; the model is
shown in RCL names) or ``inconclusive`` (unknown/timeout; never proved).

Two variants, tried in order (docs/decisions.md, "Side conditions"):

``as written``
    the producers' guarantees alone entail the conjunct (the premise of
    R1/R2/R3 exactly as printed);
``with producers' assumptions``
    the producers' guarantees *and their assumptions* entail it.  A consumer
    only ever reads outputs produced while the producer's assumption held
    (a contract promises nothing otherwise, lines 462-495), so this is sound
    for the composed system; the record says which variant was discharged.

A counterexample is only ever shown from the second variant, so it
satisfies the producers' assumptions as well as their guarantees.

A side condition that neither variant discharges is tried a third time, ``in
context`` (:mod:`.context`; docs/calculus.md): against the whole upstream
cone, each guarantee under its own node's assumption, with the environment
assumptions and facts of the cone, the cone's loops opened as rule R4 does.
Its verdict (``verdict``) is ``discharged`` (locally, by one of the two
variants above), ``discharged in context`` (the upstream premises used are
named), ``failed`` (with the counterexample of the whole cone; a local
refutation the cone does not rule out) or ``inconclusive``.

Each rule instance is labelled with the rule actually applied, from the
graph's shape: R3 (join) when several nodes feed the node, R2 (branch) when
its single producer's output is also read by another node, R1 (sequence)
otherwise; R4 is added for a node on a cycle.
"""
from __future__ import annotations

import dataclasses

from dataclasses import dataclass
from typing import Any, Mapping, Sequence, TypedDict

import z3

from rclverify.semantics.encode import Encoder
from rclverify.records.composition_records import CompositionRecord, EnvironmentAssumption, RuleInstance
from rclverify.semantics.nicemodel import nicer_model
from rclverify.calculus.context import ConeContext
from rclverify.calculus.side_condition import (IN_CONTEXT as IN_CONTEXT, STATUS as STATUS,
                                               VARIANT_AS_WRITTEN as VARIANT_AS_WRITTEN,
                                               VARIANT_IN_CONTEXT as VARIANT_IN_CONTEXT,
                                               VARIANT_WITH_ASSUMPTIONS as VARIANT_WITH_ASSUMPTIONS, ConeView,
                                               SideCondition as SideCondition, defined_goal, explain_local,
                                               in_context, name_undefined)
from rclverify.calculus.summary import decide as decide_by_summaries
from rclverify.semantics.query import DEFAULT_TIMEOUT_MS, prove, solver_session
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.walk import free_names, subexpressions
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.calculus.rules import R4_ASSUMPTION, contract_text, instance_rule, rule_instances, rules_at
from rclverify.calculus.scale import probable_mismatches


def conjuncts(e: ast.Expr) -> list[ast.Expr]:
    """Top-level conjuncts of a formula (``a and (b and c)`` -> ``[a, b, c]``)."""
    if isinstance(e, ast.Binary) and e.op == "and":
        return conjuncts(e.left) + conjuncts(e.right)
    return [e]


def free_io(e: ast.Expr) -> set[tuple[str | None, str]]:
    """The I/O names ``(prefix, name)`` a formula mentions: every ``in.``/``out.``
    name, and the unprefixed names not bound inside it (a bare ``r`` may be an
    input; the caller decides which names are I/O)."""
    prefixed = {(v.prefix, v.name) for v in subexpressions(e) if isinstance(v, ast.Var) and v.prefix is not None}
    return prefixed | {(None, n) for n in free_names(e)}


def _loc(l: ast.Loc) -> str:
    return f"{l.file}:{l.line}:{l.col}"


@dataclass(frozen=True)
class NodeComposition:
    """Everything the calculus says about one node (JSON via :meth:`to_json`)."""

    node: str
    rules: tuple[str, ...]
    producers: tuple[str, ...]
    side_conditions: tuple[SideCondition, ...]
    environment_assumptions: tuple[EnvironmentAssumption, ...]
    instances: tuple[RuleInstance, ...]
    derived_property: str
    cone: tuple[str, ...]
    loop_assumption: str | None = None
    cone_environment: tuple[tuple[str, str], ...] = ()
    guarantee: str = ""


def split_assumption(checked: Checked, model: SystemModel, node: str) -> tuple[list[ast.Expr], list[ast.Expr]]:
    """(internal conjuncts, environment conjuncts) of ``node``'s assumption."""
    cn = checked.nodes[node]
    internal_vars = model.internal_inputs(node)
    internal: list[ast.Expr] = []
    env: list[ast.Expr] = []
    for cl in cn.node.assumes:
        for c in conjuncts(cl.formula):
            if isinstance(c, ast.BoolLit) and c.value:
                continue
            names = {n for p, n in free_io(c) if (p == "in" or (p is None and n in cn.inputs))}
            (internal if names & internal_vars else env).append(c)
    return internal, env


class _EnvKey(TypedDict):
    """The (checked, model) pair the environment texts are remembered for, and the texts by node."""
    key: tuple[Checked, SystemModel] | None
    texts: dict[str, tuple[str, ...]]


class _EnvCache(_EnvKey, total=False):
    """:class:`_EnvKey` with the environment conjuncts by node and the pair they were made for."""
    exprs: dict[str, tuple[ast.Expr, ...]]
    exprs_key: tuple[Checked, SystemModel] | None


_ENV_TEXTS: _EnvCache = {"key": None, "texts": {}}


def _environment_texts(checked: Checked, model: SystemModel, node: str) -> tuple[str, ...]:
    """The environment conjuncts of ``node``'s assumption as RCL text,
    remembered for the last (checked, model) pair: every node of an upstream
    cone needs them, and in one process (a doit run) the cones of a chain of
    N nodes would otherwise split N*N/2 assumptions."""
    if _ENV_TEXTS["key"] is None or _ENV_TEXTS["key"][0] is not checked or _ENV_TEXTS["key"][1] is not model:
        _ENV_TEXTS["key"], _ENV_TEXTS["texts"] = (checked, model), {}
    texts: dict[str, tuple[str, ...]] = _ENV_TEXTS["texts"]
    if node not in texts:
        texts[node] = tuple(expr_to_rcl(c) for c in environment_conjuncts(checked, model, node))
    return texts[node]


def environment_texts(checked: Checked, model: SystemModel, node: str) -> tuple[str, ...]:
    """The environment conjuncts of ``node``'s assumption as RCL text (what
    a derived property lists; remembered per (checked, model))."""
    return _environment_texts(checked, model, node)


def environment_conjuncts(checked: Checked, model: SystemModel, node: str) -> tuple[ast.Expr, ...]:
    """The environment conjuncts of ``node``'s assumption
    (:func:`split_assumption`), remembered like :func:`_environment_texts`:
    the in-context check of every node downstream reads them."""
    if _ENV_TEXTS["key"] is None or _ENV_TEXTS["key"][0] is not checked or _ENV_TEXTS["key"][1] is not model:
        _ENV_TEXTS["key"], _ENV_TEXTS["texts"] = (checked, model), {}
    exprs: dict[str, tuple[ast.Expr, ...]] = _ENV_TEXTS.setdefault("exprs", {})
    if _ENV_TEXTS.get("exprs_key") is not _ENV_TEXTS["key"]:
        exprs.clear()
        _ENV_TEXTS["exprs_key"] = _ENV_TEXTS["key"]
    if node not in exprs:
        exprs[node] = tuple(split_assumption(checked, model, node)[1])
    return exprs[node]


@solver_session()
def compose_node(checked: Checked, model: SystemModel, node: str, *,
                 facts: Mapping[str, Sequence[ast.Expr]] | None = None,
                 timeout_ms: int = DEFAULT_TIMEOUT_MS, summaries: bool = True) -> NodeComposition:
    """Apply the calculus to ``node``: discharge its side conditions with Z3.

    ``facts`` are the plan's environment facts per node (RCL formulas over
    that node's inputs and outputs); only a side condition that fails
    locally reads them, with the rest of its upstream cone (:mod:`.context`).
    Returns a :class:`NodeComposition`.  Never raises on solver trouble
    (an unknown answer is an ``inconclusive`` side condition).  A side
    condition decided in context is first tried from the summaries of the
    producers' cones (:mod:`.summary`), then, unless that proves it, over
    the whole cone; ``summaries=False`` reads the whole cone always (the
    oracle test: the verdicts are the same).  The side conditions share one
    solver session
    (:func:`~rclverify.semantics.query.solver_session`), asked in a fixed order.
    """
    cn = checked.nodes[node]
    producers = model.producers(node)
    rules = rules_at(model, node)
    internal, env = split_assumption(checked, model, node)
    enc = Encoder(checked.env, model.alias())
    hyps, hyp_text, prod_assumptions, prod_a_text = _producer_premises(checked, producers, enc)
    rule = instance_rule(model, node) or "R1"
    who = ", ".join(producers)
    scs = []
    cone_ctx: ConeContext | None = None
    # one loop, not a step per method: Z3 numbers a new term with the id of a freed one and the `let` names of
    # every recorded script follow those ids, so the answers below live exactly as long as they always did
    for k, c in enumerate(internal, 1):
        goal = enc.formula(defined_goal(c), cn)  # c and its definedness (docs/semantics.md, "Definedness")
        links = _links_of(model, cn, node, c)
        head = (f"rclverify side condition {node}.sc{k} ({rule}): guarantees of {who} "
                f"entail {expr_to_rcl(c)}\nsource {_loc(c.loc)}; unsat means discharged")
        r = prove(goal, hyps, enc, timeout_ms=timeout_ms, comment=head + "\nvariant: " + VARIANT_AS_WRITTEN)
        variant, used_text = VARIANT_AS_WRITTEN, tuple(hyp_text)
        first = r
        if r.status != "proved" and prod_assumptions:
            r = prove(goal, hyps + prod_assumptions, enc, timeout_ms=timeout_ms,
                      comment=head + "\nvariant: " + VARIANT_WITH_ASSUMPTIONS)
            variant, used_text = VARIANT_WITH_ASSUMPTIONS, tuple(hyp_text) + tuple(prod_a_text)
        status = STATUS[r.status]
        expl = explain_local(node, who, producers, links, bool(prod_assumptions), variant, first, r)
        duration = round(first.duration_s + (r.duration_s if r is not first else 0.0), 4)
        shown = r.model  # integers and short decimals where Z3 finds them, re-checked (semantics/nicemodel.py)
        if status == "failed" and r.model:
            asked = hyps + (prod_assumptions if variant == VARIANT_WITH_ASSUMPTIONS else [])
            shown = nicer_model([*asked, z3.Not(goal)], enc, r.model).model
        sc = SideCondition(f"{node}.sc{k}", node, rule, expr_to_rcl(c), _loc(c.loc), used_text,
                           status, duration, r.smt2, shown, expl, variant, tuple(links), status)
        if status != "discharged":  # context before blame (docs/calculus.md)
            sc, cone_ctx = _in_context_step(checked, model, node, c, sc, cone_ctx, head, links,
                                            facts, timeout_ms, summaries)
        if sc.status == "failed" and defined_goal(c) is not c:  # a division its premises let see a zero?
            sc = name_undefined(sc, c, cn, enc, hyps + prod_assumptions, who, cone_ctx, timeout_ms)
        if sc.status != "discharged":  # neither locally nor in context: a power of ten between the ranges?
            scale = tuple(probable_mismatches(checked, model.links_into(node), enc, node, c))
            if scale:
                sc = dataclasses.replace(sc, scale=scale, explanation=sc.explanation + "".join(
                    f" {m['message'][0].upper()}{m['message'][1:]}." for m in scale))
        scs.append(sc)
    env_assumptions = tuple(EnvironmentAssumption(node=node, text=expr_to_rcl(c), source=_loc(c.loc)) for c in env)
    g_text = contract_text([g.formula for g in cn.node.guarantees])
    a_text = contract_text([a.formula for a in cn.node.assumes])
    instances = rule_instances(checked, model, node, rule, a_text, g_text, bool(scs))
    cone = model.upstream(node)
    cone_env = tuple((m, t) for m in cone for t in _environment_texts(checked, model, m))
    derived = ("(" + " and ".join(t for _, t in cone_env) + ")" if cone_env else "TRUE") + f" => <> G_{node}"
    loop = model.loop_of(node)
    return NodeComposition(node, rules, tuple(producers), tuple(scs), env_assumptions,
                           tuple(instances), derived, tuple(cone),
                           R4_ASSUMPTION.format(loop="{" + ", ".join(loop) + "}") if loop else None, cone_env, g_text)


def _producer_premises(checked: Checked, producers: Sequence[str], enc: Encoder
                       ) -> tuple[list[z3.BoolRef], list[str], list[z3.BoolRef], list[str]]:
    """The producers' guarantees and their assumptions (``TRUE`` left
    out), each encoded by ``enc`` and as ``"P guarantee k: RCL text"``
    (``"P assumption k: ..."``): ``(guarantees, their texts, assumptions,
    their texts)``, in producer order."""
    hyps, hyp_text = [], []
    prod_assumptions, prod_a_text = [], []
    for p in producers:
        pn = checked.nodes[p]
        for k, g in enumerate(pn.node.guarantees, 1):
            hyps.append(enc.formula(g.formula, pn))
            hyp_text.append(f"{p} guarantee {k}: {expr_to_rcl(g.formula)}")
        for k, a in enumerate(pn.node.assumes, 1):
            if isinstance(a.formula, ast.BoolLit) and a.formula.value:
                continue
            prod_assumptions.append(enc.formula(a.formula, pn))
            prod_a_text.append(f"{p} assumption {k}: {expr_to_rcl(a.formula)}")
    return hyps, hyp_text, prod_assumptions, prod_a_text


def _in_context_step(checked: Checked, model: SystemModel, node: str, c: ast.Expr, sc: SideCondition,
                     cone_ctx: ConeContext | None, head: str, links: list[str],
                     facts: Mapping[str, Sequence[ast.Expr]] | None, timeout_ms: int,
                     summaries: bool) -> tuple[SideCondition, ConeContext | None]:
    """``sc`` (conjunct ``c``, not discharged locally) decided again in
    context: from the summaries of the producers' cones when they prove it
    (``summaries``), else over the whole upstream cone ``cone_ctx`` (made
    here the first time a side condition of ``node`` needs it); returns the
    side condition and the cone (:mod:`.summary`, :mod:`.context`)."""
    who = ", ".join(model.producers(node))
    env_of = lambda m: environment_conjuncts(checked, model, m)  # noqa: E731
    comment = head + "\nvariant: " + VARIANT_IN_CONTEXT
    goal = defined_goal(c)
    cr = (decide_by_summaries(checked, model, node, goal, env_of, facts, comment + " (the summaries of the "
                              "producers' cones)", timeout_ms) if summaries else None)
    if cr is not None:  # proved from the producers' summaries: the cone is not read (calculus/summary.py)
        return in_context(sc, cr, ConeView(tuple(model.upstream(node)), ()), who), cone_ctx
    if cone_ctx is None:
        cone_ctx = ConeContext(checked, model, node, env_of, facts)
    cr = cone_ctx.decide(goal, comment + " (the upstream cone; each guarantee under its node's assumption)",
                         timeout_ms)
    read_from = {x.split(".", 1)[0] for x in links}
    keep: set[str] = ({node}.union(*(model.upstream(p) for p in read_from)) if read_from
                      else set(cone_ctx.cone))
    return in_context(sc, cr, cone_ctx, who, keep), cone_ctx


def _links_of(model: SystemModel, cn: Any, node: str, c: ast.Expr) -> list[str]:
    """The connections carrying the inputs a conjunct mentions, as
    ``Producer.out.x -> Node.in.y (via name/topic/plan)``."""
    names = {n for p, n in free_io(c) if (p == "in" or (p is None and n in cn.inputs))}
    topics = {t.match.name: f"{t.msg_type} {t.field}" for t in cn.node.topics
              if t.match is not None and t.match.prefix in (None, "in")}
    return [f"{l.from_node}.out.{l.from_var} -> {node}.in.{l.to_var} (via {l.via}"
            + (f", topic {topics[l.to_var]})" if l.to_var in topics else ")")
            for l in model.links_into(node) if l.to_var in names]


def composition_json(c: NodeComposition, smt2_paths: Sequence[str]) -> CompositionRecord:
    """JSON form of a node's composition; ``smt2_paths`` parallel to its side conditions."""
    return {
        "node": c.node, "rules": list(c.rules), "producers": list(c.producers),
        "side_conditions": [sc.to_json(p) for sc, p in zip(c.side_conditions, smt2_paths)],
        "environment_assumptions": list(c.environment_assumptions), "instances": list(c.instances),
        "derived_property": c.derived_property, "loop_assumption": c.loop_assumption,
        # the cone's size only: the list is model.upstream(node) (the report takes every cone at once from
        # SystemModel.upstream_masks); a list per node was quadratic along a chain, 70% of these artifacts
        "cone_size": len(c.cone),
        "cone_environment_assumptions": [f"{text}  [{node}]" for node, text in c.cone_environment],
        "guarantee": c.guarantee,
    }
