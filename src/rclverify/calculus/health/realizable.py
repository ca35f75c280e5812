"""Contract health, realizability: can the guarantees be met for every input
the assumption admits (docs/decisions.md, "Contract health and lint")?

A contract ``(A, G)`` is *realizable* when ``forall in. A(in) -> exists out.
G(in, out)``: whatever admissible input arrives, some output satisfies every
guarantee (the paper's node "verified to preserve its guarantees when its
assumptions are satisfied", lines 740-768, presupposes one exists; Kind 2
checks the same of its contracts).  Consistency (:mod:`.checks`) asks only
that *some* input and output satisfy the contract; a contract can be
consistent and still leave inputs without an answer: the case study's
Agent, whose guarantee 2 demands ``inspect(i)`` at an uninspected waypoint
while its guarantee 3, as published, demands the move to waypoint 0 at
every step.

The check asks Z3 for an input with no answer::

    A(in) and F_in(in) and forall out. (typing(out) and F_out(in, out) -> not (G1 and ... and Gn))

(``F_in``/``F_out``: the plan's environment facts of the node over its inputs
only / mentioning an output; ``typing``: every NATURAL part of an output is
``>= 0``: the output itself, a constructor's field, a tuple's component,
at any depth, :func:`natural_typing`; the encoder's axioms cover the first
two only, and an ``unsat`` over outputs the type excludes, a tuple ``(-1,
0)`` of ``(NATURAL, NATURAL)``, proved contracts realizable that are not.
A sequence's or a set's NATURAL elements are not typed: there a ``sat``
is still an input with no answer, an ``unsat`` proves nothing and nothing
is reported).  With function-typed inputs it
first asks for such an input in which every function is a finite table
(:mod:`.witness`), which Z3 finds in a fraction of the general query's time;
a table witness is a genuine input.  Without function-typed inputs the
query is first given to Z3's quantifier elimination (the ``qe`` tactic,
complete for linear arithmetic, as the deadlock check of
:mod:`rclverify.calculus.requirements.deadlock` does): the quantifier over the
outputs is what the general solver struggles with (a Planner of four linear
guarantees went undecided in 5.6 s that ``qe`` decides in 0.02 s).  Then it names the guarantees that
conflict: the smallest set of them (single guarantees, then pairs) that
already has no answer for some input.

An output sequence its interface bounds (``bounds``: a ``T[<=N]`` or
``T[N]`` field) is quantified item by item over the lengths it can carry
(:mod:`.bounded`), and an implementation's outputs given as terms
(``implementation``) decide the contract realizable when Z3 proves they
answer every admissible input (:mod:`.implemented`: decided by a witness).

An answer is looked for first (:mod:`.realizer`): output terms, constants
or affine in the inputs, that answer every admissible input prove the
contract realizable by a quantifier-free query, and the quantified query
above is then not asked (on a 200-node chain it was a third of the health
stage; docs/scale.md).  Without such terms, or with function-typed inputs,
or where the NATURAL typing is not exact, the query above decides.

It reports a ``problem`` finding (check ``realizable``) with the input that
has no answer, and an ``ok`` finding when Z3 proves the contract realizable
(by the answer's query or the quantified one: unsat; the quantified query's
SMT-LIB2 text is kept either way, and a second solver decides the answer's
query, else the quantified one: docs/second-solver.md).  Nothing is reported when Z3 cannot decide
within the budget, or when an output is function-typed (``forall`` over a
function is beyond first-order logic: not checked, docs/decisions.md).
"""
from __future__ import annotations

import itertools
import time
from typing import Mapping, Sequence

import z3

from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import Encoder
from rclverify.semantics import wallclock
from rclverify.semantics.query import render_model, satisfiable, smt2_script, tactic_solver
from rclverify.lang import ast
from rclverify.semantics.natural import natural_typing
from rclverify.lang.types import Checked, CheckedNode, FuncT, SeqT
from rclverify.calculus.health.bounded import Bound, expand
from rclverify.calculus.health.finding import Finding
from rclverify.calculus.health.implemented import implemented
from rclverify.calculus.health.realizer import Witness, find_witness
from rclverify.calculus.health.shape import outputs_mentioned
from rclverify.calculus.health.witness import finite_witness, has_tables, points_for

#: Budget of one realizability query (milliseconds' worth of Z3 resource steps).
REALIZABLE_TIMEOUT_MS = 2_000
#: Budget of the quantifier elimination asked first (ms worth of Z3 resource
#: steps): ``qe`` decides the linear contracts it is complete for in a few
#: thousand steps (the warehouse Planner: 22,000), and on a query outside
#: its fragment (a quantifier over a sequence's items: the ros2_robot
#: example's ScanGuard) it spent the whole query budget, 4 million steps and
#: 3 s of one idle core, before the general solver decided in 0.01 s.
QE_MS = 100
#: Answers of a simple shape tried for outputs that are all sequences (:func:`_sequence_answers`).
MAX_SEQUENCE_ANSWERS = 4
#: Guarantees beyond this many are not searched for the conflicting subset.
MAX_SUBSET_SEARCH = 5
#: Budget of the first look at each subset of one size in the search for the
#: conflicting guarantees (ms worth of Z3 resource steps); only when no subset of that
#: size shows a conflict within it are they asked again with
#: :data:`REALIZABLE_TIMEOUT_MS` (guarantee 1 of the Agent alone has no
#: conflict: its witness query spent 0.8 s on the whole budget before
#: guarantee 2's was asked).  Guarantee 2's table witness needs between 400
#: and 500 ms worth: at 250 it was found only in the second pass (1.1 s in
#: all), at 600 in the first (0.3 s), the same finding.
SUBSET_FIRST_MS = 600


def _where(l: ast.Loc) -> str:
    return f"{l.file}:{l.line}:{l.col}"


def _conj(fs: Sequence[z3.BoolRef]) -> z3.BoolRef:
    """The conjunction of ``fs``: ``True`` when empty (Z3's printer writes an
    empty ``And`` as a bare ``and``, which no SMT-LIB2 reader takes)."""
    return conj(*fs) if len(fs) > 1 else fs[0] if fs else z3.BoolVal(True)


class _Query:
    """The node's contract encoded once: inputs' formulas, guarantees, and the outputs to quantify."""

    def __init__(self, checked: Checked, node: str, facts: Sequence[tuple[ast.Expr, ast.Loc]],
                 instances: tuple[int, int] | None, bounds: Mapping[str, Bound] | None = None) -> None:
        cn = checked.nodes[node]
        self.cn, self.instances = cn, instances
        self.enc = enc = Encoder(checked.env)
        self.given = [enc.formula(a.formula, cn) for a in cn.node.assumes]
        self.given += [enc.formula(f, cn) for f, _ in facts if not outputs_mentioned(f, cn)]
        self.out_facts = [enc.formula(f, cn) for f, _ in facts if outputs_mentioned(f, cn)]
        self.guarantees = [enc.formula(g.formula, cn) for g in cn.node.guarantees]
        # the outputs the guarantees or facts constrain: another (one a skeleton declares of the empty
        # type `{}`, say) can take any value, so quantifying over it changes nothing
        named: set[str] = set()
        for f in [g.formula for g in cn.node.guarantees] + [f for f, _ in facts]:
            named |= outputs_mentioned(f, cn)
        constrained = [v for v in cn.outputs if v in named]
        self.names = constrained
        self.outs = [enc.io_symbol(cn, "out", v) for v in constrained]
        typed = Encoder(checked.env)  # the outputs' names, and only theirs
        for v in constrained:
            typed.io_symbol(cn, "out", v)
        self.typing: list[z3.BoolRef] = []
        self.types = [cn.outputs[v] for v in constrained]
        #: the output sequences the interface bounds, by index in ``outs``, written out over their lengths
        #: (:mod:`.bounded`) when that is small enough
        self.bounds = {k: (bounds or {})[v] for k, v in enumerate(constrained)
                       if v in (bounds or {}) and isinstance(cn.outputs[v], SeqT)}
        trial = expand(self.outs, self.types, self.bounds, z3.BoolVal(True)) if self.bounds else None
        if trial is None:
            self.bounds = {}
        self.bounded = {constrained[k]: b for k, b in self.bounds.items()}
        #: every NATURAL part of the outputs typed: without it an ``unsat`` is not a proof (module docstring)
        self.exact = trial.exact if trial is not None else True
        for k, v in enumerate(constrained):
            if not isinstance(cn.outputs[v], FuncT):
                cs, ok = natural_typing(enc.io_symbol(cn, "out", v), cn.outputs[v])
                self.typing += cs
                self.exact = self.exact and (ok or k in self.bounds)
        out_names = {typed.symbol_name(cn.name, "out", v) for v in constrained}
        for name in out_names:  # bound below: not free symbols of the query (models show the inputs)
            enc.symbols.pop(name, None)

    def formula(self, ks: Sequence[int]) -> z3.BoolRef:
        """The query with guarantees ``ks`` (0-based) only."""
        g = [self.guarantees[k] for k in ks]
        body = z3.Implies(_conj([*self.typing, *self.out_facts]), z3.Not(_conj(g)))
        e = expand(self.outs, self.types, self.bounds, body) if self.bounds else None
        return _conj([*self.given, e.formula if e is not None else z3.ForAll(self.outs, body)])

    def answer(self, ks: Sequence[int], comment: str, general: bool = True, budget_ms: int = REALIZABLE_TIMEOUT_MS
               ) -> tuple[str, dict[str, str] | None, float, str]:
        """``(sat|other, input model, seconds, SMT-LIB2 text)`` of the query
        over guarantees ``ks``; ``general=False``: with function-typed inputs,
        the table witness only (the search for the conflicting subset).
        ``budget_ms`` (ms worth of Z3 resource steps) bounds the table
        witness; the other queries have :data:`REALIZABLE_TIMEOUT_MS`."""
        f = self.formula(ks)
        t0 = time.perf_counter()
        if has_tables(self.enc):
            w = finite_witness(self.enc, [f], points_for(self.instances), budget_ms)
            if w.status == "sat":
                text = smt2_script(self.enc.axioms() + [f], comment)()
                return "sat", w.model, round(time.perf_counter() - t0, 4), text
            if not general:
                return "inconclusive", None, round(time.perf_counter() - t0, 4), ""
        else:
            status, model = self._eliminated(f)
            if status in ("sat", "unsat"):
                text = smt2_script(self.enc.axioms() + [f], comment)()
                return status, model, round(time.perf_counter() - t0, 4), text
        r = satisfiable([("no output for this input", f)], self.enc, timeout_ms=REALIZABLE_TIMEOUT_MS,
                        comment=comment, retry=False)
        return r.status, r.model, round(time.perf_counter() - t0, 4), r.smt2 if r.status in ("sat", "unsat") else ""

    def witness(self, node: str) -> Witness | None:
        """Output terms that answer every admissible input (:mod:`.realizer`),
        asked once Z3 proved the contract realizable; ``None`` with
        function-typed inputs or none found."""
        free = [s.decl for s in self.enc.symbols.values()]
        if any(isinstance(d, z3.FuncDeclRef) for d in free):
            return None
        full = [d.decl().name() for d in [*free, *self.outs]]  # a constant's name (str() would print it)
        names = {n: n[len(node) + 1:] if n.startswith(node + ".") else n for n in full}
        body = _conj([*self.typing, *self.out_facts, *self.guarantees])
        return find_witness(self.enc.axioms() + self.given, body, self.outs, free, names)

    def _eliminated(self, f: z3.BoolRef) -> tuple[str, dict[str, str] | None]:
        """``(sat|unsat|unknown, input model)`` of ``f`` asked of Z3's
        quantifier elimination then its SMT solver, within :data:`QE_MS`
        (resource steps, as :func:`rclverify.semantics.query.budgeted_solver`)."""
        s = tactic_solver(QE_MS, ("qe", "smt"))
        s.add(*self.enc.axioms(), f)
        try:
            r = wallclock.check(s)
        except z3.Z3Exception:  # a tactic that refuses the query: undecided here, the general query follows
            return "unknown", None
        if r == z3.sat:
            return "sat", render_model(s.model(), self.enc)
        return ("unsat", None) if r == z3.unsat else ("unknown", None)


def realizability_findings(checked: Checked, node: str, facts: Sequence[tuple[ast.Expr, ast.Loc]] = (),
                           instances: tuple[int, int] | None = None, *, bounds: Mapping[str, Bound] | None = None,
                           implementation: Mapping[str, ast.Expr] | None = None) -> list[Finding]:
    """The ``realizable`` finding of ``node``: ``problem`` when its contract
    is not realizable, ``ok`` when Z3 proves it is; ``[]`` when not decided
    or not checked (module docstring).  ``facts``: the plan's
    environment facts of the node with their locations; ``instances``: its
    ``instances`` range (the tables' size).  ``bounds``: output name -> how
    its interface bounds that output sequence (:class:`.bounded.Bound`): the
    quantifier over it is written out over its lengths (:mod:`.bounded`).
    ``implementation``: output name -> the RCL term over the inputs an
    implementation computes it by (the outputs of a proved implementation):
    when Z3 proves those terms answer every admissible input (and fit the
    bounds), they are the witness of realizability and the finding is
    ``ok``, decided by the witness; otherwise the queries above decide.
    Never raises on solver trouble.

    When the wall-clock safety net cut any of its queries
    (:mod:`rclverify.semantics.wallclock`: a loaded machine), the finding is
    ``inconclusive`` ("took longer than N s"), never the model of the path
    the cut led to: the search for the conflicting guarantees moves on to
    the next subset when one is undecided, so a cut would show another
    input and other guarantees than the budget finds."""
    with wallclock.watch() as w:
        found = _realizability(checked, node, facts, instances, bounds, implementation)
    if not w.cut:
        return found
    return [Finding(f"{node}.realizable", node, "realizable", None, "inconclusive",
                    f"Whether the contract of {node} can be implemented was not decided here.",
                    f"A realizability query {wallclock.cut_reason()}.")]


def _sequence_answers(cn: CheckedNode, names: Sequence[str]) -> list[dict[str, ast.Expr]]:
    """Answers of a simple shape when every output in ``names`` is a
    sequence: each an input sequence of its type or the one-item sequence
    of an input of its item type (declaration order; at most
    :data:`MAX_SEQUENCE_ANSWERS`); ``[]`` otherwise."""
    per: list[list[ast.Expr]] = []
    for v in names:
        t = cn.outputs[v]
        if not isinstance(t, SeqT):
            return []
        opts: list[ast.Expr] = [ast.Var(i, "in") for i, ti in cn.inputs.items() if ti == t]
        opts += [ast.SeqLit((ast.Var(i, "in"),)) for i, ti in cn.inputs.items() if ti == t.elem]
        if not opts:
            return []
        per.append(opts)
    return [dict(zip(names, c)) for c in itertools.islice(itertools.product(*per), MAX_SEQUENCE_ANSWERS)]


def _smallest_conflict(q: _Query, node: str, every: list[int]) -> tuple[list[int], tuple[dict[str, str] | None, str] | None, float]:
    """A smallest set of guarantees (0-based) no output can answer together
    for some admissible input, searched by size (up to
    :data:`MAX_SUBSET_SEARCH` guarantees; ``every`` beyond that or when no
    smaller set conflicts); returns it, the (model, query text) of the query
    that found it (``None``: none smaller than ``every``), and the solver's
    seconds spent."""
    secs = 0.0
    if not 1 < len(every) <= MAX_SUBSET_SEARCH:
        return every, None, secs
    for size in range(1, len(every)):
        subsets = list(itertools.combinations(every, size))
        # with tables, a first look at each subset of this size, then the whole budget: the first conflict
        # in that order is reported (a smallest set of guarantees without an answer); without tables the
        # queries have their whole budget whatever budget_ms says, so they are asked once
        for budget in ((SUBSET_FIRST_MS, REALIZABLE_TIMEOUT_MS) if has_tables(q.enc) else (REALIZABLE_TIMEOUT_MS,)):
            for ks in subsets:
                st, m, dt, text = q.answer(ks, f"health {node}: is there an input guarantees "
                                                f"{', '.join(str(k + 1) for k in ks)} cannot answer?",
                                           general=False, budget_ms=budget)
                secs += dt
                if st == "sat":
                    return list(ks), (m, text), secs
    return every, None, secs


def _realizability(checked: Checked, node: str, facts: Sequence[tuple[ast.Expr, ast.Loc]],
                   instances: tuple[int, int] | None, bounds: Mapping[str, Bound] | None = None,
                   implementation: Mapping[str, ast.Expr] | None = None) -> list[Finding]:
    """:func:`realizability_findings`, whatever the wall clock did."""
    cn = checked.nodes[node]
    n = cn.node
    if not n.guarantees or not n.outputs:
        return []
    q = _Query(checked, node, facts, instances, bounds)
    if not q.outs:
        return []  # no guarantee constrains an output: any output answers (the shape checks say so)
    if any(isinstance(o, z3.FuncDeclRef) for o in q.outs):
        return []  # forall over a function-typed output: not first-order, not checked
    every = list(range(len(n.guarantees)))
    comment = f"health {node}: is there an input no output answers?"
    over = "".join(f" The quantifier over out.{v} ranges over the sequences its interface carries ({b.text()}), "
                   "written out item by item." for v, b in q.bounded.items())
    # a witness first: the implementation's outputs, else (every constrained output an unbounded sequence) an
    # answer of a simple shape; its query has no quantifier over the outputs, which cvc5 decides
    for terms, source in ([(implementation, "the implementation")] if implementation else
                          [(c, "the answer") for c in _sequence_answers(cn, q.names)] if not q.bounds else []):
        by_witness = implemented(q.enc, cn, [(v, o, cn.outputs[v]) for v, o in zip(q.names, q.outs)], q.given,
                                 [*q.out_facts, *q.guarantees], terms, q.bounded, bool(facts), source)
        if by_witness is not None:
            return [by_witness]
    # an answer first (calculus/health/realizer.py): output terms that answer every admissible input prove the
    # contract realizable with a quantifier-free query; the quantified query is asked only without one (and
    # not over written-out sequences: a term of the sequence sort may not fit the interface's bound)
    t0 = time.perf_counter()
    w = q.witness(node) if q.exact and not q.bounds else None  # None with function-typed inputs (tables: answer())
    if w is not None:
        status, model, secs = "unsat", None, round(time.perf_counter() - t0, 4)
        smt2 = smt2_script(q.enc.axioms() + [q.formula(every)], comment)()
    else:
        status, model, secs, smt2 = q.answer(every, comment)
    if status == "unsat" and not q.exact:
        return []  # proved over outputs the type excludes too (a negative element of a seq(NATURAL)): no proof
    if status == "unsat":
        sketch = (f" For instance {w.text()} answers every one of them (Z3 checked it: the witness query is unsat)."
                  if w is not None else "")
        witness_smt2 = (smt2_script(list(w.query), f"health {node}: does the witness {w.text()} leave an admissible "
                                                   "input unanswered? (unsat: it answers every one)")()
                        if w is not None else "")
        return [Finding(f"{node}.realizable", node, "realizable", None, "ok",
                        f"The contract of {node} can be implemented: every input its assumption"
                        + (" and the environment facts admit" if facts else " admits")
                        + " has an output satisfying every guarantee." + sketch,
                        "Realizability (forall in. A(in) -> exists out. G(in, out)): "
                        + ("it follows from the answer above, which Z3 proved answers every admissible input; "
                           "the query below states it (unsat)." if w is not None else
                           "Z3 proved that no admissible input lacks an answer (the query below is unsat).") + over,
                        None, None, secs, smt2=smt2,
                        witness=dict(w.terms) if w is not None else None, witness_smt2=witness_smt2)]
    if status != "sat":
        return []
    conflict, found, dt = _smallest_conflict(q, node, every)
    secs += dt
    if found is not None:
        model, smt2 = found[0], found[1] or smt2
    names = [f"guarantee {k + 1} ({_where(n.guarantees[k].loc)})" for k in conflict]
    short = [x.split(" (")[0] for x in names]
    which = short[0] if len(short) == 1 else ", ".join(short[:-1]) + f" and {short[-1]} together"
    msg = (f"The contract of {node} cannot be implemented: for an input its assumption"
           + (" and the environment facts admit" if facts else " admits") + f" (the finding's counterexample: "
           f"`rclverify explain {node}.realizable`), no output satisfies {which}.")
    expl = ("Realizability (forall in. A(in) -> exists out. G(in, out)) fails: Z3 found an admissible input for which "
            "every output violates " + (" and ".join(x.split(" (")[0] for x in names) if len(names) > 1 else names[0])
            + ". An implementation meeting the contract cannot exist; the guarantees ask for incompatible outputs there."
            + over)
    return [Finding(f"{node}.realizable", node, "realizable", conflict[0] + 1 if len(conflict) == 1 else None,
                    "problem", msg, expl, model, names, secs, smt2=smt2)]
