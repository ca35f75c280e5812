"""Contract refinement: may node contract B replace node contract A?

Paper lines 1667-1700 ("Compositionality enables Interchangeability"): a
node's implementation can be swapped for another "as long as the new
implementation conforms to the FOL contract".  Lifted from implementations to
contracts, B may replace A in any system where A was used when

1. B has A's interface: the same input names and output names, each of the
   same type (otherwise the question is ill-posed and a located error is
   raised);
2. B assumes no more than A:            ``A_A  =>  A_B``
3. B guarantees at least what A does, wherever A's assumption holds:
                                        ``A_A and G_B  =>  G_A``

``A_X`` is the conjunction of node X's assume clauses (TRUE when it has
none) and ``G_X`` the conjunction of its guarantee clauses.  Input and output
variables of A and B are the same Z3 symbols.  Each side is decided by Z3
(:func:`rclverify.semantics.query.prove`): ``proved``, ``refuted`` with a model
in RCL names, or ``inconclusive`` (unknown/timeout; never counted as proved).

Conditions (docs/decisions.md, "Refinement"):

* the *environment facts* the plan states for the node (the same facts the
  health checks and side conditions use) are hypotheses of both sides: B
  must replace A only in the environment the plan describes;
* B may read inputs A does not have when the plan or the user gives a
  condition on them (``rclverify refines A B --assume "in.extra >= 0"``):
  each condition, over B's inputs, is a hypothesis of both sides.  The result
  then states the condition under which B refines A
  (``RefinementResult.conditions``).  Without a condition an extra input is
  still an interface error.

``refines_main`` implements the command ``rclverify refines A.rcl:Node
B.rcl:Node [--assume FORMULA ...]``.

The interface check and the merged environments are :mod:`.interfaces`'.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence, TextIO

import z3

from rclverify.calculus.health.witness import finite_witness, has_tables, points_for
from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import EncodingError, Encoder
from rclverify.semantics.query import DEFAULT_TIMEOUT_MS, QueryResult, prove
from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.lang.parser import parse_formula
from rclverify.calculus.compose import free_io
from rclverify.calculus.refine_timing import timing_side
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.typecheck import load
from rclverify.lang.types import Checked, CheckedNode, Env
from rclverify.calculus.interfaces import check_interface, io_loc, merge_envs
from rclverify.calculus.shapes import RefinementJson, RefinementSideJson


@dataclass(frozen=True)
class SideResult:
    """One refinement condition.

    ``name``       ``"assumption"`` or ``"guarantee"``;
    ``statement``  the implication checked, in RCL;
    ``status``     ``proved`` / ``refuted`` / ``inconclusive``;
    ``model``      RCL name (``in.r``, ``out.radiationStatus``) -> value text,
                   for ``refuted``;
    ``reason``     Z3's reason for ``inconclusive``;
    ``smt2``       the query as SMT-LIB2; ``duration_s`` its wall time;
    ``strategy``   the retry that decided it (semantics/retry.py), '' when Z3's
                   first attempt did or nothing did.
    """

    name: str
    statement: str
    status: str
    model: Mapping[str, str] | None = None
    reason: str = ""
    smt2: str = ""
    duration_s: float = 0.0
    strategy: str = ""


@dataclass(frozen=True)
class RefinementResult:
    """The verdict on "B refines A".

    ``verdict`` is ``refines`` (both sides proved), ``does not refine``
    (a side refuted) or ``inconclusive``.
    """

    a: str
    b: str
    assumption: SideResult
    guarantee: SideResult
    conditions: tuple[str, ...] = ()
    #: the timing side (calculus/refine_timing.py): A's triggered guarantees kept as fast; None when A has none
    timing: SideResult | None = None

    @property
    def verdict(self) -> str:
        sides = (self.assumption.status, self.guarantee.status) + ((self.timing.status,) if self.timing else ())
        if all(s == "proved" for s in sides):
            return "refines"
        if "refuted" in sides:
            return "does not refine"
        return "inconclusive"

    def to_json(self) -> RefinementJson:
        """The verdict as JSON (calculus/shapes.py ``RefinementJson``)."""
        def side(s: SideResult) -> RefinementSideJson:
            return {"statement": s.statement, "status": s.status, "model": dict(s.model) if s.model else None,
                    "reason": s.reason, "duration_s": s.duration_s}
        out: RefinementJson = {"a": self.a, "b": self.b, "verdict": self.verdict, "assumption": side(self.assumption),
                               "guarantee": side(self.guarantee), "conditions": list(self.conditions)}
        if self.timing:
            out["timing"] = side(self.timing)
        return out


# ---------------------------------------------------------------------------
# The check
# ---------------------------------------------------------------------------

#: Budget of each side's first attempt (milliseconds' worth of Z3 resource steps,
#: :data:`rclverify.semantics.query.STEPS_PER_MS`): the case study's assumption side
#: takes a few hundred steps; a side this does not decide goes up the ladder of
#: :func:`rclverify.semantics.retry.retry_order`.
FIRST_MS = 250
#: Budget of the finite-table counterexample looked for when the first attempt
#: does not decide (loaded from its canonical text, the case study's guarantee
#: side takes about 3 million steps, 0.3 of it).
WITNESS_MS = 5_000

def _conj(clauses: tuple[ast.Clause, ...]) -> str:
    return " and ".join(f"({expr_to_rcl(c.formula)})" for c in clauses) or "TRUE"


def _rename(model: Mapping[str, str] | None, node: str) -> dict[str, str] | None:
    if model is None:
        return None
    prefix = f"{node}."
    return {(k[len(prefix):] if k.startswith(prefix) else k): v for k, v in model.items()}


def _table_counterexample(enc: Encoder, formulas: Sequence[z3.BoolRef],
                          points: int) -> Callable[[], dict[str, str] | None]:
    """A function looking for a model of ``formulas`` (a side's hypotheses
    and its negated goal) in which every function-typed input is a finite
    table of ``points`` points (:func:`rclverify.calculus.health.witness.finite_witness`,
    :data:`WITNESS_MS`, loaded from its canonical text as the sides are):
    such a model refutes the side, and is what the
    report shows (RCL names -> values, each table as its rows); ``None``
    when there is no function-typed input or none was found.  Asked only
    when the side's first small attempt did not decide."""
    def find() -> dict[str, str] | None:
        if not has_tables(enc):
            return None
        w = finite_witness(enc, formulas, points, WITNESS_MS, deterministic=True, simplified=True)
        return w.model if w.status == "sat" else None
    return find


def check_refinement(a: CheckedNode, b: CheckedNode, env: Env, *,
                     timeout_ms: int = DEFAULT_TIMEOUT_MS, facts: Sequence[ast.Expr] = (),
                     conditions: Sequence[ast.Expr] = (), instances: tuple[int, int] | None = None) -> RefinementResult:
    """Decide whether contract ``b`` may replace contract ``a`` (module docstring).

    ``env`` must resolve both nodes' names (see :func:`merge_envs` for nodes
    checked separately).  ``timeout_ms`` bounds each Z3 query.  ``facts``:
    the plan's environment facts of ``a``'s node (formulas over ``a``'s
    inputs and outputs); ``conditions``: formulas over ``b``'s inputs (those
    ``a`` lacks included), which allow ``b`` extra inputs.  Both are
    hypotheses of both sides and are listed in the result.  ``instances``:
    the plan's ``instances: [lo, hi]`` of ``a``'s node, the size of the
    finite tables a counterexample is first looked for with
    (:func:`rclverify.calculus.health.witness.points_for`; the first attempt of each
    side has :data:`FIRST_MS`, see :func:`rclverify.semantics.query.prove`).
    The verdict does not depend on them.  Raises
    :class:`RclError` for an interface mismatch and for formulas the Z3
    encoding does not support (located).
    """
    extra = [n for n in b.inputs if n not in a.inputs]
    check_interface(a, b, extra_inputs_ok=bool(conditions) or bool(facts))
    points = points_for(instances)
    enc = Encoder(env)
    shared: dict[str, z3.AstRef] = {}
    for prefix, group in (("in", a.inputs), ("out", a.outputs)):
        for name in group:
            shared[f"{prefix}.{name}"] = enc.io_symbol(a, prefix, name)
    try:
        def all_of(node: CheckedNode, clauses: tuple[ast.Clause, ...]) -> z3.BoolRef:
            fs = [enc.formula(c.formula, node, shared) for c in clauses]
            return conj(*fs) if fs else z3.BoolVal(True)

        aa, ga = all_of(a, a.node.assumes), all_of(a, a.node.guarantees)
        ab, gb = all_of(b, b.node.assumes), all_of(b, b.node.guarantees)
        hyps = [enc.formula(f, a, shared) for f in facts] + [enc.formula(c, b, shared) for c in conditions]
        timed = timing_side(a, b, enc, shared, hyps, aa, timeout_ms=timeout_ms)
    except EncodingError as exc:
        raise RclError([error(exc.loc, str(exc).split(": error: ", 1)[-1], "E-encoding")]) from None
    s_assume = f"{_conj(a.node.assumes)} -> {_conj(b.node.assumes)}"
    s_guar = f"{_conj(a.node.assumes)} and {_conj(b.node.guarantees)} -> {_conj(a.node.guarantees)}"
    if extra and not any(n in {v for _, v in _io_names(f)} for f in list(conditions) + list(facts) for n in extra):
        raise RclError([error(io_loc(b, "in", extra[0]), f"input {extra[0]!r} of {b.name} is not an input of {a.name} "
                                                          "and no condition mentions it; give one with --assume",
                              "E-refines-interface")])
    # decide first with what decides: each side's first attempt gets a small budget; when it
    # cannot decide, a finite-table counterexample (calculus/health/witness.py) refutes the side with that model
    # (the case study's guarantee side: 0.2 s, where MBQI after simplification took 1.2 s to build a
    # model whose wayP was a 200 kB if-then-else); else the retries of semantics/retry.py
    q1 = prove(ab, [aa, *hyps], enc, timeout_ms=timeout_ms, deterministic=True, first_ms=FIRST_MS,
               counterexample=_table_counterexample(enc, [aa, *hyps, z3.Not(ab)], points),
               comment=f"refinement, assumption side: A_{a.name} => A_{b.name}\nunsat: B assumes no more than A")
    q2 = prove(ga, [aa, gb, *hyps], enc, timeout_ms=timeout_ms, deterministic=True, first_ms=FIRST_MS,
               counterexample=_table_counterexample(enc, [aa, gb, *hyps, z3.Not(ga)], points),
               comment=f"refinement, guarantee side: A_{a.name} and G_{b.name} => G_{a.name}\n"
                       "unsat: B guarantees at least what A does")

    def side(name: str, stmt: str, q: QueryResult) -> SideResult:
        return SideResult(name, stmt, q.status, _rename(q.model, a.name), q.reason, q.smt2, q.duration_s, q.strategy)

    conds = tuple(f"{expr_to_rcl(f)}  [environment fact]" for f in facts) + tuple(
        f"{expr_to_rcl(c)}  [condition]" for c in conditions)
    timing = None
    if timed is not None:
        stmt, status, tq, why = timed
        timing = (side("timing", stmt, tq) if tq is not None and status == tq.status else
                  SideResult("timing", stmt, status, reason=why))
    return RefinementResult(a.name, b.name, side("assumption", s_assume, q1), side("guarantee", s_guar, q2), conds,
                            timing)


def _io_names(e: ast.Expr) -> set[tuple[str | None, str]]:
    return free_io(e)


# ---------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------

def split_spec(spec: str) -> tuple[str, str | None]:
    """``path.rcl:Node`` -> ``(path, Node)``; ``path.rcl`` -> ``(path, None)``."""
    head, sep, tail = spec.rpartition(":")
    if sep and tail and head and "/" not in tail and "\\" not in tail and not tail.endswith(".rcl"):
        return head, tail
    return spec, None


def load_node(spec: str) -> tuple[Checked, CheckedNode]:
    """Parse and type-check the RCL file of ``path[:Node]`` and pick the node.

    Without ``:Node`` the file must hold exactly one node.  Raises
    :class:`RclError` (located) for a missing file, a syntax or type error,
    or an unknown node (listing the nodes there are).
    """
    path, name = split_spec(spec)
    checked = load([path])
    if name is None:
        if len(checked.nodes) != 1:
            raise RclError([error(ast.Loc(path, 1, 1), f"{path} has {len(checked.nodes)} nodes "
                                                       f"({', '.join(checked.nodes) or 'none'}); "
                                                       f"write {path}:<node>", "E-refines-node")])
        name = next(iter(checked.nodes))
    if name not in checked.nodes:
        raise RclError([error(ast.Loc(path, 1, 1), f"{path} has no node {name!r}; its nodes are: "
                                                   f"{', '.join(checked.nodes) or 'none'}", "E-refines-node")])
    return checked, checked.nodes[name]


def render(result: RefinementResult, spec_a: str, spec_b: str) -> str:
    """The verdict as text (what ``rclverify refines`` prints)."""
    lines = [f"Does {spec_b} refine {spec_a}?  (may {result.b} replace {result.a})"]
    sides = [(result.assumption, "assumption (A_A -> A_B)"), (result.guarantee, "guarantee  (A_A and G_B -> G_A)")]
    if result.timing is not None:
        sides.append((result.timing, "timing     (A's deadlines kept as fast)"))
    for s, label in sides:
        lines.append(f"  {label}: {s.status}" + (f" (by {s.strategy})" if s.strategy else ""))
        lines.append(f"      {s.statement}")
        if s.status == "refuted" and s.model is not None:
            lines.append("      counterexample:")
            lines += [f"        {k} = {v}" for k, v in sorted(s.model.items())]
        if s.status == "inconclusive" and s.reason:
            lines.append(f"      solver: {s.reason}")
        if s.status == "refuted" and s.model is None and s.reason:
            lines.append(f"      {s.reason}")
    verdict = {"refines": f"yes: {result.b} ({spec_b}) refines {result.a} ({spec_a})",
               "does not refine": f"no: {result.b} ({spec_b}) does not refine {result.a} ({spec_a})",
               "inconclusive": "inconclusive: the solver could not decide every side"}[result.verdict]
    if result.conditions:
        lines.append("  under the conditions:")
        lines += [f"      {c}" for c in result.conditions]
        if result.verdict == "refines":
            verdict += " wherever these conditions hold"
    lines.append(f"verdict: {verdict}")
    return "\n".join(lines) + "\n"


def refines_main(spec_a: str, spec_b: str, *, out: TextIO | None = None, err: TextIO | None = None,
                 assumes: Sequence[str] = (), confirm: Any = None) -> int:
    """``rclverify refines A.rcl:Node B.rcl:Node``: print whether B refines A.

    ``assumes``: RCL formulas over B's inputs (``--assume``), conditions
    under which the replacement is checked (they let B read extra inputs).

    ``confirm``: the second solver, a callable from a side's
    SMT-LIB2 text to ``(agreement, why)`` (:func:`rclverify.stages.crosscheck.stage.agreement`
    of cvc5's answer); a proved side it does not confirm makes the verdict
    inconclusive (docs/second-solver.md).

    Returns the exit code: 0 when B refines A, 1 when it does not or the
    solver could not decide (the output says which), 2 on a user error
    (printed as ``file:line:col: error: message``).
    """
    out = out or sys.stdout
    err = err or sys.stderr
    try:
        ca, na = load_node(spec_a)
        cb, nb = load_node(spec_b)
        env = merge_envs(ca, cb)
        conds = [parse_formula(t) for t in assumes]
        result = check_refinement(na, nb, env, conditions=conds)
    except RclError as exc:
        for d in exc.diagnostics:
            print(d, file=err)
        return 2
    out.write(render(result, spec_a, spec_b))
    if confirm is None or result.verdict != "refines":
        return 0 if result.verdict == "refines" else 1
    sides = [s for s in (result.assumption, result.guarantee, result.timing) if s is not None and s.smt2]
    said = [(s.name, *confirm(s.smt2)) for s in sides]
    out.write("second solver: " + "; ".join(f"{name} side: {a} ({why})" for name, a, why in said) + "\n")
    if any(a in ("disagree", "inconclusive") for _, a, _ in said):
        out.write("verdict: inconclusive: the second solver does not confirm every side (docs/second-solver.md)\n")
        return 1
    return 0


__all__ = ["RefinementResult", "SideResult", "check_interface", "check_refinement", "load_node", "merge_envs",
           "refines_main", "render"]
