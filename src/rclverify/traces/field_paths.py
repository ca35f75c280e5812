"""Field paths into a ROS message, as the ROS grounding reads them
(docs/monitors.md, "Sequences of messages"): ``linear.x`` of a
``geometry_msgs/Twist``, ``pose.pose.position.x``, ``ranges[0]``,
``ranges[-1]`` the last element, ``poses[*].position.x`` every item's.

A message is its fields as a dict, nested messages as dicts, arrays as lists
(:func:`field_value`).  A field that is not there is a :class:`MappingError`,
the error of a message that does not map (:mod:`rclverify.traces.mapping`).
"""
from __future__ import annotations

import re
from typing import Any, Mapping, Sequence


class MappingError(Exception):
    """A message that the rule for its variable cannot map (reason in ``str``)."""



_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
_PATH = re.compile(rf"{_NAME}(?:\[(?:-?\d+|\*)\])*(?:\.{_NAME}(?:\[(?:-?\d+|\*)\])*)*")
_INDEX = re.compile(r"\[(-?\d+|\*)\]")
#: The step of a path that reads every item of an array (written ``[*]``): ``poses[*].position.x``.
EVERY = "*"


def is_path(name: str) -> bool:
    """Whether a ``fields`` entry is written as a path (has ``.`` or ``[``)."""
    return "." in name or "[" in name or "]" in name


def parse_path(text: str) -> tuple[str | int, ...] | None:
    """``pose.pose.position.x`` -> ``("pose", "pose", "position", "x")``,
    ``ranges[-1]`` -> ``("ranges", -1)``, ``poses[*].position.x`` ->
    ``("poses", EVERY, "position", "x")``; ``None`` when ``text`` is not a
    path (field names joined by ``.``, each followed by any number of
    integer indexes ``[k]``, negative counting from the end, and at most one
    ``[*]`` in the whole path: every item of that array, docs/monitors.md
    "Sequences of messages")."""
    if not _PATH.fullmatch(text) or text.count("[*]") > 1:
        return None
    steps: list[str | int] = []
    for part in text.split("."):
        steps.append(part.split("[", 1)[0])
        steps.extend(EVERY if k == EVERY else int(k) for k in _INDEX.findall(part))
    return tuple(steps)


def field_value(fields: Mapping[str, object], name: str) -> Any:
    """The value of field ``name`` of a message (its fields as a dict, nested
    messages as dicts, arrays as lists): a top-level key as it is (also one
    that is literally ``a.b``, as some loggers flatten), else the path
    :func:`parse_path` reads.  Raises :class:`MappingError` naming the
    step that does not exist (with the fields there are) or the index out
    of range."""
    if name in fields:
        return fields[name]
    steps = parse_path(name) if is_path(name) else None
    if steps is None:
        raise MappingError(f"the message has no field {name}")
    return _follow(fields, steps, name)


def _follow(fields: Any, steps: Sequence[str | int], name: str, done: str = "") -> Any:
    """The value at ``steps`` below ``fields`` (``done``: the path read so far, for the errors); an
    :data:`EVERY` step gives the list of what the rest of the path reads in each item."""
    cur: Any = fields
    for at, step in enumerate(steps):
        if step == EVERY:
            if not isinstance(cur, (list, tuple)):
                raise MappingError(f"the message has no field {name}: {done} is not an array")
            return [_follow(item, steps[at + 1:], name, f"{done}[{i}]") for i, item in enumerate(cur)]
        if isinstance(step, int):
            if not isinstance(cur, (list, tuple, bytes, bytearray)):
                raise MappingError(f"the message has no field {name}: {done} is not an array")
            if not -len(cur) <= step < len(cur):
                raise MappingError(f"the message has no field {name}: index {step} is out of range "
                                   f"({done} has {len(cur)} element(s))")
            cur = cur[step]
            done += f"[{step}]"
            continue
        if not isinstance(cur, Mapping):
            raise MappingError(f"the message has no field {name}: {done} is not a message with fields")
        if step not in cur:
            have = ", ".join(str(k) for k in cur) or "no fields"
            where = repr(done) if done else "the message"
            raise MappingError(f"the message has no field {name}: {where} has no field {step!r} (it has: {have})")
        cur = cur[step]
        done = f"{done}.{step}" if done else step
    return cur
