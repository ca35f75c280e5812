"""The codec of doit's task state in its SQLite store: doit's JSON, decoded by msgspec.

doit keeps each task's state (its file dependencies' signatures, its
``uptodate`` values) as a JSON text per task in ``.doit.sqlite``
(``doit.dependency.SqliteDB``) and decodes every task's text in every run,
a no-op included: 4,289 texts, 6.7 MB, at 1000 nodes.  :class:`StateCodec`
is doit's own ``JSONCodec`` with its ``encode`` as it is, so the store
stays doit's and a workspace verified before keeps its state; it reads
with msgspec's JSON decoder (26-42 ms against 64-78 ms for those texts)
and, for a text msgspec refuses (``NaN``, ``Infinity``, a
number beyond a double, an unpaired surrogate: what Python's ``json``
accepts and RFC 8259 does not), with the standard library's, so every text
decodes to the value doit's codec gives (tests/app/test_doit_codec.py).
:func:`rclverify.app.tasks.doit_config` hands it to doit as ``codec_cls``.
"""
from __future__ import annotations

from typing import Any

import msgspec
from doit.dependency import JSONCodec


class StateCodec(JSONCodec):  # type: ignore[misc]
    """doit's ``JSONCodec``: its ``encode`` as it is, :meth:`decode` by msgspec first."""

    def __init__(self) -> None:
        super().__init__()
        self._fast = msgspec.json.Decoder()

    def decode(self, data: str) -> Any:
        """The value of the JSON text ``data``, as ``json.JSONDecoder().decode`` gives it.
        Raises ``json.JSONDecodeError`` for a text that is not JSON, as doit's codec does."""
        try:
            return self._fast.decode(data)
        except (msgspec.DecodeError, msgspec.ValidationError):
            return self.decoder.decode(data)
