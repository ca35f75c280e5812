"""Repair suggestions, each checked by Z3 before it is returned.

Three kinds (docs/diagnosis.md):

``guard``
    a vacuous or inconsistent guarantee ``forall v | P -> Q`` whose
    unsat core names another guarantee ``G_c = forall w | P_c -> Q_c`` of
    the same node: ``P_c`` gets a guard ``g and (P_c)``.  Candidates are
    the conjunctions of the atoms of the node's other premises that speak
    of ``G_c``'s bound variables (atoms on variables ``G_c`` binds and never
    uses first), fewest atoms first: the first that Z3 accepts is the
    weakest guard among the candidates.
``strengthen-producer`` / ``weaken-consumer``
    a failed side condition ``G_p => c``: the producer's guarantees get
    ``c`` (in the producer's output names) as a new guarantee -- the weakest
    strengthening of ``G_p`` that entails ``c`` --; or the consumer's
    conjunct ``c`` is replaced by the strongest of the producer's own
    conjuncts on the linked variables (in the consumer's input names) that
    Z3 proves entailed.
``constant``
    a refuted Hoare triple: numeric literals of the program are replaced by
    numeric literals of the guarantee's conjunct, fewest replacements first,
    until every triple of the program's plan entry is discharged.

A suggestion is returned only when Z3 *showed* (``sat`` or ``proved``, never
``unknown``): the edited contract still parses and type-checks, it is
consistent (the health check ``contract-consistent`` is ``ok``), the
problem is gone (the guarantee can fire / the side condition is
discharged / every triple is discharged), and what else changes status
(``cost``: every health finding, side condition or triple whose status
differs from before the edit).
"""
from __future__ import annotations

import difflib
import itertools
import re
from typing import Any, Mapping, Sequence

import z3

from ..calculus.compose import conjuncts
from ..rcl import ast
from ..rcl.printer import expr_to_rcl
from ..rcl.errors import RclError
from ..rcl.walk import free_names, subexpressions
from ..logic import world
from . import recheck
from .edits import Edit

#: Most candidates tried per problem (each costs Z3 queries).
MAX_CANDIDATES = 12
#: Most atoms in a guard.
MAX_GUARD_ATOMS = 3


def _peel(e: ast.Expr) -> tuple[list[str], ast.Expr]:
    names: list[str] = []
    while isinstance(e, ast.Quant) and e.kind == "forall":
        names += [n for b in e.bindings for n in b.names]
        e = e.body
    return names, e


def _record(kind: str, summary: str, edit: Edit, source: str, checks: list[dict[str, str]],
            cost: list[dict[str, str]]) -> dict[str, Any]:
    return {"kind": kind, "summary": summary, "file": edit.file, "edit": edit.to_json(source),
            "diff": edit.diff(source), "checks": checks, "cost": cost,
            "checked_by": f"z3 {z3.get_version_string()}"}


def _disjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "or":
        return _disjuncts(e.left) + _disjuncts(e.right)
    return [e]


_FLIP = {"==": "!=", "!=": "==", "<": ">=", "<=": ">", ">": "<=", ">=": "<"}


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
        return f"{expr_to_rcl(a)} {_FLIP[e.ops[0]]} {expr_to_rcl(b)}"
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
    from ..health.checks import INSTANCE_TIMEOUT_MS
    from ..logic.encode import Encoder
    from ..logic.query import prove
    from ..rcl.parser import parse_formula
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
            implies[(g, h)] = prove(goal, facts, enc, timeout_ms=INSTANCE_TIMEOUT_MS,
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
                 before: Mapping[str, str]) -> dict[str, Any] | None:
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
    # atoms on the variables the guarantee binds and never uses first (the lint's hint)
    unused = {v for v in bound if v not in used}
    atoms.sort(key=lambda t: not any(re.search(rf"(?<![\w']){re.escape(v)}(?![\w'])", t) for v in unused))
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
        system = recheck.edited_system(ws, edit)
        if system is None:
            continue
        checked, _ = system
        fired = {}
        for k, at in victims:
            fired[f"{node}.g{k}.non-vacuous"] = recheck.premise_fires(ws, checked, node, k, at)
            if fired[f"{node}.g{k}.non-vacuous"] != "sat":
                break
        if any(v != "sat" for v in fired.values()):
            continue
        if recheck.consistent(ws, checked, node) != "sat":
            continue
        # the checks just answered are not asked again
        known = {**{k: "ok" for k in fired}, f"{node}.contract-consistent": "ok"}
        after = recheck.health(ws, checked, node, {k: at for k, at in victims if at is not None}, known=known)
        checks = [{"check": f"{node}.contract-consistent", "status": "consistent (Z3: sat, witness found)"}]
        checks += [{"check": f"{node}.g{k}.non-vacuous" + (f" at {at}" if at is not None else ""),
                    "status": "can fire (Z3: sat, witness found)"} for k, at in victims]
        fired_text = ", ".join(f"guarantee {k}" + (f" (at the instance {at} where it was vacuous)" if at is not None else "")
                               for k, at in victims)
        if how == "range":
            same = equiv.get(guard, [])
            why = (f"restricts {_and_text([f'`{v}`' for v in numeric])}: it {ranged_why[guard]}"
                   + (f"; Z3 proved it the same as `{'`, `'.join(same)}` under the environment facts" if same else "")
                   + "; no weaker range restriction passed")
        else:
            why = f"no guard of fewer atoms among the {len(atoms)} candidate atoms passed"
        summary = (f"Guard guarantee {culprit} of {node} with `{guard}`: Z3 found witnesses that the guarded "
                   f"contract is consistent" + (f" and that {fired_text} can fire" if victims else "")
                   + f"; the guard {why}.")
        # compared with the stage's own statuses: the checks asked again (not the replacement check)
        return _record("guard", summary, edit, source, checks,
                       recheck.changes({k: v for k, v in before.items() if k in after or ".g" in k}, after))
    return None


def _and_text(xs: Sequence[str]) -> str:
    return xs[0] if len(xs) == 1 else ", ".join(xs[:-1]) + " and " + xs[-1]


def _numeric_vars(ws: Any, cn: Any, formula: ast.Expr) -> dict[str, str]:
    """``{name: "NATURAL" | "INTEGER"}`` of the outer ``forall``'s bound
    variables of those types, in binding order."""
    from ..rcl.typecheck import domain_type
    from ..rcl.types import Scalar
    out: dict[str, str] = {}
    e = formula
    while isinstance(e, ast.Quant) and e.kind == "forall":
        for b in e.bindings:
            t = domain_type(b, cn, ws.checked.env)
            if isinstance(t, Scalar) and t.name in ("NATURAL", "INTEGER"):
                out.update({v: t.name for v in b.names})
        e = e.body
    return out


def _link_pairs(sc: Mapping[str, Any]) -> list[tuple[str, str, str, str]]:
    """``(producer, out var, consumer, in var)`` of a side condition's links
    (``Planner.out.speed -> Controller.in.speed (via name)``)."""
    out = []
    for l in sc.get("links", []):
        m = re.match(r"^(\w+)\.out\.(\w+) -> (\w+)\.in\.(\w+)", l)
        if m:
            out.append((m.group(1), m.group(2), m.group(3), m.group(4)))
    return out


def _rename(text: str, pairs: Sequence[tuple[str, str]]) -> str:
    for a, b in pairs:
        text = re.sub(rf"(?<![\w.']){re.escape(a)}(?![\w'])", b, text)
    return text


def side_condition_repairs(ws: Any, sc: Mapping[str, Any], before_sc: Mapping[str, str]) -> list[dict[str, Any]]:
    """Repairs of the failed side condition ``sc`` (a report row): a
    strengthened producer guarantee, and a weakened consumer assumption,
    each returned only when Z3 discharged the side condition on the edited
    contracts and the edited node's contract is consistent.  ``before_sc``
    maps every side condition id of the system to its status before."""
    pairs = _link_pairs(sc)
    if not pairs:
        return []
    consumer = sc["node"]
    producers = sorted({p for p, _, _, _ in pairs})
    out: list[dict[str, Any]] = []
    # the conjunct of the consumer's assumption, located
    cons = ws.checked.nodes[consumer].node
    target = None
    for a in cons.assumes:
        for c in conjuncts(a.formula):
            if expr_to_rcl(c) == sc["conjunct"] and c.loc.end_line:
                target = c
    if target is None:
        return []
    to_producer = [(f"in.{iv}", f"out.{ov}") for _, ov, _, iv in pairs]
    to_consumer = [(f"out.{ov}", f"in.{iv}") for _, ov, _, iv in pairs]

    def cost_of(checked: Any, model: Any, nodes: Sequence[str], health_nodes: Sequence[str]) -> tuple[dict[str, str], list[dict[str, str]]] | None:
        after: dict[str, str] = {}
        for n in nodes:
            after.update(recheck.side_conditions(checked, model, n, ws))
        if after.get(sc["id"]) != "discharged":
            return None
        h_before: dict[str, str] = {}
        h_after: dict[str, str] = {}
        for n in health_nodes:  # both asked the same way, so a change is the edit's
            h_before.update(recheck.health(ws, ws.checked, n))
            h_after.update(recheck.health(ws, checked, n))
            if h_after.get(f"{n}.contract-consistent") != "ok":
                return None
        before = {k: v for k, v in before_sc.items() if k in after}
        return after, recheck.changes({**before, **h_before}, {**after, **h_after})

    # 1. strengthen the producer: the conjunct, in its output names, as a new guarantee
    if len(producers) == 1:
        p = producers[0]
        pn = ws.checked.nodes[p].node
        last = pn.guarantees[-1] if pn.guarantees else None
        if last is not None and last.loc.end_line:
            rel = last.loc.file
            source = recheck.source_text(ws, rel)
            line = source.splitlines()[last.loc.line - 1]
            indent = line[:len(line) - len(line.lstrip())]
            new_g = _rename(sc["conjunct"], to_producer)
            edit = Edit(rel, last.loc.end_line, last.loc.end_col, last.loc.end_line, last.loc.end_col,
                        f"\n{indent}guarantee( {new_g} )")
            system = recheck.edited_system(ws, edit)
            if system is not None:
                consumers = sorted({l.to_node for l in system[1].links if l.from_node == p})
                res = cost_of(*system, consumers, [p])
                if res is not None:
                    out.append(_record(
                        "strengthen-producer",
                        f"Strengthen {p}: add the guarantee `{new_g}`, the weakest strengthening of {p}'s "
                        f"guarantees that entails {consumer}'s assumption `{sc['conjunct']}`; Z3 discharged "
                        f"{sc['id']} and {p}'s contract stays consistent. {p}'s evidence must then establish "
                        "the new guarantee.",
                        edit, source,
                        [{"check": sc["id"], "status": "discharged (Z3: proved)"},
                         {"check": f"{p}.contract-consistent", "status": "ok (Z3: sat)"}], res[1]))
    # 2. weaken the consumer: replace the conjunct by a producer conjunct on the same variables
    cands: list[str] = []
    linked = {f"out.{ov}" for _, ov, _, _ in pairs}
    for p in producers:
        for g in ws.checked.nodes[p].node.guarantees:
            for c in conjuncts(g.formula):
                t = expr_to_rcl(c)
                if any(re.search(rf"(?<![\w.']){re.escape(v)}(?![\w'])", t) for v in linked):
                    t2 = _rename(t, to_consumer)
                    if "out." not in t2 and t2 != sc["conjunct"] and t2 not in cands:
                        cands.append(t2)
    # not what the consumer already assumes; closest to the conjunct it replaces first
    already = {expr_to_rcl(c) for a in cons.assumes for c in conjuncts(a.formula)}
    cands = [t for t in cands if t not in already]
    cands.sort(key=lambda t: -difflib.SequenceMatcher(None, t, sc["conjunct"]).ratio())
    rel = target.loc.file
    source = recheck.source_text(ws, rel)
    for t in cands[:MAX_CANDIDATES]:
        edit = Edit(rel, target.loc.line, target.loc.col, target.loc.end_line, target.loc.end_col, t)
        system = recheck.edited_system(ws, edit)
        if system is None:
            continue
        res = cost_of(*system, [consumer], [consumer])
        if res is None:
            continue
        out.append(_record(
            "weaken-consumer",
            f"Weaken {consumer}'s assumption: `{sc['conjunct']}` becomes `{t}`, what "
            f"{' and '.join(producers)} guarantee{'s' if len(producers) == 1 else ''}; Z3 discharged {sc['id']} and "
            f"{consumer}'s contract stays consistent. {consumer}'s evidence must then establish its guarantees "
            "for the wider inputs.",
            edit, source,
            [{"check": sc["id"], "status": "discharged (Z3: proved)"},
             {"check": f"{consumer}.contract-consistent", "status": "ok (Z3: sat)"}], res[1]))
        break
    return out


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


def _num_value(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def hoare_repair(ws: Any, node: str, guarantee: int, program: str,
                 before: Mapping[str, str]) -> dict[str, Any] | None:
    """The change of program constants (to constants of guarantee
    ``guarantee`` of ``node``) under which every triple of the plan entry of
    ``program`` is discharged, fewest changes first; ``None`` when none
    passes.  ``before`` maps the entry's obligation ids to their statuses."""
    from ..backends.hoare import lang
    idx = next((i for i, e in enumerate(ws.plan.evidence.get(node, ()))
                if e.backend == "hoare" and e.config.get("program") == program), None)
    if idx is None:
        return None
    source = recheck.source_text(ws, program)
    prog = lang.parse_program(source, program)
    prog_nums = [n for n in _numbers(prog.body) if n.loc.end_line]
    g = ws.checked.nodes[node].node.guarantees[guarantee - 1]
    contract = []
    for n in _numbers(g.formula):
        if n.text not in contract:
            contract.append(n.text)
    distinct = sorted({n.text for n in prog_nums if n.text not in contract}, key=_num_value)
    if not distinct or not contract:
        return None
    tried = 0
    for size in range(1, len(distinct) + 1):
        for olds in itertools.combinations(distinct, size):
            for news in itertools.product(contract, repeat=size):
                if tried >= MAX_CANDIDATES * 4:
                    return None
                # keep the order of the thresholds: a larger constant stays larger
                if list(news) != sorted(news, key=_num_value) or len(set(news)) != size:
                    continue
                tried += 1
                mapping = dict(zip(olds, news))
                new_text = _replace_numbers(source, prog_nums, mapping)
                after = recheck.hoare_statuses(ws, node, idx, program, new_text)
                if not after or any(s not in ("discharged", "pending") for s in after.values()):
                    continue
                if not any(s == "discharged" for s in after.values()):
                    continue
                first = [n for n in prog_nums if n.text in mapping]
                lo = min(first, key=lambda n: (n.loc.line, n.loc.col))
                hi = max(first, key=lambda n: (n.loc.end_line, n.loc.end_col))
                span = Edit(program, lo.loc.line, lo.loc.col, hi.loc.end_line, hi.loc.end_col, "")
                region = span.deleted(source)
                edit = Edit(program, lo.loc.line, lo.loc.col, hi.loc.end_line, hi.loc.end_col,
                            _replace_numbers(region, [_shift(n, lo) for n in first], mapping))
                said = ", ".join(f"{a} -> {b}" for a, b in mapping.items())
                return _record(
                    "constant",
                    f"Change the constants of {program}: {said} (the constants of guarantee {guarantee} of "
                    f"{node}); Z3 then discharges every triple of the program ({len(after)} in all, "
                    f"{sum(1 for s in after.values() if s == 'pending')} still pending for what the program "
                    "does not model).",
                    edit, source, [{"check": k, "status": v + (" (Z3: proved)" if v == "discharged" else "")}
                                   for k, v in sorted(after.items())],
                    recheck.changes(before, after))
    return None


class _At:
    def __init__(self, text: str, line: int, col: int, end_line: int, end_col: int) -> None:
        from ..rcl.ast import Loc
        self.text = text
        self.loc = Loc("", line, col, end_line, end_col)


def _shift(n: Any, lo: Any) -> _At:
    """``n``'s location relative to the start of ``lo`` (line 1, col 1)."""
    line = n.loc.line - lo.loc.line + 1
    col = n.loc.col - (lo.loc.col - 1 if n.loc.line == lo.loc.line else 0)
    end_col = n.loc.end_col - (lo.loc.col - 1 if n.loc.end_line == lo.loc.line else 0)
    return _At(n.text, line, col, n.loc.end_line - lo.loc.line + 1, end_col)


def _replace_numbers(text: str, nums: Sequence[Any], mapping: Mapping[str, str]) -> str:
    """``text`` with each literal of ``nums`` whose text ``mapping`` names
    replaced (from the last to the first, so earlier positions hold)."""
    for n in sorted(nums, key=lambda n: (n.loc.line, n.loc.col), reverse=True):
        if n.text in mapping:
            text = Edit("", n.loc.line, n.loc.col, n.loc.end_line, n.loc.end_col, mapping[n.text]).apply(text)
    return text
