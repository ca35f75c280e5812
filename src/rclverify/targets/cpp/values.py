"""Function tables and constructor terms as C++ values of the generated check header (docs/generate.md).

A function-typed input or output ``A x B --> C`` whose arguments and result are ``REAL``,
``INTEGER``, ``NATURAL``, ``BOOL`` or an enumeration is ``rclverify_rt::Table<C, A, B>``: the
finite table (``rows``, key tuple -> result) and the default (``otherwise``), as
:class:`rclverify.semantics.values.FiniteFunction` holds it; applying it looks the key up by ``==`` (a
``REAL`` argument a double), as the Python reading's dictionary does.  A constructor set whose
constructors take such arguments is a struct ``Term<Name>`` (the constructor's index ``ctor`` and
one field per argument, ``<ctor>_<k>``) with ``==`` as :class:`rclverify.semantics.values.Term`'s (same
constructor, equal arguments).  ``INTEGER`` and ``NATURAL`` inside them are ``std::int64_t``.

Text for the driver (``contract_driver.hpp``, one word per value): a table
``1.5,2->3;0.5,1->0;*->0`` (rows ``args->result``, the default ``*->result``), a term
``move(1.5,2)``; numbers as C++ reads them, booleans ``1``/``0``, enumeration values by name.
"""
from __future__ import annotations

from typing import Any

from rclverify.lang.types import DataT, EnumT, FuncT, Scalar, Type
from rclverify.targets.cpp.common import CPP_SCALARS, camel_words
from rclverify.targets.names import ctor_field, snake
from rclverify.targets.shapes import TermCtor, TermFields

#: RCL scalar -> C++ type inside a table or a term: a field's, but INTEGER and NATURAL both std::int64_t (module docstring)
_INNER = {**CPP_SCALARS, "NATURAL": "std::int64_t"}


def inner_type(t: Type) -> str | None:
    """The C++ type of a table's argument or result, or a term's argument; ``None``: not held."""
    if isinstance(t, Scalar):
        return _INNER.get(t.name)
    if isinstance(t, EnumT):
        return "std::uint8_t"
    return None


def kind_of(t: Type) -> str | None:
    """The translator's kind of a value of type ``t`` (``double``, ``int``, ``bool``, ``enum:<Name>``)."""
    if isinstance(t, Scalar):
        return {"REAL": "double", "INTEGER": "int", "NATURAL": "int", "BOOL": "bool"}.get(t.name)
    if isinstance(t, EnumT):
        return f"enum:{t.name}"
    if isinstance(t, DataT) and term_struct(t) is not None:
        return f"term:{t.name}"
    return None


def table_type(t: FuncT) -> str | None:
    """``rclverify_rt::Table<R, A...>`` of a function type, ``None`` when not held."""
    parts = [inner_type(x) for x in (t.result, *t.args)]
    if any(p is None for p in parts):
        return None
    return f"rclverify_rt::Table<{', '.join(parts)}>"  # type: ignore[arg-type]


def term_struct(t: DataT) -> str | None:
    """``Term<Name>`` of a constructor set, ``None`` when an argument is not held."""
    if any(inner_type(a) is None for _, args in t.ctors for a in args):
        return None
    return "Term" + camel_words(t.name)


def term_fields(t: DataT) -> TermFields:
    """The template context of ``Term<Name>``: per constructor its index, name and arguments
    (field, C++ type)."""
    ctors: list[TermCtor] = []
    for k, (name, args) in enumerate(t.ctors):
        ctors.append({"index": k, "name": name, "fn": snake(name),
                      "args": [{"field": ctor_field(name, j), "cpp": inner_type(a)} for j, a in enumerate(args)]})
    return {"name": t.name, "struct": term_struct(t), "ctors": ctors}


def parse_code(t: Type, var: str) -> str:
    """A C++ expression reading a value of type ``t`` (scalar, enumeration, term) from the
    ``std::string`` named ``var``."""
    if isinstance(t, EnumT):
        return f"parse_{snake(t.name)}({var})"
    if isinstance(t, DataT):
        return f"parse_{snake(t.name)}({var})"
    cpp = inner_type(t)
    if cpp == "bool":
        return f'({var} == "1" || {var} == "TRUE" || {var} == "true")'
    if cpp == "double":
        return f"std::strtod({var}.c_str(), nullptr)"
    return f"static_cast<std::int64_t>(std::strtoll({var}.c_str(), nullptr, 10))"


def table_parse(t: FuncT, target: str) -> str:
    """C++ statements filling table ``target`` from the driver's text ``v``."""
    args = ", ".join(parse_code(a, f"cand_args[{k}]") for k, a in enumerate(t.args))
    return (f"{target} = {{}};\n"
            f"        rclverify_rt::read_table(v, {len(t.args)}, [&](const std::vector<std::string> & cand_args, "
            f"const std::string & cand_res) {{\n"
            f"          if (cand_args.empty()) {{\n            {target}.otherwise = {parse_code(t.result, 'cand_res')};\n"
            f"          }} else {{\n            {target}.set(std::make_tuple({args}), {parse_code(t.result, 'cand_res')});\n"
            f"          }}\n        }});")


def data_types(checked: Any) -> list[DataT]:
    """The constructor sets of the context a ``Term<Name>`` holds, by name."""
    seen = {t.name: t for t in checked.env.ctors.values() if isinstance(t, DataT)}
    return [seen[n] for n in sorted(seen) if term_struct(seen[n]) is not None]


__all__ = ["data_types", "inner_type", "kind_of", "parse_code", "table_parse", "table_type", "term_fields",
           "term_struct"]
