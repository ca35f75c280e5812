"""The semantics table: one entry per RCL operator giving its meaning.

RCL's operators (docs/rcl-language.md; the connectives and arithmetic of
the paper's EBNF, shared/reference lines 499-555) are ``not``, unary ``-``,
``abs(t)`` (an extension: the absolute value), ``sqrt(t)``, ``sin(t)`` and
``cos(t)`` (extensions: the mathematical functions, radians),
``and or -> <=>``, ``== != < <= > >=`` and ``+ - * /``.  Each has ONE
:class:`Operator` entry in :data:`OPERATORS` (binary) or :data:`UNARY`;
every evaluator and compiler reads its operator's meaning from that entry
instead of restating it:

* :attr:`Operator.exact` is the reference meaning on Python values
  (:mod:`rclverify.semantics.values`): REAL is exact (DESIGN.md: REAL -> Z3
  Real), so a float operand is taken as the rational it denotes, integers
  never overflow, and a division by zero raises :class:`Undecided` (RCL
  leaves it unspecified: the formula is not decided, never guessed).  The
  direct evaluator, its compiled closures and the straight-line code call it.
* :attr:`Operator.double` is the IEEE-754 binary64 reading a ROS node
  computes in (:mod:`rclverify.semantics.floatsem`): ``+ - * /`` on
  doubles, division by zero undecided as above, a NaN compares false.
* For the connectives, :attr:`Operator.decisive` and :attr:`Operator.decided`
  state the short circuit (left to right: a left operand whose truth is
  ``decisive`` gives ``decided`` without the right one being evaluated),
  :attr:`Operator.exact` the truth table on ``bool`` values.
* The text fields give the operator in the languages code is generated
  in, where it maps one to one: :attr:`Operator.python` and :attr:`Operator.cpp`
  (format strings over ``{l}`` and ``{r}``; ``None`` where the generator
  must call a helper, e.g. exact arithmetic in Python, division in C++),
  :attr:`Operator.python_reading` (arithmetic on operands already in one
  reading: the evaluator generated packages carry),
  :attr:`Operator.z3` (the ``z3.ArithRef`` method, or the Z3 function of a
  connective), :attr:`Operator.numpy` (the numpy ufunc's name for the
  column evaluation of recorded runs), :attr:`Operator.smtlib`, :attr:`Operator.dafny`.
* :attr:`Operator.partial` states where a partial operator is undefined
  (:class:`Partial`: which operand must avoid which value, and what the
  failure is called); ``None`` for a total operator.  The well-definedness
  conditions every proof path proves are generated from it
  (:mod:`rclverify.semantics.definedness`), with the connectives'
  short circuit (:attr:`Operator.decisive`) as their guards.  Division is
  RCL's only partial binary operator and ``sqrt`` (an argument below 0) its
  only partial unary one: RCL has no modulo and no sequence indexing
  (docs/semantics.md, "Definedness").
* :attr:`Operator.identity` is the neutral element (``and`` TRUE, ``+`` 0, ...)
  when there is one; :attr:`Operator.converse` and :attr:`Operator.negation`
  relate the comparisons (``a < b`` is ``b > a`` and ``not (a >= b)``).

``tests/semantics/test_operators.py`` checks each entry against the reference
evaluator, the double reading against Python's floats and the text fields
by compiling them.
"""
from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable, Literal, Mapping

Kind = Literal["connective", "comparison", "arithmetic", "negation"]


class Undecided(Exception):
    """The formula cannot be decided by direct evaluation (reason in ``str``):
    a division by zero, a value missing or of the wrong form."""


@dataclass(frozen=True)
class Partial:
    """Where a partial operator is undefined: its operand number ``operand``
    (0 the left, 1 the right) must differ from ``excluded``; ``failure``
    names what happens otherwise (``"division by zero"``).  The condition
    is Why3's, Dafny's and SPARK's for the operator (their ``div``/``/``
    checks: the divisor is not zero); ``relation`` ``">="`` states the
    domain of ``sqrt`` (its argument is at least 0: C's and Python's ``sqrt``
    domain, a NaN or ``ValueError`` outside it)."""

    operand: int
    excluded: int
    failure: str
    #: how the operand must relate to ``excluded``: ``"!="`` (a divisor), ``">="`` (``sqrt``'s argument)
    relation: str = "!="


@dataclass(frozen=True)
class Operator:
    """One RCL operator's meaning (module docstring).

    ``symbol`` is its RCL spelling, ``name`` the field's word for it,
    ``arity`` 1 or 2; the callables take Python values and return one."""

    symbol: str
    name: str
    kind: Kind
    arity: int
    exact: Callable[..., Any]
    double: Callable[..., Any]
    python: str | None = None
    cpp: str | None = None
    z3: str | None = None
    numpy: str | None = None
    smtlib: str | None = None
    dafny: str | None = None
    #: the Python text over two operands already in one reading (both ``Fraction`` for the exact
    #: reading, ``float``/``int`` for the double one), where the value's type carries the reading
    python_reading: str | None = None
    identity: Any = None
    decisive: bool | None = None
    decided: bool | None = None
    converse: str | None = None
    negation: str | None = None
    #: what a zero divisor does: ``"undecided"`` (both readings) or ``""`` (cannot happen)
    zero_divisor: str = ""
    #: where the operator is undefined (:class:`Partial`); ``None`` for a total operator
    partial: Partial | None = None


def _exact_number(x: Any) -> Any:
    """A float as the rational it denotes (ints and Fractions unchanged)."""
    return Fraction(x) if type(x) is float else x


def _double_number(x: Any) -> Any:
    """A number as the double a ROS node holds (ints stay ints, as in C++ and Python)."""
    return float(x) if type(x) is Fraction else x


def _exact_arith(raw: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
    def meaning(x: Any, y: Any) -> Any:  # _exact_number inlined: on the evaluator's hot path
        return raw(Fraction(x) if type(x) is float else x, Fraction(y) if type(y) is float else y)
    return meaning


def _exact_div(x: Any, y: Any) -> Any:
    if y == 0:
        raise Undecided("division by zero")
    return Fraction(_exact_number(x)) / Fraction(_exact_number(y))


def _double_arith(raw: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
    def meaning(x: Any, y: Any) -> Any:  # _double_number inlined
        return raw(float(x) if type(x) is Fraction else x, float(y) if type(y) is Fraction else y)
    return meaning


def _double_div(x: Any, y: Any) -> Any:
    x, y = _double_number(x), _double_number(y)
    if y == 0:
        raise Undecided("division by zero")
    return x / y


def _exact_math(fn: Callable[[float], float], name: str) -> Callable[[Any], Any]:
    """A mathematical function's exact-reading meaning: exact where the value is
    rational (``sqrt`` of a rational square, ``sin(0)``, ``cos(0)``), else the
    binary64 value of Python's ``math`` taken as the rational it denotes (no
    real number of the result is representable: docs/semantics.md,
    "Mathematical functions"); outside the domain :class:`Undecided`."""
    def meaning(x: Any) -> Any:
        x = _exact_number(x)
        if name == "sqrt":
            if x < 0:
                raise Undecided("square root of a negative number")
            q = Fraction(x)
            n, d = math.isqrt(q.numerator), math.isqrt(q.denominator)
            if n * n == q.numerator and d * d == q.denominator:
                return Fraction(n, d)
        elif x == 0:
            return Fraction(0) if name == "sin" else Fraction(1)
        return Fraction(_double_math(fn, name)(x))
    return meaning


def _double_math(fn: Callable[[float], float], name: str) -> Callable[[Any], Any]:
    """A mathematical function on the double a ROS node holds (Python's
    ``math``, i.e. the C library's ``sqrt``/``sin``/``cos``): a negative
    ``sqrt`` argument is :class:`Undecided` (C gives NaN, Python raises), as is
    ``sin``/``cos`` of an infinity; a NaN argument gives NaN."""
    def meaning(x: Any) -> Any:
        v = float(x)
        if name == "sqrt" and v < 0:
            raise Undecided("square root of a negative number")
        try:
            return fn(v)
        except (ValueError, OverflowError):
            raise Undecided(f"{name} of {v!r}") from None
    return meaning


def _math_entry(name: str, fn: Callable[[float], float], word: str, partial: Partial | None = None) -> Operator:
    python = (f"(math.sqrt({{x}}) if {{x}} >= 0 else _undecided({partial.failure!r}))" if partial is not None
              else f"math.{name}({{x}})")
    return Operator(name, word, "arithmetic", 1, _exact_math(fn, name), _double_math(fn, name), python=python,
                    cpp=f"std::{name}({{x}})", z3=None, numpy=name, smtlib=None,
                    partial=partial)


def _double_cmp(raw: Callable[[Any, Any], bool]) -> Callable[[Any, Any], bool]:
    def meaning(x: Any, y: Any) -> bool:  # _double_number inlined
        return bool(raw(float(x) if type(x) is Fraction else x, float(y) if type(y) is Fraction else y))
    return meaning


def _connective(symbol: str, name: str, truth: Callable[[bool, bool], bool], *, python: str, cpp: str,
                z3: str, smtlib: str, dafny: str, identity: bool | None, decisive: bool | None,
                decided: bool | None) -> Operator:
    return Operator(symbol, name, "connective", 2, truth, truth, python=python, cpp=cpp, z3=z3, smtlib=smtlib,
                    dafny=dafny, identity=identity, decisive=decisive, decided=decided)


def _comparison(symbol: str, name: str, raw: Callable[[Any, Any], bool], *, z3: str, numpy: str,
                smtlib: str | None, converse: str, negation: str) -> Operator:
    return Operator(symbol, name, "comparison", 2, raw, _double_cmp(raw), python=f"({{l}} {symbol} {{r}})",
                    cpp=f"({{l}} {symbol} {{r}})", z3=z3, numpy=numpy, smtlib=smtlib, dafny=symbol, converse=converse,
                    negation=negation)


_ENTRIES = (
    _connective("and", "conjunction", lambda a, b: a and b, python="({l} and {r})", cpp="({l} && {r})",
                z3="And", smtlib="and", dafny="&&", identity=True, decisive=False, decided=False),
    _connective("or", "disjunction", lambda a, b: a or b, python="({l} or {r})", cpp="({l} || {r})",
                z3="Or", smtlib="or", dafny="||", identity=False, decisive=True, decided=True),
    _connective("->", "implication", lambda a, b: (not a) or b, python="((not {l}) or {r})",
                cpp="(!{l} || {r})", z3="Implies", smtlib="=>", dafny="==>", identity=None, decisive=False, decided=True),
    _connective("<=>", "equivalence", lambda a, b: a == b, python="({l} == {r})", cpp="({l} == {r})",
                z3="__eq__", smtlib="=", dafny="<==>", identity=True, decisive=None, decided=None),
    _comparison("==", "equality", operator.eq, z3="__eq__", numpy="equal", smtlib="=", converse="==",
                negation="!="),
    _comparison("!=", "disequality", operator.ne, z3="__ne__", numpy="not_equal", smtlib=None, converse="!=",
                negation="=="),
    _comparison("<", "less than", operator.lt, z3="__lt__", numpy="less", smtlib="<", converse=">",
                negation=">="),
    _comparison("<=", "at most", operator.le, z3="__le__", numpy="less_equal", smtlib="<=", converse=">=",
                negation=">"),
    _comparison(">", "greater than", operator.gt, z3="__gt__", numpy="greater", smtlib=">", converse="<",
                negation="<="),
    _comparison(">=", "at least", operator.ge, z3="__ge__", numpy="greater_equal", smtlib=">=", converse="<=",
                negation="<"),
    Operator("+", "addition", "arithmetic", 2, _exact_arith(operator.add), _double_arith(operator.add),
             cpp="({l} + {r})", z3="__add__", numpy="add", smtlib="+",
             dafny="+", python_reading="({l} + {r})", identity=0),
    Operator("-", "subtraction", "arithmetic", 2, _exact_arith(operator.sub), _double_arith(operator.sub),
             cpp="({l} - {r})", z3="__sub__", numpy="subtract", smtlib="-",
             dafny="-", python_reading="({l} - {r})"),
    Operator("*", "multiplication", "arithmetic", 2, _exact_arith(operator.mul), _double_arith(operator.mul),
             cpp="({l} * {r})", z3="__mul__", numpy="multiply", smtlib="*",
             dafny="*", python_reading="({l} * {r})", identity=1),
    Operator("/", "division", "arithmetic", 2, _exact_div, _double_div, cpp=None, z3="__truediv__",
             numpy="true_divide", smtlib="/", dafny="/", python_reading="({l} / {r})", zero_divisor="undecided",
             partial=Partial(1, 0, "division by zero")),
)

#: binary operator symbol -> its entry
OPERATORS: Mapping[str, Operator] = {o.symbol: o for o in _ENTRIES}

#: unary operator symbol -> its entry (``not`` on truth values, ``-`` on numbers: exact in both readings)
UNARY: Mapping[str, Operator] = {
    "not": Operator("not", "negation", "negation", 1, operator.not_, operator.not_, python="(not {x})",
                    cpp="(!{x})", z3="Not", numpy="logical_not", smtlib="not"),
    "-": Operator("-", "unary minus", "arithmetic", 1, operator.neg, operator.neg, python="(-{x})",
                  cpp="(-{x})", z3="__neg__", numpy="negative", smtlib="-"),
    # |x|: exact in both readings (the sign bit cleared; abs(NaN) is NaN, which compares false);
    # SMT-LIB's ``abs`` is of the Ints theory only, so the solvers get ``ite`` (targets/smtlib.py, semantics/translate.py)
    "abs": Operator("abs", "absolute value", "arithmetic", 1, abs, abs, python="abs({x})",
                    cpp="std::abs({x})", z3=None, numpy="absolute", smtlib=None),
    # the mathematical functions (docs/semantics.md, "Mathematical functions"): Z3 reads them as uninterpreted
    # functions with true facts (semantics/mathfacts.py); sqrt is partial: its argument must be >= 0
    "sqrt": _math_entry("sqrt", math.sqrt, "square root", Partial(0, 0, "square root of a negative number", ">=")),
    "sin": _math_entry("sin", math.sin, "sine"),
    "cos": _math_entry("cos", math.cos, "cosine"),
}

CONNECTIVES = frozenset(s for s, o in OPERATORS.items() if o.kind == "connective")
COMPARISONS = frozenset(s for s, o in OPERATORS.items() if o.kind == "comparison")
ARITHMETIC = frozenset(s for s, o in OPERATORS.items() if o.kind == "arithmetic")


def is_nan(x: Any) -> bool:
    """Whether ``x`` is a float NaN (no RCL number: the exact reading rejects it,
    :func:`rclverify.semantics.values.exact`; the double reading compares it false)."""
    return type(x) is float and math.isnan(x)


__all__ = ["ARITHMETIC", "COMPARISONS", "CONNECTIVES", "OPERATORS", "Operator", "Partial", "UNARY", "Undecided",
           "is_nan"]
