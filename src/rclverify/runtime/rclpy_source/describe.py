"""The message definitions a ROS 2 Python has, as rosidl described them when
its packages were built: what the live monitor reads a contract type with
when the workspace has no definition of it (docs/ros2.md, "Two sources").
The agent (:mod:`.agent`, ``--describe``) is run once and each description
it returns is checked to hash to its own hash.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.runtime.dds.type_descriptions import declare
from rclverify.runtime.dds.types import DdsTypeError, Declaration
from rclverify.runtime.rclpy_source.agent_process import RclpyUnavailable, agent_answer


def installed_declarations(python: Path, names: list[str], timeout_s: float = 60.0) -> dict[str, Declaration]:
    """The definitions the ROS 2 Python ``python`` has of message types ``names`` (``pkg/msg/T``), as
    rosidl described them when the packages were built (the agent's ``--describe``), each checked to
    hash to the hash rosidl gave it (:func:`~rclverify.runtime.dds.types.declare`): what a contract type
    with no local definition is read with (:meth:`~rclverify.runtime.dds.types.TypeBook.add_declaration`).
    A type the Python has no description of is left out.  Raises :class:`RclpyUnavailable` (one line)
    when the agent cannot run or answer, or a description does not hash to its own hash."""
    what = f"the ROS 2 Python {python} could not describe {', '.join(names)}"
    answer = agent_answer(python, ["--describe", *names], timeout_s, what, what)
    out: dict[str, Declaration] = {}
    for name, found in answer.get("types", {}).items():
        if found is None:
            continue
        try:
            out[name] = declare(name, str(found["hash"]), found["description"], str(found["from"]))
        except (DdsTypeError, KeyError, TypeError) as exc:
            raise RclpyUnavailable(f"the ROS 2 Python {python}'s description of {name}: {exc}") from None
    return out


__all__ = ["installed_declarations"]
