"""One side condition of the calculus: its record, the words for its local
verdict, and its verdict in context.

A side condition (:mod:`.compose`; paper lines 564-690, the premise of
R1-R3) is first decided locally, from its producers' guarantees as written
and then with their assumptions; one neither variant discharges is decided
again against its upstream cone (:mod:`.context`, :mod:`.summary`), and
:func:`in_context` folds that verdict into the record.  The explanations
say in words what Z3 answered (docs/calculus.md).

A conjunct that divides is proved with its well-definedness conditions
(docs/semantics.md, "Definedness"): the goal is :func:`defined_goal`, and
a side condition that is not discharged names the condition its
producers' guarantees do not ensure (:func:`undefined_note`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable, Protocol, Sequence

import z3

from rclverify.calculus.context import ConeContext, ContextResult
from rclverify.calculus.shapes import ContextRecord, LocalVerdict, ScaleMismatch
from rclverify.records.composition_records import SideCondition as SideConditionJson
from rclverify.lang import ast
from rclverify.lang.types import CheckedNode
from rclverify.semantics.definedness import conditions, guarded
from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import QueryResult, prove

STATUS = {"proved": "discharged", "refuted": "failed", "inconclusive": "inconclusive"}

VARIANT_AS_WRITTEN = "as written"
VARIANT_WITH_ASSUMPTIONS = "with producers' assumptions"
VARIANT_IN_CONTEXT = "in context"
#: How many premises of an in-context proof its explanation names (all are its hypotheses).
NAMED = 8
#: The verdict of a side condition discharged against its upstream cone.
IN_CONTEXT = "discharged in context"


@dataclass(frozen=True)
class SideCondition:
    """One side condition of a node and how it was decided (JSON via :meth:`to_json`)."""

    id: str
    node: str
    rule: str
    conjunct: str
    source: str
    hypotheses: tuple[str, ...]
    status: str
    duration_s: float
    smt2: str
    model: dict[str, str] | None = None
    explanation: str = ""
    variant: str = ""
    links: tuple[str, ...] = ()
    #: ``discharged`` (locally), ``discharged in context``, ``failed`` or ``inconclusive`` (:mod:`.compose`)
    verdict: str = ""
    #: how the in-context check went (``None`` when the side condition was discharged locally): ``cone``
    #: (its size), ``used`` (premises of the proof), ``used_nodes``, ``opened`` (links opened, rule R4),
    #: ``violated`` (nodes whose assumption the counterexample violates), ``joins``, ``local`` (the
    #: local verdict: ``status``, ``variant``, ``model``)
    context: ContextRecord | None = None
    #: probable scale mismatches behind a side condition that is not discharged (:mod:`.scale`)
    scale: tuple[ScaleMismatch, ...] = ()

    def to_json(self, smt2_path: str) -> SideConditionJson:
        """The side condition as the compose stage's record holds it (records/composition_records.py
        ``SideCondition``), ``smt2_path`` its query's workspace-relative path."""
        out: SideConditionJson = {
            "id": self.id, "node": self.node, "rule": self.rule, "conjunct": self.conjunct, "source": self.source,
            "hypotheses": list(self.hypotheses), "status": self.status, "duration_s": self.duration_s,
            "smt2": smt2_path, "model": self.model, "explanation": self.explanation, "variant": self.variant,
            "links": list(self.links), "verdict": self.verdict or self.status, "context": self.context}
        if self.scale:
            out["scale_mismatch"] = list(self.scale)
        return out


def defined_goal(c: ast.Expr) -> ast.Expr:
    """The formula a side condition proves for conjunct ``c``: ``c`` and its
    well-definedness conditions (:func:`rclverify.semantics.definedness.guarded`;
    ``c`` itself when it does not divide)."""
    return guarded(c)


class _Answer(Protocol):
    """What :func:`undefined_note` reads of an answer (a :class:`QueryResult` or a :class:`ContextResult`)."""

    @property
    def status(self) -> str: ...

    @property
    def model(self) -> dict[str, str] | None: ...


def undefined_note(c: ast.Expr, decide: Callable[[ast.Expr, str], _Answer], premises: str
                   ) -> tuple[str, dict[str, str] | None]:
    """Why a conjunct ``c`` that divides is not proved, when the reason is a
    division: ``(sentence, counterexample)`` for the first of its
    well-definedness conditions that ``decide`` (a formula and a comment ->
    Z3's answer, ``refuted`` with a model when the premises of the side
    condition's verdict allow it false) refutes, e.g. " It is not defined
    there: the division at f.rcl:3:20 needs in.d != 0, which the guarantees
    of P do not ensure (counterexample: in.d = 0)." with ``premises`` "the
    guarantees of P"; ``("", None)`` when no condition is refuted (the
    conjunct itself is what fails) or ``c`` does not divide."""
    for cond in conditions(c):
        r = decide(cond.formula, f"rclverify definedness of {cond.where}: {cond.text}; unsat means defined")
        if r.status == "refuted":
            shown = ", ".join(f"{k} = {v}" for k, v in sorted((r.model or {}).items()))
            return (f" It is not defined there: {cond.describe()}, which {premises} do not ensure"
                    + (f" (counterexample: {shown})." if shown else "."), r.model)
    return "", None


def local_decider(cn: CheckedNode, enc: Encoder, hyps: Sequence[z3.BoolRef], timeout_ms: int
                  ) -> Callable[[ast.Expr, str], QueryResult]:
    """The ``decide`` of :func:`undefined_note` for a side condition of
    node ``cn`` decided locally: is the formula valid under ``hyps``?"""
    return lambda f, comment: prove(enc.formula(f, cn), list(hyps), enc, timeout_ms=timeout_ms, comment=comment)


def name_undefined(sc: SideCondition, c: ast.Expr, cn: CheckedNode, enc: Encoder, hyps: Sequence[z3.BoolRef],
                   who: str, cone: ConeContext | None, timeout_ms: int) -> SideCondition:
    """``sc`` (failed; conjunct ``c`` of node ``cn``'s assumption, which
    divides) with the definedness condition behind its failure named
    (:func:`undefined_note`): decided in context over ``cone`` when its
    verdict was, else from ``hyps`` (the producers' guarantees and
    assumptions; ``who`` names the producers).  The counterexample becomes
    the one with the zero divisor.  ``sc`` unchanged when every condition
    is proved."""
    if sc.variant == VARIANT_IN_CONTEXT and cone is not None:
        in_cone = cone
        note, model = undefined_note(c, lambda f, comment: in_cone.decide(f, comment, timeout_ms),
                                     "the premises of its upstream cone")
    else:
        note, model = undefined_note(c, local_decider(cn, enc, hyps, timeout_ms), f"the guarantees of {who}")
    return dataclasses.replace(sc, explanation=sc.explanation + note, model=model) if note else sc


def explain_local(node: str, who: str, producers: Sequence[str], links: Sequence[str], assumptions: bool,
                  variant: str, first: QueryResult, r: QueryResult) -> str:
    """The words for a side condition of ``node`` decided locally: ``who``
    its producers as text, ``links`` the connections carrying the inputs
    the conjunct reads (``Producer.out.x -> Node.in.y (...)``),
    ``assumptions`` whether the producers have any, ``variant`` the one
    that gave ``r``, ``first`` the answer as written (module docstring of
    :mod:`.compose`)."""
    status = STATUS[r.status]
    if status == "discharged" and variant == VARIANT_AS_WRITTEN:
        expl = (f"Discharged as written: Z3 proved that the guarantees of {who} entail this conjunct of "
                f"{node}'s assumption.")
    elif status == "discharged":
        expl = (f"Discharged with the producers' assumptions: the guarantees of {who} alone do not entail "
                f"this conjunct of {node}'s assumption ({first.status}), but together with the assumptions "
                f"of {who} they do. {node} only reads outputs produced while those assumptions held, so the "
                "link is sound; the environment must meet the producers' assumptions.")
    elif status == "failed":
        feeders = sorted({x.split(".", 1)[0] for x in links}, key=producers.index) or producers
        expl = (f"{' and '.join(feeders)} and {node} are not correctly linked on {'; '.join(links) or 'no link'}: "
                f"Z3 found values satisfying every guarantee{' and assumption' if assumptions else ''} of {who} "
                f"that violate this conjunct of {node}'s assumption (model below). What "
                f"{' and '.join(feeders)} guarantee{'s' if len(feeders) == 1 else ''} about "
                f"{'these outputs' if len(links) > 1 else 'this output'} is weaker than what {node} assumes.")
    else:
        expl = (f"Z3 could not decide the side condition (reason given by Z3: {r.reason or 'unknown'}); "
                "it is not proved.")
        if first.status == "refuted":
            expl += (" As written it is refuted, but that model violates the producers' assumptions, so it "
                     "is not shown.")
    if r.strategy:
        expl += f" Z3's default strategy gave up; answered with {r.strategy}."
    return expl


@dataclass(frozen=True)
class ConeView:
    """What :func:`in_context` reads of a cone: its nodes and the links its
    loops are opened at (a :class:`.ConeContext` has both)."""

    cone: tuple[str, ...]
    cut: tuple[str, ...]


def in_context(sc: SideCondition, cr: ContextResult, ctx: ConeContext | ConeView, who: str,
               keep: set[str] | None = None) -> SideCondition:
    """``sc`` (decided locally, not discharged) with the verdict of its
    in-context check ``cr`` over the cone ``ctx`` (:mod:`.context`): the
    status, verdict, hypotheses, model, explanation, SMT-LIB2 text (the local
    query, ``(reset)``, the in-context query) and the ``context`` record.
    A counterexample shows the nodes of ``keep`` (the consumer and the cones
    of the producers of the inputs the conjunct reads: the values traced
    back to their sources, not a sibling branch feeding another input)."""
    node = sc.node
    local: LocalVerdict = {"status": sc.status, "variant": sc.variant, "model": sc.model}
    size = len(ctx.cone)
    record: ContextRecord = {"cone": size, "used": [u.split(":", 1)[0] for u in cr.used],
                             "used_nodes": list(cr.used_nodes),
                             "opened": list(ctx.cut), "violated": list(cr.violated), "joins": list(cr.joins),
                             "local": local}
    if cr.summaries:
        record["summaries"] = list(cr.summaries)
    opened = ("; the loop of its cone is opened at " + ", ".join(ctx.cut) + " (rule R4, paper lines 717-768: "
              "the value read there is taken as arbitrary, so no guarantee is used to discharge its own premise)"
              if ctx.cut else "")
    cone_words = (f"the upstream cone of {node} ({size} node{'s' if size != 1 else ''}: every guarantee under its "
                  f"own node's assumption, the environment assumptions and facts{opened})")
    local_words = (f"The guarantees of {who} alone do not entail this conjunct of {node}'s assumption "
                   f"({'refuted' if sc.status == 'failed' else 'undecided'} locally, {sc.variant})")
    smt2 = sc.smt2 + "\n(reset)\n" + cr.smt2
    duration = round(sc.duration_s + cr.duration_s, 4)
    strategy = f" Z3's default strategy gave up on the in-context query; answered with {cr.strategy}." if cr.strategy else ""
    if cr.status == "proved":
        labels = [u.split(":", 1)[0] for u in cr.used]
        named = ", ".join(labels[:NAMED]) + (f" and {len(labels) - NAMED} more premises (all listed as its hypotheses)"
                                              if len(labels) > NAMED else "") if labels else "no premise"
        expl = (f"Discharged in context. {local_words}, but {cone_words} does: Z3 proved it from {named}. Sound for "
                f"the composed system as long as the environment assumptions of the cone hold.")
        if cr.summaries:
            expl += (f" The proof read the summaries of the cones of {', '.join(cr.summaries)} (what each cone "
                     "establishes about the values read outside it, built producer by producer and each proved "
                     "implied by its cone) instead of the cone itself; the premises named are those they rest on.")
        if cr.joins:
            expl += (f" The proof reads {', '.join(cr.joins)} along more than one path; like the requirement checks "
                     "it rests on R3's simplifying assumption that the outputs a join reads persist and are available "
                     "together (paper line 660).")
        return SideCondition(sc.id, node, sc.rule, sc.conjunct, sc.source, tuple(cr.used), "discharged", duration,
                             smt2, None, expl + strategy, VARIANT_IN_CONTEXT, sc.links, IN_CONTEXT, record)
    if cr.status == "refuted":
        expl = (f"{sc.explanation} Checked in context too: with {cone_words}, Z3 still finds values violating it "
                "(the counterexample below, traced back through the cone to its sources).")
        if cr.violated:
            expl += (f" In it the assumption of {', '.join(cr.violated)} does not hold, so "
                     f"{'its guarantees promise' if len(cr.violated) == 1 else 'their guarantees promise'} nothing "
                     "there: the side conditions upstream are the first to repair.")
        if ctx.cut:
            expl += " The value on an opened link is arbitrary, so the counterexample may use one the loop never produces."
        shown = ({k: v for k, v in cr.model.items() if k.split(".", 1)[0] in keep}
                 if cr.model is not None and keep is not None else cr.model)
        return SideCondition(sc.id, node, sc.rule, sc.conjunct, sc.source, sc.hypotheses, "failed", duration,
                             smt2, shown, expl + strategy, VARIANT_IN_CONTEXT, sc.links, "failed", record)
    expl = (f"{local_words}; checked in context, with {cone_words}, Z3 could not decide it ({cr.reason or 'unknown'}). "
            "It is not proved, and no counterexample of the whole cone is known.")
    return SideCondition(sc.id, node, sc.rule, sc.conjunct, sc.source, sc.hypotheses, "inconclusive", duration,
                         smt2, None, expl + strategy, VARIANT_IN_CONTEXT, sc.links, "inconclusive", record)
