"""The base of every backend's evidence payload (``<backend>/payload.py``): one msgspec configuration (frozen, unknown
keys refused, defaults left out of the JSON, the ``backend`` tag field) and
the one way a payload becomes an evidence record's ``details`` (:meth:`EvidencePayload.details`), or a
producer's JSON object is checked against it (:meth:`EvidencePayload.checked`)."""
from __future__ import annotations

from typing import Mapping

import msgspec


class EvidencePayload(msgspec.Struct, frozen=True, forbid_unknown_fields=True, omit_defaults=True,
                      tag_field="backend"):
    """A backend's evidence payload; a subclass names its backend as its ``tag``."""

    def details(self) -> dict[str, object]:
        """The payload as an evidence record's ``details``: its fields not at their default, without the
        ``backend`` tag (the record names its backend itself)."""
        out: dict[str, object] = msgspec.to_builtins(self)
        del out["backend"]
        return out

    @classmethod
    def checked(cls, details: Mapping[str, object]) -> Mapping[str, object]:
        """``details`` as given, once it decodes as this payload (the producer's JSON written unchanged).
        Raises :class:`msgspec.ValidationError` for a key no field declares or a value of another type."""
        msgspec.convert({**details, "backend": cls.__struct_config__.tag}, cls)
        return details


__all__ = ["EvidencePayload"]
