"""A message's fields in the canonical form a run's identity hashes
(:mod:`.run_identity`; docs/statistics.md, "A run's identity"): flattened
to ``(dotted path, value)`` pairs sorted by path, from a ROSMonitoring
log's mapping (:func:`flat`) or a bag's decoded message (:func:`flat_message`)
alike, a number by its value, a NaN or an infinity as the text the live
monitor writes, bytes and arrays as lists; the pairs a topic rule reads
(:func:`only_read`); the header stamp's paths (:func:`is_stamp`); and the
compact JSON each record is hashed as (:func:`canonical_json`).
"""
from __future__ import annotations

import dataclasses
from typing import Any, Callable

#: The member rosidl gives a message without fields (rosbags decodes it; the live monitor leaves it out).
_EMPTY_MEMBER = "structure_needs_at_least_one_member"


def flat_message(prefix: str, msg: Any, names: Callable[[Any], tuple[str, ...]],
                 out: list[tuple[str, Any]]) -> None:
    """A decoded bag message's fields into ``out`` as :func:`flat` puts the same message's fields
    read from a log (``names``: a message's field names): rosbags' message classes also hold the
    type's constants and name as dataclass fields, which are not the message's, and the live
    monitor's log, decoded with other classes, does not hold them."""
    for n in names(msg):
        if n == _EMPTY_MEMBER:
            continue
        x = getattr(msg, n)
        p = prefix + n
        t = type(x)
        if t is float:
            out.append((p, int(x) if x.is_integer() else x if -_INF < x < _INF else repr(x)))
        elif t is int or t is str or t is bool:
            out.append((p, x))
        elif hasattr(x, "__dataclass_fields__"):
            k = len(out)
            flat_message(p + ".", x, names, out)
            if len(out) == k:
                out.append((p, {}))
        else:
            out.append((p, _message_value(x, names)))


def _message_value(v: Any, names: Callable[[Any], tuple[str, ...]]) -> Any:
    """A decoded field's value that is no scalar and no message, as :func:`_value` gives it from a log:
    an array as a list, a message in a sequence as its sorted flattened pairs."""
    if hasattr(v, "tolist"):
        return _value(v.tolist())
    if isinstance(v, (list, tuple)):
        out = []
        for x in v:
            if hasattr(x, "__dataclass_fields__"):
                pairs: list[tuple[str, Any]] = []
                flat_message("", x, names, pairs)
                out.append(sorted_pairs(pairs))
            else:
                out.append(_message_value(x, names))
        return out
    return _value(v)


def field_names(store: Any) -> Callable[[Any], tuple[str, ...]]:
    """A decoded message's field names, as its type's definition in ``store`` (a rosbags type store)
    lists them (not its constants), each type's looked up once."""
    known: dict[str, tuple[str, ...]] = {}

    def names(msg: Any) -> tuple[str, ...]:
        t = getattr(msg, "__msgtype__", "")
        got = known.get(t)
        if got is None:
            defs = store.fielddefs.get(t)
            got = known[t] = (tuple(f[0] for f in defs[1]) if defs is not None else
                              tuple(f.name for f in dataclasses.fields(msg) if f.default is dataclasses.MISSING))
        return got
    return names


def is_stamp(path: str) -> bool:
    """Whether a flattened field's ``path`` is the header stamp or below it."""
    return path == "header.stamp" or path.startswith("header.stamp.")


def only_read(pairs: list[tuple[str, Any]], paths: tuple[str, ...] | None) -> list[tuple[str, Any]]:
    """The flattened ``pairs`` a rule reading ``paths`` reads (all of them for ``None``): a pair at a path,
    below it or above it (a value the path's steps go into)."""
    if not paths:
        return pairs
    return [kv for kv in pairs
            if any(kv[0] == p or kv[0].startswith(p + ".") or p.startswith(kv[0] + ".") for p in paths)]


def flat(prefix: str, fields: Any, out: list[tuple[str, Any]]) -> None:
    """The fields of mapping ``fields`` into ``out`` as ``(path, value)``: a field's path is
    ``prefix.name`` (``name`` at the top), a nested mapping's fields are flattened (an empty one, or
    one holding rosidl's placeholder member alone, is ``{}`` at its path), any other value is
    :func:`_value`'s."""
    for k, x in fields.items():
        if k == _EMPTY_MEMBER:
            continue
        p = f"{prefix}.{k}" if prefix else str(k)
        t = type(x)
        if t is float:
            out.append((p, int(x) if x.is_integer() else x if -_INF < x < _INF else repr(x)))
        elif t is int or t is str or t is bool:
            out.append((p, x))
        elif isinstance(x, dict):
            n = len(out)
            flat(p, x, out)
            if len(out) == n:
                out.append((p, {}))
        else:
            out.append((p, _value(x)))


def _value(v: Any) -> Any:
    """``v`` canonical: a float that is an integer as that integer, a NaN or an infinity as the text the
    live monitor writes for it (``"nan"``, ``"inf"``, ``"-inf"``), bytes and arrays as lists, a mapping
    as its sorted flattened pairs; booleans, integers, other floats and text as they are."""
    t = type(v)
    if t is float:
        if v.is_integer():
            return int(v)
        return v if -_INF < v < _INF else repr(v)
    if t is list or t is tuple:
        return [_value(x) for x in v]
    if isinstance(v, dict):
        pairs: list[tuple[str, Any]] = []
        flat("", v, pairs)
        return sorted_pairs(pairs)
    if isinstance(v, (bytes, bytearray)):
        return list(v)
    if hasattr(v, "tolist"):  # an array, or a numpy scalar
        return _value(v.tolist())
    return v


def sorted_pairs(pairs: list[tuple[str, Any]]) -> list[list[Any]]:
    """``pairs`` sorted by path; two of one path (a log naming ``a.b`` and ``a: {b}``) by their JSON."""
    pairs.sort(key=_first)
    if len({p for p, _ in pairs}) != len(pairs):
        pairs.sort(key=lambda kv: (kv[0], _ENCODE(kv[1])))
    return [[p, x] for p, x in pairs]


def _first(kv: tuple[str, Any]) -> str:
    return kv[0]


_INF = float("inf")


def _encode(v: Any) -> bytes:
    """Compact JSON of a canonical record (msgspec: floats by their shortest repr, integers exact)."""
    global _ENCODE
    import msgspec  # deferred: start-up (only where a run is counted)
    _ENCODE = msgspec.json.Encoder(order="sorted").encode
    return _ENCODE(v)


_ENCODE: Callable[[Any], bytes] = _encode


def canonical_json(v: Any) -> bytes:
    """Compact JSON of a canonical record (:func:`_encode`'s encoder, made once)."""
    return _ENCODE(v)
