"""The SARIF 2.1.0 objects rclverify writes and reads, as types: one TypedDict per object.

``reports/assurance.sarif`` is written by :mod:`rclverify.report.sarif`; a
result's ``fixes`` are the checked repairs :func:`sarif_fix`
writes; the language server reads the fixes back (:mod:`rclverify.tools.lsp`).
Sections (§) are those of the OASIS SARIF 2.1.0 standard.  A key written
only in some cases is ``NotRequired``; a value only passed on to JSON (a
result's ``properties``) is ``object``.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Mapping, NotRequired, TypedDict

from rclverify.records.repair_rows import EditRow


class SarifText(TypedDict):
    """A ``message`` (§3.11) or an inserted ``artifactContent`` (§3.3): plain text."""
    text: str


class SarifArtifactLocation(TypedDict):
    """A file relative to the workspace root (§3.4); ``uriBaseId`` in the log's locations, not in a fix."""
    uri: str
    uriBaseId: NotRequired[str]


class SarifRegion(TypedDict):
    """A place in a file (§3.30): 1-based line, the column when known; a fix's deleted region has its end."""
    startLine: int
    startColumn: NotRequired[int]
    endLine: NotRequired[int]
    endColumn: NotRequired[int]


class SarifReplacement(TypedDict):
    """The region deleted and the text inserted in its place (§3.57)."""
    deletedRegion: SarifRegion
    insertedContent: SarifText


class SarifArtifactChange(TypedDict):
    """The replacements in one file (§3.56)."""
    artifactLocation: SarifArtifactLocation
    replacements: NotRequired[list[SarifReplacement]]


class SarifFix(TypedDict):
    """One fix (§3.55): its ``description`` and the changes to each file."""
    description: NotRequired[SarifText]
    artifactChanges: NotRequired[list[SarifArtifactChange]]


class SarifPhysicalLocation(TypedDict):
    """A file and a place in it (§3.29)."""
    artifactLocation: SarifArtifactLocation
    region: SarifRegion


class SarifLocation(TypedDict):
    """A result's location (§3.28); ``id`` and ``message`` only for a related location."""
    physicalLocation: SarifPhysicalLocation
    id: NotRequired[int]
    message: NotRequired[SarifText]


class SarifSuppression(TypedDict):
    """A plan acknowledgement of a result (§3.35): ``kind`` external, ``status`` accepted."""
    kind: str
    status: str
    justification: str
    location: NotRequired[SarifLocation]


class SarifResult(TypedDict):
    """One ``result`` (§3.27); ``partialFingerprints`` holds the item's stable key,
    ``properties`` the item's fields (JSON values, only written), ``fixes`` the checked repairs."""
    ruleId: str
    level: str
    message: SarifText
    locations: list[SarifLocation]
    partialFingerprints: dict[str, str]
    properties: dict[str, object]
    relatedLocations: NotRequired[list[SarifLocation]]
    suppressions: NotRequired[list[SarifSuppression]]
    fixes: NotRequired[list[SarifFix]]
    ruleIndex: NotRequired[int]


class SarifLevel(TypedDict):
    """A rule's ``defaultConfiguration`` (§3.50)."""
    level: str


class SarifDescriptor(TypedDict):
    """A rule as the driver lists it (§3.49, ``reportingDescriptor``)."""
    id: str
    name: str
    shortDescription: SarifText
    defaultConfiguration: SarifLevel


class SarifDriver(TypedDict):
    """The tool that made the log (§3.19): rclverify, its version and every rule it may report."""
    name: str
    version: str
    rules: list[SarifDescriptor]


class SarifTool(TypedDict):
    """A run's ``tool`` (§3.18)."""
    driver: SarifDriver


class SarifRun(TypedDict):
    """The one run of the log (§3.14); ``properties`` the report's workspace, plan, status and gate."""
    tool: SarifTool
    originalUriBaseIds: dict[str, object]
    columnKind: str
    results: list[SarifResult]
    properties: dict[str, object]


#: ``reports/assurance.sarif`` (§3.13): the schema, the version and one run.
SarifLog = TypedDict("SarifLog", {"$schema": str, "version": str, "runs": list[SarifRun]})


def sarif_fix(description: str, edit: EditRow) -> SarifFix:
    """A SARIF 2.1.0 ``fix`` object (§3.55) for a repair's edit (decoded,
    :class:`~rclverify.records.repair_rows.EditRow`): one ``artifactChange`` (§3.56) with one
    ``replacement`` (§3.57)."""
    return {"description": {"text": description},
            "artifactChanges": [{
                "artifactLocation": {"uri": edit.file},
                "replacements": [{
                    "deletedRegion": {"startLine": edit.line, "startColumn": edit.col,
                                      "endLine": edit.end_line, "endColumn": edit.end_col},
                    "insertedContent": {"text": edit.inserted}}]}]}


#: Base id of every artifact location: the workspace root.
SRCROOT = "%SRCROOT%"


def split_location(text: str) -> tuple[str, int, int] | None:
    """``'contracts/x.rcl:12:5'`` -> ``('contracts/x.rcl', 12, 5)``; ``None``
    when ``text`` is not of that shape (or names no file)."""
    parts = str(text).rsplit(":", 2)
    if len(parts) != 3 or not parts[0] or not parts[1].isdigit() or not parts[2].isdigit():
        return None
    return parts[0], int(parts[1]), int(parts[2])


def sarif_locations(text: str) -> list[SarifLocation]:
    """The SARIF ``locations`` of ``text`` (``file:line:col``, 1-based,
    relative to :data:`SRCROOT`): one, or none when ``text`` names no file
    (a ``<...>`` pseudo-file, or not that shape)."""
    loc = split_location(text)
    if loc is None or loc[0].startswith("<"):
        return []
    file, line, col = loc
    region: SarifRegion = {"startLine": max(1, line)}
    if col >= 1:
        region["startColumn"] = col
    return [{"physicalLocation": {"artifactLocation": {"uri": file, "uriBaseId": SRCROOT}, "region": region}}]


def sarif_result(rule: str, level: str, text: str, where: str, key: str, props: Mapping[str, object]) -> SarifResult:
    """One SARIF ``result`` of rule ``rule`` at ``where`` (``file:line:col``),
    fingerprinted by the report item ``key`` (``rclverifyItem/v1``)."""
    return {"ruleId": rule, "level": level, "message": {"text": text}, "locations": sarif_locations(where),
            "partialFingerprints": {"rclverifyItem/v1": key}, "properties": dict(props)}


__all__ = ["SRCROOT", "sarif_locations", "sarif_result", "split_location", "SarifArtifactChange", "SarifArtifactLocation", "SarifDescriptor", "SarifDriver", "SarifFix", "SarifLevel",
           "SarifLocation", "SarifLog", "SarifPhysicalLocation", "SarifRegion", "SarifReplacement", "SarifResult",
           "SarifRun", "SarifSuppression", "SarifText", "SarifTool", "sarif_fix"]
