"""Float-faithful judgement of an RCL formula on values a running node published.

RCL speaks of reals; a ROS node computes in IEEE-754 double arithmetic and
publishes doubles.  Judged as exact rationals, a node that computes
``1000 * 1.2`` and publishes ``1200.0`` violates ``out.d == 1000 * in.r``
(``1.2`` as a double is 1.1999999999999999555...): a false alarm on a correct
node.  A recorded value is therefore judged by what the node could have
computed (docs/monitors.md, "Numbers on the wire"):

* **exact**: the formula on the values as exact rationals, literals as the
  decimals they spell (:func:`rclverify.semantics.evaluate.evaluate`, then Z3 on
  the concrete values where that cannot decide; the semantics of the rest
  of the tool, shared/DESIGN.md);
* **double**: the same formula evaluated in IEEE-754 binary64 arithmetic as
  the node computes it: every non-integer literal rounded to the nearest
  double, every ``+ - * /`` rounded (Python's ``float`` operations are
  binary64, round-to-nearest-even), left to right as written, comparisons
  on the doubles.  Integers stay exact (an ``INTEGER`` is an integer on the
  node too).  The recorded values themselves are never rounded or moved:
  ``out.x <= 30`` is false of a published 30.000000000000004 in every
  semantics but a declared tolerance;
* **tolerance** (only when one is declared, :class:`Tolerance` of
  :mod:`rclverify.semantics.tolerance`): exact
  arithmetic, and a comparison that reads a recorded value treats numbers
  within the tolerance as equal: ``a == b`` iff ``|a - b| <= tol``,
  ``a <= b`` iff ``a < b`` or equal so, ``a < b`` iff ``a < b`` and not
  equal so, ``!=`` the negation of ``==`` (one consistent logic, so ``not``
  flips nothing it should not).  Comparisons among bound variables and
  literals alone stay exact.

:func:`judge` answers *holds* when the formula holds in one of these
(each evaluated as a whole: no mixing of semantics inside one formula,
which could make ``a and not a`` hold), names the one that decided, and
answers *false* only when it is false in every one that applies: a real
violation is caught in all of them.  When exact arithmetic says false and a
float semantics cannot decide, the answer is undecided with the reason,
never false: that would be the false alarm this module removes.

Soundness of the float semantics' quantifiers: the exact evaluator's
shortcuts (candidate values from equalities, pins, preimages) rest on exact
equality, which rounding and tolerance break (``x + 1 == out.y`` has many
double solutions).  Under double and tolerance a quantifier is therefore
enumerated over a finite domain only: ``BOOL``, an enumeration, a finite
set, an ``INTEGER``/``NATURAL`` variable bounded by literal guards
(``k <= 12 -> ...``), or a numeric variable the body never mentions; any
other quantifier is undecided there, except, under double, a ``REAL``/``INTEGER``/``NATURAL``
variable whose body changes truth only at finitely many points computable from the values
(table keys, the terms it is compared with): it is decided exactly at those candidate points
and one point in each gap (:mod:`rclverify.semantics.candidates`, :mod:`rclverify.semantics.candidate_points`; a ``REAL`` ranges over the
doubles there).  A formula whose evaluation cannot
differ between exact and double (no rounding arithmetic, every literal a
double) is not evaluated again (:func:`float_sensitive`).

One function (:func:`judge`) decides, for the monitors of recorded and live
runs (``backends/monitors``: ``check.py``, ``deadlines.py``, and through them
``online.py``, the ROS 1/2 live monitors and the oracle), and for the
guarantee checks of the property tests (``backends/property_tests/harness.py``:
a Python implementation computes in doubles too).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable, Mapping

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang import types as T
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.candidate_points import quantify
from rclverify.semantics.symbols import EncodingError
from rclverify.semantics.eval_shapes import MAX_RANGE, _integer_range, _unused
from rclverify.semantics.evaluate import Evaluator, Undecided, evaluate_why
from rclverify.semantics.floatsens import float_sensitive
from rclverify.semantics.operators import COMPARISONS, OPERATORS
from rclverify.semantics.tolerance import Tolerance, ToleranceError, parse_tolerance, ulp_distance
from rclverify.semantics.values import Value

#: The semantics a verdict may be decided in, in the order they are tried.
SEMANTICS = ("exact", "double", "tolerance")

#: comparison symbol -> its exact meaning (the semantics table's entry)
_CMP = {s: OPERATORS[s].exact for s in COMPARISONS}
#: operator symbol -> its double meaning (the semantics table's entry)
_DOUBLE: Mapping[str, Callable[[Any, Any], Any]] = {s: o.double for s, o in OPERATORS.items()}
#: The most assignments a quantifier is enumerated over under double or tolerance.
MAX_ENUMERATION = 100_000


@dataclass(frozen=True)
class Judgement:
    """The truth of a formula on recorded values and the semantics that decided it.

    ``truth`` True/False, ``None`` undecided (``reason`` says why; a reason
    starting ``no value for`` means an I/O value is missing).
    ``semantics``: for True the one semantics it holds in (``exact``,
    ``double`` or ``tolerance``), for False every semantics that was applied
    and agreed (``exact``, ``exact, double``, ``exact, double, tolerance``),
    ``""`` when undecided."""

    truth: bool | None
    semantics: str = ""
    reason: str = ""


def judge(formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object],
          tolerance: Tolerance | None = None) -> Judgement:
    """Does ``formula`` (an RCL formula of ``node``) hold of the recorded
    ``values`` (qualified names ``in.r``/``out.d`` -> values of
    :mod:`rclverify.semantics.values`) in exact arithmetic, in the node's double
    arithmetic, or within ``tolerance`` (module docstring)?  Never raises for
    a value or formula it cannot handle: the judgement is then undecided
    with the reason.  Exact is tried first (direct evaluation, Z3 on the
    concrete values where that cannot decide); double and tolerance only when
    exact does not hold and they could answer otherwise."""
    v, reason = evaluate_why(formula, checked, node, values)  # one evaluation gives the truth and, undecided, why
    if v is None:
        if "no value for" in reason:  # an I/O value is missing: no semantics can decide
            return Judgement(None, "", reason)
        import z3  # deferred: start-up (Z3 only for a value the direct evaluation leaves undecided)
        from rclverify.semantics.concrete import check_concrete  # deferred: start-up (loads z3, the encoder and the type checker only when called)
        try:
            v, reason = check_concrete(formula, checked, node, values)
        except (ValueError, TypeError, KeyError, EncodingError, z3.Z3Exception) as exc:  # a value Z3 cannot take
            v, reason = None, f"{reason}; Z3 on concrete values failed: {exc}"
    if v is True:
        return Judgement(True, "exact")
    tried = ["exact"]
    open_: list[str] = []
    if float_sensitive(formula, checked, node):
        d, why = _run(_Double(checked, node, values), formula)
        if d is True:
            return Judgement(True, "double", "false in exact arithmetic, true in IEEE-754 double arithmetic "
                                             "(as the node computes)")
        tried.append("double")
        if d is None:
            open_.append(f"in double arithmetic: {why}")
    if tolerance and float_sensitive(formula, checked, node, tolerant=True):
        ev = _Tolerant(checked, node, values)
        ev.tolerance = tolerance
        t, why = _run(ev, formula)
        if t is True:
            return Judgement(True, "tolerance", f"false in exact and double arithmetic, true within the declared "
                                                f"tolerance ({tolerance.text()})")
        tried.append("tolerance")
        if t is None:
            open_.append(f"within the tolerance: {why}")
    if v is False and not open_:
        return Judgement(False, ", ".join(tried), reason)
    if v is False:
        return Judgement(None, "", "false in exact arithmetic, undecided " + "; ".join(open_))
    return Judgement(None, "", reason)


def holds_in(semantics: str, formula: ast.Expr, checked: Checked, node: CheckedNode, values: Mapping[str, object],
             tolerance: Tolerance | None = None) -> bool | None:
    """Does ``formula`` hold of ``values`` in the one arithmetic ``semantics``
    (``exact``, ``double``, ``tolerance``), ``None`` when undecided there?
    The monitor judges every guarantee of one message in one arithmetic
   : a message whose
    guarantees hold only in different arithmetics holds in none."""
    if semantics == "exact":
        j = judge(formula, checked, node, values)
        return j.truth if j.semantics.startswith("exact") or j.truth is not True else False
    if semantics == "double":
        return _run(_Double(checked, node, values), formula)[0]
    ev = _Tolerant(checked, node, values)
    ev.tolerance = tolerance or Tolerance()
    return _run(ev, formula)[0]


def _run(ev: Evaluator, formula: ast.Expr) -> tuple[bool | None, str]:
    try:
        return bool(ev.eval(formula, {})), ""
    except Undecided as exc:
        return None, str(exc)
    except (TypeError, ZeroDivisionError, OverflowError, ValueError) as exc:
        return None, f"a value has the wrong form for the formula: {exc}"


#: a literal's text -> its value in the double reading (parsed once)
_DOUBLE_LITERALS: dict[str, int | float] = {}


class _Double(Evaluator):
    """The formula in IEEE-754 binary64 arithmetic (module docstring)."""

    mode = "double"

    def literal(self, e: ast.NumLit) -> Any:
        hit = _DOUBLE_LITERALS.get(e.text)
        if hit is None:
            v = e.value
            hit = _DOUBLE_LITERALS[e.text] = int(v) if v.denominator == 1 else float(v)
        return hit

    def arith(self, op: str, x: Any, y: Any) -> Any:
        """``x op y`` in binary64 (the double meaning of the semantics table)."""
        return _DOUBLE[op](x, y)

    def compare(self, e: ast.Compare, b: Mapping[str, Value], op: str, x: Any, y: Any) -> bool:
        """``x op y`` on the doubles (the double meaning of the semantics table)."""
        truth: bool = _DOUBLE[op](x, y)
        return truth

    def quant(self, e: ast.Quant, b: Mapping[str, Value]) -> bool:
        got = quantify(self, e, b, _finite_domain, MAX_ENUMERATION)
        return _enumerate(self, e, b) if got is None else got


class _Tolerant(Evaluator):
    """The formula in exact arithmetic with comparisons of recorded values up
    to a tolerance (module docstring)."""

    mode = "tolerance"
    tolerance: Tolerance = Tolerance()

    def compare(self, e: ast.Compare, b: Mapping[str, Value], op: str, x: Any, y: Any) -> bool:
        if not (_number(x) and _number(y)) or not _reads_io(e, b, self.io_names):
            return bool(_CMP[op](x, y))
        close = self.tolerance.close(x, y)
        if op == "==":
            return close
        if op == "!=":
            return not close
        if op == "<=":
            return x <= y or close
        if op == ">=":
            return x >= y or close
        if op == "<":
            return x < y and not close
        return x > y and not close  # ">"

    def quant(self, e: ast.Quant, b: Mapping[str, Value]) -> bool:
        return _enumerate(self, e, b)


def _number(v: Any) -> bool:
    return not isinstance(v, bool) and isinstance(v, (int, float, Fraction))


_IO_READS: dict[int, tuple[ast.Compare, bool, frozenset[str]]] = {}


def _reads_io(e: ast.Compare, b: Mapping[str, Value], io: frozenset[str]) -> bool:
    """Does comparison ``e`` read a recorded value: an ``in.``/``out.``
    variable, or a bare I/O name not bound by a quantifier (``b``)?"""
    hit = _IO_READS.get(id(e))
    if hit is None or hit[0] is not e:
        names: set[str] = set()
        prefixed = _io_names(e.operands, names)
        if len(_IO_READS) >= 10_000:
            _IO_READS.clear()
        hit = _IO_READS[id(e)] = (e, prefixed, frozenset(names))
    return hit[1] or any(n in io and n not in b for n in hit[2])


def _io_names(e: Any, bare: set[str]) -> bool:
    """Collect the bare names under ``e``; True when it reads a prefixed I/O variable."""
    if isinstance(e, ast.Var):
        if e.prefix is not None:
            return True
        bare.add(e.name)
        return False
    if isinstance(e, tuple):
        return any([_io_names(x, bare) for x in e])
    if isinstance(e, ast.Loc) or not hasattr(e, "__dataclass_fields__"):
        return False
    return any([_io_names(getattr(e, f), bare) for f in e.__dataclass_fields__])


def _enumerate(ev: Evaluator, e: ast.Quant, b: Mapping[str, Value]) -> bool:
    """Quantifier ``e`` by enumerating finite domains only (module docstring)."""
    names: list[str] = []
    doms: list[list[Any]] = []
    size = 1
    for bd in e.bindings:
        for n in bd.names:
            dom = _finite_domain(ev, e, bd, n, b)
            names.append(n)
            doms.append(dom)
            size *= max(len(dom), 1)
            if size > MAX_ENUMERATION:
                raise Undecided(f"quantifier over more than {MAX_ENUMERATION} values")
    count = 0
    for combo in itertools.product(*doms):
        cur = dict(b)
        cur.update(zip(names, combo))
        holds = bool(ev.eval(e.body, cur))
        if e.kind == "forall":
            if not holds:
                return False
        elif e.kind == "exists":
            if holds:
                return True
        elif holds:
            count += 1
            if count > 1:
                return False
    return e.kind == "forall" or (e.kind == "exists_unique" and count == 1)


def _finite_domain(ev: Evaluator, e: ast.Quant, bd: ast.Binding, name: str, b: Mapping[str, Value]) -> list[Any]:
    dom = bd.domain
    if isinstance(dom, typeexpr.TEnum):
        return list(dom.values)
    typ: Any = None
    if isinstance(dom, typeexpr.TBase):
        typ = T.Scalar(dom.name) if dom.name in ("REAL", "INTEGER", "NATURAL", "BOOL") else None
    elif isinstance(dom, typeexpr.TName):
        typ = ev.env.types.get(dom.name)
    elif isinstance(dom, (ast.SetLit, ast.Var)):
        return list(ev.collection(dom, b))
    if isinstance(typ, T.EnumT):
        return list(typ.values)
    if isinstance(typ, T.Scalar):
        if typ.name == "BOOL":
            return [False, True]
        if e.kind in ("forall", "exists") and _unused(e, name, bd):
            return [0]  # the body does not read it: one value of the (non-empty) domain stands for all
        bounded = _integer_range(e.body, name, typ.name, e.kind)
        if bounded is not None and len(bounded) <= MAX_RANGE:
            return bounded
        raise Undecided(f"{name} ranges over {typ.name} without a literal bound: not enumerable "
                        f"outside exact arithmetic")
    raise Undecided(f"quantifier over {type(dom).__name__} is not finite")


__all__ = ["Judgement", "SEMANTICS", "Tolerance", "ToleranceError", "float_sensitive", "holds_in", "judge", "parse_tolerance",
           "ulp_distance"]
