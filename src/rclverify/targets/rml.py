"""RCL guarantees -> RML (the Runtime Monitoring Language), paper lines 873-975.

The translation follows the paper's rules (Fig. "RML partial translation"):
(and/or) -> ``/\\``/``\\/``; (implies) -> ``(not t1) \\/ t2``, the paper's
three-way disjunction simplified; (iff) -> ``(t1 /\\ t2) \\/ (not t1 /\\ not t2)``;
(equals)/(not-equals) -> an event type and its negated event type; (exists)
-> ``{let x; t}``; (guarantee) -> ``(t)*``; (guarantees) -> ``G1 /\\ ... /\\ Gn``.
Negation is pushed inward (De Morgan) down to negated event types
(``not matches``), so implication and negation keep their meaning.

Decisions where the paper is silent (docs/monitors.md):

* the universally quantified variables at the top of a guarantee become a
  ``{let ...}`` under the ``*``: each repetition binds them afresh from the
  events, so every instance the run exhibits is checked (the paper's own
  translation of guarantee 2, lines 1590-1640);
* a nested ``forall`` (or ``not exists``) is expressible when every
  conjunct that mentions its variables is a negated atom: the variables
  become ``_`` wildcards of a negated event type ("no event matches");
* atoms comparing a scalar with constants become event types with a
  ``with`` guard;
* anything else -- ``exists_unique`` (uniqueness needs counting over all
  events), a nested universal variable in a positive atom or in arithmetic,
  a comparison between two observed values -- is reported as not
  expressible, with the part and the reason, and no term is emitted for
  that guarantee rather than one that means less.

Event types are named after the RCL variable (first letter lower-cased, as
the RML compiler requires), ``topic`` is the topic name and the message
fields are flattened beside it, as ROSMonitoring sends them.

The specification's parts and its event types are :mod:`.rml_spec`'s.
"""
from __future__ import annotations

import dataclasses
import re
from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.mapping import TopicRule
from rclverify.semantics.operators import OPERATORS
from rclverify.semantics.widths import at_widths
from rclverify.targets.rml_spec import (EventType, EventTypes, Inexpressible, Spec as Spec, Term, literal_text,
                                        rml_id as rml_id)

class Translator(EventTypes):
    """Translates the guarantees of one node; ``msg_fields`` maps a message type
    (``pkg/msg/Type``) to its ``[(field, ros_type)]``."""

    def __init__(self, checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                 msg_fields: Mapping[str, list[tuple[str, str]]]) -> None:
        self.checked, self.node, self.rules, self.msg_fields = checked, node, rules, msg_fields
        self.spec = Spec(node.name)
        self._declared: dict[tuple[str, bool], EventType] = {}
        self._guards: dict[tuple[str, str], str] = {}
        self.topic_of: dict[str, ast.Topic] = {}
        for t in node.node.topics:
            if t.match is not None:
                key = ("in." if (t.match.prefix == "in" or (t.match.prefix is None and t.match.name in node.inputs))
                       else "out.") + t.match.name
                self.topic_of.setdefault(key, t)

    # -- formulas ----------------------------------------------------------------
    def io_key(self, v: ast.Var) -> str | None:
        if v.prefix is not None:
            return v.qualified
        if v.name in self.node.inputs:
            return "in." + v.name
        if v.name in self.node.outputs:
            return "out." + v.name
        return None

    def data(self, e: ast.Expr, bound: Mapping[str, str], wild: frozenset[str]) -> str:
        """An RML data expression for an RCL term over bound variables and constants."""
        if isinstance(e, ast.NumLit):
            return e.text if re.fullmatch(r"[0-9]+(\.[0-9]+)?", e.text) else literal_text(e.value)
        if isinstance(e, ast.Var) and e.prefix is None and e.name in bound:
            if e.name in wild:
                return "_"
            return bound[e.name]
        if isinstance(e, ast.Var) and e.prefix is None and e.name in self.checked.env.enum_values:
            return f"'{e.name}'"
        if isinstance(e, ast.BoolLit):
            return "true" if e.value else "false"
        if isinstance(e, ast.Unary) and e.op == "-":
            return f"-{self.data(e.operand, bound, wild)}"
        if isinstance(e, ast.Binary) and e.op in ("+", "-", "*", "/"):
            left, right = self.data(e.left, bound, wild), self.data(e.right, bound, wild)
            if "_" in (left, right):
                raise Inexpressible(e, "a universally quantified variable inside arithmetic cannot be a wildcard")
            return f"{left}{e.op}{right}"
        raise Inexpressible(e, "only bound variables, literals and arithmetic on them can be event type "
                               "parameters")

    def atom(self, e: ast.Expr, neg: bool, bound: Mapping[str, str], wild: frozenset[str]) -> str:
        """Translate an atom (the (equals)/(not-equals) rules)."""
        if isinstance(e, ast.Apply):  # bare BOOL function application
            e = ast.Compare(("==",), (e, ast.BoolLit(True)), e.loc)
        if isinstance(e, ast.Member):
            if not isinstance(e.collection, ast.SetLit):
                raise Inexpressible(e, "membership in a set that is not a literal")
            eqs = [ast.Compare(("==",), (e.elem, i), e.loc) for i in e.collection.items]
            conj = neg != e.negated  # not (a in S) = all !=
            parts = [self.atom(q, conj, bound, wild) for q in eqs]
            return "(" + (" /\\ " if conj else " \\/ ").join(parts) + ")"
        if not isinstance(e, ast.Compare):
            raise Inexpressible(e, "not an atom RML can observe")
        if len(e.ops) > 1:
            parts = [self.atom(ast.Compare((op,), (a, b), e.loc), False, bound, wild)
                     for op, a, b in zip(e.ops, e.operands, e.operands[1:])]
            if neg:
                parts = [self.atom(ast.Compare((op,), (a, b), e.loc), True, bound, wild)
                         for op, a, b in zip(e.ops, e.operands, e.operands[1:])]
                return "(" + " \\/ ".join(parts) + ")"
            return "(" + " /\\ ".join(parts) + ")"
        op, (lhs, rhs) = e.ops[0], e.operands
        side, other = self._observed(lhs), rhs
        if side is None:
            side, other = self._observed(rhs), lhs
            op = OPERATORS[op].converse or op  # type: ignore[assignment]  # read with its operands swapped
        if side is None:
            raise Inexpressible(e, "the comparison mentions no input or output of the node")
        if self._observed(other) is not None:
            raise Inexpressible(e, "a comparison between two observed values needs two events at once")
        if op not in ("==", "!="):
            return self._guarded(e, side, op, other, neg, bound, wild)
        negate = neg != (op == "!=")
        if isinstance(side, ast.Apply):  # function-typed input/output
            key = self.io_key(side.func)
            ftype = self.node.io_type(side.func)
            assert key is not None and isinstance(ftype, T.FuncT)
            args = [self.data(a, bound, wild) for a in side.args]
            name = rml_id(side.func.name)
            if isinstance(ftype.result, T.Scalar) and ftype.result.name == "BOOL":
                if not isinstance(other, ast.BoolLit):
                    raise Inexpressible(e, "a BOOL function compared with something other than TRUE/FALSE")
                negate = negate != (not other.value)
                et = self.event_type(key, name, list(ftype.args), negated=negate)
            else:
                args.append(self.data(other, bound, wild))
                et = self.event_type(key, name, list(ftype.args) + [ftype.result], negated=negate)
            return self._use(et, args, e, negate)
        assert isinstance(side, ast.Var)
        key = self.io_key(side)
        typ = self.node.io_type(side)
        assert key is not None and typ is not None
        name = rml_id(side.name)
        if isinstance(typ, T.DataT):
            if not (isinstance(other, ast.Apply) and other.func.name in self.checked.env.ctors) and not (
                    isinstance(other, ast.Var) and other.name in self.checked.env.ctors):
                raise Inexpressible(e, "a constructor-typed value compared with something that is not a term")
            ctor = other.func.name if isinstance(other, ast.Apply) else other.name
            cargs = other.args if isinstance(other, ast.Apply) else ()
            arg_types = list(typ.ctor(ctor) or ())
            et = self.event_type(key, f"{name}_{rml_id(ctor)}", [T.EnumT("ctor", ())] + arg_types,
                                 fixed=((0, f"'{ctor}'"),), negated=negate)
            return self._use(et, [self.data(a, bound, wild) for a in cargs], e, negate)
        et = self.event_type(key, name, [typ], negated=negate)
        return self._use(et, [self.data(other, bound, wild)], e, negate)

    def _use(self, et: EventType, args: list[str], e: ast.Expr, negate: bool) -> str:
        if "_" in args and not negate:
            raise Inexpressible(e, "a universally quantified variable in a positive atom would need every "
                                   "value to be observed")
        return et.name + (f"({', '.join(args)})" if args else "")

    def _observed(self, e: ast.Expr) -> Any:
        if isinstance(e, ast.Apply) and e.func.name not in self.checked.env.ctors and self.io_key(e.func):
            return e
        if isinstance(e, ast.Var) and self.io_key(e) and e.name not in self.checked.env.enum_values:
            typ = self.node.io_type(e)
            if typ is not None and not isinstance(typ, T.FuncT):
                return e
        return None

    def _guarded(self, e: ast.Expr, side: Any, op: str, other: ast.Expr, neg: bool,
                 bound: Mapping[str, str], wild: frozenset[str]) -> str:
        if not isinstance(side, ast.Var):
            raise Inexpressible(e, "an ordering on a function value")
        key = self.io_key(side)
        typ = self.node.io_type(side)
        assert key is not None and typ is not None
        value = self.data(other, bound, wild)
        if any(b in value for b in bound.values()) or "_" in value:
            raise Inexpressible(e, "an ordering against a quantified variable")
        guard = f"x1 {op} {value}"
        gk = (key, guard)
        if gk not in self._guards:
            self._guards[gk] = f"{rml_id(side.name)}_c{sum(1 for k in self._guards if k[0] == key) + 1}"
        name = self._guards[gk]
        et = self.event_type(key, name, [typ], negated=neg, guard=guard)
        return f"{et.name}(_)"

    def tr(self, e: ast.Expr, neg: bool, bound: dict[str, str], wild: frozenset[str]) -> str:
        """The RML term for ``e`` (``not e`` when ``neg``)."""
        if isinstance(e, ast.Unary) and e.op == "not":
            return self.tr(e.operand, not neg, bound, wild)
        if isinstance(e, ast.Binary) and e.op in ("and", "or"):
            conj = (e.op == "and") != neg
            return "(" + self.tr(e.left, neg, bound, wild) + (" /\\ " if conj else " \\/ ") + \
                self.tr(e.right, neg, bound, wild) + ")"
        if isinstance(e, ast.Binary) and e.op == "->":
            if neg:
                return "(" + self.tr(e.left, False, bound, wild) + " /\\ " + self.tr(e.right, True, bound, wild) + ")"
            return "(" + self.tr(e.left, True, bound, wild) + " \\/ " + self.tr(e.right, False, bound, wild) + ")"
        if isinstance(e, ast.Binary) and e.op == "<=>":
            a, b = self.tr(e.left, False, bound, wild), self.tr(e.right, False, bound, wild)
            na, nb = self.tr(e.left, True, bound, wild), self.tr(e.right, True, bound, wild)
            if neg:
                return f"(({a} /\\ {nb}) \\/ ({na} /\\ {b}))"
            return f"(({a} /\\ {b}) \\/ ({na} /\\ {nb}))"
        if isinstance(e, ast.Quant):
            return self.quant(e, neg, bound, wild)
        if isinstance(e, ast.BoolLit):
            raise Inexpressible(e, "a constant formula observes no event")
        return self.atom(e, neg, bound, wild)

    def _names(self, e: ast.Quant, bound: Mapping[str, str]) -> dict[str, str]:
        out = dict(bound)
        taken = set(bound.values())
        for n in e.variables:
            base = rml_id(n)
            cand, k = base, 1
            while cand in taken:
                k += 1
                cand = f"{base}{k}"
            taken.add(cand)
            out[n] = cand
        return out

    def quant(self, e: ast.Quant, neg: bool, bound: dict[str, str], wild: frozenset[str]) -> str:
        if e.kind == "exists_unique":
            raise Inexpressible(e, "uniqueness needs counting over all events; an RML event type matches "
                                   "one event at a time")
        existential = (e.kind == "exists") != neg
        inner = self._names(e, bound)
        if existential:
            body = self.tr(e.body, neg, inner, wild)
            return "{let " + ", ".join(inner[n] for n in e.variables) + "; " + body + "}"
        # universal, nested: conjuncts without the variables pulled out; the rest as wildcards
        vars_ = set(e.variables)
        parts = _conjuncts(e.body) if not neg else [e.body]
        outside = [p for p in parts if not _mentions(p, vars_)]
        inside = [p for p in parts if _mentions(p, vars_)]
        w = wild | vars_
        terms = [self.tr(p, neg, inner, wild) for p in outside]
        terms += [self.tr(p, neg, inner, frozenset(w)) for p in inside]
        return "(" + " /\\ ".join(terms) + ")" if len(terms) > 1 else terms[0]

    def guarantee(self, k: int, clause: ast.Clause) -> Term:
        """``G<k> = {let ...; t}*;`` for one guarantee (the (guarantee) rule)."""
        f = clause.formula
        rcl = expr_to_rcl(f)
        saved = (list(self.spec.event_types), dict(self._declared), dict(self._guards))
        try:
            if isinstance(f, ast.Quant) and f.kind == "forall":
                names = self._names(f, {})
                body = self.tr(f.body, False, names, frozenset())
                text = "{let " + ", ".join(names[n] for n in f.variables) + "; " + body + "}*"
            else:
                text = "(" + self.tr(f, False, {}, frozenset()) + ")*"
        except Inexpressible as exc:
            self.spec.event_types, self._declared, self._guards = saved[0], saved[1], saved[2]
            return Term(k, rcl, part=exc.part, why=exc.why)
        return Term(k, rcl, text=text)


def _conjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


def _mentions(e: Any, names: set[str]) -> bool:
    if isinstance(e, ast.Var):
        return e.prefix is None and e.name in names
    if isinstance(e, ast.Quant):
        names = names - set(e.variables)
    for attr in ("args", "operand", "left", "right", "operands", "elem", "collection", "items", "body"):
        c = getattr(e, attr, None)
        if c is None:
            continue
        for x in (c if isinstance(c, tuple) else (c,)):
            if _mentions(x, names):
                return True
    return False


def translate(checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
              msg_fields: Mapping[str, list[tuple[str, str]]], widths: Mapping[str, str] | None = None) -> Spec:
    """The node's RML specification: one term per expressible guarantee, the
    reason for each inexpressible one (paper lines 873-975).  ``widths``
    (``"in.x"`` -> ``float32``/``float64``: the IDL width of the field each
    variable travels in) reads each comparison at the width of what it
    compares (:func:`rclverify.semantics.widths.at_widths`; docs/semantics.md,
    "Widths"): a guard compares a ``float32`` field with the exact decimal of
    its constant's ``float32`` value (``with p <= 0.20000000298023223876953125``)."""
    tr = Translator(checked, node, rules, msg_fields)
    for k, clause in enumerate(node.node.guarantees, 1):
        if widths:
            clause = dataclasses.replace(clause, formula=at_widths(clause.formula, widths, checked.env.constants))
        tr.spec.terms.append(tr.guarantee(k, clause))
    return tr.spec
