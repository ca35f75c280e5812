"""From a node's RCL guarantee to Hoare triples over a program.

The paper turns the Radiation Sensor's guarantee into four Hoare triples over
its program (shared/reference, lines 1492-1508): the guarantee reads
``forall i | command = inspect(i) -> (inspected(i) and (0 <= r < 120 -> status
= green) and ...)`` and each consequence becomes ``{premise} P {consequence}``.
This module does that for any guarantee:

* a guarantee ``forall vars | H -> C`` (``H`` optional, the ``forall``
  optional) is split into the conjuncts of ``C``;
* a conjunct ``P -> Q`` gives the triple ``{A and H and P} program {Q}``, a
  plain conjunct ``Q`` gives ``{A and H} program {Q}``, where ``A`` is the
  node's assumption (all its ``assume`` clauses);
* the plan's ``binding`` maps RCL inputs to program expressions over the
  initial state (``in.r: radiation_at(i)``) and RCL outputs to program
  variables read in the final state (``out.radiationStatus: output``); a
  bound variable of the outer ``forall`` named like a program variable is
  that variable's initial value (``i``), other bound variables are fixed but
  arbitrary values;
* in the postcondition an input means its value when the program started
  (the program's ``old(x)`` constants); a part of ``A``/``H``/``P`` that
  mentions a bound output is moved into the postcondition as a premise;
* an I/O name in the conjunct that the binding does not cover makes the
  triple *not checkable* by this backend: it is exported with a ``pending``
  reason and never discharged.

Encoding uses the system's :class:`rclverify.semantics.encode.Encoder`, so the
program's sorts and the contract's are the same Z3 sorts.  The plan entry
(the program and its binding) is checked by :mod:`.config`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import z3

from rclverify.semantics.connectives import conj
from rclverify.semantics.definedness import Condition, conditions
from rclverify.semantics.encode import Encoder
from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.lang.printer import binding_to_rcl, expr_to_rcl, is_type
from rclverify.lang.typecheck import domain_type
from rclverify.lang.visit import Visitor, children
from rclverify.lang.types import NATURAL, CheckedNode, Type
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.config import HoareConfig
from rclverify.backends.hoare.program_model import ProgramModel


def rcl_text(e: ast.Expr) -> str:
    """RCL text of ``e`` (``and``/``or`` under ``->`` parenthesised)."""
    return expr_to_rcl(e, explicit=True)


# --------------------------------------------------------------------------
# Conjuncts of a guarantee
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class Conjunct:
    """One triple to prove, in RCL terms.

    ``guarantee``/``index`` are 1-based (the guarantee clause, the conjunct in
    it); ``bindings`` are the outer ``forall``'s; ``assumption`` the node's
    assume formulas; ``hypothesis`` ``H`` and ``premise`` ``P`` (``None``
    when absent); ``conclusion`` ``Q``; ``uncovered`` the I/O names of
    ``P``/``Q`` the plan's binding does not cover (non-empty -> pending).
    """

    guarantee: int
    index: int
    clause: ast.Clause
    bindings: tuple[ast.Binding, ...]
    assumption: tuple[ast.Expr, ...]
    hypothesis: ast.Expr | None
    premise: ast.Expr | None
    conclusion: ast.Expr
    loc: ast.Loc
    uncovered: tuple[str, ...] = ()

    @property
    def conjunct_text(self) -> str:
        body = self.conclusion if self.premise is None else ast.Binary("->", self.premise, self.conclusion)
        return rcl_text(body)

    @property
    def pending_reason(self) -> str:
        if not self.uncovered:
            return ""
        return (f"the program does not model {', '.join(self.uncovered)}; "
                "bind it in the plan or cover it with another backend")


def _conjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


class _IoNames(Visitor[None]):
    """The qualified I/O names of a formula in order of first occurrence
    (:func:`io_names`): a name bound by an enclosing quantifier is not one;
    ranges and tuple quantifiers are not looked into."""

    def __init__(self, node: CheckedNode) -> None:
        self.node = node
        self.out: list[str] = []

    def generic_visit(self, x: Any, scope: frozenset[str]) -> None:
        for c in children(x):
            self.visit(c, scope)

    def visit_Var(self, v: ast.Var, scope: frozenset[str]) -> None:
        if v.prefix is None and v.name in scope:
            return
        if v.prefix is not None:
            q = v.qualified
        elif v.name in self.node.inputs:
            q = f"in.{v.name}"
        elif v.name in self.node.outputs:
            q = f"out.{v.name}"
        else:
            return
        if q not in self.out:
            self.out.append(q)

    def visit_Quant(self, x: ast.Quant, scope: frozenset[str]) -> None:
        for b in x.bindings:
            if not is_type(b.domain):
                self.visit(b.domain, scope)
        self.visit(x.body, scope | frozenset(x.variables))

    def visit_SeqRange(self, x: ast.SeqRange, scope: frozenset[str]) -> None:
        return None

    def visit_TupleQuant(self, x: ast.TupleQuant, scope: frozenset[str]) -> None:
        return None


def io_names(e: ast.Expr, node: CheckedNode, bound: frozenset[str] = frozenset()) -> list[str]:
    """Qualified I/O names (``in.r``, ``out.inspected``) occurring in ``e``, in order."""
    names = _IoNames(node)
    names.visit(e, bound)
    return names.out


def conjuncts(node: CheckedNode, covered: set[str] | frozenset[str]) -> list[Conjunct]:
    """Split every guarantee of ``node`` into triples (see the module text).

    ``covered`` are the qualified I/O names the plan binds.  Returns them in
    guarantee order, conjuncts left to right.
    """
    n = node.node
    assumption = tuple(c.formula for c in n.assumes)
    out: list[Conjunct] = []
    for g, clause in enumerate(n.guarantees, start=1):
        f = clause.formula
        bindings: tuple[ast.Binding, ...] = ()
        if isinstance(f, ast.Quant) and f.kind == "forall":
            bindings, f = f.bindings, f.body
        bound = frozenset(nm for b in bindings for nm in b.names)
        hyp: ast.Expr | None = None
        if isinstance(f, ast.Binary) and f.op == "->":
            hyp, f = f.left, f.right
        for k, part in enumerate(_conjuncts(f), start=1):
            premise: ast.Expr | None = None
            concl = part
            if isinstance(part, ast.Binary) and part.op == "->":
                premise, concl = part.left, part.right
            names = io_names(part, node, bound)
            uncovered = tuple(q for q in names if q not in covered)
            loc = part.loc if part.loc.line else clause.loc
            out.append(Conjunct(g, k, clause, bindings, assumption, hyp, premise, concl, loc, uncovered))
    return out


def precondition_parts(c: Conjunct, outputs: Mapping[str, str], node: CheckedNode
                       ) -> tuple[list[ast.Expr], list[ast.Expr]]:
    """Split ``A``, ``H``, ``P`` into (pre-state parts, post-state premises):
    a part mentioning a bound output can only be evaluated after the program."""
    pre: list[ast.Expr] = []
    post: list[ast.Expr] = []
    bound = frozenset(nm for b in c.bindings for nm in b.names)
    for part in [*c.assumption, *([c.hypothesis] if c.hypothesis is not None else []),
                 *([c.premise] if c.premise is not None else [])]:
        outs = [q for q in io_names(part, node, bound) if q.startswith("out.") and q in outputs]
        (post if outs else pre).append(part)
    return pre, post


def _conj(parts: list[ast.Expr]) -> ast.Expr:
    if not parts:
        return ast.BoolLit(True)
    e = parts[0]
    for p in parts[1:]:
        e = ast.Binary("and", e, p)
    return e


def statement(c: Conjunct, cfg: HoareConfig, node: CheckedNode, program_vars: frozenset[str] = frozenset()) -> str:
    """The triple in readable RCL form, e.g.
    ``forall i in NATURAL: {0 <= in.r and ...} radiation_sensor {out.radiationStatus == green}
    where in.r = radiation_at(i), out.radiationStatus = output, i = program variable i``.
    ``program_vars`` are the program's variables (bound variables named like
    one are identified with it)."""
    pre, post_prem = precondition_parts(c, cfg.outputs, node)
    post: ast.Expr = c.conclusion
    if post_prem:
        post = ast.Binary("->", _conj(post_prem), post)
    head = ""
    if c.bindings:
        head = "forall " + ", ".join(_binding_text(b) for b in c.bindings) + ": "
    text = f"{head}{{{rcl_text(_conj(pre))}}} {cfg.stem} {{{rcl_text(post)}}}"
    binds = [f"{k} = {v}" for k, v in sorted(cfg.binding_text.items())]
    binds += [f"{nm} = program variable {nm}" for b in c.bindings for nm in b.names if nm in program_vars]
    if binds:
        text += " where " + ", ".join(binds)
    return text


def _binding_text(b: ast.Binding) -> str:
    return binding_to_rcl(b)


# --------------------------------------------------------------------------
# Encoding a conjunct as Z3 pre/postconditions over the program
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class EncodedTriple:
    """A triple over the program's Z3 vocabulary.

    ``pre``            over the initial-state constants;
    ``post``           over the final-state constants (inputs as ``old(x)``);
    ``background``     facts true in every state (encoder typing axioms,
                       ranges of fixed bound variables);
    ``observe``        RCL input name -> its initial-state term, and each bound
                       variable that is not a program variable -> its constant
                       (shown in counterexamples);
    ``observe_final``  RCL output name -> program variable;
    ``names``          Z3 symbol name -> display name (``in.command``);
    ``pre_defined``    the well-definedness conditions of the precondition
                       (:func:`rclverify.semantics.definedness.conditions`),
                       each with its formula over the initial-state constants;
    ``post_defined``   those of the postcondition, over the final-state ones;
    ``pre_guards``     the ranges of the guarantee's bound variables (part of
                       ``pre``), the hypotheses of the precondition's conditions.
    """

    pre: z3.BoolRef
    post: z3.BoolRef
    background: tuple[z3.BoolRef, ...]
    observe: Mapping[str, z3.ExprRef]
    observe_final: Mapping[str, str]
    names: Mapping[str, str] = field(default_factory=dict)
    pre_defined: tuple[tuple[Condition, z3.BoolRef], ...] = ()
    post_defined: tuple[tuple[Condition, z3.BoolRef], ...] = ()
    pre_guards: tuple[z3.BoolRef, ...] = ()


def _encode(enc: Encoder, e: ast.Expr, node: CheckedNode, symbols: Mapping[str, object],
            bound: Mapping[str, z3.ExprRef]) -> z3.BoolRef:
    """Encode ``e`` with its free bound-variable names given by ``bound``."""
    return enc.formula(e, node, symbols, bound=bound)


def _to_old(m: ProgramModel, t: z3.ExprRef) -> z3.ExprRef:
    return z3.substitute(t, *[(m.consts[n], m.olds[n]) for n in m.consts]) if m.consts else t


def encode_triple(c: Conjunct, cfg: HoareConfig, m: ProgramModel, enc: Encoder, node: CheckedNode,
                  program: lang.Program) -> EncodedTriple:
    """Encode a (covered) conjunct as pre/postcondition over program ``m``.

    Raises :class:`RclError` when a bound variable of the guarantee and the
    program variable of the same name have different sorts (located at the
    variable's declaration).
    """
    env = enc.env
    pre_b: dict[str, z3.ExprRef] = {}
    post_b: dict[str, z3.ExprRef] = {}
    pre_guards: list[z3.BoolRef] = []
    background: list[z3.BoolRef] = []
    scope: dict[str, Type] = {}
    fixed: dict[str, z3.ExprRef] = {}
    taken = set(m.consts) | set(m.funcs) | {f"old({n})" for n in m.consts}
    for b in c.bindings:
        t = domain_type(b, node, env, scope)
        sort = enc.sort(t)
        for nm in b.names:
            scope[nm] = t
            if nm in m.consts:
                if m.consts[nm].sort() != sort:
                    msg = f"variable {nm!r} is {m.types.vars[nm]} but the guarantee at {c.clause.loc} binds it in {t}"
                    raise RclError([error(m.types.var_loc(program, nm), msg, "E-type")])
                pre_b[nm], post_b[nm] = m.consts[nm], m.olds[nm]
                if t == NATURAL:
                    pre_guards.append(m.consts[nm] >= 0)
            else:
                zname = nm
                while zname in taken:
                    zname += "'"
                taken.add(zname)
                v = z3.Const(zname, sort)
                pre_b[nm] = post_b[nm] = v
                fixed[nm] = v
                if t == NATURAL:
                    background.append(v >= 0)
        if not is_type(b.domain):
            for nm in b.names:
                member = ast.Member(ast.Var(nm), b.domain)  # type: ignore[arg-type]
                pre_guards.append(_encode(enc, member, node, {}, pre_b))
    pre_syms: dict[str, object] = {}
    post_syms: dict[str, object] = {}
    observe: dict[str, z3.ExprRef] = dict(fixed)
    for key, expr in cfg.inputs.items():
        if isinstance(expr, lang.Name) and expr.name in m.funcs:
            pre_syms[key] = post_syms[key] = m.funcs[expr.name]
            continue
        term = m.term(expr)
        pre_syms[key], post_syms[key] = term, _to_old(m, term)
        observe[key] = term
    for key, var in cfg.outputs.items():
        post_syms[key] = m.consts[var]
    pre_parts, post_prem = precondition_parts(c, cfg.outputs, node)
    pre = conj(*pre_guards, *[_encode(enc, p, node, pre_syms, pre_b) for p in pre_parts])
    post = _encode(enc, c.conclusion, node, post_syms, post_b)
    if post_prem:
        post = z3.Implies(conj(*[_encode(enc, p, node, post_syms, post_b) for p in post_prem]), post)
    post_rcl = c.conclusion if not post_prem else ast.Binary("->", _conj(post_prem), c.conclusion, c.conclusion.loc)
    pre_defined = tuple((d, _encode(enc, d.formula, node, pre_syms, pre_b))
                        for d in conditions(_conj(pre_parts)))
    post_defined = tuple((d, _encode(enc, d.formula, node, post_syms, post_b)) for d in conditions(post_rcl))
    background.extend(enc.axioms())
    names = {s.z3name: s.display.split(".", 1)[1] if s.display.startswith(node.name + ".") else s.display
             for s in enc.symbols.values()}
    return EncodedTriple(pre, post, tuple(background), observe,
                         {k: v for k, v in cfg.outputs.items()}, names, pre_defined, post_defined, tuple(pre_guards))
