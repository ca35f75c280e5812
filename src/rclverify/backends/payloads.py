"""The backends' evidence payloads as one union tagged by ``backend``, decoded once.

An evidence record's ``details`` is its backend's JSON object.  Each
backend declares its payload as a :class:`msgspec.Struct` beside itself
(``backends/hoare/payload.py`` :class:`HoarePayload`,
``backends/property_tests/payload.py`` :class:`PropertyTestsPayload`,
``backends/monitors/payload.py`` :class:`MonitorsPayload`,
``backends/experiment/payload.py`` :class:`ExperimentPayload`,
``backends/review/payload.py`` :class:`ReviewPayload`,
``backends/dafny/payload.py`` :class:`DafnyPayload`, and the ``ajpf``
backend's, SPIN's or AJPF's, ``backends/model_checking/payload.py``
:class:`AjpfPayload`), each tagged by its backend's name; :func:`payload_of`
decodes a record's ``details`` into the one its ``backend`` names (msgspec's
tagged union, the tag taken from the record), so a reader decodes it once
and reads attributes mypy checks.  A key a payload does not declare is
refused (docs/records.md, "Evidence payloads").
"""
from __future__ import annotations

from typing import Any, Mapping, Union

import msgspec

from rclverify.backends.dafny.payload import DafnyPayload
from rclverify.backends.experiment.payload import ExperimentPayload
from rclverify.backends.hoare.payload import HoarePayload
from rclverify.backends.model_checking.payload import AjpfPayload
from rclverify.backends.monitors.payload import MonitorsPayload
from rclverify.backends.property_tests.payload import PropertyTestsPayload
from rclverify.backends.review.payload import ReviewPayload

#: The payloads declared as Structs, told apart by their ``backend`` tag.
Payload = Union[HoarePayload, PropertyTestsPayload, MonitorsPayload, ExperimentPayload, ReviewPayload, DafnyPayload, AjpfPayload]
#: The backends whose payload is a Struct.
TYPED: frozenset[str] = frozenset(c.__struct_config__.tag for c in (  # type: ignore[misc]
    HoarePayload, PropertyTestsPayload, MonitorsPayload, ExperimentPayload, ReviewPayload, DafnyPayload, AjpfPayload))


def payload_of(backend: str, details: Mapping[str, Any]) -> Payload | None:
    """The payload ``details`` of an evidence record of ``backend`` decoded into its Struct; ``None`` for a
    backend that declares none (not one of rclverify's).  Raises :class:`msgspec.ValidationError` (a ``ValueError``)
    for a key the backend's payload does not declare or a value of another type."""
    if backend not in TYPED:
        return None
    decoded: Payload = msgspec.convert({**details, "backend": backend}, Payload)
    return decoded


__all__ = ["Payload", "TYPED", "payload_of"]
