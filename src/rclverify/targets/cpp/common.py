"""Names the C++ translation modules share (:mod:`.expr`, :mod:`.quant`): the error a
formula outside the translated fragment raises, the C++ constant of an enumeration value and the
C++ type of an RCL scalar."""
from __future__ import annotations

from rclverify.lang.types import EnumT
from rclverify.targets.typemap import snake


#: RCL scalar -> C++ type of a struct field (a table's or term's NATURAL is signed: :mod:`.cpp_values`)
CPP_SCALARS = {"REAL": "double", "INTEGER": "std::int64_t", "NATURAL": "std::uint64_t", "BOOL": "bool"}


class Untranslatable(ValueError):
    """A formula (part) outside the translated fragment; the message says which construct."""


def enum_const(t: EnumT, value: str) -> str:
    """The C++ constant of an enumeration value: ``kRadStatRed``."""
    return "k" + camel_words(t.name) + camel_words(value)


def camel_words(s: str) -> str:
    """``rad_stat``, ``RadStat`` -> ``RadStat`` (by rosidl's snake_case words)."""
    return "".join(p[:1].upper() + p[1:] for p in snake(s).split("_"))


__all__ = ["CPP_SCALARS", "Untranslatable", "camel_words", "enum_const"]
