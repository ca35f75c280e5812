"""The base of every record defined once (docs/decisions.md, "One
definition per record"): a frozen msgspec Struct that refuses a key it does
not declare, written as its JSON object with every field and read back from
one.

A record's class states its fields, each with its description
(:data:`DOC`), from which its part of docs/assurance.schema.json is
generated (:mod:`.schema_gen`); producers build the class, and readers
decode the JSON into it (:meth:`Row.of`, :func:`decode_rows`) and read
attributes mypy checks.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping, TypeVar

import msgspec

#: a field's description, as the generated JSON Schema shows it
DOC = msgspec.Meta

R = TypeVar("R", bound="Row")


class Row(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """A record defined once: its subclasses declare the fields."""

    def to_json(self) -> dict[str, Any]:
        """The record as its JSON object (every field, in the order declared)."""
        out: dict[str, Any] = msgspec.to_builtins(self)
        return out

    @classmethod
    def of(cls: type[R], row: R | Mapping[str, Any]) -> R:
        """``row`` (a record of this class or its JSON object) as a record.
        Raises :class:`msgspec.ValidationError` for a key no field declares,
        a missing field or a value of another type, :class:`TypeError` for
        a record of another class."""
        if isinstance(row, cls):
            return row
        if not isinstance(row, Mapping):
            raise TypeError(f"a {type(row).__name__} is not a {cls.__name__} nor its JSON object")
        return msgspec.convert(dict(row), cls)


def decode_rows(cls: type[R], rows: Iterable[R | Mapping[str, Any]]) -> list[R]:
    """``rows`` (JSON objects, as built or as read back from
    ``reports/assurance.json``, or records of ``cls`` already decoded)
    decoded into ``cls``, in order (raises as :meth:`Row.of`)."""
    return [cls.of(r) for r in rows]


__all__ = ["DOC", "Row", "decode_rows"]
