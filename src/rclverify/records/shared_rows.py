"""The field lists several report records share because they mean the same
thing, declared once as bases the records derive from (their JSON and their
part of docs/assurance.schema.json are as if each declared the fields
itself: a base's fields come first, in the order declared, so a list is
declared here only where it means the same thing in each record and leads
each record's fields; the trailing ``inputs``, ``stale``, ``altered`` of the
stages' rows stay in each, since a base would move them first in the JSON):

* :class:`WorkspacePlaceRow`: a place in the workspace (a design file's
  field, a contract clause, a NoDL finding's place): ``file``, ``line``,
  ``col``;
* :class:`GuaranteeRefRow`: a guarantee of a node: ``node`` and its
  1-based ``guarantee``;
* :class:`ItemRow`: a report item a reader can point at: its stable
  ``id``, the anchor the HTML report, SARIF and ``rclverify explain`` use.
"""
from __future__ import annotations

from typing import Annotated

from rclverify.records.row import DOC, Row


class WorkspacePlaceRow(Row, frozen=True, forbid_unknown_fields=True):
    """A place in the workspace: a file, a line and a column."""

    file: Annotated[str, DOC(description="Workspace-relative file.")]
    line: Annotated[int, DOC(description="Line, 1-based.")]
    col: Annotated[int, DOC(description="Column, 1-based.")]


class GuaranteeRefRow(Row, frozen=True, forbid_unknown_fields=True):
    """A guarantee of a node."""

    node: Annotated[str, DOC(description="The node.")]
    guarantee: Annotated[int, DOC(description="The guarantee, 1-based.")]


class ItemRow(Row, frozen=True, forbid_unknown_fields=True):
    """A report item with its stable id."""

    id: Annotated[str, DOC(description="The item's stable id (the anchor the HTML report, SARIF and "
                                       "`rclverify explain` use).")]


__all__ = ["GuaranteeRefRow", "ItemRow", "WorkspacePlaceRow"]
