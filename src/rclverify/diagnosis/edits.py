"""A repair as a text edit of one workspace file: applied, shown as a
unified diff (:mod:`difflib`) and as a SARIF 2.1.0 replacement (§3.57:
``deletedRegion`` and ``insertedContent``)."""
from __future__ import annotations

import difflib
from dataclasses import dataclass

from rclverify.records.stage_records import EditJson


@dataclass(frozen=True)
class Edit:
    """Replace the text of ``file`` from (``line``, ``col``) up to, not
    including, (``end_line``, ``end_col``) by ``text``; positions 1-based,
    columns counted in characters (SARIF's default ``columnKind``
    ``unicodeCodePoints`` for text without surrogates)."""

    file: str
    line: int
    col: int
    end_line: int
    end_col: int
    text: str

    def _offset(self, lines: list[str], line: int, col: int) -> int:
        return sum(len(x) for x in lines[:line - 1]) + col - 1

    def apply(self, source: str) -> str:
        """``source`` (the whole file) with the edit made."""
        lines = source.splitlines(keepends=True)
        a = self._offset(lines, self.line, self.col)
        b = self._offset(lines, self.end_line, self.end_col)
        return source[:a] + self.text + source[b:]

    def deleted(self, source: str) -> str:
        """The text the edit replaces."""
        lines = source.splitlines(keepends=True)
        return source[self._offset(lines, self.line, self.col):self._offset(lines, self.end_line, self.end_col)]

    def diff(self, source: str) -> str:
        """The unified diff (3 lines of context) from ``source`` to the edited file."""
        new = self.apply(source)
        return "".join(difflib.unified_diff(source.splitlines(keepends=True), new.splitlines(keepends=True),
                                            f"a/{self.file}", f"b/{self.file}"))

    def to_json(self, source: str) -> EditJson:
        return {"file": self.file, "line": self.line, "col": self.col, "end_line": self.end_line,
                "end_col": self.end_col, "inserted": self.text, "deleted": self.deleted(source)}
