"""Diagnostics: the located messages a user sees.

Every error a user can cause is a :class:`Diagnostic` printed as
``file:line:col: error|warning: message``.  :class:`RclError` carries one or
more diagnostics out of a stage; the CLI prints them and exits 1, never with a
traceback.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Iterable, Literal

if TYPE_CHECKING:  # annotations only: a no-op doit run imports this module but no AST
    from rclverify.lang.ast import Loc

Severity = Literal["error", "warning"]


@dataclass(frozen=True)
class Diagnostic:
    """One located message; ``code`` is a short stable identifier (e.g. ``E-name``)."""

    severity: Severity
    loc: Loc
    message: str
    code: str = ""

    def __str__(self) -> str:
        return f"{self.loc}: {self.severity}: {self.message}"

    def to_json(self) -> dict[str, object]:
        return {
            "severity": self.severity, "file": self.loc.file, "line": self.loc.line,
            "col": self.loc.col, "message": self.message, "code": self.code,
        }


class RclError(Exception):
    """A user error with one or more located diagnostics (all of them errors
    or warnings; at least one error)."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        self.diagnostics = tuple(diagnostics)
        super().__init__("\n".join(map(str, self.diagnostics)))


def error(loc: Loc, message: str, code: str = "") -> Diagnostic:
    return Diagnostic("error", loc, message, code)


def warning(loc: Loc, message: str, code: str = "") -> Diagnostic:
    return Diagnostic("warning", loc, message, code)
