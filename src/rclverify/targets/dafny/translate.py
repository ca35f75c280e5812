"""RCL formulas -> Dafny expressions (for ``requires``/``ensures`` clauses).

The translation keeps the meaning the Z3 encoding gives a formula
(:mod:`rclverify.semantics.encode`, shared/DESIGN.md "Semantics"):

* connectives: ``not`` -> ``!``, ``and`` -> ``&&``, ``or`` -> ``||``,
  ``->`` -> ``==>``, ``<=>`` -> ``<==>``; every compound sub-expression is
  parenthesised, so Dafny's precedence never changes the reading;
* chained comparisons ``a < b <= c`` -> ``(a < b) && (b <= c)``;
* numbers: NATURAL <: INTEGER <: REAL widening is made explicit, because
  Dafny does not mix ``int`` and ``real``: an integer literal in a real
  context is written ``120.0``, any other integer term ``(t as real)``;
  ``/`` is real division (both sides widened), as in the Z3 encoding;
* ``x in T`` for a type name ``T``: true for the type itself, ``x >= 0`` for
  ``NATURAL``, ``x.Floor as real == x`` for a real tested against
  ``INTEGER``;
* quantifiers: ``forall(x', y' in REAL, i in NATURAL | P)`` ->
  ``(forall x': real, y': real, i: nat :: P)`` (Dafny's ``nat`` adds the
  ``i >= 0`` guard the Z3 encoding adds); a binding over a set term adds
  ``x in S`` as guard (``==>`` under ``forall``, ``&&`` under ``exists``);
  a ``forall``/``exists`` all of whose bindings range over set or sequence
  literals (``exists(w in {4, 5} | P)``) is expanded into the finite
  conjunction/disjunction of its instances (up to 64), which is equivalent
  and leaves Dafny no trigger to miss;
  ``exists_unique(xs | P)`` -> ``(exists xs :: P && (forall ys :: P[ys] ==>
  ys == xs))``; a binding over the empty type ``{}`` makes ``forall`` true
  and ``exists`` false (as in the Z3 encoding).  Dafny picks the triggers
  itself and may warn ("No terms found to trigger on"); the runner records
  such warnings;
* names: I/O variables, constants and bound variables get Dafny-safe names
  (:func:`.types.dafny_ident`); a bound variable that would capture a
  parameter, a constant or a datatype value is renamed; an enumeration
  value or constructor whose name is shadowed is qualified (``RadStat.red``).

Quantifying over functions is rejected with a located
:class:`~rclverify.model.plan.errors.PlanError`.  The quantifiers are
translated by :mod:`rclverify.targets.dafny.quantifiers`, mixed into
:class:`Translator`.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Mapping

from rclverify.lang import ast
from rclverify.semantics.operators import OPERATORS, UNARY
from rclverify.semantics.widths import at_widths
from rclverify.lang.types import (
    BOOL,
    INTEGER,
    NATURAL,
    REAL,
    STRING,
    CheckedNode,
    DataT,
    EmptyT,
    EnumT,
    Env,
    FuncT,
    SeqT,
    SetT,
    TupleT,
    Type,
    numeric_join,
    qualified_base,
)
from rclverify.targets.dafny.quantifiers import Bound, QuantifierTranslation
from rclverify.targets.dafny.text import dafny_string, real_literal, strip_parens, value_join, wrap
from rclverify.targets.dafny.types import dafny_ident

_BASE_NAMES = {"REAL": REAL, "INTEGER": INTEGER, "NATURAL": NATURAL, "BOOL": BOOL}
_INT_LIT = re.compile(r"\A(\(?)(-?\d+)(\)?)\Z")
#: Most items a literal range `<a upto b>` is spelled out to.
_RANGE_LIMIT = 1000


@dataclass
class Translator(QuantifierTranslation):
    """Translates the formulas of one node into Dafny expressions.

    ``env``     the checked environment (contexts);
    ``node``    the node whose formulas are translated;
    ``io``      ``"in.x"``/``"out.x"`` -> Dafny parameter name;
    ``consts``  RCL constant name -> Dafny constant name;
    ``taken``   further Dafny names in scope (datatype, type and method names);
    ``widths``  ``"in.x"``/``"out.x"`` -> ``float32``/``float64``, the IDL width of the
                field each variable travels in: each comparison is read at the width of
                what it compares (:func:`rclverify.semantics.widths.at_widths`;
                docs/semantics.md, "Widths"), so a constant compared with a ``float32``
                field is the exact ``real`` of its ``float32`` value
                (``p <= 0.20000000298023223876953125``).

    :meth:`formula` returns the Dafny text of a BOOL formula; raises
    :class:`PlanError` (located) for constructs Dafny cannot express.
    """

    env: Env
    node: CheckedNode
    io: Mapping[str, str]
    consts: Mapping[str, str] = field(default_factory=dict)
    taken: frozenset[str] = frozenset()
    widths: Mapping[str, str] = field(default_factory=dict)
    used_consts: set[str] = field(default_factory=set)
    used_types: list[Type] = field(default_factory=list)

    # -- entry points ---------------------------------------------------------------
    def formula(self, e: ast.Expr) -> str:
        """Dafny text of the formula ``e`` (type-checked RCL, BOOL)."""
        text, t = self.tr(at_widths(e, self.widths, self.env.constants), {})
        if t != BOOL:
            raise self._err(e.loc, f"expected a formula, found a term of type {t}")
        return strip_parens(text)

    def term(self, e: ast.Expr) -> tuple[str, Type]:
        """Dafny text and RCL type of the term ``e``."""
        return self.tr(e, {})

    # -- internals ------------------------------------------------------------------------
    def _names_in_scope(self, scope: Mapping[str, Bound]) -> set[str]:
        return set(self.io.values()) | set(self.consts.values()) | set(self.taken) | {b.dafny for b in scope.values()}

    def _value_names(self) -> set[str]:
        return {dafny_ident(v) for v in self.env.enum_values} | {dafny_ident(c) for c in self.env.ctors}

    def _io_name(self, v: ast.Var) -> str | None:
        if v.prefix is not None:
            return self.io.get(v.qualified)
        if v.name in self.node.inputs:
            return self.io.get(f"in.{v.name}")
        if v.name in self.node.outputs:
            return self.io.get(f"out.{v.name}")
        return None

    def _value(self, name: str, owner: EnumT | DataT, scope: Mapping[str, Bound]) -> str:
        d = dafny_ident(name)
        shadowed = d in set(self.io.values()) | set(self.consts.values()) | {b.dafny for b in scope.values()}
        return f"{dafny_ident(owner.name)}.{d}" if shadowed else d

    @staticmethod
    def conv(text: str, src: Type, dst: Type) -> str:
        """Widen ``text`` (of type ``src``) to ``dst`` where Dafny needs it (int -> real)."""
        if dst == REAL and src in (NATURAL, INTEGER):
            m = _INT_LIT.match(text)
            if m:
                return f"{m.group(1)}{m.group(2)}.0{m.group(3)}"
            return f"({text} as real)"
        if isinstance(src, TupleT) and isinstance(dst, TupleT) and src != dst and len(src.elems) == len(dst.elems):
            # component by component: `(1, 2)` where `(real, real)` is expected
            return "(" + ", ".join(Translator.conv(f"{wrap(text)}.{k}", a, b)
                                   for k, (a, b) in enumerate(zip(src.elems, dst.elems))) + ")"
        return text

    def _join(self, items: list[tuple[str, Type]]) -> tuple[list[str], Type]:
        t: Type | None = None
        for _, it in items:
            if t is None:
                t = it
            elif numeric_join(t, it) is not None:
                t = numeric_join(t, it)
        if t is None:
            return [], EmptyT("{}")
        return [self.conv(s, it, t) for s, it in items], t

    # -- the translation --------------------------------------------------------------
    def tr(self, e: ast.Expr, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        """``(text, type)`` of ``e`` with bound variables ``scope``; records the
        type in :attr:`used_types` (the stub declares the datatypes used)."""
        text, t = self._tr(e, scope)
        if t not in self.used_types:
            self.used_types.append(t)
        return text, t

    def _tr(self, e: ast.Expr, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        if isinstance(e, ast.BoolLit):
            return ("true" if e.value else "false"), BOOL
        if isinstance(e, ast.NumLit):
            if e.is_integral:
                return str(int(e.value)), NATURAL
            return real_literal(e.value), REAL
        if isinstance(e, ast.Var):
            return self.var(e, scope)
        if isinstance(e, ast.Apply):
            return self.apply(e, scope)
        if isinstance(e, ast.Unary):
            s, t = self.tr(e.operand, scope)
            if e.op == "not":
                return f"!{wrap(s)}", BOOL
            if e.op == "-":
                return f"(-{wrap(s)})", (REAL if t == REAL else INTEGER)
            if e.op == "abs":
                zero = "0.0" if t == REAL else "0"
                return f"(if {wrap(s)} >= {zero} then {wrap(s)} else -{wrap(s)})", (REAL if t == REAL else INTEGER)
            if e.op == "sqrt" or e.op == "sin" or e.op == "cos":
                raise self._err(e.loc, f"{e.op} has no Dafny counterpart (Dafny's reals have no {UNARY[e.op].name}); "
                                       f"the obligation is left to the Z3 calculus")
            ast.unhandled(e.op)
        if isinstance(e, ast.Binary):
            return self.binary(e, scope)
        if isinstance(e, ast.Compare):
            return self.compare(e, scope)
        if isinstance(e, ast.Member):
            s = self.member(self.tr(e.elem, scope), e.collection, scope)
            return (f"!{wrap(s)}" if e.negated else s), BOOL
        if isinstance(e, (ast.SetLit, ast.SeqLit)):
            texts, t = self._join([self.tr(i, scope) for i in e.items])
            if isinstance(e, ast.SetLit):
                return "{" + ", ".join(texts) + "}", SetT(t)
            return "[" + ", ".join(texts) + "]", SeqT(t)
        if isinstance(e, ast.TupleLit):
            parts = [self.tr(i, scope) for i in e.items]
            return "(" + ", ".join(s for s, _ in parts) + ")", TupleT(tuple(t for _, t in parts))
        if isinstance(e, ast.Quant):
            return self.quant(e, scope), BOOL
        if isinstance(e, ast.TupleQuant):
            return self.tuple_quant(e, scope), BOOL
        if isinstance(e, ast.StrLit):
            return dafny_string(e.value, e.loc), STRING
        if isinstance(e, ast.SeqRange):
            return self.seq_range(e, scope)
        if isinstance(e, ast.First):  # docs/semantics.md, "The first published value"
            raise self._err(e.loc, "first(...) has no Dafny counterpart: a method's contract sees one call, not "
                                   "the run's history of an input")
        raise self._err(getattr(e, "loc", ast.NOLOC), f"unsupported expression {type(e).__name__}")  # pragma: no cover

    def seq_range(self, e: ast.SeqRange, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        """``<a upto b>`` with literal bounds, as the sequence it stands for
        (at most :data:`_RANGE_LIMIT` items; Dafny 2 has no sequence
        constructor).  With other bounds it is expressible only on the right
        of ``in`` (:meth:`member`); here it is a located error."""
        lo, hi = e.lo, e.hi
        if isinstance(lo, ast.NumLit) and isinstance(hi, ast.NumLit) and lo.is_integral and hi.is_integral:
            a, z = int(lo.value), int(hi.value)
            if z - a + 1 <= _RANGE_LIMIT:
                return "[" + ", ".join(str(k) for k in range(a, z + 1)) + "]", SeqT(NATURAL if a >= 0 else INTEGER)
        raise self._err(e.loc, f"a range is expressible in the Dafny contract stub only on the right of 'in' or "
                               f"with literal bounds at most {_RANGE_LIMIT} apart")

    def var(self, v: ast.Var, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        if v.prefix is None and v.name in scope:
            b = scope[v.name]
            return b.dafny, b.type
        io = self._io_name(v)
        if io is not None:
            t = self.node.io_type(v)
            assert t is not None
            return io, t
        if v.prefix is None:
            if v.name in self.env.constants:
                t, value = self.env.constants[v.name]
                if v.name in self.consts:
                    self.used_consts.add(v.name)
                    return self.consts[v.name], t
                s, vt = self.tr(value, {})
                return self.conv(s, vt, t), t
            if v.name in self.env.enum_values:
                enum = self.env.enum_values[v.name]
                return self._value(v.name, enum, scope), enum
            if v.name in self.env.ctors:
                data = self.env.ctors[v.name]
                return self._value(v.name, data, scope), data
        raise self._err(v.loc, f"unknown name {v.qualified!r} in node {self.node.name}")

    def apply(self, e: ast.Apply, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        f = e.func
        is_var = f.prefix is not None or f.name in scope or self._io_name(f) is not None or f.name in self.env.constants
        args = [self.tr(a, scope) for a in e.args]
        if not is_var and f.name in self.env.ctors:
            data = self.env.ctors[f.name]
            params = data.ctor(f.name) or ()
            texts = [self.conv(s, t, p) for (s, t), p in zip(args, params)]
            return f"{self._value(f.name, data, scope)}({', '.join(texts)})", data
        fs, ft = self.var(f, scope)
        if not isinstance(ft, FuncT):
            raise self._err(f.loc, f"{f.qualified} has type {ft} and cannot be applied")
        texts = [self.conv(s, t, p) for (s, t), p in zip(args, ft.args)]
        return f"{fs}({', '.join(texts)})", ft.result

    def binary(self, e: ast.Binary, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        (ls, lt), (rs, rt) = self.tr(e.left, scope), self.tr(e.right, scope)
        entry = OPERATORS[e.op]
        if entry.kind == "connective":
            return f"({ls} {entry.dafny} {rs})", BOOL
        if e.op == "/":
            return f"({self.conv(ls, lt, REAL)} {entry.dafny} {self.conv(rs, rt, REAL)})", REAL
        j = numeric_join(lt, rt)
        if j is None:
            raise self._err(e.loc, f"'{e.op}' needs numbers, found {lt} and {rt}")
        t: Type = INTEGER if (e.op == "-" and j == NATURAL) else j
        return f"({self.conv(ls, lt, j)} {entry.dafny} {self.conv(rs, rt, j)})", t

    def compare(self, e: ast.Compare, scope: Mapping[str, Bound]) -> tuple[str, Type]:
        vals = [self.tr(o, scope) for o in e.operands]
        parts = []
        for op, (a, at), (b, bt) in zip(e.ops, vals, vals[1:]):
            j = value_join(at, bt)
            if j is not None:
                a, b = self.conv(a, at, j), self.conv(b, bt, j)
            parts.append(f"({a} {OPERATORS[op].dafny} {b})")
        return (parts[0] if len(parts) == 1 else "(" + " && ".join(parts) + ")"), BOOL

    def _type_name(self, c: ast.Expr, scope: Mapping[str, Bound]) -> Type | None:
        """The type a bare name used as a collection denotes (``RadStat``, ``NATURAL``), if any."""
        if not isinstance(c, ast.Var) or c.prefix is not None or c.name in scope or self._io_name(c) is not None:
            return None
        if c.name in _BASE_NAMES:
            return _BASE_NAMES[c.name]
        if (product := qualified_base(c.name)) is not None:
            return product  # `REAL.REAL`: the pairs of reals
        return self.env.types.get(c.name)

    def member(self, elem: tuple[str, Type], coll: ast.Expr, scope: Mapping[str, Bound]) -> str:
        es, et = elem
        if isinstance(coll, ast.SeqRange):
            # `e in <lo upto hi>`: an integer between the bounds
            (ls, lt), (hs, ht) = self.tr(coll.lo, scope), self.tr(coll.hi, scope)
            j = numeric_join(numeric_join(et, lt) or et, ht) or et
            integral = self._in_carrier(es, et, INTEGER)
            bounds = f"({self.conv(ls, lt, j)} <= {self.conv(es, et, j)} <= {self.conv(hs, ht, j)})"
            return bounds if integral == "true" else f"({integral} && {bounds})"
        tt = self._type_name(coll, scope)
        if tt is not None:
            return self._in_carrier(es, et, tt)
        cs, ct = self.tr(coll, scope)
        if isinstance(ct, (SetT, SeqT)) and numeric_join(et, ct.elem) == REAL:
            # Dafny keeps int and real apart (nat and int mix freely): widen the integer side
            if ct.elem != REAL:
                if not isinstance(coll, (ast.SetLit, ast.SeqLit)):
                    raise self._err(coll.loc, f"membership of a {et} in a collection of {ct.elem} needs a "
                                              "conversion Dafny cannot apply to a whole collection")
                items = [self.conv(s, t, REAL) for s, t in (self.tr(i, scope) for i in coll.items)]
                cs = ("{" if isinstance(coll, ast.SetLit) else "[") + ", ".join(items) + (
                    "}" if isinstance(coll, ast.SetLit) else "]")
            es = self.conv(es, et, REAL)
        return f"({es} in {cs})"

    def _in_carrier(self, es: str, et: Type, tt: Type) -> str:
        """``es in T`` for a type ``T`` used as a set: the integrality and
        sign a value of type ``et`` must have to be a ``T``, component by
        component for a product such as ``REAL.REAL`` (``es.0``, ``es.1``)."""
        if isinstance(tt, TupleT) and isinstance(et, TupleT) and len(tt.elems) == len(et.elems):
            parts = [self._in_carrier(f"{es}.{k}", e, t) for k, (e, t) in enumerate(zip(et.elems, tt.elems))]
            return "(" + " && ".join(parts) + ")"
        if tt == NATURAL and et in (NATURAL, INTEGER):
            return f"({es} >= 0)"
        if tt == NATURAL and et == REAL:
            return f"((({es}.Floor as real) == {es}) && ({es} >= 0.0))"
        if tt == INTEGER and et == REAL:
            return f"(({es}.Floor as real) == {es})"
        if isinstance(tt, EmptyT):
            return "false"
        return "true"

