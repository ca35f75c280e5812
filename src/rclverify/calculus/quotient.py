"""Assumption calculation: the weakest contract of a node its neighbours need
(``rclverify quotient``; docs/calculus.md, "The quotient").

The paper leaves "calculating a contract's assumptions when composing two
contracts" to future work (lines 1848-1888, after Cobleigh et al.).  For a
node ``M`` declared by its interface only (or whose contract is to be
replaced), with inputs ``i`` and outputs ``o``, and the rest of the system
as it is:

* the **targets**: every side condition of every node downstream of ``M``
  (a conjunct of its assumption over produced inputs, decided in context,
  :mod:`.context`) and every formal, non-temporal requirement whose cone
  holds ``M`` (:mod:`rclverify.calculus.requirements.check`); each is judged on the
  premises its own check uses, ``M``'s contract aside (``P_t``);
* the **assumption** ``A(i) = exists w. P_M(w, i)``, where ``P_M`` are the
  premises of ``M``'s upstream cone (each guarantee under its node's
  assumption, environment assumptions and facts): the strongest assumption
  the context establishes, so ``M``'s own side conditions are discharged
  in context and its guarantee may rely on all of it;
* the **guarantee** ``G(i, o) = and_t forall w. P_t(w, i, o) -> t``: what
  every target needs of ``M``'s outputs whatever the values ``M`` cannot
  see; any guarantee that serves every target implies it where ``A``
  holds, so ``(A, G)`` is the largest contract in the refinement order
  under which the targets hold: the quotient of the targets by the rest of
  the system (Incer et al., "The Quotient in Assume-Guarantee Contracts";
  Pacti computes it on polyhedra).

Exact for linear arithmetic: both are quantifier-eliminated by Z3
(:mod:`.linear`) and printed as RCL.  Beyond it (functions, enumerations,
a result outside the fragment) a sound approximation is offered instead and
said so: ``TRUE`` as the assumption and, as the guarantee, the targets of
``M``'s direct consumers that speak of ``M``'s outputs alone, renamed.
Either way nothing is printed before Z3 re-checks it: the contract is put in
place, the whole system type-checked again, every target's side condition
decided (:func:`.compose.compose_node`) and every target requirement checked
(:func:`rclverify.calculus.requirements.check.check_requirement`); a target not
discharged or not proved makes :class:`QuotientError`.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import z3

from rclverify.semantics.encode import Encoder
from rclverify.semantics.subterms import subterms
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import BOOL, INTEGER, NATURAL, REAL, Checked
from rclverify.model.system.model import SystemModel
from rclverify.calculus.compose import split_assumption
from rclverify.calculus.cone_paths import opened_links
from rclverify.calculus.linear import clauses_under, eliminate, to_rcl
from rclverify.model.plan.load import all_requirements
from rclverify.lang.walk import subexpressions
from rclverify.lang.typecheck import check
from rclverify.semantics import wallclock
from rclverify.calculus.quotient_targets import PROVED, Target, compare_contract, confirmed, conj_all, node_block, recheck_targets

ARITH = (BOOL, INTEGER, NATURAL, REAL)


class QuotientError(Exception):
    """No contract can be given (the message says why); the command exits 1."""


@dataclass(frozen=True)
class Quotient:
    """The computed contract: ``assumption``/``guarantee`` as RCL text,
    ``exact`` (linear fragment) or a sound approximation (``how`` says
    which), the ``targets`` and their verdicts with the contract in place
    (``recheck``: ``[(id, verdict)]``), notes (targets not considered,
    the current contract compared), and ``node_text``: the RCL node block."""

    node: str
    assumption: str
    guarantee: str
    exact: bool
    how: str
    targets: tuple[str, ...]
    recheck: tuple[tuple[str, str], ...]
    notes: tuple[str, ...]
    node_text: str
    #: the second solver on each proved re-check: ``(id, agreement, why)`` (empty without one)
    solvers: tuple[tuple[str, str, str], ...] = ()


class _System:
    """The premises of the system with ``node``'s contract set aside."""

    def __init__(self, checked: Checked, model: SystemModel, plan: Any, node: str) -> None:
        self.checked, self.model, self.plan, self.node = checked, model, plan, node
        self.enc = Encoder(checked.env, model.alias())

    def env(self, m: str, enc: Encoder) -> list[z3.BoolRef]:
        cn = self.checked.nodes[m]
        out = [enc.formula(f.expr, cn) for f in self.plan.facts.get(m, ())]
        if m != self.node:
            out += [enc.formula(c, cn) for c in split_assumption(self.checked, self.model, m)[1]]
        return out

    def guarantees(self, m: str, enc: Encoder, conditional: bool) -> list[z3.BoolRef]:
        if m == self.node:
            return []
        cn = self.checked.nodes[m]
        parts = [enc.formula(a.formula, cn) for a in cn.node.assumes
                 if not (isinstance(a.formula, ast.BoolLit) and a.formula.value)]
        gs = [enc.formula(g.formula, cn) for g in cn.node.guarantees]
        return [z3.Implies(conj_all(parts), g) for g in gs] if conditional and parts else gs

    def cone_premises(self, cone: Sequence[str], consumer: str, enc: Encoder) -> list[z3.BoolRef]:
        """The premises of a side condition of ``consumer`` decided in context (:mod:`.context`)."""
        out: list[z3.BoolRef] = []
        for m in cone:
            if m != consumer:
                out += self.guarantees(m, enc, True)
            out += self.env(m, enc)
        return out


def targets(sysm: _System) -> tuple[list[Target], list[str]]:
    """The targets of the module docstring, and notes on what is left out."""
    checked, model, plan, node = sysm.checked, sysm.model, sysm.plan, sysm.node
    out: list[Target] = []
    notes: list[str] = []
    for d in model.nodes:
        if d == node or node not in model.upstream(d):
            continue
        cut = opened_links(model, d)
        enc = sysm.enc if not cut else Encoder(checked.env, {k: v for k, v in model.alias().items()
                                                               if k not in {(l.to_node, "in", l.to_var) for l in cut}})
        internal = split_assumption(checked, model, d)[0]
        if not internal:
            continue
        prem = tuple(sysm.cone_premises(model.upstream(d), d, enc))
        for k, c in enumerate(internal, 1):
            out.append(Target("side condition", f"{d}.sc{k}", expr_to_rcl(c), prem,
                              enc.formula(c, checked.nodes[d]), d, c))
    from rclverify.calculus.requirements.check import cone_of, formals_of  # deferred: start-up (loads rclverify.calculus.health, rclverify.calculus.requirements and more only when called)
    from rclverify.calculus.requirements.temporal_check import is_temporal  # deferred: start-up (loads rclverify.calculus.health, rclverify.calculus.requirements and more only when called)
    for req in all_requirements(plan):
        if req.formal is None:
            continue
        if is_temporal(req, checked, plan):
            notes.append(f"requirement {req.id} is temporal: not among the targets")
            continue
        formal, assuming = formals_of(req, checked)
        assert formal is not None
        cone = cone_of([formal, *assuming], model)
        if node not in cone:
            continue
        enc = sysm.enc
        req_prem: list[z3.BoolRef] = []
        for m in cone:
            req_prem += sysm.guarantees(m, enc, False) + sysm.env(m, enc)
        symbols = {f"{p}.{n}.{p}.{v}": enc.io_symbol(checked.nodes[n], p, v)
                   for f in (formal, *assuming) for n, p, v in f.mentions}
        req_prem += [enc.formula(a.expr, a.scope, symbols) for a in assuming]
        out.append(Target("requirement", req.id, " ".join(req.formal.text.split()), tuple(req_prem),
                          enc.formula(formal.expr, formal.scope, symbols)))
    return out, notes


def _constants(fs: Sequence[z3.ExprRef]) -> dict[str, z3.ExprRef]:
    """The free constants of ``fs`` by name; raises :class:`_Beyond` for a
    free function (a quantifier cannot range over it)."""
    out: dict[str, z3.ExprRef] = {}
    for x in subterms(fs):
        if z3.is_app(x) and x.decl().kind() == z3.Z3_OP_UNINTERPRETED:
            if x.decl().arity() > 0:
                raise _Beyond(f"{x.decl().name()} is a function")
            out[x.decl().name()] = x
    return out


class _Beyond(Exception):
    """The computation leaves linear arithmetic."""




def quotient(checked: Checked, model: SystemModel, plan: Any, node: str,
             confirm: Callable[[str], tuple[str, str]] | None = None) -> Quotient:
    """The weakest contract of ``node`` (module docstring), re-checked.

    A node on a loop (every service client and server pair is one) is
    computed with the loop opened as the calculus opens it (rule R4, paper
    lines 717-768): its upstream premises are the loop's other guarantees,
    each under its own node's assumption, the node's own outputs among the
    hidden values; the contract is then re-checked with the loop composed,
    where the in-context side conditions open the loop at its back edges
    (:mod:`.context`), and a note says so.

    ``confirm``: the second solver (docs/second-solver.md), a
    callable from a proved re-check's SMT-LIB2 script to ``(agreement,
    why)``; a re-check it does not confirm (``disagree``,
    ``inconclusive``) is not proved, so the contract does not re-check.

    Raises :class:`QuotientError` for an unknown node, a node with nothing
    to serve (no target), and a contract that does not re-check."""
    if node not in checked.nodes:
        raise QuotientError(f"no node named {node!r}; nodes: {', '.join(checked.nodes)}")
    loop = model.loop_of(node)
    cn = checked.nodes[node]
    sysm = _System(checked, model, plan, node)
    tgts, notes = targets(sysm)
    if not tgts:
        raise QuotientError(f"nothing downstream of {node} assumes anything of it and no formal requirement's cone "
                            "holds it: any contract serves (assume( TRUE ) with a guarantee of your choice)")
    try:
        a_text, g_text = _exact(sysm, model, node, tgts)
        how = ("exact: the weakest contract (linear arithmetic; Z3's quantifier elimination, the guarantee "
               "simplified where the assumption holds)")
    except _Beyond as why:
        a_text, g_text = "TRUE", _approximate(sysm, tgts)
        how = (f"a sound approximation, not the weakest contract ({why}): assumption TRUE; guarantee: what the "
               "direct consumers assume of its outputs")
    block = node_block(cn.node, a_text, g_text)
    recheck, said = confirmed(recheck_targets(checked, plan, node, block, tgts), confirm)
    bad = [f"{i} {v}" for i, v in recheck if v not in PROVED]
    if bad:
        raise QuotientError(f"the contract computed for {node} ({how}) does not re-check"
                            f"{' with Z3 and cvc5' if confirm else ' with Z3'}: " + "; ".join(bad) + f"\n{block}")
    if loop:
        notes.append(f"{node} lies on the loop {{{', '.join(loop)}}}: computed with the loop opened as rule R4 opens it "
                     "(the loop's other guarantees, each under its node's assumption, with this node's outputs "
                     "hidden; paper lines 717-768) and re-checked with the loop composed")
    notes += compare_contract(cn, a_text, g_text, checked, model, plan)
    return Quotient(node, a_text, g_text, how.startswith("exact"), how,
                    tuple(f"{t.kind} {t.id}: {t.text}" for t in tgts), tuple(recheck), tuple(notes), block,
                    tuple(said))


def _exact(sysm: _System, model: SystemModel, node: str, tgts: Sequence[Target]) -> tuple[str, str]:
    """The weakest contract of ``node`` as RCL text ``(assumption,
    guarantee)``: the upstream premises with all but the node's inputs
    eliminated, and the targets under them with all but the node's inputs
    and outputs eliminated (Z3's ``qe``), simplified and printed.  Raises
    :class:`_Beyond` when anything leaves linear arithmetic."""
    enc = sysm.enc
    cn = sysm.checked.nodes[node]
    ins = {v: enc.io_symbol(cn, "in", v) for v in cn.inputs if cn.inputs[v] in ARITH}
    outs = {v: enc.io_symbol(cn, "out", v) for v in cn.outputs if cn.outputs[v] in ARITH}
    names = {str(s): f"in.{v}" for v, s in ins.items()} | {str(s): f"out.{v}" for v, s in outs.items()}
    if len(ins) < len(cn.inputs) or len(outs) < len(cn.outputs):
        raise _Beyond("an input or output of the node is not a number or a Boolean")
    up = [m for m in model.upstream(node)]
    p_up = sysm.cone_premises(up, node, enc)
    keep = set(names)
    inputs = {str(x) for x in ins.values()}
    hidden = [c for n, c in sorted(_constants(p_up).items()) if n not in inputs]  # outputs too: A is over i
    a = eliminate(z3.Exists(hidden, conj_all(p_up)) if hidden else conj_all(p_up))
    parts = []
    for t in tgts:
        body = z3.Implies(conj_all(list(t.premises)), t.goal)
        hid = [c for n, c in sorted(_constants([body]).items()) if n not in keep]
        parts.append(z3.ForAll(hid, body) if hid else body)
    g = eliminate(conj_all(parts))
    if a is None or g is None:
        raise _Beyond("Z3's quantifier elimination left a quantifier")
    _no_answer(sysm, a, g, list(outs.values()), names)
    a = clauses_under(a)
    g = clauses_under(g, [a])
    a_text, g_text = to_rcl(a, names), to_rcl(g, names)
    if a_text is None or g_text is None:
        raise _Beyond("the eliminated formula is not linear arithmetic RCL can print")
    return a_text, g_text


def render(q: Quotient, target_texts: Mapping[str, str] | None = None) -> str:
    """The command's output: RCL comment lines saying what the contract
    serves, how it was computed and re-checked, then the node block
    (jinja2 template ``calculus/templates/quotient.rcl.j2``)."""
    import jinja2  # deferred: start-up (loads jinja2 only when called)
    env = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.calculus", "templates"), autoescape=False,
                             keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True)
    texts = target_texts or {}
    return env.get_template("quotient.rcl.j2").render(
        q=q, targets=[texts.get(t, t) for t in q.targets],
        recheck="; ".join(f"{i} {v}" for i, v in q.recheck),
        solvers="; ".join(f"{i} {a}" for i, a, _ in q.solvers))


def _no_answer(sysm: _System, a: z3.BoolRef, g: z3.BoolRef, outs: Sequence[z3.ExprRef],
               names: Mapping[str, str]) -> None:
    """Raise :class:`QuotientError` when some input the assumption admits
    has no output meeting the guarantee (with the node's environment
    facts): then no implementation can serve the targets (the quotient is
    unrealizable, :mod:`rclverify.calculus.health.realizable`), and the input is
    named."""
    facts = sysm.env(sysm.node, sysm.enc)
    body = conj_all([g] + facts)
    s = z3.Solver()
    wallclock.limit(s, 20_000)  # steps decide, the clock is a net
    s.add(a, z3.ForAll(list(outs), z3.Not(body)) if outs else z3.Not(body))
    if s.check() != z3.sat:
        return
    m = s.model()
    shown = ", ".join(f"{names[d.name()]} = {m[d]}" for d in sorted(m.decls(), key=lambda d: d.name())
                      if d.name() in names)
    raise QuotientError(f"no contract of {sysm.node} can serve its neighbours: for the input {shown}, which its "
                        "upstream cone can produce, no output meets what they need"
                        + (" (with its environment facts)" if facts else ""))


def _approximate(sysm: _System, tgts: Sequence[Target]) -> str:
    """The guarantee of the approximation: the direct consumers' side
    conditions that read only ``node``'s outputs, over its names."""
    model, node = sysm.model, sysm.node
    parts = []
    for t in tgts:
        if t.kind != "side condition" or t.conjunct is None:
            continue
        fed = {l.to_var: l.from_var for l in model.links_into(t.consumer) if l.from_node == node}
        cons = sysm.checked.nodes[t.consumer]
        mentioned = {v.name for v in _vars(t.conjunct)} & (set(cons.inputs) | set(cons.outputs))
        if not mentioned or not mentioned <= set(fed):
            continue
        parts.append(expr_to_rcl(_rename(t.conjunct, {v: ("out", fed[v]) for v in mentioned})))
    if not parts:
        raise QuotientError(f"{node}'s contract is beyond linear arithmetic and no target speaks of its outputs alone: "
                            "no contract computed (docs/calculus.md)")
    return " and ".join(f"({p})" for p in parts) if len(parts) > 1 else parts[0]


def _vars(e: ast.Expr) -> list[ast.Var]:
    return [v for v in subexpressions(e) if isinstance(v, ast.Var)]


def _rename(e: Any, to: Mapping[str, tuple[str, str]]) -> Any:
    """``e`` with each input variable of ``to`` renamed (``in.y`` -> ``out.x``)."""
    if isinstance(e, ast.Var):
        if e.name in to and e.prefix in (None, "in"):
            p, n = to[e.name]
            return ast.Var(n, p, e.loc)  # type: ignore[arg-type]
        return e
    if dataclasses.is_dataclass(e) and not isinstance(e, (type, ast.Loc)):
        kw = {}
        for f in dataclasses.fields(e):
            v = getattr(e, f.name)
            if isinstance(v, tuple):
                kw[f.name] = tuple(_rename(x, to) for x in v)
            elif dataclasses.is_dataclass(v):
                kw[f.name] = _rename(v, to)
        return dataclasses.replace(e, **kw) if kw else e
    return e
