"""Repair suggestions, each checked by Z3 before it is returned: the record
every repair is (:func:`_record`), the guard of a vacuous or inconsistent
guarantee, and the helpers the other kinds share.

The kinds (docs/diagnosis.md), each in its module:

``guard`` (here)
    a vacuous or inconsistent guarantee ``forall v | P -> Q`` whose
    unsat core names another guarantee ``G_c = forall w | P_c -> Q_c`` of
    the same node: ``P_c`` gets a guard ``g and (P_c)``: range restrictions
    of its bound variables first, weakest first, then conjunctions of the
    atoms of the node's other premises, fewest atoms first.
``strengthen-producer`` / ``rescale-producer`` / ``weaken-consumer`` (:mod:`.sidecond`)
    a failed side condition, ranked by what the repair costs the user.
``split-budget`` (:mod:`.deadline`)
    an end-to-end deadline over its budget: which hop must become how fast.
``tighten-bound`` / ``strengthen-guarantee`` (:mod:`.requirement`)
    a refuted requirement.
``constant`` (:mod:`.constants`)
    a refuted Hoare triple: the program's constants changed to the guarantee's.
``program`` (:mod:`.hoare_tokens`)
    a refuted Hoare triple no change of constants repairs: a one-token correction of the program (an
    operator's strictness, ``and``/``or``, ``+``/``-``, a number moved by one), every triple proved again.
``code`` (:mod:`.code_repair`)
    a failing property test: a one-token correction of the implementation's culprit line, checked by
    running the node's property tests again on a scratch copy (not by Z3 alone).

A suggestion is returned only when Z3 *showed* (``sat`` or ``proved``, never
``unknown``) that the problem is gone on the edited text.  That is all Z3
shows: the record's ``proves`` says what followed, ``not_shown`` what the
engineer must still judge (that the change is right for the robot, and the
evidence it asks for), and ``cost`` what else changes status.
"""
from __future__ import annotations

import hashlib
import itertools
import re
from typing import Any, Mapping, Sequence

import z3

from rclverify.calculus.compose import conjuncts
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.errors import RclError
from rclverify.lang.walk import free_names, subexpressions
from rclverify.semantics import world
from rclverify.diagnosis import recheck
from rclverify.diagnosis.edits import Edit
from rclverify.records.stage_records import Repair
from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import prove
from rclverify.lang.parser import parse_formula
from rclverify.lang.typecheck import domain_type
from rclverify.lang.types import Scalar
from rclverify.semantics.operators import OPERATORS

#: Most candidates tried per problem (each costs Z3 queries).
MAX_CANDIDATES = 12
#: Most atoms in a guard.
MAX_GUARD_ATOMS = 3
#: The first budget of each "does guard g imply guard h" query (milliseconds' worth of
#: Z3 resource steps; :func:`rclverify.semantics.query.prove`'s ``first_ms``).
FIRST_LOOK_MS = 100


def _peel(e: ast.Expr) -> tuple[list[str], ast.Expr]:
    names: list[str] = []
    while isinstance(e, ast.Quant) and e.kind == "forall":
        names += [n for b in e.bindings for n in b.names]
        e = e.body
    return names, e


def _record(kind: str, summary: str, edit: Edit, source: str, checks: list[dict[str, str]],
            cost: list[dict[str, str]], proves: str = "", not_shown: str = "") -> Repair:
    """One repair: ``kind``, ``summary`` (what to change and why), the
    ``edit`` (JSON, :meth:`Edit.to_json`) and its unified ``diff``, the
    ``checks`` Z3 answered, the ``cost`` (status changes), ``proves``
    (what Z3 showed follows from the edited text: "Controller.sc2 follows
    from the edited contracts") and ``not_shown`` (what Z3 did not show:
    that the change is safe; the evidence it asks for), ``checked_by`` (Z3's
    version) and ``sha256`` (:func:`text_sha256` of ``source``: ``rclverify
    repair --apply`` writes the edit only over that text)."""
    return {"kind": kind, "summary": summary, "file": edit.file, "edit": edit.to_json(source),
            "diff": edit.diff(source), "checks": checks, "cost": cost,
            "proves": proves or "the problem no longer follows from the edited text",
            "not_shown": not_shown or "that the change is right for the robot",
            "checked_by": f"z3 {z3.get_version_string()}", "sha256": text_sha256(source)}


def text_sha256(text: str) -> str:
    """The hex sha256 of ``text`` encoded as UTF-8: a file's text as :meth:`pathlib.Path.read_text` gives it
    (universal newlines), the digest a repair records of the file it edits."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _disjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "or":
        return _disjuncts(e.left) + _disjuncts(e.right)
    return [e]


def _negated(op: str) -> str:
    """The comparison that is ``op``'s negation, from the semantics table."""
    return str(OPERATORS[op].negation)


def _negation(e: ast.Expr) -> str:
    """RCL text of ``not e``, written as a reader would: ``not exists(..)``
    -> ``exists(..)``, ``i > 5`` -> ``i <= 5``, ``f(i) == FALSE`` ->
    ``f(i) == TRUE``."""
    if isinstance(e, ast.Unary) and e.op == "not":
        return expr_to_rcl(e.operand)
    if isinstance(e, ast.Compare) and len(e.ops) == 1:
        a, b = e.operands
        if e.ops[0] in ("==", "!=") and isinstance(b, ast.BoolLit):
            flipped = b.value if e.ops[0] == "!=" else not b.value
            return f"{expr_to_rcl(a)} == {'TRUE' if flipped else 'FALSE'}"
        return f"{expr_to_rcl(a)} {_negated(e.ops[0])} {expr_to_rcl(b)}"
    return f"not ({expr_to_rcl(e)})"


def _fact_bounds(facts: Sequence[ast.Expr]) -> dict[str, tuple[str, str]]:
    """``{function name: (op, bound text)}`` of the facts of the form
    ``forall(x, y in D | in.f(x, y) <= N)`` (``<``, ``<=``; a numeric
    literal ``N``): every result of ``f`` is at most (below) ``N``."""
    out: dict[str, tuple[str, str]] = {}
    for f in facts:
        _, body = _peel(f)
        if (isinstance(body, ast.Compare) and len(body.ops) == 1 and body.ops[0] in ("<", "<=")
                and isinstance(body.operands[0], ast.Apply) and isinstance(body.operands[1], ast.NumLit)):
            out[body.operands[0].func.name] = (body.ops[0], body.operands[1].text)
    return out


def _shifted(e: ast.Expr, names: set[str]) -> bool:
    """Is ``e`` a variable of ``names``, or one shifted by a literal (``i + 1``)?"""
    if isinstance(e, ast.Var) and e.prefix is None:
        return e.name in names
    return (isinstance(e, ast.Binary) and e.op in ("+", "-") and isinstance(e.right, ast.NumLit)
            and _shifted(e.left, names))


def range_guards(premise: ast.Expr, numeric: Sequence[str], facts: Sequence[ast.Expr]) -> list[tuple[str, str]]:
    """Guards that restrict the numeric bound variables ``numeric`` of a
    guarantee ``forall .. | premise -> ..`` to the instances it was meant
    for, as RCL texts, in the order built:

    1. the negation of each disjunct of the premise that speaks of one of
       them (``.. or not exists(x, y in REAL | in.wayP(x, y) == i + 1)`` ->
       ``exists(x, y in REAL | in.wayP(x, y) == i + 1)``: ``i`` has a
       successor): the guarantee no longer fires merely because its
       variable is out of range;
    2. the environment facts' bound on a function (``in.wayP(x, y) <= 12``)
       applied to the term the premise compares that function's result
       with (``in.wayP(x, y) == i + 1`` -> ``i + 1 <= 12``).

    Returns ``[(guard text, what it says), ...]`` without repeats.
    """
    names = set(numeric)
    out: dict[str, str] = {}
    for d in _disjuncts(premise):
        if free_names(d) & names:
            out.setdefault(_negation(d), f"drops the premise's disjunct `{expr_to_rcl(d)}`")
    bounds = _fact_bounds(facts)
    for e in subexpressions(premise):
        if isinstance(e, ast.Compare) and len(e.ops) == 1 and e.ops[0] == "==":
            for f, t in (e.operands, e.operands[::-1]):
                if isinstance(f, ast.Apply) and f.func.name in bounds and _shifted(t, names):
                    op, n = bounds[f.func.name]
                    out.setdefault(f"{expr_to_rcl(t)} {op} {n}",
                                   f"keeps `{expr_to_rcl(t)}` among the values the environment facts allow "
                                   f"`{expr_to_rcl(f.func)}` (`{op} {n}`)")
    return list(out.items())


def _weakest_first(ws: Any, node: str, guards: list[str], var_types: Mapping[str, str]) -> tuple[list[str], dict[str, list[str]]]:
    """``guards`` ordered so that no guard comes after one Z3 proves
    strictly weaker under the node's environment facts (``g -> h`` valid
    and not ``h -> g``: ``h`` is weaker), ties in the given order; and, for
    each guard, the others Z3 proves equivalent to it.  A pair Z3 cannot
    decide in its budget counts as incomparable.  Among guards no other is
    strictly weaker than, one without quantifiers comes first (Z3 decides
    the checks of the guarded contract more easily; of two equivalent
    guards either is the weakest)."""
    from rclverify.calculus.health.vacuity import INSTANCE_TIMEOUT_MS  # deferred: start-up (loads rclverify.calculus.health, rclverify.calculus.refine_timing and more only when called)
    if len(guards) < 2:
        return guards, {g: [] for g in guards}
    checked = ws.checked
    cn = checked.nodes[node]
    binds = ", ".join(f"{v} in {t}" for v, t in var_types.items())
    world.fresh()
    enc = Encoder(checked.env)
    facts = [enc.formula(f.expr, cn) for f in ws.plan.facts.get(node, ())]
    implies: dict[tuple[str, str], bool] = {}
    for g in guards:
        for h in guards:
            if g == h:
                continue
            try:
                goal = enc.formula(parse_formula(f"forall({binds} | ({g}) -> ({h}))", "<guard>", 1, 1), cn)
            except (RclError, KeyError, ValueError, z3.Z3Exception):
                implies[(g, h)] = False
                continue
            # a small first look, then the retries in the laddered order (finite instantiation first:
            # the case study's `i + 1 <= 12` -> `exists(.. wayP(x, y) == i + 1)`, which the default strategy
            # spent its whole budget on); every strategy still gets its whole budget, so what is proved is
            # the same (semantics/query.py, prove's first_ms)
            implies[(g, h)] = prove(goal, facts, enc, timeout_ms=INSTANCE_TIMEOUT_MS, first_ms=FIRST_LOOK_MS,
                                    comment=f"repair: does `{g}` imply `{h}`?").status == "proved"
    todo, order = sorted(guards, key=lambda g: "exists(" in g or "forall(" in g), []
    while todo:
        # the first guard no remaining guard is strictly weaker than
        pick = next((g for g in todo if not any(implies[(g, h)] and not implies[(h, g)] for h in todo if h != g)),
                    todo[0])
        order.append(pick)
        todo.remove(pick)
    equiv = {g: [h for h in guards if h != g and implies[(g, h)] and implies[(h, g)]] for g in guards}
    return order, equiv


def guard_repair(ws: Any, node: str, culprit: int, victims: Sequence[tuple[int, int | None]],
                 before: Mapping[str, str]) -> Repair | None:
    """A guard for guarantee ``culprit`` of ``node`` under which each
    victim ``(k, at)`` -- guarantee ``k``, at the instance ``at`` of its
    first NATURAL variable where it was vacuous, or ``None`` -- can fire and
    the contract is consistent, or ``None`` when no candidate passes Z3.
    ``before`` is the node's health ``{finding id: status}`` before the edit
    (for the cost, which re-runs every health check of the node).

    Candidates, in the order tried (docs/diagnosis.md, "Guard"): first the
    range restrictions of the guarantee's numeric bound variables
    (:func:`range_guards`), weakest first under the environment facts
    (:func:`_weakest_first`); then conjunctions of the atoms of the node's
    other premises on the guarantee's bound variables, fewest atoms first.
    The first candidate Z3 accepts is returned."""
    cn = ws.checked.nodes[node]
    gs = cn.node.guarantees
    if not 1 <= culprit <= len(gs):
        return None
    bound, body = _peel(gs[culprit - 1].formula)
    if not (bound and isinstance(body, ast.Binary) and body.op == "->"):
        return None
    premise = body.left
    used = free_names(gs[culprit - 1].formula.body if isinstance(gs[culprit - 1].formula, ast.Quant) else body)
    atoms = _premise_atoms(gs, culprit, bound, used)
    numeric = _numeric_vars(ws, cn, gs[culprit - 1].formula)
    ranged_why = dict(range_guards(premise, list(numeric), [f.expr for f in ws.plan.facts.get(node, ())]))
    ranged, equiv = _weakest_first(ws, node, list(ranged_why), numeric)
    loc = premise.loc
    if not loc.end_line:
        return None
    rel = loc.file
    source = recheck.source_text(ws, rel)
    old = Edit(rel, loc.line, loc.col, loc.end_line, loc.end_col, "").deleted(source)
    candidates: list[tuple[str, str]] = [(g, "range") for g in ranged]
    for size in range(1, min(MAX_GUARD_ATOMS, len(atoms)) + 1):
        candidates += [(" and ".join(combo), "atoms") for combo in itertools.combinations(atoms, size)]
    for guard, how in candidates[:MAX_CANDIDATES]:
        edit = Edit(rel, loc.line, loc.col, loc.end_line, loc.end_col, f"{guard} and ({old})")
        after = _guarded_health(ws, node, edit, victims)
        if after is None:
            continue
        if how == "range":
            same = equiv.get(guard, [])
            why = (f"restricts {_and_text([f'`{v}`' for v in numeric])}: it {ranged_why[guard]}"
                   + (f"; Z3 proved it the same as `{'`, `'.join(same)}` under the environment facts" if same else "")
                   + "; no weaker range restriction passed")
        else:
            why = f"no guard of fewer atoms among the {len(atoms)} candidate atoms passed"
        return _guard_record(node, culprit, victims, guard, why, edit, source, before, after)
    return None


def _premise_atoms(gs: Sequence[Any], culprit: int, bound: Sequence[str], used: set[str]) -> list[str]:
    """The atoms of the node's other guarantees' premises that mention only
    variables guarantee ``culprit`` binds (``bound``), those on a variable it
    binds and never uses (``used``: the ones it does) first (the lint's hint)."""
    atoms: list[str] = []
    for j, g in enumerate(gs, 1):
        if j == culprit:
            continue
        jb, jbody = _peel(g.formula)
        if not (isinstance(jbody, ast.Binary) and jbody.op == "->"):
            continue
        for a in conjuncts(jbody.left):
            mentioned = free_names(a) & set(jb)
            if mentioned and mentioned <= set(bound):
                text = expr_to_rcl(a)
                if text not in atoms:
                    atoms.append(text)
    unused = {v for v in bound if v not in used}
    atoms.sort(key=lambda t: not any(re.search(rf"(?<![\w']){re.escape(v)}(?![\w'])", t) for v in unused))
    return atoms


def _guarded_health(ws: Any, node: str, edit: Edit, victims: Sequence[tuple[int, int | None]]) -> dict[str, str] | None:
    """The node's health after ``edit`` (:func:`recheck.health`) when Z3
    found that every victim can fire (or, with none, that the contract is
    consistent), else ``None``."""
    system = recheck.edited_system(ws, edit)
    if system is None:
        return None
    checked, _ = system
    fired = {}
    for k, at in victims:
        fired[f"{node}.g{k}.non-vacuous"] = recheck.premise_fires(ws, checked, node, k, at)
        if fired[f"{node}.g{k}.non-vacuous"] != "sat":
            break
    if any(v != "sat" for v in fired.values()):
        return None
    # a premise query holds the assumption, every guarantee and the facts: a victim's witness is one of
    # consistency too, which is asked only when there is no victim
    if not victims and recheck.consistent(ws, checked, node) != "sat":
        return None
    # the checks just answered are not asked again
    known = {**{k: "ok" for k in fired}, f"{node}.contract-consistent": "ok"}
    return recheck.health(ws, checked, node, {k: at for k, at in victims if at is not None}, known=known)


def _guard_record(node: str, culprit: int, victims: Sequence[tuple[int, int | None]], guard: str, why: str,
                  edit: Edit, source: str, before: Mapping[str, str], after: dict[str, str]) -> Repair:
    """The repair record of the guard Z3 accepted (``why``: why this one)."""
    checks = [{"check": f"{node}.contract-consistent", "status": "consistent (Z3: sat, witness found)"}]
    checks += [{"check": f"{node}.g{k}.non-vacuous" + (f" at {at}" if at is not None else ""),
                "status": "can fire (Z3: sat, witness found)"} for k, at in victims]
    fired_text = ", ".join(f"guarantee {k}" + (f" (at the instance {at} where it was vacuous)" if at is not None else "")
                           for k, at in victims)
    summary = (f"Guard guarantee {culprit} of {node} with `{guard}`: Z3 found witnesses that the guarded "
               f"contract is consistent" + (f" and that {fired_text} can fire" if victims else "")
               + f"; the guard {why}.")
    # compared with the stage's own statuses: the checks asked again (not the replacement check)
    return _record("guard", summary, edit, source, checks,
                   recheck.changes({k: v for k, v in before.items() if k in after or ".g" in k}, after),
                   proves=(f"{fired_text} can fire and {node}'s contract is consistent (witnesses found)"
                           if victims else f"{node}'s contract is consistent (a witness found)"),
                   not_shown=(f"that guarantee {culprit} still says what {node} is meant to do where the guard "
                              f"is false; {node}'s evidence must then establish the guarded guarantee"))


def _and_text(xs: Sequence[str]) -> str:
    return xs[0] if len(xs) == 1 else ", ".join(xs[:-1]) + " and " + xs[-1]


def _numeric_vars(ws: Any, cn: Any, formula: ast.Expr) -> dict[str, str]:
    """``{name: "NATURAL" | "INTEGER"}`` of the outer ``forall``'s bound
    variables of those types, in binding order."""
    out: dict[str, str] = {}
    e = formula
    while isinstance(e, ast.Quant) and e.kind == "forall":
        for b in e.bindings:
            t = domain_type(b, cn, ws.checked.env)
            if isinstance(t, Scalar) and t.name in ("NATURAL", "INTEGER"):
                out.update({v: t.name for v in b.names})
        e = e.body
    return out


def _rename(text: str, pairs: Sequence[tuple[str, str]]) -> str:
    for a, b in pairs:
        text = re.sub(rf"(?<![\w.']){re.escape(a)}(?![\w'])", b, text)
    return text


def _numbers(e: Any) -> list[Any]:
    """Every numeric literal (``Num``/``NumLit`` with a location) under ``e``, in source order."""
    out: list[Any] = []
    todo = [e]
    while todo:
        x = todo.pop()
        if type(x).__name__ in ("Num", "NumLit") and getattr(x, "loc", None) is not None:
            out.append(x)
            continue
        if isinstance(x, (tuple, list)):
            todo.extend(reversed(x))
        elif hasattr(x, "__dataclass_fields__"):
            todo.extend(reversed([getattr(x, f) for f in x.__dataclass_fields__ if f != "loc"]))
    return sorted(out, key=lambda n: (n.loc.line, n.loc.col))
