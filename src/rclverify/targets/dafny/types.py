"""RCL types -> Dafny types, and Dafny-safe identifiers.

The mapping (paper lines 499-555 for the RCL types, lines 1667-1762 for the
Agent re-specified in Dafny):

=============================  ===============================================
RCL type                       Dafny
=============================  ===============================================
``REAL``                       ``real``
``INTEGER``                    ``int``
``NATURAL``                    ``nat``
``BOOL``                       ``bool``
enumeration ``{a, b}``         ``datatype Name = a | b``
constructor set                ``datatype Name = move(move_0: real, move_1:
``{move(REAL, REAL), ...}``    real) | ...``; destructor ``<ctor>_<k>`` (the
                               same accessor names as the Z3 encoding; Dafny
                               forbids two constructors sharing a destructor
                               name with different types)
function ``A x B --> R``       total arrow ``(A, B) -> R`` (a method
                               parameter, see :mod:`.stubgen`)
``set(T)`` / ``seq(T)``        ``set<T>`` / ``seq<T>``
tuple ``(A, B)``               ``(A, B)``
the empty type ``{}``          rejected (no Dafny value, no method parameter)
=============================  ===============================================

A context type name used for an input or output becomes a Dafny type
synonym (``type WayP = (real, real) -> nat``) so that the method signature
reads like the RCL ``inputs(...)`` clause.

Rejections are :class:`~rclverify.model.plan.errors.PlanError` (an
:class:`~rclverify.lang.errors.RclError`) located at the RCL construct.
"""
from __future__ import annotations

import re
from typing import Iterable

from rclverify.model.plan.errors import PlanError
from rclverify.lang import ast
from rclverify.lang.errors import error
from rclverify.lang.types import DataT, EmptyT, EnumT, FuncT, Scalar, SeqT, SetT, TupleT, Type

#: Dafny keywords and built-in type names an RCL name must not collide with.
RESERVED = frozenset("""
abstract allocated as assert assume bool break by calc case char class codatatype colemma
const constructor datatype decreases default else ensures exists expect export extends false
forall fresh function ghost if imap import in include inductive int invariant iset
iterator label lemma map match method modifies modify module multiset nameonly nat new
newtype null object old opened optional ORDINAL predicate print protected reads real
refines requires return returns reveal reveals seq set static string then this trait true
twostate type unchanged var while witness yield yields
""".split())

_SCALARS = {"REAL": "real", "INTEGER": "int", "NATURAL": "nat", "BOOL": "bool", "STRING": "string"}
_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_']*\Z")


def dafny_ident(name: str, taken: Iterable[str] = ()) -> str:
    """A Dafny identifier for the RCL name ``name``.

    RCL names (letters, digits, ``_`` and primes ``x'``) are valid Dafny
    identifiers except for Dafny keywords, names starting with ``_`` and
    names containing ``__`` (reserved by Dafny); those get a ``r_`` prefix
    or have their underscores merged.  A trailing ``_`` is appended until
    the result is not in ``taken``.  Returns a string.
    """
    out = re.sub(r"_{2,}", "_", name)
    if not _IDENT.match(out) or out in RESERVED:
        out = "r_" + out.lstrip("_")
    taken = set(taken)
    while out in taken:
        out += "_"
    return out


def _reject(loc: ast.Loc, what: str) -> PlanError:
    return PlanError([error(loc, f"{what} cannot be expressed in the Dafny contract stub", "E-dafny-type")])


def dafny_type(t: Type, loc: ast.Loc, what: str = "this type") -> str:
    """The Dafny type text of the resolved RCL type ``t``.

    ``loc``/``what`` locate and name the construct in a rejection, e.g.
    ``what="input sensors of type SensorsType"``.  Raises
    :class:`PlanError` for the empty type ``{}`` and for function types
    nested inside sets (Dafny sets need element types with equality).
    """
    if isinstance(t, Scalar):
        return _SCALARS[t.name]
    if isinstance(t, (EnumT, DataT)):
        return dafny_ident(t.name)
    if isinstance(t, EmptyT):
        raise _reject(loc, f"{what}: the empty type {{}} ({t.name}) has no values, so it")
    if isinstance(t, FuncT):
        args = [dafny_type(a, loc, what) for a in t.args]
        dom = args[0] if len(args) == 1 and not isinstance(t.args[0], TupleT) else "(" + ", ".join(args) + ")"
        return f"{dom} -> {dafny_type(t.result, loc, what)}"
    if isinstance(t, SetT):
        if isinstance(t.elem, FuncT):
            raise _reject(loc, f"{what}: a set of functions ({t})")
        return f"set<{dafny_type(t.elem, loc, what)}>"
    if isinstance(t, SeqT):
        return f"seq<{dafny_type(t.elem, loc, what)}>"
    if isinstance(t, TupleT):
        return "(" + ", ".join(dafny_type(e, loc, what) for e in t.elems) + ")"
    raise _reject(loc, f"{what} ({t!r})")  # pragma: no cover - every Type is handled above


def datatypes_in(t: Type) -> list[EnumT | DataT]:
    """Every enumeration / constructor set ``t`` mentions (dependencies first)."""
    out: list[EnumT | DataT] = []

    def walk(x: Type) -> None:
        if isinstance(x, EnumT):
            if x not in out:
                out.append(x)
        elif isinstance(x, DataT):
            if x in out:
                return
            for _, args in x.ctors:
                for a in args:
                    walk(a)
            out.append(x)
        elif isinstance(x, FuncT):
            for a in x.args:
                walk(a)
            walk(x.result)
        elif isinstance(x, (SetT, SeqT)):
            walk(x.elem)
        elif isinstance(x, TupleT):
            for e in x.elems:
                walk(e)

    walk(t)
    return out


def datatype_decl(t: EnumT | DataT, loc: ast.Loc) -> str:
    """``datatype RadStat = red | orange | green`` (one line, no trailing newline).

    Constructor arguments are named ``<ctor>_<k>`` (0-based), e.g.
    ``move(move_0: real, move_1: real)``.  Raises :class:`PlanError` when an
    argument type cannot be mapped.
    """
    name = dafny_ident(t.name)
    if isinstance(t, EnumT):
        alts = [dafny_ident(v) for v in t.values]
    else:
        alts = []
        for cname, args in t.ctors:
            c = dafny_ident(cname)
            if not args:
                alts.append(c)
                continue
            fields = ", ".join(f"{c}_{k}: {dafny_type(a, loc, f'argument {k + 1} of constructor {cname}')}"
                               for k, a in enumerate(args))
            alts.append(f"{c}({fields})")
    return f"datatype {name} = " + " | ".join(alts)
