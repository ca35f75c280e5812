"""Weakest preconditions of the hoare backend's language, as Z3 formulas.

The paper proves the Radiation Sensor's triples by hand with the assignment
axiom, the conditional rule and the rule of consequence (shared/reference,
lines 1505-1541 and appendix B, 1984-).  This module mechanises the same
calculus backwards from a postcondition (Dijkstra's weakest preconditions,
partial correctness):

* ``wp(x := e, Q)      = Q[e/x]``  (and ``e >= 0`` when ``x`` is NATURAL and
  ``e`` is not syntactically NATURAL: the value must stay in the type);
* ``wp(S1; S2, Q)      = wp(S1, wp(S2, Q))``;
* ``wp(if c then S1 else S2 end, Q) = (c -> wp(S1, Q)) and (not c -> wp(S2, Q))``;
* ``wp(skip, Q)        = Q``;
* ``wp(while c invariant I do S end, Q) = I``, with two verification
  conditions collected on the side: ``I and c => wp(S, I)`` (the body
  preserves the invariant) and ``I and not c => Q`` (on exit the invariant
  establishes what follows).  As in Hoare's while rule, the loop VCs hold in
  an arbitrary state at the loop head: the invariant must state everything the
  code after the loop relies on, including variables the loop leaves alone
  (write ``n == old(n)``).

Everything is a Z3 term of the program's model
(:class:`~.program_model.ProgramModel`: variables, ``old(x)`` and externs
as Z3 constants and functions, in the RCL encoder's sorts).  Alongside the precondition the computation records a proof
outline: the assertion that holds before every statement, as in the paper's
proof figures.

Definedness (docs/semantics.md, "Definedness"): a division in the program
must not divide by zero.  Every application of a partial operator of the
semantics table (:attr:`rclverify.semantics.operators.Operator.partial`)
gets verification conditions of its own, computed by the same calculus run
for that one application (``wp(..., target=...)``): where the expression
holding it is evaluated, its condition (``d != 0``, under the guards the
connectives' short circuit puts before it, as
:func:`rclverify.semantics.definedness.right_guard` states it) must hold; the
statements before it carry it back to the initial state, a loop's body and
its exit to the loop head (under the invariant), and a loop's condition is
evaluated at the head of every iteration.  In that run a loop's weakest
precondition is ``TRUE``: that the invariant holds on entry is the
ordinary run's to prove (its ``main`` VC), so a definedness VC fails only
for a division that can see a zero divisor.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import z3

from rclverify.semantics.operators import OPERATORS
from rclverify.lang.ast import Loc
from rclverify.lang.types import NATURAL
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.check import expr_type
from rclverify.backends.hoare.program_model import ProgramModel


def partial_applications(body: tuple[lang.Stmt, ...]) -> list[lang.Binary]:
    """Every application of a partial operator (division) in ``body``, in
    program order (conditions, then branches; a loop's condition before its
    body).  Each is one definedness target of :func:`wp`."""
    out: list[lang.Binary] = []

    def expr(e: lang.Expr) -> None:
        if isinstance(e, lang.Binary):
            expr(e.left)
            expr(e.right)
            if OPERATORS[e.op].partial is not None:
                out.append(e)
        elif isinstance(e, lang.Unary):
            expr(e.operand)
        elif isinstance(e, lang.Call):
            for a in e.args:
                expr(a)

    def block(stmts: tuple[lang.Stmt, ...]) -> None:
        for s in stmts:
            if isinstance(s, lang.Assign):
                expr(s.value)
            elif isinstance(s, lang.If):
                expr(s.cond)
                block(s.then_)
                block(s.else_)
            elif isinstance(s, lang.While):
                expr(s.cond)
                block(s.body)
    block(body)
    return out


def requirement_text(target: lang.Binary) -> str:
    """The condition a partial application needs, as program text (``d != 0``)."""
    p = OPERATORS[target.op].partial
    assert p is not None
    operand = (target.left, target.right)[p.operand]
    return f"{lang.expr_text(operand)} != {p.excluded}"


def contains(e: lang.Expr | lang.Stmt, target: lang.Binary) -> bool:
    """Whether ``target`` (by identity) occurs in expression or statement ``e``."""
    if e is target:
        return True
    if isinstance(e, lang.Binary):
        return contains(e.left, target) or contains(e.right, target)
    if isinstance(e, lang.Unary):
        return contains(e.operand, target)
    if isinstance(e, lang.Call):
        return any(contains(a, target) for a in e.args)
    if isinstance(e, lang.Assign):
        return contains(e.value, target)
    if isinstance(e, lang.If):
        return contains(e.cond, target) or any(contains(x, target) for x in (*e.then_, *e.else_))
    if isinstance(e, lang.While):
        return contains(e.cond, target) or any(contains(x, target) for x in e.body)
    return False


def defined_at(e: lang.Expr, target: lang.Binary, m: ProgramModel) -> z3.BoolRef | None:
    """The condition under which evaluating ``e`` applies ``target`` inside
    its domain (``guards -> d != 0``, the guards of the connectives' short
    circuit from the semantics table); ``None`` when ``target`` is not in ``e``."""
    if e is target:
        p = OPERATORS[target.op].partial
        assert p is not None
        operand = m.term((target.left, target.right)[p.operand])
        return operand != p.excluded
    if isinstance(e, lang.Binary):
        left = defined_at(e.left, target, m)
        if left is not None:
            return left
        right = defined_at(e.right, target, m)
        if right is None:
            return None
        entry = OPERATORS[e.op]
        if entry.kind != "connective" or entry.decisive is None:  # both operands evaluated
            return right
        c = m.formula(e.left)  # the guard of semantics.definedness.right_guard, on Z3 terms
        return z3.Implies(c if entry.decisive is False else z3.Not(c), right)
    if isinstance(e, lang.Unary):
        return defined_at(e.operand, target, m)
    if isinstance(e, lang.Call):
        for a in e.args:
            found = defined_at(a, target, m)
            if found is not None:
                return found
    return None


# --------------------------------------------------------------------------
# Proof outline items and verification conditions
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class OutlineItem:
    """One line of a proof outline.

    ``kind`` ``"assert"``: ``formula`` holds at this point, ``note`` says which
    rule produced it; ``kind`` ``"code"``: ``text`` is a line of the program
    (``line`` its line in the program file).  ``depth`` is the nesting level.
    """

    depth: int
    kind: Literal["assert", "code"]
    text: str = ""
    formula: z3.BoolRef | None = None
    note: str = ""
    line: int = 0


@dataclass(frozen=True)
class VC:
    """A verification condition: ``hyps => goal`` must be valid.

    ``id``      stable name (``main``, ``loop@7.preserve``, ``loop@7.exit``);
    ``label``   one sentence for readers; ``loc`` where it comes from;
    ``state``   ``"initial"`` (the variables are the program's initial state)
                or ``"loop"`` (an arbitrary state at the loop head).
    """

    id: str
    label: str
    hyps: tuple[z3.BoolRef, ...]
    goal: z3.BoolRef
    loc: Loc
    state: Literal["initial", "loop"]


@dataclass(frozen=True)
class WP:
    """Result of :func:`wp`: the weakest precondition, the loop VCs collected
    on the way (program order), and the proof outline (top to bottom)."""

    pre: z3.BoolRef
    vcs: tuple[VC, ...]
    outline: tuple[OutlineItem, ...]


def _rule(s: lang.Stmt, m: ProgramModel) -> str:
    if isinstance(s, lang.Assign):
        if _needs_range(s, m):
            return f"assignment axiom, with {s.target} >= 0 (NATURAL)"
        return "assignment axiom"
    if isinstance(s, lang.If):
        return "conditional rule"
    if isinstance(s, lang.While):
        return "loop invariant (while rule)"
    return "skip axiom"


def _needs_range(s: lang.Assign, m: ProgramModel) -> bool:
    return m.types.vars[s.target] == NATURAL and expr_type(s.value, m.types) != NATURAL


def _stmt(s: lang.Stmt, post: z3.BoolRef, m: ProgramModel, depth: int, target: lang.Binary | None = None
          ) -> tuple[z3.BoolRef, list[VC], list[OutlineItem]]:
    """wp of one statement: (pre, VCs, outline lines of the statement itself);
    with ``target``, of that partial application's definedness alone (module docstring)."""
    line = s.loc.line
    if target is not None:
        return _stmt_defined(s, post, m, depth, target)
    if isinstance(s, lang.Assign):
        value = m.value_for(s.target, m.term(s.value))
        pre = z3.substitute(post, (m.consts[s.target], value))
        if _needs_range(s, m):
            pre = z3.And(value >= 0, pre)
        return pre, [], [OutlineItem(depth, "code", lang.stmt_header(s), line=line)]
    if isinstance(s, lang.Skip):
        return post, [], [OutlineItem(depth, "code", "skip", line=line)]
    if isinstance(s, lang.If):
        c = m.formula(s.cond)
        w1, vcs1, items1 = _block(s.then_, post, m, depth + 1, "the if's postcondition")
        w2, vcs2, items2 = _block(s.else_, post, m, depth + 1,
                                  "the if's postcondition" if s.else_ else "the if's postcondition (no else: skip)")
        pre = z3.And(z3.Implies(c, w1), z3.Implies(z3.Not(c), w2))
        items = [OutlineItem(depth, "code", lang.stmt_header(s), line=line), *items1,
                 OutlineItem(depth, "code", "else"), *items2, OutlineItem(depth, "code", "end")]
        return pre, vcs1 + vcs2, items
    assert isinstance(s, lang.While)
    c, inv = m.formula(s.cond), m.formula(s.invariant)
    wbody, vcs_body, items_body = _block(s.body, inv, m, depth + 1, "the invariant, re-established")
    vid = f"loop@{line}"
    preserve = VC(f"{vid}.preserve", f"the loop at line {line} preserves its invariant",
                  (inv, c), wbody, s.loc, "loop")
    exit_ = VC(f"{vid}.exit", f"on exit from the loop at line {line}, the invariant establishes what follows",
               (inv, z3.Not(c)), post, s.loc, "loop")
    items = [OutlineItem(depth, "code", lang.stmt_header(s), line=line),
             OutlineItem(depth + 1, "assert", formula=z3.And(inv, c),
                         note=f"invariant and loop condition; implies the next assertion ({preserve.id})"),
             *items_body, OutlineItem(depth, "code", "end"),
             OutlineItem(depth, "assert", formula=z3.And(inv, z3.Not(c)),
                         note=f"invariant and negated condition; implies the next assertion ({exit_.id})")]
    return inv, [preserve, *vcs_body, exit_], items


def _stmt_defined(s: lang.Stmt, post: z3.BoolRef, m: ProgramModel, depth: int, target: lang.Binary
                  ) -> tuple[z3.BoolRef, list[VC], list[OutlineItem]]:
    """The definedness run's wp of one statement for partial application
    ``target`` (module docstring): the ordinary rules with ``target``'s
    condition added where its expression is evaluated, a loop's wp ``TRUE``."""
    if z3.is_true(post) and not contains(s, target):
        return post, [], []
    line = s.loc.line
    if isinstance(s, lang.Assign):
        pre = z3.substitute(post, (m.consts[s.target], m.value_for(s.target, m.term(s.value))))
        here = defined_at(s.value, target, m)
        return (pre if here is None else z3.And(here, pre)), [], []
    if isinstance(s, lang.Skip):
        return post, [], []
    if isinstance(s, lang.If):
        c = m.formula(s.cond)
        w1, vcs1, _ = _block(s.then_, post, m, depth + 1, "", target)
        w2, vcs2, _ = _block(s.else_, post, m, depth + 1, "", target)
        pre = z3.And(z3.Implies(c, w1), z3.Implies(z3.Not(c), w2))
        here = defined_at(s.cond, target, m)
        return (pre if here is None else z3.And(here, pre)), vcs1 + vcs2, []
    assert isinstance(s, lang.While)
    c, inv = m.formula(s.cond), m.formula(s.invariant)
    wbody, vcs_body, _ = _block(s.body, z3.BoolVal(True), m, depth + 1, "", target)
    vid = f"loop@{line}"
    vcs: list[VC] = []
    here = defined_at(s.cond, target, m)
    if here is not None:
        vcs.append(VC(f"{vid}.condition", f"the condition of the loop at line {line} is defined at its head",
                      (inv,), here, s.loc, "loop"))
    if not z3.is_true(wbody):
        vcs.append(VC(f"{vid}.body", f"the body of the loop at line {line} is defined", (inv, c), wbody, s.loc,
                      "loop"))
    vcs.extend(vcs_body)
    if not z3.is_true(post):
        vcs.append(VC(f"{vid}.after", f"what follows the loop at line {line} is defined", (inv, z3.Not(c)), post,
                      s.loc, "loop"))
    return z3.BoolVal(True), vcs, []


def _block(stmts: tuple[lang.Stmt, ...], post: z3.BoolRef, m: ProgramModel, depth: int, post_note: str,
           target: lang.Binary | None = None) -> tuple[z3.BoolRef, list[VC], list[OutlineItem]]:
    segments: list[tuple[lang.Stmt, z3.BoolRef, list[VC], list[OutlineItem]]] = []
    q = post
    for s in reversed(stmts):
        pre_s, vcs_s, items_s = _stmt(s, q, m, depth, target)
        segments.append((s, pre_s, vcs_s, items_s))
        q = pre_s
    segments.reverse()
    items: list[OutlineItem] = []
    vcs: list[VC] = []
    for s, pre_s, vcs_s, items_s in segments:
        items.append(OutlineItem(depth, "assert", formula=pre_s, note=_rule(s, m)))
        items.extend(items_s)
        vcs.extend(vcs_s)
    items.append(OutlineItem(depth, "assert", formula=post, note=post_note))
    return q, vcs, items


def wp(body: tuple[lang.Stmt, ...], post: z3.BoolRef, m: ProgramModel, target: lang.Binary | None = None) -> WP:
    """Weakest precondition of ``body`` for ``post`` (a Z3 formula over the
    current-state constants of ``m``).

    Returns :class:`WP`: ``pre`` over the initial-state constants, the loop
    VCs (``state == "loop"``) and the proof outline.  With ``target`` (one
    of :func:`partial_applications`) it is the definedness run for that
    application (module docstring; call it with ``post`` ``TRUE``): no
    outline, and only the loop VCs that read the condition.  Pure: no solver call.
    """
    pre, vcs, items = _block(body, post, m, 0, "postcondition", target)
    return WP(pre, tuple(vcs), tuple(items) if target is None else ())


def main_vc(pre: z3.BoolRef, result: WP, m: ProgramModel, loc: Loc) -> VC:
    """The triple's own VC: ``pre and old(x) == x (for every x) => wp(program, post)``."""
    formulas = [pre, result.pre]
    olds = m.olds_in(formulas)
    links = tuple(m.olds[n] == m.consts[n] for n in olds)
    return VC("main", "the precondition implies the weakest precondition of the program",
              (pre, *links), result.pre, loc, "initial")

