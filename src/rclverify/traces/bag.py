"""ROS 1 ``.bag`` and ROS 2 (sqlite3, MCAP) bags through ``rosbags``.

A ROS 2 bag from Iron on carries each topic's message definition, and
``rosbags`` decodes with it (and checks its type hash), whatever the
workspace defines.  For a bag without definitions (rosbag2 before Iron),
standard message types come from ``rosbags``' type store (ROS 2 Humble's
definitions, which cover ROS 1's common types too); the workspace's own
``.msg`` files (``<dir>/<pkg>/msg/<Type>.msg``) are registered on top, and a
message they do not read is an error that says how to give the recording
robot's definition.
"""
from __future__ import annotations

import copy
from enum import IntEnum
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Sequence

from rclverify.traces.bag_late import of_reader
from rclverify.traces.events import Event, TraceError, header_stamp

if TYPE_CHECKING:  # rosbags is the optional ``ros`` extra: its types only for the checker
    from rosbags.interfaces.typing import Typesdict


def _definitions(msg_dirs: Sequence[Path]) -> tuple[tuple[str, str, Path], ...]:
    """``(type name, text, file)`` of every ``<pkg>/msg/<Type>.msg`` under ``msg_dirs``, in the
    order :func:`custom_types` registers them.  Raises :class:`TraceError` (naming the file) for
    a file that is not a regular one (a FIFO or device would block the read: traces/guard.py)."""
    found: list[tuple[str, str, Path]] = []
    for d in msg_dirs:
        for f in sorted(d.rglob("*.msg")):
            if not f.is_file():
                raise TraceError(f"{f}:1: error: not a regular file (a FIFO, device or socket): not read")
            found.append((f"{f.parent.parent.name}/msg/{f.stem}", f.read_text(encoding="utf-8"), f))
    return tuple(found)


def custom_types(msg_dirs: Sequence[Path]) -> Typesdict:
    """Type definitions parsed from every ``<pkg>/msg/<Type>.msg`` under ``msg_dirs``.

    Raises :class:`TraceError` (naming the file) for a definition rosbags rejects,
    :class:`~rclverify.core.extras.MissingExtra` when there are definitions
    and rosbags, the ``ros`` extra, is not installed.
    """
    return _parsed(_definitions(msg_dirs))


def _parsed(definitions: tuple[tuple[str, str, Path], ...]) -> Typesdict:
    if not definitions:
        return {}
    from rclverify.core.extras import require  # deferred: start-up (loads rosbags and more only when called)
    get_types_from_msg = require("rosbags.typesys", "reading the workspace's .msg definitions").get_types_from_msg
    types: Typesdict = {}
    for name, text, f in definitions:
        try:
            types.update(get_types_from_msg(text, name))
        except Exception as exc:  # rosbags raises its own parse errors
            raise TraceError(f"{f}:1: error: bad message definition: {exc}") from None
    return types


#: The type stores this process made, by the workspace's message definitions (name and text of each
#: ``.msg``).  Making one registers every standard type again when the workspace redefines one
#: (about 60 ms), and a pipeline run opens its bags once per monitored node; each caller gets its
#: own copy (:func:`_copy`), so what one caller registers or removes stays in its copy.
_STORES: dict[tuple[tuple[str, str], ...], Any] = {}
_STORES_KEPT = 8


def _copy(store: Any) -> Any:
    """A ``rosbags`` type store with ``store``'s definitions and generated classes in dicts of its own
    and an empty (de)serialiser cache: registering or removing a type in it changes neither
    ``store`` nor another copy, and its cache is made from its own definitions."""
    out = copy.copy(store)
    out.fielddefs, out.types, out.cache = dict(store.fielddefs), dict(store.types), {}
    return out


def typestore(msg_dirs: Sequence[Path]) -> Any:
    """A ``rosbags`` type store with the standard types plus the workspace's.

    A workspace ``.msg`` of a standard type that differs from rosbags' (ROS 2
    Humble's) definition replaces it: the robot's distribution may have
    changed it (``sensor_msgs/Range`` gained ``variance`` after Humble), and
    rosbags refuses a second definition of a registered name
    (``TypesysError``), which made every bag of such a workspace unreadable.
    Equal definitions are registered once per process (:data:`_STORES`); each call
    returns a copy of its own.  Raises :class:`TraceError` as :func:`custom_types` does.
    """
    definitions = _definitions(msg_dirs)
    key = tuple((name, text) for name, text, _ in definitions)
    if (store := _STORES.get(key)) is not None:
        return _copy(store)
    from rosbags.typesys import Stores, get_typestore  # deferred: start-up (loads rosbags and more only when called)
    store = get_typestore(Stores.ROS2_HUMBLE)
    own = _parsed(definitions)
    if any(store.fielddefs.get(name, fields) != fields for name, fields in own.items()):
        standard = {name: fields for name, fields in store.fielddefs.items() if name not in own}
        store = get_typestore(Stores.EMPTY)
        store.register(standard)
    store.register(own)
    if len(_STORES) >= _STORES_KEPT:
        _STORES.pop(next(iter(_STORES)))
    _STORES[key] = store
    return _copy(store)


def field_definitions(msg_dirs: Sequence[Path], names: Iterable[str]) -> dict[str, Any]:
    """``{type name: (constants, fields)}`` (rosbags' ``fielddefs`` form) of the message types
    ``names`` (``pkg/msg/Type``) and of every type their fields name, nested or in arrays, as
    :func:`typestore` defines them; a name it does not know is left out.

    In a process that keeps its start-up (:mod:`rclverify.core.cache.startup`, the
    ``message-definitions`` part) the result is kept under the names and the name and text of
    every ``.msg`` under ``msg_dirs``: the standard store alone costs about 0.2 CPU s to load
    (rosbags builds it from each older distribution's), which a run on a log would pay on
    every start.  Raises :class:`TraceError` as :func:`custom_types` does (a definition rosbags
    refuses is never kept)."""
    wanted = sorted(set(names))
    definitions = _definitions(msg_dirs)
    from rclverify.core.cache.startup import active  # deferred: start-up (loads rclverify.core.cache.store only when called)
    kept = active()
    contents = ("\0".join(wanted), *(f"{name}\0{text}" for name, text, _ in definitions))
    got = kept.get("message-definitions", *contents) if kept is not None else None
    if isinstance(got, dict):
        return got
    defs = typestore(msg_dirs).fielddefs
    out: dict[str, Any] = {}
    todo = [n for n in wanted if n in defs]
    while todo:
        name = todo.pop()
        if name in out:
            continue
        out[name] = defs[name]
        todo += [n for _, kind in defs[name][1] for n in _named(kind) if n in defs and n not in out]
    if kept is not None:
        kept.put("message-definitions", _kept_kinds(out), *contents)
    return out


class FieldKind(IntEnum):
    """rosbags' ``Nodetype`` (the kind of a parsed message field), its names and values, as the start-up
    cache keeps the definitions: a kept entry read back then does not load ``rosbags.interfaces``
    (2 ms of the monitor command's start-up).  Readers of a kind compare its ``name``."""

    BASE = 1
    NAME = 2
    ARRAY = 3
    SEQUENCE = 4


def _kept_kinds(value: Any) -> Any:
    """``value`` (rosbags' ``fielddefs`` form: mappings, lists and tuples of names, kinds and values) with
    each ``Nodetype`` member the :class:`FieldKind` member of its name."""
    if isinstance(value, IntEnum):
        return FieldKind[value.name] if type(value).__name__ == "Nodetype" else value
    if isinstance(value, dict):
        return {k: _kept_kinds(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(map(_kept_kinds, value))
    return value


def _named(kind: Any) -> Iterator[str]:
    """The message type names a rosbags field kind refers to (a nested message, an array's items)."""
    if kind[0].name == "NAME":
        yield kind[1]
    elif kind[0].name in ("ARRAY", "SEQUENCE"):
        yield from _named(kind[1][0])


def flatten(msg: Any) -> dict[str, object]:
    """A deserialised message as a dict of its fields (nested messages as dicts,
    arrays as lists, an array of messages as a list of dicts), so a mapping's
    field path (``pose.pose.position.x``, ``poses[0].position.x``) reads a
    bag as it reads a log."""
    out: dict[str, object] = {}
    for name in getattr(msg, "__dataclass_fields__", {}):
        if name == "__msgtype__":
            continue
        out[name] = _value(getattr(msg, name))
    return out


def _value(v: Any) -> Any:
    if hasattr(v, "__dataclass_fields__"):
        return flatten(v)
    if hasattr(v, "tolist"):
        return v.tolist()
    if isinstance(v, (list, tuple)):
        return [_value(x) for x in v]
    return v


def read_bag(path: Path, msg_dirs: Sequence[Path] = ()) -> Iterator[Event]:
    """Stream the events of a bag in time order.

    Raises :class:`TraceError` ``path: message N: error: ...`` when the bag
    cannot be opened or a message cannot be read (a truncated file); the
    events before it have already been yielded.
    """
    reader = open_bag(path, typestore(msg_dirs))
    index = 0
    try:
        messages = reader.messages()
        while True:
            try:
                item = next(messages)
            except StopIteration:
                break
            except Exception as exc:
                raise TraceError(f"{path}: message {index}: error: cannot read the bag "
                                 f"(truncated?): {exc}") from None
            conn, stamp, raw = item
            yield bag_event(reader, path, index, conn, stamp, raw)
            index += 1
    finally:
        try:
            reader.close()
        except Exception:
            pass


def open_bag(path: Path, store: Any) -> Any:
    """An opened ``rosbags`` reader of the bag at ``path``; raises :class:`TraceError` as :func:`read_bag`."""
    from rosbags.highlevel import AnyReader  # deferred: start-up (loads rosbags and more only when called)
    try:
        reader = AnyReader([path], default_typestore=store)
        reader.open()
    except Exception as exc:
        raise TraceError(f"{path}: message 0: error: cannot open the bag: {exc}") from None
    return reader


def _what_to_do(conn: Any) -> str:
    """For a message of a ROS 2 bag that carries no definition of its type (rosbag2 before Iron
    wrote none): that the monitor's definition was used, and how to give the recording robot's."""
    fmt = getattr(getattr(conn, "msgdef", None), "format", None)
    if getattr(fmt, "name", "") != "NONE" or conn.msgtype.count("/") != 2:
        return ""  # the bag's own definition was used: the bytes are what is wrong
    pkg, _, name = conn.msgtype.partition("/msg/")
    return (f"; the bag carries no definition of {conn.msgtype}, and the monitor's (the workspace's .msg files, "
            f"else ROS 2 Humble's) does not read it: give the recording robot's as DIR/{pkg}/msg/{name}.msg with "
            "DIR in the mapping's msg_dirs")


def bag_event(reader: Any, path: Path, index: int, conn: Any, stamp: int, raw: bytes) -> Event:
    """The event of message ``index`` of the bag (``stamp`` in ns, ``raw`` its bytes), as :func:`read_bag`
    makes it; raises :class:`TraceError` (located) when the message cannot be decoded."""
    try:
        msg = reader.deserialize(raw, conn.msgtype)
    except Exception as exc:
        hint = _what_to_do(conn)
        why = str(exc).rstrip(".") + hint if hint else str(exc)
        raise TraceError(f"{path}: message {index} (topic {conn.topic}, {len(raw)} bytes): error: "
                         f"cannot decode {conn.msgtype}: {why}") from None
    fields = flatten(msg)  # its header's stamp, when it has one, is its own time (docs/semantics.md)
    lates = of_reader(reader)  # heard late by the live monitor that recorded the bag (traces/bag_late.py)
    return Event(index, stamp / 1e9, conn.topic.lstrip("/"), fields, f"{path.name}: message {index}",
                 header_stamp(fields) if "header" in fields else None,
                 late=lates.at(conn.topic, stamp) if lates else 0.0)
