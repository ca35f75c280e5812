"""Safety properties proved by IC3/PDR: Z3's Spacer on constrained Horn clauses.

``always prop`` over a :class:`~.tsys.TransitionSystem` holds when some
predicate ``Inv`` over one state is an *inductive invariant* that implies
it.  The three conditions are constrained Horn clauses over the unknown
relation ``Inv`` (Bjorner, Gurfinkel, McMillan, Rybalchenko, "Horn clause
solvers for program verification", 2015)::

    init(s)                  ->  Inv(s)
    Inv(s) and trans(s, t)   ->  Inv(t)
    Inv(s) and not prop(s)   ->  false

Z3's ``HORN`` solver, whose engine is Spacer (Komuravelli, Gurfinkel,
Chaki, "SMT-based model checking for recursive programs", CAV 2014, an
IC3/PDR of Bradley, VMCAI 2011, over arithmetic, arrays and data types),
answers ``sat`` with an interpretation of ``Inv``, ``unsat`` when no
invariant exists (a run reaches ``not prop``), or ``unknown`` (time limit,
a theory it does not handle: then nothing is concluded).

Spacer works in a Z3 context of its own: the clauses are translated into a
new context, and the interpretation back into the caller's.  Its search
depended on what the caller's context held before: in a context that
earlier queries had filled, it spent its whole budget on a system whose one
reachable state has no successor, which it proves at once in a fresh
context (tests/calculus/test_temporal_pdr.py).  A requirement's decision asks
k-induction, the hint and Houdini first, in the caller's context; they no
longer change what Spacer answers.

The interpretation is a **certificate**, never trusted as it comes:
:func:`recheck` asks a plain Z3 solver the three conditions again on it
(each ``unsat`` needed), and only a certificate that passes proves the
property.  An ``unsat`` is turned into a counterexample by bounded model
checking from the initial states (:func:`shortest_violation`); a run that
is not found within the time limit leaves the verdict ``inconclusive``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import z3

from rclverify.calculus.requirements.tsys import Pred, TransitionSystem, trace_of
from rclverify.semantics import wallclock
from rclverify.semantics.connectives import conj

#: At most this many characters of a certificate are shown in a verdict's detail.
SHOWN = 600


@dataclass
class HornAnswer:
    """What Spacer said of ``always prop``: ``status`` ``invariant`` (then
    ``invariant`` is the certificate, a Z3 formula over :func:`named_state`),
    ``reachable`` (a run violates it) or ``unknown`` (``reason`` says why);
    ``seconds`` the wall time of the query."""

    status: str
    invariant: z3.BoolRef | None = None
    reason: str = ""
    seconds: float = 0.0
    trace: list[dict[str, str]] = field(default_factory=list)


def named_state(ts: TransitionSystem, prime: bool = False) -> dict[str, z3.ExprRef]:
    """One state of ``ts`` as Z3 constants named as its variables (``x'``
    with ``prime``): the names a certificate is shown in."""
    return {n: z3.Const(n + ("'" if prime else ""), s) for n, s in ts.sorts.items()}


def _conjuncts(e: z3.ExprRef) -> list[z3.ExprRef]:
    """The conjuncts of ``e``, nested ``And`` flattened."""
    if z3.is_and(e):
        return [c for k in e.children() for c in _conjuncts(k)]
    return [e]


def _names(e: z3.ExprRef, known: dict[str, str]) -> set[str]:
    """The state variables ``e`` mentions (``known``: constant name -> variable)."""
    out, seen, todo = set(), set(), [e]
    while todo:
        x = todo.pop()
        if x.get_id() in seen:
            continue
        seen.add(x.get_id())
        if z3.is_const(x) and x.decl().name() in known:
            out.add(known[x.decl().name()])
        todo.extend(x.children() if z3.is_app(x) else [x.body()] if z3.is_quantifier(x) else [])
    return out


def cone_of_influence(ts: TransitionSystem, prop: Pred) -> tuple[list[str], list[z3.ExprRef], list[z3.ExprRef]]:
    """The variables ``prop`` depends on through the step relation, and the
    conjuncts of ``init`` and ``trans`` (over :func:`named_state`) that
    mention them: every conjunct touching one of them brings in every
    variable it mentions, to a fixpoint (Clarke, Grumberg, Peled, "Model
    Checking", the cone of influence).  The conjuncts left out mention none
    of these variables; leaving them out lets more runs through, so an
    invariant of the reduced system is one of ``ts`` (the certificate is
    re-checked on ``ts`` anyway) while a run of it is searched again on
    ``ts``."""
    a, b = named_state(ts), named_state(ts, prime=True)
    known = {**{n: n for n in ts.sorts}, **{n + "'": n for n in ts.sorts}}
    parts = [(c, _names(c, known)) for c in _conjuncts(ts.init(a)) + _conjuncts(ts.trans(a, b))]
    cone = _names(prop(a), known)
    grew = True
    while grew:
        grew = False
        for _, vs in parts:
            if vs & cone and not vs <= cone:
                cone |= vs
                grew = True
    n_init = len(_conjuncts(ts.init(a)))
    keep = [i for i, (_, vs) in enumerate(parts) if vs & cone]
    return ([n for n in ts.sorts if n in cone], [parts[i][0] for i in keep if i < n_init],
            [parts[i][0] for i in keep if i >= n_init])


def spacer_invariant(ts: TransitionSystem, prop: Pred, timeout_ms: int) -> HornAnswer:
    """Ask Spacer for an inductive invariant of ``ts`` implying ``prop``
    (module docstring), over the variables of its cone of influence
    (:func:`cone_of_influence`).  ``timeout_ms`` bounds the query
    (milliseconds).  Never raises on solver trouble: a theory or quantifier
    Spacer refuses is ``unknown`` with Z3's message."""
    names, init, trans = cone_of_influence(ts, prop)
    a, b = named_state(ts), named_state(ts, prime=True)
    if not names:  # a property of no variable: the clauses over every variable (a relation needs one)
        names, init, trans = list(ts.sorts), [ts.init(a)], [ts.trans(a, b)]
    bad = z3.Not(prop(a))
    home, own = bad.ctx, z3.Context()  # the caller's context, and Spacer's own (module docstring)
    rel = z3.Function("Inv", *[ts.sorts[n].translate(own) for n in names], z3.BoolSort(own))
    av, bv = [a[n].translate(own) for n in names], [b[n].translate(own) for n in names]
    init_own = [f.translate(own) for f in init]
    trans_own = [f.translate(own) for f in trans]
    bad_own = bad.translate(own)
    t0 = time.perf_counter()
    try:
        h = z3.SolverFor("HORN", ctx=own)
        wallclock.limit(h, timeout_ms)  # steps decide, the clock is a net
        h.add(z3.ForAll(av, z3.Implies(conj(*init_own) if init_own else z3.BoolVal(True, own), rel(*av))))
        h.add(z3.ForAll(av + bv, z3.Implies(conj(rel(*av), *trans_own), rel(*bv))))
        h.add(z3.ForAll(av, z3.Implies(conj(rel(*av), bad_own), z3.BoolVal(False, own))))
        r = h.check()
        took = time.perf_counter() - t0
        if r == z3.sat:
            return HornAnswer("invariant", invariant=_interpretation(h.model(), rel, av).translate(home), seconds=took)
        if r == z3.unsat:
            return HornAnswer("reachable", seconds=took)
        return HornAnswer("unknown", reason=(h.reason_unknown().strip().splitlines() or ["unknown"])[0].rstrip(": "),
                          seconds=took)
    except z3.Z3Exception as exc:  # a clause Spacer does not take (a quantifier in the step relation)
        text = str(exc.value if hasattr(exc, "value") else exc).strip()
        return HornAnswer("unknown", reason=(text.splitlines() or ["refused"])[0].rstrip(": "),
                          seconds=time.perf_counter() - t0)


def _interpretation(m: z3.ModelRef, rel: z3.FuncDeclRef, args: list[z3.ExprRef]) -> z3.BoolRef:
    """The model's interpretation of ``rel`` applied to ``args``: its
    entries, then its default with Z3's bound variables ``Var(i)`` replaced
    by ``args[i]`` (``Model.eval`` of the application was seen to answer
    ``True`` for such an interpretation, which :func:`recheck` caught)."""
    fi = m[rel]
    if fi is None:  # Spacer left it unconstrained: any relation will do, the weakest is checked
        return z3.BoolVal(True, rel.ctx)
    body = z3.substitute_vars(fi.else_value(), *args)
    for k in range(fi.num_entries()):
        e = fi.entry(k)
        body = z3.If(conj(*[x == e.arg_value(j) for j, x in enumerate(args)]), e.value(), body)
    return body


def _prime(ts: TransitionSystem, f: z3.BoolRef) -> z3.BoolRef:
    a, b = named_state(ts), named_state(ts, prime=True)
    return z3.substitute(f, *[(a[n], b[n]) for n in ts.sorts])


def recheck(ts: TransitionSystem, prop: Pred, inv: z3.BoolRef, timeout_ms: int) -> str | None:
    """Check certificate ``inv`` (over :func:`named_state`) independently of
    the solver that found it: ``init => inv``, ``inv and trans => inv'``,
    ``inv => prop``, each by a plain Z3 query that must be ``unsat``.
    Returns ``None`` when all three hold, else which condition fails (or
    could not be decided) in words."""
    a, b = named_state(ts), named_state(ts, prime=True)
    for cond, what in ((conj(ts.init(a), z3.Not(inv)), "an initial state lies outside it"),
                       (conj(inv, ts.trans(a, b), z3.Not(_prime(ts, inv))), "a step leaves it"),
                       (conj(inv, z3.Not(prop(a))), "it does not imply the property")):
        s = z3.Solver()
        wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
        s.add(cond)
        r = s.check()
        if r == z3.sat:
            return f"the certificate is not valid: {what}"
        if r == z3.unknown:
            return f"the certificate could not be re-checked: whether {what} is undecided ({s.reason_unknown()})"
    return None


def shortest_violation(ts: TransitionSystem, prop: Pred, start: int, timeout_ms: int,
                       limit: int = 200) -> tuple[int, list[dict[str, str]]] | str:
    """The shortest run from an initial state ending outside ``prop``, of
    ``start`` .. ``limit`` steps (bounded model checking, one incremental
    solver): ``(steps, trace)``; else why none was found (a sentence).
    ``timeout_ms`` bounds the whole search."""
    deadline = time.perf_counter() + timeout_ms / 1000
    states = [ts.state(0, "v")]
    s = z3.Solver()
    s.add(ts.init(states[0]))
    for n in range(limit + 1):
        if n >= start:
            left = int((deadline - time.perf_counter()) * 1000)
            if left <= 0:
                return f"no run of up to {n - 1} steps violating it was found within {timeout_ms} ms"
            s.set("timeout", left)
            r = s.check(z3.Not(prop(states[n])))
            if r == z3.sat:
                return n, trace_of(s.model(), states)
            if r == z3.unknown:
                return f"Z3 could not decide whether a run of {n} steps violates it ({s.reason_unknown()})"
        states.append(ts.state(n + 1, "v"))
        s.add(ts.trans(states[n], states[n + 1]))
    return f"no run of up to {limit} steps violating it was found"


def shown(f: z3.ExprRef) -> str:
    """A certificate as one line in RCL's notation (``and``, ``or``,
    ``not``, ``==``, ``<=``; a negated comparison flipped), at most
    :data:`SHOWN` characters; a term outside that notation in Z3's."""
    text = " ".join(_rcl(f, top=True).split()).replace("|", "")
    return text if len(text) <= SHOWN else text[:SHOWN - 3] + "..."


_FLIP = {z3.Z3_OP_LE: ">", z3.Z3_OP_GE: "<", z3.Z3_OP_LT: ">=", z3.Z3_OP_GT: "<=", z3.Z3_OP_EQ: "!=",
         z3.Z3_OP_DISTINCT: "=="}
_OPS = {z3.Z3_OP_LE: "<=", z3.Z3_OP_GE: ">=", z3.Z3_OP_LT: "<", z3.Z3_OP_GT: ">", z3.Z3_OP_EQ: "==",
        z3.Z3_OP_DISTINCT: "!=", z3.Z3_OP_ADD: "+", z3.Z3_OP_SUB: "-", z3.Z3_OP_MUL: "*",
        z3.Z3_OP_AND: "and", z3.Z3_OP_OR: "or", z3.Z3_OP_IMPLIES: "->"}


def _rcl(e: z3.ExprRef, top: bool = False) -> str:
    if not z3.is_app(e):  # a quantifier: Z3's notation
        return str(e)
    if z3.is_true(e) or z3.is_false(e):
        return "TRUE" if z3.is_true(e) else "FALSE"
    if z3.is_const(e) or z3.is_int_value(e) or z3.is_rational_value(e):
        return str(e)
    kind, kids = e.decl().kind(), e.children()
    if kind == z3.Z3_OP_NOT:
        inner = kids[0]
        k2 = inner.decl().kind() if z3.is_app(inner) else None
        if k2 in _FLIP and len(inner.children()) == 2:
            return f"{_rcl(inner.children()[0])} {_FLIP[k2]} {_rcl(inner.children()[1])}"
        return f"not {_rcl(inner)}"
    if kind in _OPS and len(kids) >= 2:
        text = f" {_OPS[kind]} ".join(_rcl(k) for k in kids)
        return text if top and kind == z3.Z3_OP_AND else f"({text})"
    return str(e)
