"""The backends' evidence payloads as one union tagged by ``backend``, decoded once.

An evidence record's ``details`` is its backend's JSON object.  The
backends whose payload is a :class:`msgspec.Struct` declare it beside
themselves (``backends/hoare/payload.py`` :class:`HoarePayload`,
``backends/property_tests/payload.py`` :class:`PropertyTestsPayload`,
``backends/monitors/payload.py`` :class:`MonitorsPayload`), each
tagged by its backend's name; :func:`payload_of` decodes a record's
``details`` into the one its ``backend`` names (msgspec's tagged union,
the tag taken from the record), so a reader decodes it once and reads
attributes mypy checks.  The other backends' payloads are still read as
JSON objects.
"""
from __future__ import annotations

from typing import Any, Mapping, Union

import msgspec

from rclverify.backends.hoare.payload import HoarePayload
from rclverify.backends.monitors.payload import MonitorsPayload
from rclverify.backends.property_tests.payload import PropertyTestsPayload

#: The payloads declared as Structs, told apart by their ``backend`` tag.
Payload = Union[HoarePayload, PropertyTestsPayload, MonitorsPayload]
#: The backends whose payload is a Struct.
TYPED: frozenset[str] = frozenset(c.__struct_config__.tag for c in (HoarePayload, PropertyTestsPayload, MonitorsPayload))  # type: ignore[misc]


def payload_of(backend: str, details: Mapping[str, Any]) -> Payload | None:
    """The payload ``details`` of an evidence record of ``backend`` decoded into its Struct; ``None`` for a
    backend whose payload is no Struct yet.  Raises :class:`msgspec.ValidationError` (a ``ValueError``)
    for a key the backend's payload does not declare or a value of another type."""
    if backend not in TYPED:
        return None
    decoded: Payload = msgspec.convert({**details, "backend": backend}, Payload)
    return decoded


__all__ = ["Payload", "TYPED", "payload_of"]
