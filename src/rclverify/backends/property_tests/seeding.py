"""Inputs that satisfy a node's assumption *and* its environment facts, from
Z3 models seeded by Hypothesis draws (docs/property-tests.md, "Environment
facts").

The plan's environment facts (``environment: <Node>: facts:``) say what the
environment is known to satisfy, e.g. for the Agent that the scenario has
the waypoints 0..12 (paper lines 990, 1420-1445).  Filtering draws by such a
fact starves: an existence fact ("every k <= 12 has a waypoint") almost never
holds on a random finite table.  So inputs are built from a Z3 model:

* :meth:`Seeder.base`: every function-typed input the formulas (assumption
  plus usable facts) mention becomes a table of ``n`` entries at fixed
  distinct keys ``(0, 0), (1, 1), ...`` with unknown results and an unknown
  default; the table (``ite`` over the keys, as
  :func:`rclverify.semantics.concrete.finite_interpretation` builds for a
  concrete table) replaces the function symbol; Z3 (tactics ``simplify``,
  ``qe``, ``smt``) finds the results.  ``n`` is the first of
  :data:`EXTRA_SIZES` with a model.  Computed once per node and process, in
  a fresh Z3 context fed the formulas' SMT-LIB text, so the model does not
  depend on what the process asked Z3 before (same seed, same evidence, also
  in the generated pytest file run alone);
* :meth:`rclverify.backends.property_tests.strategies.InputSpace.vary`: per
  example, Hypothesis varies the model's tables (keys moved, drawn entries
  added or overriding).

Every example is then checked by
:func:`~rclverify.semantics.concrete.check_concrete` (the harness's filter), so
the encoding here never decides validity on its own.  Facts that name an
output cannot constrain inputs and are not used for drawing (reported).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import z3

from rclverify.semantics.concrete import to_z3
from rclverify.semantics.connectives import conj
from rclverify.semantics.encode import Encoder, EncodingError, sort_of
from rclverify.semantics import wallclock
from rclverify.semantics.retry import SAFETY_TIMEOUT_MS
from rclverify.lang import ast
from rclverify.lang import typeexpr
from rclverify.lang.types import Checked, CheckedNode, DataT, EnumT, FuncT, Scalar, Type
from rclverify.semantics.values import FiniteFunction, Term

EXTRA_SIZES = (0, 1, 2, 4, 8, 16, 32, 64)
#: Z3's resource budget for one table size (its ``rlimit``, about 2 s on an
#: idle core): a budget of work, not of wall-clock time, so the same tables
#: are found on a loaded machine, in a parallel run and on CI (a wall-clock
#: limit let a busy machine miss the size that works and starve the draw).
SEED_RLIMIT = 8_000_000


def names_output(e: Any, node: CheckedNode) -> bool:
    """Does formula ``e`` mention an output of ``node``?"""
    if isinstance(e, ast.Var):
        return e.prefix == "out" or (e.prefix is None and e.name in node.outputs and e.name not in node.inputs)
    if isinstance(e, tuple):
        return any(names_output(x, node) for x in e)
    if hasattr(e, "__dataclass_fields__"):
        return any(names_output(getattr(e, f), node) for f in e.__dataclass_fields__ if f != "loc")
    return False


def split_facts(facts: tuple[ast.Expr, ...], node: CheckedNode) -> tuple[tuple[ast.Expr, ...], tuple[ast.Expr, ...]]:
    """``(usable, not_usable)``: facts over inputs only, and facts naming an output."""
    usable = tuple(f for f in facts if not names_output(f, node))
    return usable, tuple(f for f in facts if names_output(f, node))


def _from_z3(v: z3.ExprRef, t: Type) -> Any:
    """A model value as a value of :mod:`rclverify.semantics.values`; ``ValueError`` when it is not one."""
    if isinstance(t, Scalar):
        if t.name == "BOOL":
            return z3.is_true(v)
        if t.name == "REAL":
            if not z3.is_rational_value(v):
                raise ValueError(f"not a rational: {v}")
            q = Fraction(v.as_fraction())
            return float(q) if Fraction(float(q)) == q else q
        if not z3.is_int_value(v):
            raise ValueError(f"not an integer: {v}")
        return v.as_long()
    if isinstance(t, EnumT):
        name = v.decl().name()
        if name not in t.values:
            raise ValueError(f"not a value of {t}: {v}")
        return name
    if isinstance(t, DataT):
        name = v.decl().name()
        args = t.ctor(name)
        if args is None:
            raise ValueError(f"not a constructor of {t.name}: {v}")
        return Term(name, tuple(_from_z3(v.arg(k), a) for k, a in enumerate(args)))
    raise ValueError(f"no model value conversion for {t}")


def _natural(x: z3.ExprRef, t: Type) -> list[z3.BoolRef]:
    return [x >= 0] if t == Scalar("NATURAL") else []


def _points(args: tuple[Type, ...], n: int) -> list[tuple[Any, ...]] | None:
    """``n`` distinct concrete argument tuples ``(j, j, ...)`` (numeric arguments only)."""
    if not all(isinstance(a, Scalar) and a.name in ("REAL", "INTEGER", "NATURAL") for a in args):
        return None
    return [tuple(float(j) if a == Scalar("REAL") else j for a in args) for j in range(n)]


def min_entries(formulas: tuple[ast.Expr, ...]) -> int:
    """A number of table entries below which no table of :meth:`Seeder._solve`
    can satisfy ``formulas``: an existence fact ``forall(k in NATURAL | k
    <= N -> exists(.. | in.f(..) == k))`` (also ``k < N``) needs ``N + 1``
    (``N``) distinct results of ``f``, and a table of ``n`` entries and a
    default has at most ``n + 1``.  Sizes below it are not tried: the first
    size with a model, hence the model, is the same, without Z3's search
    for the sizes that cannot work (the Agent's 13 waypoints: 0.9 CPU s
    for 8 entries in each process that draws its inputs)."""
    least = 0
    for f in formulas:
        if not (isinstance(f, ast.Quant) and f.kind == "forall" and len(f.bindings) == 1
                and len(f.bindings[0].names) == 1 and isinstance(f.bindings[0].domain, typeexpr.TBase)
                and f.bindings[0].domain.name == "NATURAL"):
            continue
        k = f.bindings[0].names[0]
        body = f.body
        if not (isinstance(body, ast.Binary) and body.op == "->" and isinstance(body.left, ast.Compare)
                and len(body.left.ops) == 1 and body.left.ops[0] in ("<", "<=")):
            continue
        var, bound = body.left.operands
        if not (isinstance(var, ast.Var) and var.prefix is None and var.name == k and isinstance(bound, ast.NumLit)
                and bound.value.denominator == 1):
            continue
        values = int(bound.value) + (1 if body.left.ops[0] == "<=" else 0)  # k = 0 .. N
        ex = body.right
        if not (isinstance(ex, ast.Quant) and ex.kind == "exists" and isinstance(ex.body, ast.Compare)
                and len(ex.body.ops) == 1 and ex.body.ops[0] == "=="):
            continue
        a, b = ex.body.operands
        if any(isinstance(x, ast.Apply) and isinstance(y, ast.Var) and y.prefix is None and y.name == k
               for x, y in ((a, b), (b, a))):
            least = max(least, values - 1)
    return least


#: Base models by node, input types and formulas.  They hold plain values of
#: rclverify.semantics.values, no Z3 object, and each is computed in a Z3 context of its
#: own from the formulas' SMT-LIB text, so it does not depend on the process's
#: Z3 state: it is kept across rclverify.semantics.world.fresh() (a clean run and
#: an incremental one draw from the same model; the Agent's three guarantees
#: share one instead of solving it three times).
_BASE: dict[tuple[Any, ...], dict[str, object] | None] = {}


class SeedingCut(Exception):
    """The wall-clock safety net stopped the search for a base model before
    its step budget did (a loaded machine: docs/decisions.md, "Results never
    depend on the wall clock"); its text says so.  Raised by
    :meth:`Seeder.base` instead of trying the next table size, whose model
    would be another seed and so other examples."""


@dataclass
class Seeder:
    """A base model of ``formulas`` (assumption + usable facts of ``node``) and the
    repair of drawn examples with it (see the module docstring)."""

    checked: Checked
    node: CheckedNode
    formulas: tuple[ast.Expr, ...]

    def _solve(self, n: int) -> dict[str, object] | None:
        """Tables of ``n`` entries at fixed distinct keys, results and defaults from Z3."""
        enc = Encoder(self.checked.env)
        phi = conj(*[enc.formula(f, self.node) for f in self.formulas])
        side: list[Any] = []
        funcs: list[tuple[z3.FuncDeclRef, z3.ExprRef]] = []
        readback: dict[str, Any] = {}
        declared = {s.z3name.split(".", 1)[1]: s.decl for s in enc.symbols.values()}
        for q, decl in declared.items():
            t = self.node.inputs[q[3:]] if q.startswith("in.") else None
            if t is None:
                return None
            if isinstance(t, FuncT):
                keys = _points(t.args, n)
                if keys is None:
                    return None
                vals = [z3.Const(f"{q}#v{j}", sort_of(t.result)) for j in range(n)]
                d = z3.Const(f"{q}#default", sort_of(t.result))
                for v in (*vals, d):
                    side.extend(_natural(v, t.result))
                xs = [z3.Var(k, sort_of(a)) for k, a in enumerate(t.args)]
                body: z3.ExprRef = d
                for key, v in reversed(list(zip(keys, vals))):
                    body = z3.If(conj(*[x == to_z3(k, a, enc) for x, k, a in zip(xs, key, t.args)]), v, body)
                funcs.append((decl, body))
                readback[q] = (t, keys, vals, d)
            else:
                side.extend(_natural(decl, t))
                readback[q] = (t, None, decl, None)
        if funcs:
            phi = z3.substitute_funs(phi, *funcs)
        # A fresh Z3 context: the model depends only on these formulas, not on
        # what else this process asked Z3 before (the generated pytest file
        # runs alone and must see the same examples as the backend).
        ctx = z3.Context()
        s = z3.Then("simplify", "qe", "smt", ctx=ctx).solver()
        s.set("rlimit", SEED_RLIMIT)
        wallclock.note_limit(s, SAFETY_TIMEOUT_MS)  # a safety net only, told apart when it fires
        text = z3.Solver()
        text.add(phi, *side)
        s.add(z3.parse_smt2_string(text.to_smt2(), ctx=ctx))  # by its text: no state carried over
        r, cut = wallclock.check_cut(s)
        if cut:  # the clock, not the budget: the next size's model would be another seed
            raise SeedingCut(wallclock.cut_reason())
        if r != z3.sat:
            return None
        m = s.model()
        by_name = {d.name(): d for d in m.decls()}

        def value(x: z3.ExprRef, t: Type) -> Any:
            d = by_name.get(x.decl().name())
            v = m[d] if d is not None else None
            if v is None:  # not in the model: any value will do; take the sort's first
                v = m.eval(z3.FreshConst(x.sort().translate(ctx)), model_completion=True)
            return _from_z3(v, t)
        out: dict[str, object] = {}
        for q, (t, keys, vals, d) in readback.items():
            if keys is None:
                out[q] = value(vals, t)
            else:
                table = {k: value(v, t.result) for k, v in zip(keys, vals)}
                out[q] = FiniteFunction(table, value(d, t.result), len(t.args))
        return out

    def base(self) -> dict[str, object] | None:
        """A model of the formulas with the fewest table entries in :data:`EXTRA_SIZES`
        (cached per node and formulas; ``None``: none found)."""
        key = (self.node.name, tuple((k, str(t)) for k, t in self.node.inputs.items()),
               tuple(map(str, self.formulas)))
        if key not in _BASE:
            found = None
            least = min_entries(self.formulas)
            for n in [m for m in EXTRA_SIZES if m >= least] or EXTRA_SIZES[-1:]:
                try:
                    found = self._solve(n)
                except (EncodingError, ValueError):
                    found = None
                    break
                if found is not None:
                    break
            _BASE[key] = found
        return _BASE[key]


__all__ = ["Seeder", "SeedingCut", "names_output", "split_facts"]
