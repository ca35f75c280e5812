"""The base of every backend's evidence payload (``hoare/payload.py``,
``property_tests/payload.py``, ``monitors/payload.py``): one msgspec configuration (frozen, unknown
keys refused, defaults left out of the JSON, the ``backend`` tag field) and
the one way a payload becomes an evidence record's ``details``."""
from __future__ import annotations

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


__all__ = ["EvidencePayload"]
