"""Semantic (resolved) RCL types and the typing environment.

The type checker (:mod:`rclverify.lang.typecheck`) resolves every
:data:`rclverify.lang.typeexpr.TypeExpr` into a :data:`Type` below: context names
are expanded, enumerations and constructor sets keep the context name they
were declared under (it names the Z3 sort and the Dafny datatype).

Numeric subtyping: ``NATURAL <: INTEGER <: REAL`` (paper section 3.2 uses
the three as the usual number sets).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Mapping, Union

from rclverify.lang import ast
from rclverify.lang.units import Unit

ScalarName = Literal["REAL", "INTEGER", "NATURAL", "BOOL", "STRING"]


@dataclass(frozen=True)
class Scalar:
    name: ScalarName

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class EnumT:
    """Enumeration; ``name`` is the context name (or a synthetic one)."""

    name: str
    values: tuple[str, ...]

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class DataT:
    """Constructor set; ``ctors`` is ``((ctor name, (arg types...)), ...)``."""

    name: str
    ctors: tuple[tuple[str, tuple["Type", ...]], ...]

    def __str__(self) -> str:
        return self.name

    def ctor(self, name: str) -> tuple["Type", ...] | None:
        for n, args in self.ctors:
            if n == name:
                return args
        return None


@dataclass(frozen=True)
class FuncT:
    args: tuple["Type", ...]
    result: "Type"

    def __str__(self) -> str:
        return " x ".join(map(str, self.args)) + " --> " + str(self.result)


@dataclass(frozen=True)
class EmptyT:
    """The empty type ``{}``; no value inhabits it."""

    name: str = "{}"

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class SetT:
    elem: "Type"

    def __str__(self) -> str:
        return f"set({self.elem})"


@dataclass(frozen=True)
class SeqT:
    elem: "Type"

    def __str__(self) -> str:
        return f"seq({self.elem})"


@dataclass(frozen=True)
class TupleT:
    elems: tuple["Type", ...]

    def __str__(self) -> str:
        return "(" + ", ".join(map(str, self.elems)) + ")"


Type = Union[Scalar, EnumT, DataT, FuncT, EmptyT, SetT, SeqT, TupleT]

REAL = Scalar("REAL")
INTEGER = Scalar("INTEGER")
NATURAL = Scalar("NATURAL")
BOOL = Scalar("BOOL")
STRING = Scalar("STRING")
NUMERIC_RANK = {"NATURAL": 0, "INTEGER": 1, "REAL": 2}
BASE_NAMES: tuple[ScalarName, ...] = ("REAL", "INTEGER", "NATURAL", "BOOL", "STRING")


def qualified_base(name: str) -> TupleT | None:
    """The product type a qualified built-in term denotes, else ``None``.

    ``"REAL.REAL"`` -> ``(REAL, REAL)``; ``"NATURAL.INTEGER"`` -> ``(NATURAL,
    INTEGER)``.  The original RCL tool's grammar lets built-in type names be
    joined by ``.`` as a term, and its contracts use it as the set of pairs a
    tuple ranges over: ``(x, y) in REAL.REAL`` (docs/rcl-language.md).  A
    plain name or a single base type gives ``None``.
    """
    parts = name.split(".")
    if len(parts) < 2 or not all(p in BASE_NAMES for p in parts):
        return None
    return TupleT(tuple(Scalar(p) for p in parts))  # type: ignore[arg-type]


def is_numeric(t: Type) -> bool:
    return isinstance(t, Scalar) and t.name in NUMERIC_RANK


def numeric_join(a: Type, b: Type) -> Scalar | None:
    """The least numeric supertype of ``a`` and ``b`` (``None`` if either is not numeric)."""
    if not (isinstance(a, Scalar) and isinstance(b, Scalar) and is_numeric(a) and is_numeric(b)):
        return None
    return a if NUMERIC_RANK[a.name] >= NUMERIC_RANK[b.name] else b


def assignable(src: Type, dst: Type) -> bool:
    """``src`` may be used where ``dst`` is expected (numeric widening allowed)."""
    if src == dst:
        return True
    if is_numeric(src) and is_numeric(dst):
        assert isinstance(src, Scalar) and isinstance(dst, Scalar)
        return NUMERIC_RANK[src.name] <= NUMERIC_RANK[dst.name]
    if isinstance(src, SetT) and isinstance(dst, SetT) or isinstance(src, SeqT) and isinstance(dst, SeqT):
        # A collection of the empty type (the literals {} and <>) is empty,
        # so it belongs to every set/sequence type.
        return isinstance(src.elem, EmptyT) or assignable(src.elem, dst.elem)
    if isinstance(src, TupleT) and isinstance(dst, TupleT):
        return len(src.elems) == len(dst.elems) and all(map(assignable, src.elems, dst.elems))
    return False


def comparable(a: Type, b: Type) -> bool:
    """``a == b`` is well-typed."""
    return assignable(a, b) or assignable(b, a)


@dataclass(frozen=True)
class Env:
    """The resolved global environment of a set of RCL files (their contexts).

    ``types``        context type name -> resolved type;
    ``constants``    constant name -> (type, defining expression);
    ``enum_values``  enumeration value -> its enumeration type;
    ``ctors``        constructor name -> its constructor-set type;
    ``units``        constant name -> its unit of measure (declared, or the
                     unit of its value), for the constants that have one.
    """

    types: Mapping[str, Type] = field(default_factory=dict)
    constants: Mapping[str, tuple[Type, ast.Expr]] = field(default_factory=dict)
    enum_values: Mapping[str, EnumT] = field(default_factory=dict)
    ctors: Mapping[str, DataT] = field(default_factory=dict)
    units: Mapping[str, Unit] = field(default_factory=dict)


@dataclass(frozen=True)
class CheckedNode:
    """A node whose contract type-checked: its AST and resolved I/O types.
    ``units`` maps ``"in.x"``/``"out.y"`` to the declared unit of measure of
    the inputs and outputs that declare one (docs/rcl-language.md, "Units of
    measure")."""

    node: ast.Node
    inputs: Mapping[str, Type]
    outputs: Mapping[str, Type]
    units: Mapping[str, Unit] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.node.name

    def io_type(self, var: ast.Var) -> Type | None:
        """Type of ``in.x``/``out.x``/bare ``x`` (inputs first for bare names)."""
        if var.prefix == "in":
            return self.inputs.get(var.name)
        if var.prefix == "out":
            return self.outputs.get(var.name)
        return self.inputs.get(var.name) or self.outputs.get(var.name)

    def unit_of(self, prefix: str, name: str) -> Unit | None:
        """The declared unit of ``in.name``/``out.name`` (``prefix`` ``"in"``
        or ``"out"``), ``None`` when it declares none."""
        return self.units.get(f"{prefix}.{name}")


@dataclass(frozen=True)
class Checked:
    """The result of type checking: environment plus nodes by name (source order)."""

    env: Env
    nodes: Mapping[str, CheckedNode]
    specs: tuple[ast.Spec, ...] = ()
