"""RCL formulas as C++17 expressions over a node's ``Inputs``/``Outputs`` structs (docs/generate.md).

The generated check header (``contract_checks.hpp``, no ROS dependency) evaluates
each assumption and guarantee clause the way rclverify's monitor reads a
recorded value in its *double* semantics (``semantics/floatsem.py`` ``_Double``,
docs/monitors.md "Numbers on the wire"): every non-integer literal is the
nearest double (the C++ compiler rounds a decimal literal to nearest), every
``+ - * /`` is a binary64 operation, left to right as written, integers stay
integers (``std::int64_t``), comparisons on the doubles.  With a declared
tolerance a second reading compares numbers that read a recorded value up to
the tolerance (``rclverify_rt::close``), in double arithmetic too.

A comparison with a field of known width (``widths``: the IDL type of the
field each variable travels in) is read at that width, as every path reads
it (:func:`rclverify.semantics.widths.at_widths`; docs/semantics.md,
"Widths"): a constant compared with a ``float32`` field is written as the
exact decimal of its ``float32`` value (``in.p <= 0.2`` as ``in.p <=
double{0.20000000298023223876953125}``, the double ``0.2f`` converts to),
so the check answers as ``p <= 0.2f`` in the node does.

Plain C++ has no exact rational arithmetic: the monitor's first reading,
*exact* (the values as rationals, literals as the decimals they spell), is
not made.  A formula exact arithmetic finds true and double arithmetic
false is therefore false here and true to the monitor (no case in the
examples; the oracle test counts them).  Integer arithmetic overflows at
2**63 where Python's does not, and an integer compared with a double is
converted to the double (exact below 2**53).

Translated: ``REAL``/``INTEGER``/``NATURAL``/``BOOL`` and enumeration
variables (``in.x``, ``out.y``, bare I/O names), numeric and boolean
literals, enumeration values, context constants, ``not``, unary ``-``,
``and or -> <=>``, ``+ - * /`` (``/`` by zero is undecided, as in
rclverify), chained comparisons, membership in a literal set, and
quantifiers as the double reading enumerates them (:mod:`.cpp_quant`: loops
over finite domains and over candidate points; anything else undecided with its reason).
Function tables and constructor terms of scalar and enumeration arguments
(:mod:`.cpp_values`): a table applied, a term built and compared with ``==``/``!=``.
Anything else (functions not applied, sets and sequences as values,
tuples, strings) raises :class:`Untranslatable`: the clause's check then
answers *undecided* (the monitor's ``inconclusive``), never a guess.
"""
from __future__ import annotations

from typing import Any, Mapping, cast

from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode, DataT, EnumT, FuncT, Scalar, Type
from rclverify.lang.visit import Visitor
from rclverify.semantics.operators import OPERATORS, UNARY
from rclverify.semantics.widths import at_widths
from rclverify.targets.cpp.common import CPP_SCALARS, Untranslatable, enum_const
from rclverify.targets.cpp.quant import quantifier
from rclverify.targets.cpp.values import kind_of, table_type, term_struct
from rclverify.targets.names import field_name, snake

def cpp_type(t: Type) -> str | None:
    """The C++ field type of an RCL type, ``None`` when the header cannot hold it."""
    if isinstance(t, Scalar):
        return CPP_SCALARS.get(t.name)
    if isinstance(t, EnumT):
        return "std::uint8_t"
    if isinstance(t, FuncT):
        return table_type(t)
    if isinstance(t, DataT):
        return term_struct(t)
    return None


class CppTranslator(Visitor[tuple[str, str]]):
    """Translates the formulas of one node; ``mode`` is ``double`` or ``tolerance``; ``widths``
    (``"in.x"`` -> ``float32``/``float64``) the widths its comparisons are read at (module docstring).

    ``translate(formula)`` returns a C++ expression of type ``bool`` reading ``in``
    and ``out`` (``const Inputs&``, ``const Outputs&``) that may throw
    ``rclverify_rt::Undecided``; raises :class:`Untranslatable`."""

    def __init__(self, checked: Checked, node: CheckedNode, mode: str = "double",
                 widths: Mapping[str, str] | None = None) -> None:
        self.env, self.node, self.mode = checked.env, node, mode
        self.widths: Mapping[str, str] = widths or {}
        #: the quantified variables in scope: RCL name -> (C++ name, kind) (:mod:`.cpp_quant`)
        self.bound: dict[str, tuple[str, str]] = {}
        #: why a translated formula may be undecided (a quantifier the double reading cannot enumerate)
        self.notes: list[str] = []

    def translate(self, e: ast.Expr) -> str:
        code, kind = self.expr(at_widths(e, self.widths, self.env.constants))
        if kind != "bool":
            raise Untranslatable(f"a clause of type {kind}")
        return code

    # -- expressions: (code, kind) with kind bool / int / double / enum:<Name> ------------
    def expr(self, e: ast.Expr) -> tuple[str, str]:
        """``e`` as ``(code, kind)``: the method ``visit_<Class>`` of its class;
        a construct without one raises :class:`Untranslatable` naming it."""
        return self.visit(e)

    def generic_visit(self, e: Any) -> tuple[str, str]:
        raise Untranslatable(_CONSTRUCTS.get(type(e).__name__, type(e).__name__))

    def visit_BoolLit(self, e: ast.BoolLit) -> tuple[str, str]:
        return ("true" if e.value else "false"), "bool"

    def visit_NumLit(self, e: ast.NumLit) -> tuple[str, str]:
        if e.is_integral:
            return f"std::int64_t{{{int(e.value)}}}", "int"
        return f"double{{{e.text}}}", "double"

    def visit_Var(self, e: ast.Var) -> tuple[str, str]:
        return self.var(e)

    def visit_Unary(self, e: ast.Unary) -> tuple[str, str]:
        code, kind = self.expr(e.operand)
        text = cast(str, UNARY[e.op].cpp)
        if e.op == "not":
            return text.format(x=self._bool(code, kind)), "bool"
        if e.op == "-" or e.op == "abs":
            if kind not in ("int", "double"):
                raise Untranslatable(f"{UNARY[e.op].name} on {kind}")
            return text.format(x=code), kind
        if e.op == "sqrt" or e.op == "sin" or e.op == "cos":  # <cmath> on a double; a negative sqrt gives NaN
            if kind not in ("int", "double"):
                raise Untranslatable(f"{UNARY[e.op].name} on {kind}")
            return text.format(x=f"static_cast<double>({code})"), "double"
        ast.unhandled(e.op)

    def visit_Binary(self, e: ast.Binary) -> tuple[str, str]:
        return self.binary(e)

    def visit_Compare(self, e: ast.Compare) -> tuple[str, str]:
        return self.compare(e)

    def visit_Member(self, e: ast.Member) -> tuple[str, str]:
        return self.member(e)

    def visit_Quant(self, e: ast.Quant) -> tuple[str, str]:
        return quantifier(self, e)

    def visit_Apply(self, e: ast.Apply) -> tuple[str, str]:
        return self.apply(e)

    def var(self, v: ast.Var) -> tuple[str, str]:
        if v.prefix is None and v.name in self.bound:  # a quantified variable first, as rclverify resolves names
            return self.bound[v.name]
        if v.prefix is None and v.name in self.env.enum_values:
            et = self.env.enum_values[v.name]
            return enum_const(et, v.name), f"enum:{et.name}"
        if v.prefix is None and v.name in self.env.constants:
            code, kind = self.expr(self.env.constants[v.name][1])
            return f"({code})", kind
        if v.prefix is None and v.name in self.env.ctors:
            return self.apply(ast.Apply(v, (), v.loc))
        if v.prefix in ("in", "out"):
            side, name = v.prefix, v.name
        elif v.prefix is None and (v.name in self.node.inputs or v.name in self.node.outputs):
            side, name = ("in" if v.name in self.node.inputs else "out"), v.name
        else:
            raise Untranslatable(f"variable {v.name}")
        t = (self.node.inputs if side == "in" else self.node.outputs).get(name)
        field = f"{side}.{field_name(name)}"
        if isinstance(t, Scalar) and t.name == "REAL":
            return field, "double"
        if isinstance(t, Scalar) and t.name == "INTEGER":
            return field, "int"
        if isinstance(t, Scalar) and t.name == "NATURAL":
            return f"static_cast<std::int64_t>({field})", "int"
        if isinstance(t, Scalar) and t.name == "BOOL":
            return field, "bool"
        if isinstance(t, EnumT):
            return field, f"enum:{t.name}"
        if isinstance(t, DataT) and term_struct(t) is not None:
            return field, f"term:{t.name}"
        if isinstance(t, FuncT) and table_type(t) is not None:
            return field, "table"
        raise Untranslatable(f"{side}.{name} of type {t}")

    def apply(self, e: ast.Apply) -> tuple[str, str]:
        """A constructor term (``TermX::make_<ctor>(args)``) or a table application
        (``in.f(args)``), each argument converted to the declared type."""
        f = e.func
        if f.prefix is None and f.name in self.env.ctors and f.name not in self.bound:
            t = self.env.ctors[f.name]
            struct = term_struct(t)
            if struct is None:
                raise Untranslatable(f"a constructor term of {t.name} (an argument not held here)")
            types = dict(t.ctors)[f.name]
            args = [self._arg(a, at) for a, at in zip(e.args, types)]
            return f"{struct}::make_{snake(f.name)}({', '.join(args)})", f"term:{t.name}"
        code, kind = self.var(f)
        if kind != "table":
            raise Untranslatable(f"an application of {f.qualified}")
        ft = (self.node.inputs if (f.prefix == "in" or (f.prefix is None and f.name in self.node.inputs))
              else self.node.outputs)[f.name]
        assert isinstance(ft, FuncT)  # its kind is "table"
        rk = kind_of(ft.result)
        if rk is None:
            raise Untranslatable(f"a function result of type {ft.result}")
        args = [self._arg(a, at) for a, at in zip(e.args, ft.args)]
        return f"{code}({', '.join(args)})", rk

    def _arg(self, a: ast.Expr, t: Type) -> str:
        """Argument ``a`` as the C++ type of declared type ``t``."""
        code, kind = self.expr(a)
        want = kind_of(t)
        if want == kind:
            return code
        if want == "double" and kind == "int":
            return f"static_cast<double>({code})"
        raise Untranslatable(f"an argument of kind {kind} where {t} is declared")

    def binary(self, e: ast.Binary) -> tuple[str, str]:
        """A connective or arithmetic as the C++ text of its entry in the semantics
        table; ``/`` (no 1:1 text: a zero divisor is undecided) as ``rclverify_rt::div``."""
        (lc, lk), (rc, rk) = self.expr(e.left), self.expr(e.right)
        entry = OPERATORS[e.op]
        if entry.kind == "connective":
            return cast(str, entry.cpp).format(l=self._bool(lc, lk), r=self._bool(rc, rk)), "bool"
        if lk not in ("int", "double") or rk not in ("int", "double"):
            raise Untranslatable(f"arithmetic on {lk}, {rk}")
        if entry.cpp is None:  # "/": the runtime's division
            return f"rclverify_rt::div({lc}, {rc})", "double"
        kind = "int" if lk == rk == "int" else "double"
        return entry.cpp.format(l=lc, r=rc), kind

    def compare(self, e: ast.Compare) -> tuple[str, str]:
        parts = [self.expr(x) for x in e.operands]
        reads = [_reads_io(x, self.node) for x in e.operands]
        out = []
        for k, op in enumerate(e.ops):
            (lc, lk), (rc, rk) = parts[k], parts[k + 1]
            numeric = lk in ("int", "double") and rk in ("int", "double")
            text = cast(str, OPERATORS[op].cpp)
            if not numeric and (lk != rk or op not in ("==", "!=")):
                raise Untranslatable(f"comparison {op} of {lk} and {rk}")
            if numeric and self.mode == "tolerance" and (reads[k] or reads[k + 1]):
                out.append(f"rclverify_rt::tol_cmp(rclverify_rt::Cmp::{_CMP_NAMES[op]}, "
                           f"static_cast<double>({lc}), static_cast<double>({rc}), kTolerance)")
            elif numeric and lk != rk:  # int against double: compared as doubles
                out.append(text.format(l=f"static_cast<double>({lc})", r=f"static_cast<double>({rc})"))
            else:
                out.append(text.format(l=lc, r=rc))
        return (out[0] if len(out) == 1 else "(" + " && ".join(out) + ")"), "bool"

    def member(self, e: ast.Member) -> tuple[str, str]:
        if not isinstance(e.collection, ast.SetLit):
            raise Untranslatable("membership in a set that is not a literal")
        code, kind = self.expr(e.elem)
        tests = []
        for item in e.collection.items:
            ic, ik = self.expr(item)
            if kind in ("int", "double") and ik in ("int", "double"):  # exact ==, as the set's (no tolerance)
                tests.append(f"{code} == {ic}" if ik == kind else
                             f"static_cast<double>({code}) == static_cast<double>({ic})")
                continue
            if ik != kind:
                raise Untranslatable(f"membership of {kind} in a set of {ik}")
            tests.append(f"{code} == {ic}")
        body = "(" + (" || ".join(tests) or "false") + ")"
        return (f"(!{body})" if e.negated else body), "bool"

    @staticmethod
    def _bool(code: str, kind: str) -> str:
        if kind != "bool":
            raise Untranslatable(f"a connective on {kind}")
        return code


_CONSTRUCTS = {"TupleQuant": "a quantifier with a tuple binder", "Apply": "a function or constructor term",
               "SetLit": "a set", "SeqLit": "a sequence", "TupleLit": "a tuple", "StrLit": "a string",
               "SeqRange": "a sequence range",
               "First": "first(...), which needs the run's history of an input (docs/semantics.md)"}
_CMP_NAMES = {"==": "kEq", "!=": "kNe", "<": "kLt", "<=": "kLe", ">": "kGt", ">=": "kGe"}


def _reads_io(e: ast.Expr, node: CheckedNode) -> bool:
    """Does ``e`` read an input or output (the tolerance applies to such comparisons only)?"""
    if isinstance(e, ast.Var):
        return e.prefix in ("in", "out") or (e.prefix is None and (e.name in node.inputs or e.name in node.outputs))
    if isinstance(e, ast.Unary):
        return _reads_io(e.operand, node)
    if isinstance(e, ast.Binary):
        return _reads_io(e.left, node) or _reads_io(e.right, node)
    return False
