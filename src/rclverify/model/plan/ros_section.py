"""The plan's ``ros:`` section, typed: :class:`RosSection` (docs/ros.md, "Grounding").

The plan keeps the section as written (:attr:`rclverify.model.plan.model.Plan.ros`, checked by the
plan's schema, ``model/plan/plan.schema.json``, with located errors when the plan is read); each
reader decodes it once, where it enters, with :meth:`RosSection.of`, and reads attributes after.
"""
from __future__ import annotations

from typing import Any, Mapping

import msgspec


class RosSection(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """The ``ros:`` section: the colcon/catkin ``workspaces``, ``launch`` files and their ``args``, the
    recorded ``bags``, the trace ``mapping`` file (``""``: none), the graph node of a contract node
    (``nodes``), a topic's message fields (``fields``, ``C.T`` or ``T``), the graph nodes to ``ignore`` and
    the topics published from outside the scanned code (``external``); each path workspace-relative."""

    workspaces: tuple[str, ...] = ()
    launch: tuple[str, ...] = ()
    args: dict[str, str | int | float | bool] = {}
    bags: tuple[str, ...] = ()
    mapping: str = ""
    nodes: dict[str, str] = {}
    fields: dict[str, list[str]] = {}
    ignore: tuple[str, ...] = ()
    external: tuple[str, ...] = ()

    @classmethod
    def of(cls, section: RosSection | Mapping[str, Any] | None) -> RosSection:
        """``section`` (the plan's ``ros:`` as written, or its record; ``None`` or empty: no section, every
        field empty) as a :class:`RosSection`.  Raises :class:`msgspec.ValidationError` for a section the
        plan's schema refuses (a key it does not declare, a value of another type)."""
        if isinstance(section, RosSection):
            return section
        return msgspec.convert(dict(section or {}), cls)


__all__ = ["RosSection"]
