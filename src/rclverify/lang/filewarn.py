"""Whole-file warnings that need only the parsed file.

``file_warnings(spec)`` -> list of warning :class:`~rclverify.lang.errors.Diagnostic`.

* ``W-empty-file``: the file holds no ``context`` and no ``node`` clause
  (empty, or only comments).  The paper's EBNF (shared/reference line 503,
  ``start : contract_clause+``) requires at least one clause; the tool reads
  such a file as an empty contract set but says so, since an empty file
  given to ``rclverify check`` is almost always a mistake.
"""
from __future__ import annotations

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, warning


def file_warnings(spec: ast.Spec) -> list[Diagnostic]:
    """Warnings about ``spec`` as a whole (see the module docstring)."""
    if not spec.contexts and not spec.nodes:
        return [warning(ast.Loc(spec.file, 1, 1), "empty contract file: no context or node clause", "W-empty-file")]
    return []
