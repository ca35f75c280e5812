"""RCL types to ROS 2 interface field types (docs/generate.md, "Type mapping").

Scalars: ``REAL`` float64, ``INTEGER`` int64, ``NATURAL`` uint64, ``BOOL``
bool, ``STRING`` string.  An enumeration is a ``uint8`` with one named
constant per value in the message that holds the field.  A constructor set,
a tuple and a function table become nested messages of the interface
package; sets and sequences become unbounded arrays (an array of arrays is
wrapped in a nested message, which ROS 2 requires).  The empty type ``{}``
is ``std_msgs/Empty``.  Field and constant names follow the ROS 2 interface
rules (design article "Interface definition", rosidl): fields lower
snake_case, constants upper case, message names CamelCase.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.errors import RclError, error
from rclverify.targets import names
from rclverify.lang.types import DataT, EmptyT, EnumT, FuncT, Scalar, SeqT, SetT, TupleT, Type

#: RCL scalar name -> ROS 2 primitive type
SCALARS: dict[str, str] = {"REAL": "float64", "INTEGER": "int64", "NATURAL": "uint64", "BOOL": "bool",
                           "STRING": "string"}

#: Interface packages every ROS 2 distribution ships (their types are used, never generated)
STANDARD_PACKAGES = names.STANDARD_PACKAGES


#: the name rules live in :mod:`.names` (one module for every generated name)
snake = names.snake
camel = names.msg_name


@dataclass
class Field:
    """One line ``<ros_type> <name>  # comment`` of an interface definition."""

    ros_type: str
    name: str
    comment: str = ""


@dataclass
class Constant:
    """``uint8 NAME=value  # comment``."""

    ros_type: str
    name: str
    value: int
    comment: str = ""


@dataclass
class Section:
    """The fields and constants of a message, or one part of a service or action."""

    fields: list[Field] = field(default_factory=list)
    constants: list[Constant] = field(default_factory=list)

    def add_field(self, f: Field) -> None:
        """Add ``f`` unless a field of that name is there (same type: shared; another type: suffixed)."""
        for old in self.fields:
            if old.name == f.name:
                if old.ros_type == f.ros_type:  # shared: keep what each user's comment adds
                    extra = [c for c in f.comment.split("; ") if c and c not in old.comment.split("; ")]
                    old.comment = "; ".join([c for c in old.comment.split("; ") if c] + extra)
                    return
                f = Field(f.ros_type, f"{f.name}_{len(self.fields)}", f.comment)
        self.fields.append(f)

    def add_constant(self, c: Constant) -> None:
        """Add ``c`` unless a constant of that name is there."""
        if all(old.name != c.name for old in self.constants):
            self.constants.append(c)


class TypeMapper:
    """Maps resolved RCL types to ROS 2 field types of interface package ``pkg``.

    ``nested`` collects the nested messages made on the way (name -> section),
    to be written as ``msg/<Name>.msg`` of ``pkg``.
    """

    def __init__(self, pkg: str) -> None:
        self.pkg = pkg
        self.nested: dict[str, Section] = {}
        #: nested message -> (the RCL type it holds, who made it: ``Planner's in.goal``)
        self.made: dict[str, tuple[Type, str]] = {}
        #: where the field being mapped is declared, and whose it is (set by the caller)
        self.loc: ast.Loc = ast.Loc("", 0, 0)
        self.who = ""

    def field(self, section: Section, name: str, t: Type, texpr: typeexpr.TypeExpr | None = None,
              comment: str = "") -> None:
        """Add the field for RCL variable ``name`` of type ``t`` (declared as ``texpr``) to ``section``."""
        hint = texpr.name if isinstance(texpr, typeexpr.TName) else camel(name)
        ros_type = self.ros_type(t, hint, section)
        note = f"RCL {texpr.name} = {t}" if isinstance(texpr, typeexpr.TName) else f"RCL {t}"
        section.add_field(Field(ros_type, names.field_name(name), "; ".join(x for x in (comment, note) if x)))

    def ros_type(self, t: Type, hint: str, holder: Section) -> str:
        """The ROS 2 type of a field of RCL type ``t``; enumeration constants go to ``holder``.

        ``hint`` names the nested message a structured type needs.  Raises ``ValueError`` for a
        type no interface field can hold (none exists among RCL's resolved types today)."""
        if isinstance(t, Scalar):
            return SCALARS[t.name]
        if isinstance(t, EnumT):
            for i, v in enumerate(t.values):
                holder.add_constant(Constant("uint8", names.constant_name(t.name, v), i, f"{t.name} value {v}"))
            return "uint8"
        if isinstance(t, EmptyT):
            return "std_msgs/Empty"
        if isinstance(t, (SetT, SeqT)):
            inner = self.ros_type(t.elem, hint + "Item", holder)
            if inner.endswith("[]"):  # ROS 2 has no array of arrays: wrap the inner array
                inner = self._nested(camel(hint) + "Item", lambda s: s.add_field(Field(inner, "elems")), t)
            return inner + "[]"
        if isinstance(t, TupleT):
            def fill(s: Section) -> None:
                for k, e in enumerate(t.elems):
                    s.add_field(Field(self.ros_type(e, f"{hint}E{k}", s), f"e{k}", f"RCL {e}"))
            return self._nested(camel(hint), fill, t)
        if isinstance(t, DataT):
            def fill_data(s: Section) -> None:
                s.add_field(Field("uint8", "ctor", "which constructor"))
                for i, (cname, args) in enumerate(t.ctors):
                    s.add_constant(Constant("uint8", names.constant_name(cname), i, f"constructor {cname}"))
                    for k, a in enumerate(args):
                        s.add_field(Field(self.ros_type(a, f"{t.name}{camel(cname)}{k}", s),
                                          names.ctor_field(cname, k), f"argument {k + 1} of {cname}, RCL {a}"))
            return self._nested(camel(t.name), fill_data, t)
        if isinstance(t, FuncT):
            def fill_fn(s: Section) -> None:
                for k, a in enumerate(t.args):
                    s.add_field(Field(self.ros_type(a, f"{hint}Arg{k}", s), f"arg{k}", f"RCL {a}"))
                s.add_field(Field(self.ros_type(t.result, f"{hint}Value", s), "value", f"RCL {t.result}"))
            return self._nested(camel(hint) + "Entry", fill_fn, t) + "[]"
        raise ValueError(f"no ROS 2 field type for RCL type {t}")

    def _nested(self, name: str, fill, t: Type) -> str:  # type: ignore[no-untyped-def]
        """The nested message ``name`` holding RCL type ``t``, made once; another type under the
        same name (``Pair`` and ``pair'``'s tuple, say) is refused at :attr:`loc`."""
        if name not in self.nested:
            s = Section()
            self.nested[name] = s  # registered first: a recursive reference ends here
            self.made[name] = (t, self.who)
            fill(s)
        elif self.made[name][0] != t:
            raise RclError([error(self.loc, f"{self.pkg}/msg/{name} would hold RCL type {t} for {self.who} and "
                                            f"{self.made[name][0]} for {self.made[name][1]}: two types, one message "
                                            f"name (rename one of them)", "generate-names")])
        return f"{self.pkg}/{name}"
