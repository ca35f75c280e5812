"""Refuting a guarantee Dafny could not prove: a counterexample shown, or the claim left unproved.

Dafny's "A postcondition might not hold on this return path" says that the
verifier could not prove the clause within its means (a loop invariant too
weak, nonlinear arithmetic, a quantifier it did not instantiate); the model
Boogie hands back with it satisfies the verification condition's negation,
which over-approximates the program (loops cut at their invariants, calls
at their contracts), so it is no counterexample.  Evidence is ``failed``
only for a refutation (docs/plan.md, "Unproved is not failed"), and a
guarantee ``g`` of the node is refuted here when all three hold:

1. *inputs*: the values of the method's ``real``/``int``/``nat``/``bool``
   parameters in Boogie's model of the error (``/mv:``, :func:`read_models`)
   are pinned; every other input stays free;
2. *every run breaks it*: Dafny proves that the user's implementation,
   unchanged, meets the refutation stub (:class:`~.stubgen.Refutation`: the
   node's assumptions, the pinned inputs, and ``ensures !(g)``), with 0
   errors, no time-out, and no construct Dafny does not prove (``assume``,
   ``{:axiom}`` ...);
3. *such inputs exist*: Z3 finds the node's assumptions satisfiable with
   the pinned inputs, by RCL's own semantics
   (:class:`~rclverify.semantics.encode.Encoder`), so step 2 is not vacuous.

Dafny's ghost methods terminate (Dafny proves it), so step 2 says every
run on those inputs ends in a state that breaks ``g``: the pinned inputs
with any witness of step 3 are a counterexample.  Anything less leaves the
guarantee unproved, and the evidence ``inconclusive`` with the reason.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Mapping, Sequence

import z3

from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics import wallclock
from rclverify.semantics.concrete import ConcreteValueError, to_z3
from rclverify.semantics.encode import Encoder
from rclverify.semantics.symbols import EncodingError
from rclverify.targets.dafny.text import real_literal
from rclverify.backends.dafny.stubgen import Stub

#: At most this many guarantee clauses are tried per run (each try is one more Dafny process).
MAX_REFUTATIONS = 3
#: Z3's budget for the assumptions' satisfiability at the pinned inputs (ms of steps: semantics/wallclock.py).
SAT_BUDGET_MS = 5_000

_ENTRY = re.compile(r"^(?P<name>\S+) -> (?P<value>.+)$")
_TOKEN = re.compile(r"\(|\)|[^\s()]+")


def read_models(text: str) -> list[dict[str, str]]:
    """The models of a Boogie model file (``/mv:``), in the order Boogie
    wrote them (one per error): each maps a top-level name (``r#0``) to the
    text of its value (``(/ 39.0 4.0)``, ``true``, ``T@U!val!3``...)."""
    models: list[dict[str, str]] = []
    cur: dict[str, str] | None = None
    for line in text.splitlines():
        if line.startswith("*** MODEL"):
            cur = {}
        elif line.startswith("*** END_MODEL"):
            if cur is not None:
                models.append(cur)
            cur = None
        elif cur is not None and (m := _ENTRY.match(line)):
            cur.setdefault(m.group("name"), m.group("value").strip())
    return models


def _sexp(tokens: list[str], k: int) -> tuple[Any, int]:
    if tokens[k] != "(":
        return tokens[k], k + 1
    items: list[Any] = []
    k += 1
    while k < len(tokens) and tokens[k] != ")":
        item, k = _sexp(tokens, k)
        items.append(item)
    return items, k + 1


def _value(x: Any) -> Fraction | bool | None:
    if isinstance(x, str):
        if x in ("true", "false"):
            return x == "true"
        try:
            return Fraction(x)
        except (ValueError, ZeroDivisionError):
            return None
    args = [_value(a) for a in x[1:]]
    if not x or any(not isinstance(a, Fraction) for a in args):
        return None
    nums: list[Fraction] = [a for a in args if isinstance(a, Fraction)]
    if x[0] == "-" and len(nums) == 1:
        return -nums[0]
    if x[0] == "-" and len(nums) == 2:
        return nums[0] - nums[1]
    if x[0] == "/" and len(nums) == 2 and nums[1] != 0:
        return nums[0] / nums[1]
    return None


def model_value(text: str) -> Fraction | bool | None:
    """The number or truth value of a model value's text (``9``, ``(- 5)``,
    ``(/ 39.0 4.0)``, ``true``), or ``None`` for anything else (a datatype
    value ``T@U!val!3``, a function's table)."""
    tokens = _TOKEN.findall(text)
    if not tokens:
        return None
    try:
        tree, end = _sexp(tokens, 0)
    except IndexError:
        return None
    return _value(tree) if end == len(tokens) else None


@dataclass(frozen=True)
class Pin:
    """One input fixed to a model's value: Dafny ``param`` and ``literal``,
    RCL ``name`` (``in.r``) and ``value`` (a :class:`~fractions.Fraction`,
    ``int`` or ``bool``, as :mod:`rclverify.semantics.values` takes them)."""

    param: str
    literal: str
    name: str
    value: Fraction | int | bool

    @property
    def shown(self) -> str:
        """``9.75``, ``1/3``, ``-2``, ``true``: the value as a report shows it."""
        v = self.value
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, int) or v.denominator == 1:
            return str(int(v))
        text = real_literal(v)
        return text if not text.startswith("(") else f"{v.numerator}/{v.denominator}"


def pins(model: Mapping[str, str], stub: Stub) -> list[Pin]:
    """The inputs of ``stub``'s method with a number or truth value in
    ``model`` (Boogie names an in-parameter ``p`` ``p#0``), as pins;
    inputs of other types, and values that do not fit the type (a negative
    ``nat``), are left free."""
    rcl = {param: name for name, param in stub.io.items() if name.startswith("in.")}
    out: list[Pin] = []
    for param, dtype in stub.params:
        v = model_value(model.get(f"{param}#0", ""))
        if v is None or param not in rcl:
            continue
        if dtype == "bool" and isinstance(v, bool):
            out.append(Pin(param, "true" if v else "false", rcl[param], v))
        elif dtype == "real" and isinstance(v, Fraction):
            out.append(Pin(param, real_literal(v), rcl[param], v))
        elif dtype in ("int", "nat") and isinstance(v, Fraction) and v.denominator == 1 and (dtype == "int" or v >= 0):
            n = int(v)
            out.append(Pin(param, str(n) if n >= 0 else f"({n})", rcl[param], n))
    return out


def assumptions_satisfiable(checked: Checked, node: CheckedNode, pinned: Sequence[Pin],
                            timeout_ms: int = SAT_BUDGET_MS) -> tuple[str, str]:
    """``(answer, reason)``: whether some inputs with the ``pinned`` values
    meet every assumption of ``node``, by Z3 on RCL's semantics: ``sat``,
    ``unsat`` or ``unknown`` (with Z3's reason, or why the assumptions
    cannot be encoded)."""
    enc = Encoder(checked.env)
    try:
        symbols: dict[str, Any] = {p.name: to_z3(p.value, node.inputs[p.name[3:]], enc) for p in pinned}
        formulas = [enc.formula(a.formula, node, symbols) for a in node.node.assumes]
    except (EncodingError, ConcreteValueError, ValueError) as exc:
        return "unknown", f"the assumptions cannot be encoded for Z3: {exc}"
    solver = wallclock.limit(z3.Solver(), timeout_ms)  # a budget of steps, the wall clock a safety net only
    solver.add(*formulas, *enc.axioms())
    answer, cut = wallclock.check_cut(solver)
    if answer == z3.unknown:
        return "unknown", f"Z3 answered unknown ({wallclock.why_unknown(solver, cut)})"
    return str(answer), ""
