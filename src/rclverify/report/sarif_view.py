"""``reports/assurance.sarif`` read back: the keys its readers read, as msgspec Structs.

:mod:`rclverify.report.sarif` writes the log (its objects typed in
:mod:`rclverify.records.sarif`); ``rclverify explain`` (:mod:`.explain`: a
rule's description, its results and their places) and the language server
(tools/lsp/lastrun.py: each result's place, level, message and fixes) read it
back.  The file is the user's to edit, so a reader is lenient: the log is
decoded once into :class:`RunView` items, and a rule or result of another
shape is left out, never an error (:func:`runs_of`).  Key names are SARIF
2.1.0's, camelCase in the file (§3.27 result, §3.49 reportingDescriptor).
"""
from __future__ import annotations

from typing import TypeVar

import msgspec

_T = TypeVar("_T")


class TextView(msgspec.Struct, frozen=True):
    """A ``message`` or a description (§3.11): its plain text."""

    text: str = ""


class RegionView(msgspec.Struct, frozen=True, rename="camel"):
    """A place in a file (§3.30): 1-based line and column (1 when not written)."""

    start_line: int = 1
    start_column: int = 1


class UriView(msgspec.Struct, frozen=True):
    """A file (§3.4), relative to the workspace root."""

    uri: str = ""


class PhysicalView(msgspec.Struct, frozen=True, rename="camel"):
    """A file and a place in it (§3.29)."""

    artifact_location: UriView = UriView()
    region: RegionView | None = None


class LocationView(msgspec.Struct, frozen=True, rename="camel"):
    """A result's location (§3.28)."""

    physical_location: PhysicalView | None = None


class ResultView(msgspec.Struct, frozen=True, rename="camel"):
    """A ``result`` (§3.27): rule id, level, message, locations and fixes (each fix the object written,
    :class:`rclverify.records.sarif.SarifFix`)."""

    rule_id: str | None = None
    level: str = "warning"
    message: TextView = TextView()
    locations: list[LocationView] = []
    fixes: list[object] = []

    def place(self) -> tuple[str, RegionView] | None:
        """The file and region of the first location that names a file; ``None`` when none does."""
        for loc in self.locations:
            phys = loc.physical_location
            if phys is not None and phys.artifact_location.uri:
                return phys.artifact_location.uri, phys.region or RegionView()
        return None


class RuleView(msgspec.Struct, frozen=True, rename="camel"):
    """A rule the driver lists (§3.49): id, name and descriptions."""

    id: str | None = None
    name: str = "SARIF rule"
    full_description: TextView | None = None
    short_description: TextView | None = None

    def description(self) -> str:
        """The full description's text, else the short one's, else ``""``."""
        return (self.full_description or self.short_description or TextView()).text


class RunView(msgspec.Struct, frozen=True):
    """One run (§3.14): the rules of its driver and its results, each of the shape above."""

    rules: list[RuleView]
    results: list[ResultView]


class _Driver(msgspec.Struct, frozen=True):
    rules: list[object] = []


class _Tool(msgspec.Struct, frozen=True):
    driver: _Driver = _Driver()


class _Run(msgspec.Struct, frozen=True):
    tool: _Tool = _Tool()
    results: list[object] = []


class _Log(msgspec.Struct, frozen=True):
    runs: list[_Run] = []


def _each(items: list[object], cls: type[_T]) -> list[_T]:
    out = []
    for item in items:
        try:
            out.append(msgspec.convert(item, cls, strict=False))
        except msgspec.ValidationError:
            continue
    return out


def runs_of(log: object) -> list[RunView]:
    """The runs of ``log`` (the parsed JSON of a SARIF log, or ``None``), each with the rules and
    results of the shapes above, in order; ``[]`` for a log of another shape.  A rule or result of
    another shape is left out.  Raises nothing."""
    try:
        runs = msgspec.convert(log, _Log, strict=False).runs
    except msgspec.ValidationError:
        return []
    return [RunView(_each(r.tool.driver.rules, RuleView), _each(r.results, ResultView)) for r in runs]


__all__ = ["LocationView", "PhysicalView", "RegionView", "ResultView", "RuleView", "RunView", "TextView", "UriView",
           "runs_of"]
