"""A ROS 2 sqlite3 bag opened through ``rosbags`` without counting its messages.

Opening a sqlite3 bag, ``rosbags`` (0.11) asks the database for each
topic's message count (a ``LEFT JOIN`` of ``topics`` and ``messages``
grouped by topic, which makes SQLite build an index of the whole messages
table) and for the first and last stamps: about 0.7 CPU s for a bag of
two million messages, before its first message is read, and nothing that
reading the messages needs.  :func:`open_uncounted` opens the bag through
the same ``AnyReader`` (metadata file, type store, message definitions and
their hashes all checked by ``rosbags``), its sqlite3 storage read by
:class:`UncountedSqlite3`: the same checks of the database's tables and
schema version, the same connections and message definitions read by the
same queries, less the counts (each connection's ``msgcount`` is 0, the
storage's stamps and count are not read).

What the counting query would have found wrong is found by reading the
messages: it reads the table's pages that the message query reads too
(that query, ``rosbags``' own, goes through the stamp index to every row),
and a reader that meets an error asks :func:`counted_open_error` for the
error ``rosbags``' own open would have raised, so that a damaged bag
reports what it reported before (traces/bag_blocks.py).  Anything this
module does not know (another ``rosbags``, a storage other than one
sqlite3 file, an unknown schema) gives ``None``: the caller opens the bag
as before.
"""
from __future__ import annotations

from functools import cache
from importlib.metadata import version
from pathlib import Path
from typing import Any

from rclverify.traces.bag import open_bag
from rclverify.traces.events import TraceError

# topics' columns by schema version (the rosbag2 sqlite3 schema: 4 from Iron on, 2-3 Foxy to Humble, 1 before)
_TOPIC_COLUMNS = {4: "id, name, type, serialization_format, offered_qos_profiles, type_description_hash",
                  2: "id, name, type, serialization_format, offered_qos_profiles",
                  1: "id, name, type, serialization_format"}


@cache
def _storage_class() -> Any:
    """:class:`UncountedSqlite3`, made on first use (``rosbags`` loads only when a bag is read)."""
    from rosbags.interfaces import Connection, ConnectionExtRosbag2, MessageDefinition, MessageDefinitionFormat  # deferred: start-up (loads rosbags and more only when called)
    from rosbags.rosbag2.errors import ReaderError  # deferred: start-up (loads rosbags and more only when called)
    from rosbags.rosbag2.metadata import ReaderMetadata, parse_qos  # deferred: start-up (loads rosbags and more only when called)
    from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader  # deferred: start-up (loads rosbags and more only when called)

    formats = {"ros2msg": MessageDefinitionFormat.MSG, "ros2idl": MessageDefinitionFormat.IDL}

    class UncountedSqlite3(Sqlite3Reader):
        """``rosbags``' sqlite3 storage whose open reads the schema and the topics, not the counts
        (module docstring).  Raises ``ReaderError`` for what it does not read as ``rosbags`` would."""

        def _open(self) -> None:
            db: Any = self.dbconn  # (open: rosbags' ``open`` made it before calling this)
            tables = {n for (n,) in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
            if not {"messages", "topics"} <= tables:
                raise ReaderError("not a rosbag2 database")  # (the counted open words it)
            if "schema" in tables:
                row = db.execute("SELECT schema_version FROM schema").fetchone()
                schema = -1 if row is None else row[0]
            else:
                columns = {c[1] for c in db.execute("PRAGMA table_info(topics)")}
                schema = 2 if "offered_qos_profiles" in columns else 1
            if not isinstance(schema, int) or schema < 1:
                raise ReaderError(f"schema {schema!r}")
            kind = 4 if schema >= 4 else 2 if schema >= 2 else 1
            msgtypes: list[dict[str, str]] = []
            defs: dict[str, tuple[str, str]] = {}
            if kind == 4:
                for name, enc, text, digest in db.execute("SELECT topic_type, encoding, encoded_message_definition, "
                                                          "type_description_hash FROM message_definitions ORDER BY id"):
                    msgtypes.append({"name": name, "encoding": enc, "msgdef": text, "digest": digest})
                    defs.setdefault(name, (enc, text))  # the first of a name, as rosbags takes it

            def msgdef(name: str) -> Any:
                if name in defs:
                    return MessageDefinition(formats[defs[name][0]], defs[name][1])
                return MessageDefinition(MessageDefinitionFormat.NONE, "")

            conns = []
            for row in db.execute(f"SELECT {_TOPIC_COLUMNS[kind]} FROM topics ORDER BY id"):
                qos = parse_qos(row[4]) if kind >= 2 else []
                conns.append(Connection(row[0], row[1], row[2], msgdef(row[2]), row[5] if kind == 4 else "", 0,
                                        ConnectionExtRosbag2(row[3], qos), self))
            if len({c.id for c in conns}) != len(conns):
                raise ReaderError("topic ids repeat")  # (a join would repeat messages; the counted open reads it)
            self.schema, self.msgtypes, self.connections = schema, msgtypes, conns
            self.metadata = ReaderMetadata(0, 2**63 - 1, 0, 0, None, None, None, None)

    return UncountedSqlite3


def open_uncounted(path: Path, store: Any) -> Any | None:
    """An opened ``AnyReader`` of the bag at ``path`` (type store ``store``) whose sqlite3
    storage was opened by :class:`UncountedSqlite3`; ``None`` where that does not apply or the
    open fails (the caller opens the bag with :func:`~.bag.open_bag`, which words the error).
    Never raises."""
    try:
        from rosbags.highlevel import AnyReader  # deferred: start-up (loads rosbags and more only when called)
        from rosbags.rosbag2.reader import DirectoryReader  # deferred: start-up (loads rosbags and more only when called)
        from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader  # deferred: start-up (loads rosbags and more only when called)
        if not version("rosbags").startswith("0.11."):
            return None
        reader = AnyReader([path], default_typestore=store)
        if not reader.is2 or len(reader.readers) != 1:
            return None
        top: Any = reader.readers[0]
        if type(top.storage) is DirectoryReader:  # this reader's own table of storage classes
            top.storage.STORAGE_PLUGINS = {**DirectoryReader.STORAGE_PLUGINS, "sqlite3": _storage_class()}
        elif type(top.storage) is Sqlite3Reader:
            top.storage = _storage_class()(top.storage.path)
        else:
            return None
        reader.open()
    except Exception:  # noqa: BLE001 - the counted open says what is wrong
        return None
    return reader


def counted_open_error(path: Path, store: Any) -> TraceError | None:
    """The error :func:`~.bag.open_bag` gives for the bag at ``path``, ``None`` when it opens it."""
    try:
        reader = open_bag(path, store)
    except TraceError as exc:
        return exc
    try:
        reader.close()
    except Exception:  # noqa: BLE001 - closing a reader only opened to ask
        pass
    return None


__all__ = ["open_uncounted", "counted_open_error"]
