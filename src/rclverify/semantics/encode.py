"""RCL formulas -> Z3 (shared/DESIGN.md "Semantics the tool commits to").

Encoding
--------
* ``REAL`` -> Real, ``INTEGER`` -> Int, ``NATURAL`` -> Int with ``>= 0``
  guards on every bound variable (``forall``: guard ``->`` body, ``exists``:
  guard ``and`` body) and an axiom for every free symbol (:meth:`Encoder.axioms`),
  ``BOOL`` -> Bool.
* Enumerations -> Z3 enumeration sorts, constructor sets -> algebraic
  datatypes (accessor ``<ctor>_<k>``, recogniser ``is_<ctor>``), both named
  after their context type; function types -> uninterpreted functions;
  ``set(T)`` -> Z3 sets, ``seq(T)`` -> Z3 sequences, tuples -> datatypes.
* ``exists_unique(x, y in D | P)`` -> ``exists x, y. P and forall x2, y2.
  P[x2, y2] -> x2 == x and y2 == y`` (uniqueness of the tuple).
* Quantifying over the empty type ``{}``: ``forall`` is TRUE, ``exists``
  FALSE; a formula that needs a value of the empty type is rejected.
* Free I/O variables become symbols named ``<Node>.<in|out>.<name>``;
  ``alias`` (the system model's connections) renames a consumer's input to
  the producer's output symbol, so that "an output variable and the input
  variable it feeds are the same symbol in the composed query".

Sorts are cached per process, so two encoders (e.g. a contract's and a Hoare
program's) agree on the sort ``RadStat``.

The encoding is split by job: sorts and coercions (:mod:`.sorts`), names
and the error (:mod:`.symbols`), formula translation (:mod:`.translate`),
model values as RCL text (:mod:`.modeltext`); this module holds the
:class:`Encoder` (symbols and their axioms) and keeps every name importable
from here.
"""
from __future__ import annotations

from typing import Any, Mapping

import z3

from rclverify.lang import ast
from rclverify.lang.types import BOOL, NATURAL, CheckedNode, DataT, Env, FuncT, SeqT, SetT, TupleT, Type
from rclverify.semantics.natural import natural_typing
from rclverify.semantics.modeltext import _render, _term_parts, _term_to_rcl_reference, _value_parts, term_to_rcl, value_to_rcl
from rclverify.semantics.sorts import (_ctor, _join_sort, _recogniser, _tuple_fields, apply_operator, coerce, enum_const, sort_of,
                    tuple_sort, widen)
from rclverify.semantics.symbols import EncodingError, Symbol, smt_symbol
from rclverify.semantics.translate import MAX_RANGE_ITEMS, _Ctx


class Encoder:
    """Encodes RCL formulas of one system into Z3.

    ``env``    the checked environment (context types, constants, values);
    ``alias``  maps ``(node, "in"|"out", var)`` to the canonical symbol name
               another I/O variable uses (consumer input -> producer output).
    """

    def __init__(self, env: Env, alias: Mapping[tuple[str, str, str], str] | None = None) -> None:
        self.env = env
        self.alias: Mapping[tuple[str, str, str], str] = alias if alias is not None else {}
        self.symbols: dict[str, Symbol] = {}

    # -- sorts and values ------------------------------------------------------------
    def sort(self, t: Type) -> z3.SortRef:
        """See :func:`sort_of`."""
        return sort_of(t)

    def enum_value(self, name: str) -> z3.ExprRef:
        """Z3 constant of an enumeration value (or argument-less constructor)."""
        if name in self.env.enum_values:
            return enum_const(self.env.enum_values[name], name)
        return _ctor(self.env.ctors[name], name)()

    def ctor(self, name: str) -> z3.FuncDeclRef:
        """Z3 constructor of constructor-set alternative ``name``."""
        return _ctor(self.env.ctors[name], name)

    # -- symbols --------------------------------------------------------------------------
    def symbol_name(self, node: str, prefix: str, var: str) -> str:
        return self.alias.get((node, prefix, var), f"{node}.{prefix}.{var}")

    def io_symbol(self, node: CheckedNode, prefix: str, var: str) -> Any:
        """The Z3 constant (or function declaration) of ``node``'s ``prefix.var``."""
        t = node.inputs[var] if prefix == "in" else node.outputs[var]
        name = self.symbol_name(node.name, prefix, var)
        if name in self.symbols:
            return self.symbols[name].decl
        display = name if name.count(".") >= 2 else f"{node.name}.{prefix}.{var}"
        if isinstance(t, FuncT):
            decl: Any = z3.Function(name, *[sort_of(a) for a in t.args], sort_of(t.result))
        else:
            decl = z3.Const(name, sort_of(t))
        self.symbols[name] = Symbol(name, display, t, decl)
        return decl

    def first_symbol(self, node: CheckedNode, var: str) -> z3.ExprRef:
        """The Boolean ``first(in.var)`` of ``node`` in a one-step query: whether
        the step's message on that input is the first published on it.  Free
        (docs/semantics.md, "The first published value": over one step either
        value is possible, every rule is asked for both), one symbol per
        input as the encoder names it (a consumer's input aliased to its
        producer's output shares the producer's)."""
        who, _, x = var.partition(".in.") if ".in." in var else (node.name, "", var)  # a requirement's Node.in.x
        owner, _, rest = self.symbol_name(who, "in", x).partition(".")
        name = f"{owner}.first({rest})"  # "<Node>.first(in.x)": the qualified name after the node, as an I/O symbol's
        if name not in self.symbols:
            self.symbols[name] = Symbol(name, f"first({who}.in.{x})", BOOL, z3.Bool(name))
        return self.symbols[name].decl

    def fresh(self, z3name: str, display: str, t: Type) -> z3.ExprRef:
        """A new free constant (e.g. a Skolem witness) shown as ``display`` in models."""
        z3name = smt_symbol(z3name)
        decl = z3.Const(z3name, sort_of(t))
        self.symbols[z3name] = Symbol(z3name, display, t, decl)
        return decl

    def axioms(self) -> list[z3.BoolRef]:
        """Typing side constraints of every free symbol created so far.

        NATURAL constants are ``>= 0``; functions with a NATURAL result are
        ``>= 0`` everywhere; constructor-set and tuple constants (and
        function results) have their NATURAL parts ``>= 0`` at any depth
        (:func:`.natural.natural_typing`), a sequence's or a set's NATURAL
        elements by a quantified axiom.
        """
        out: list[z3.BoolRef] = []
        for sym in self.symbols.values():
            t = sym.type
            if isinstance(t, FuncT):
                xs = [z3.Const(f"_a{k}", sort_of(a)) for k, a in enumerate(t.args)]
                if t.result == NATURAL:
                    out.append(z3.ForAll(xs, sym.decl(*xs) >= 0) if xs else sym.decl() >= 0)
                elif xs and isinstance(t.result, (DataT, TupleT, SeqT, SetT)):
                    cs, _ = natural_typing(sym.decl(*xs), t.result, quantified=True)
                    out += [z3.ForAll(xs, c) for c in cs]
            elif isinstance(t, (DataT, TupleT, SeqT, SetT)) or t == NATURAL:
                out += natural_typing(sym.decl, t, quantified=True)[0]
        return out

    # -- formulas ----------------------------------------------------------------------------
    def formula(self, e: ast.Expr, node: CheckedNode, symbols: Mapping[str, z3.ExprRef | z3.FuncDeclRef] | None = None,
                bound: Mapping[str, z3.ExprRef] | None = None) -> z3.BoolRef:
        """Encode a (type-checked) formula of ``node``.

        ``symbols`` maps qualified I/O names (``"in.r"``, ``"out.x"``) to Z3
        terms (or function declarations) used instead of the node's symbols;
        ``bound`` gives Z3 terms for variables bound outside ``e`` (used to
        instantiate a quantifier's body).  Raises :class:`EncodingError` for
        unsupported constructs.
        """
        r = _Ctx(self, node, dict(symbols or {})).enc(e, dict(bound or {}))
        if not z3.is_bool(r):
            raise EncodingError(e.loc, "expected a formula")
        return r

    def term(self, e: ast.Expr, node: CheckedNode, symbols: Mapping[str, z3.ExprRef | z3.FuncDeclRef] | None = None) -> z3.ExprRef:
        """Encode a term (e.g. the left-hand side of a binding) of ``node``."""
        return _Ctx(self, node, dict(symbols or {})).enc(e, {})


__all__ = ["EncodingError", "Encoder", "MAX_RANGE_ITEMS", "Symbol", "apply_operator", "coerce", "enum_const",
           "smt_symbol", "sort_of", "term_to_rcl", "tuple_sort", "value_to_rcl", "widen"]
