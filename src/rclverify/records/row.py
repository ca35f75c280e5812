"""The base of every record defined once (docs/decisions.md, "One
definition per record"): a frozen msgspec Struct that refuses a key it does
not declare, written as its JSON object with every field and read back from
one.

A record's class states its fields, each with its description
(:data:`DOC`), from which its part of docs/assurance.schema.json is
generated (:mod:`.schema_gen`); producers build the class, and readers
decode the JSON into it (:meth:`Row.of`, :func:`decode_rows`) and read
attributes mypy checks.  A reader's view of a JSON object another part
writes (the keys it reads, not the record) derives from :class:`View`.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping, TypeVar

import msgspec

#: a field's description, as the generated JSON Schema shows it
DOC = msgspec.Meta

R = TypeVar("R", bound="Row")
V = TypeVar("V", bound="View")


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


class View(msgspec.Struct, frozen=True):
    """A reader's view of a JSON object: its subclasses declare the keys read, each with its default; a key
    it does not declare is ignored, one written ``null`` is read at its default (:meth:`View.of`)."""

    @classmethod
    def of(cls: type[V], data: Mapping[str, Any]) -> V:
        """``data`` decoded, a key written ``null`` at its default; raises :class:`msgspec.ValidationError`
        for a declared key whose value has another type."""
        return msgspec.convert({k: v for k, v in data.items() if v is not None}, cls)


def decode_rows(cls: type[R], rows: Iterable[R | Mapping[str, Any]]) -> list[R]:
    """``rows`` (JSON objects, as built or as read back from
    ``reports/assurance.json``, or records of ``cls`` already decoded)
    decoded into ``cls``, in order (raises as :meth:`Row.of`)."""
    return [cls.of(r) for r in rows]


__all__ = ["DOC", "Row", "View", "decode_rows"]
