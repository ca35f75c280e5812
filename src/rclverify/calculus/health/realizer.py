"""Contract health, realizability: an answer to every input, written out.

Before Z3 is asked whether a contract is realizable (:mod:`.realizable`:
no admissible input lacks an output), this module looks for the answer
itself: terms
``w(in)``, one per output, such that the quantifier-free query

    A(in) and F_in(in) and not (typing(w(in)) and F_out(in, w(in)) and G(in, w(in)))

is unsat: ``w`` answers every input the assumption and the facts admit
(the names as in :mod:`.realizable`).  Such a ``w`` is an instance of the
realizability statement's ``exists out``, so it proves the contract
realizable on its own, and the quantified query is not asked.  Three uses:

* the proof: a quantifier-free query instead of a quantifier elimination;

* the report shows it (``out.x = 0``, ``out.d = 1000 * in.r``): the first
  sketch of an implementation, or the hint that a guarantee says less than
  meant;
* the second solver (docs/second-solver.md) decides this query instead of
  the realizability query, whose ``forall`` over the outputs sends it to a
  fresh cvc5 solver each (about 15 ms: its proof-rule database is loaded
  per solver, and the solver torn down after); this one has no quantifier
  and is decided in cvc5's shared solver, with a checked proof.

The search is counterexample guided (CEGIS): the terms are templates with
unknown parameters; a *synthesis* solver picks parameters that answer the
inputs seen so far, a *verification* query asks for an admissible input the
terms do not answer; its input is added to the synthesis solver and the
round repeats, at most :data:`ROUNDS` times per template.  Templates, in
order:

* **constants**: each output a value of its own sort (``0``, ``green``,
  ``move(1, 0)``);
* **affine**: each ``REAL`` output ``c + a1 * x1 + ...`` over the node's
  ``REAL`` and ``INTEGER`` inputs, each ``INTEGER``/``NATURAL`` output the
  same over its ``INTEGER``/``NATURAL`` inputs with integer coefficients;
  other outputs a constant.

Nothing is returned (the realizability query stands alone) when no
template answers within the rounds or budget, when the query holds a
quantifier (cvc5 would need a fresh solver either way), or when an input is
function-typed (its tables take :mod:`.witness`'s path).  Everything runs
in the stage's Z3 context in a fixed order, so an incremental run finds
what a clean one finds.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import z3

from rclverify.semantics.modeltext import value_to_rcl
from rclverify.semantics.query import budgeted_solver
from rclverify.semantics.wallclock import check
from rclverify.semantics.retry import has_quantifier

#: Synthesis/verification rounds per template.
ROUNDS = 6
#: Budget of each synthesis and each verification check (milliseconds' worth of Z3 resource steps,
#: deterministic): at most 2 templates x ROUNDS x 2 checks, 2.4 s of steps, where a node of the
#: bundled examples takes 1-3 checks of under a millisecond each.
CHECK_MS = 100
#: The first synthesis round's model made without asking the empty solver (:func:`_first_model`).
FIRST_ROUND_UNASKED = True


@dataclass(frozen=True)
class Witness:
    """Output terms that answer every admissible input.

    ``terms``  ``((output, RCL text), ...)`` in the outputs' order, names
               relative to the node (``out.y``, ``in.x + 1``);
    ``query``  the verification query Z3 answered unsat (the formulas to
               print as the second solver's script)."""

    terms: tuple[tuple[str, str], ...]
    query: tuple[z3.BoolRef, ...]

    def text(self) -> str:
        """``out.y = in.x + 1, out.z = TRUE``."""
        return ", ".join(f"{o} = {t}" for o, t in self.terms)


def find_witness(given: Sequence[z3.BoolRef], body: z3.BoolRef, outs: Sequence[z3.ExprRef],
                 inputs: Sequence[z3.ExprRef], names: dict[str, str]) -> Witness | None:
    """Output terms answering every input (module docstring), or ``None``.

    ``given``: the formulas over the inputs (the encoder's axioms, the
    assumptions, the facts over inputs only); ``body``: ``typing(out) and
    F_out(in, out) and G(in, out)``; ``outs``: the output constants (bound
    in the realizability query); ``inputs``: every other free constant of
    ``given`` and ``body``; ``names``: Z3 symbol name -> RCL name shown
    (``in.x``).  Never raises on solver trouble (``None``)."""
    if not outs or any(has_quantifier(f) for f in [*given, body]):
        return None
    try:
        for template in (_constants, _affine):
            params, terms = template(outs, inputs)
            if params is None:
                continue
            found = _cegis(params, terms, given, body, outs, inputs)
            if found is not None:
                values, query = found
                return Witness(tuple((_name(o, names), _text(t, values, names))
                                     for o, t in zip(outs, terms)), tuple(query))
    except z3.Z3Exception:
        return None
    return None


# A term of a template: (constant parameter, ((coefficient parameter, input), ...)).
_Term = tuple[z3.ExprRef, tuple[tuple[z3.ExprRef, z3.ExprRef], ...]]


def _constants(outs: Sequence[z3.ExprRef], inputs: Sequence[z3.ExprRef]
               ) -> tuple[list[z3.ExprRef] | None, list[_Term]]:
    params = [z3.Const(f"w!c{k}", o.sort()) for k, o in enumerate(outs)]
    return params, [(p, ()) for p in params]


def _affine(outs: Sequence[z3.ExprRef], inputs: Sequence[z3.ExprRef]
            ) -> tuple[list[z3.ExprRef] | None, list[_Term]]:
    reals = [x for x in inputs if x.sort() in (z3.RealSort(x.ctx), z3.IntSort(x.ctx))]
    ints = [x for x in reals if x.sort() == z3.IntSort(x.ctx)]
    params: list[z3.ExprRef] = []
    terms: list[_Term] = []
    for k, o in enumerate(outs):
        over = reals if o.sort() == z3.RealSort(o.ctx) else ints if o.sort() == z3.IntSort(o.ctx) else []
        c = z3.Const(f"w!c{k}", o.sort())
        coeffs = tuple((z3.Const(f"w!a{k}_{j}", o.sort()), x) for j, x in enumerate(over))
        params += [c, *(a for a, _ in coeffs)]
        terms.append((c, coeffs))
    if len(params) == len(outs):  # no input to be affine in: the constants already failed
        return None, []
    return params, terms


def _expr(t: _Term) -> z3.ExprRef:
    c, coeffs = t
    if not coeffs:
        return c
    return c + z3.Sum([a * (z3.ToReal(x) if c.sort() == z3.RealSort(c.ctx) and x.sort() != c.sort() else x)
                       for a, x in coeffs])


def _cegis(params: Sequence[z3.ExprRef], terms: Sequence[_Term], given: Sequence[z3.BoolRef], body: z3.BoolRef,
           outs: Sequence[z3.ExprRef], inputs: Sequence[z3.ExprRef]
           ) -> tuple[dict[int, z3.ExprRef], list[z3.BoolRef]] | None:
    """The parameters' values (by term id; ``params`` keep the ids) whose
    terms answer every admissible input, and the verification query that
    showed it (unsat); ``None`` when the template cannot, or the rounds or
    a check's budget run out."""
    answered = z3.substitute(body, *[(o, _expr(t)) for o, t in zip(outs, terms)])
    # made when the first input is to be added (_first_model); made first, as before, without
    # FIRST_ROUND_UNASKED (the reference path of tests/calculus/test_health_fast.py)
    synth: z3.Solver | None = None if FIRST_ROUND_UNASKED else budgeted_solver(CHECK_MS)
    for _ in range(ROUNDS):
        if synth is None:
            m = _first_model(params)
        elif check(synth) != z3.sat:
            return None
        else:
            m = synth.model()
        values = {p.get_id(): m.eval(p, model_completion=True) for p in params}
        ws = [z3.simplify(z3.substitute(_expr(t), *[(p, values[p.get_id()]) for p in params])) for t in terms]
        query = [*given, z3.Not(z3.substitute(body, *zip(outs, ws)))]
        v = budgeted_solver(CHECK_MS)
        v.add(*query)
        r = check(v)
        if r == z3.unsat:
            return values, query
        if r != z3.sat:
            return None
        cm = v.model()
        point = [(x, cm.eval(x, model_completion=True)) for x in inputs]
        if synth is None:  # its first check as the first round would have asked it: the same solver state
            synth = budgeted_solver(CHECK_MS)
            check(synth)
        synth.add(z3.substitute(answered, *point) if point else answered)
    return None


def _first_model(params: Sequence[z3.ExprRef]) -> z3.ModelRef:
    """The model the first synthesis check gives, made without asking it:
    before any input is added the synthesis solver holds no assertion, so
    Z3 answers ``sat`` with the empty model, in which (evaluated with model
    completion) each parameter takes its sort's default value, the value an
    empty model made here gives too (the same evaluator).  A fresh solver's
    check costs about a millisecond, most of a small contract's
    realizability check."""
    ctx = params[0].ctx if params else z3.main_ctx()
    return z3.ModelRef(z3.Z3_mk_model(ctx.ref()), ctx)


def _name(x: z3.ExprRef, names: dict[str, str]) -> str:
    n = x.decl().name()
    return str(names.get(n, n))


def _text(t: _Term, values: dict[int, z3.ExprRef], names: dict[str, str]) -> str:
    """The term with its parameters' values in RCL notation: ``in.x + 1``, ``-2 * in.y``, ``green``."""
    c, coeffs = t
    parts = []
    for a, x in coeffs:
        v = values[a.get_id()]
        if z3.is_rational_value(v) and v.numerator_as_long() == 0 or z3.is_int_value(v) and v.as_long() == 0:
            continue
        one = z3.is_int_value(v) and v.as_long() == 1 or z3.is_rational_value(v) and v.as_fraction() == 1
        parts.append(_name(x, names) if one else f"{value_to_rcl(v)} * {_name(x, names)}")
    const = values[c.get_id()]
    zero = (z3.is_int_value(const) and const.as_long() == 0
            or z3.is_rational_value(const) and const.numerator_as_long() == 0)
    if not parts or not zero:
        parts.append(value_to_rcl(const))
    return " + ".join(parts).replace("+ -", "- ")


__all__ = ["Witness", "find_witness", "ROUNDS", "CHECK_MS"]
