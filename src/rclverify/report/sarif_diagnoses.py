"""Each SARIF result of the report with its diagnosis and the repairs Z3 checked, as SARIF ``fix`` objects.

:func:`attach_diagnoses` runs on the results :func:`rclverify.report.sarif.sarif_log`
made: a result whose item has a diagnosis (matched by the item's stable
key, ``partialFingerprints["rclverifyItem/v1"]``) gets its sentence as
``properties.diagnosis`` and each checked repair as a ``fix`` (SARIF 2.1.0
§3.55) whose description says what checked it, what it shows and what it
does not (docs/diagnosis.md: "checked by Z3" is no safety claim); a failed
side condition is moved to the guarantee its diagnosis blames, the
consumer's assumption it fails a related location (§3.27.22).
"""
from __future__ import annotations

from typing import Any, Sequence

import msgspec

from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.repair_rows import RepairRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.sarif import SarifResult, sarif_fix, sarif_locations


def _set(value: Any) -> Any:
    """``value``, ``None`` for a field the row leaves unset."""
    return None if value is msgspec.UNSET else value


def attach_diagnoses(report: AssuranceReport, results: Sequence[SarifResult]) -> None:
    """Give each result its diagnosis (``properties.diagnosis``: the
    sentence naming the culprit) and its repairs as SARIF ``fix`` objects
    (§3.55; each repair was checked by Z3 before it entered the report,
    docs/diagnosis.md).  A report without ``diagnoses`` is left as it is."""
    by_key: dict[str, DiagnosisRow] = {}
    for dg in report.diagnoses:
        if dg.kind == "unit":  # a unit mismatch: the lint error at the producer (diagnosis/units.py)
            by_key[f"unit:{_set(dg.lint)}"] = dg
            continue
        if dg.kind == "deadline":
            by_key[f"deadline:{_set(dg.requirement)}"] = dg
            continue
        for prefix in ("health", "side-condition", "obligation", "requirement"):
            by_key[f"{prefix}:{dg.id}"] = dg
    for res in results:
        fp = res["partialFingerprints"]["rclverifyItem/v1"]
        d = by_key.get(fp) or (by_key.get("unit:" + fp[5:].split(":E-unit-")[0]) if ":E-unit-" in fp else None)
        if d is None:
            continue
        res["properties"]["diagnosis"] = d.sentence
        if res["partialFingerprints"]["rclverifyItem/v1"].startswith("side-condition:"):
            _at_the_culprit(res, d)
        # what Z3 showed and what it did not, with each fix: "checked by Z3" is no safety claim (docs/diagnosis.md)
        # a repair of the code is checked by the property tests (diagnosis/code_repair.py), not by Z3 alone
        fixes = [sarif_fix(f"{r.summary} {_checker(r)} show{'' if _checker(r).endswith('tests') else 's'}: "
                           f"{r.proves or 'the problem no longer follows'}; not shown: "
                           f"{r.not_shown or 'that the change is safe'}.", r.edit)
                 for r in d.repairs]
        if fixes:
            res["fixes"] = fixes


def _at_the_culprit(res: SarifResult, d: DiagnosisRow) -> None:
    """A failed side condition is located at the guarantee its diagnosis blames
    (a producer that publishes what the consumer does not accept), so that a CI
    annotation lands on the node to repair; the consumer's assumption it fails
    becomes a related location (SARIF 2.1.0 §3.27.22)."""
    guarantee = next((c for c in d.culprits if c.what.startswith("guarantee") and c.source), None)
    if guarantee is None:
        return
    at = sarif_locations(guarantee.source)
    if not at:
        return
    rel = res.get("locations") or []
    res["locations"] = at
    for i, loc in enumerate(rel):
        loc["id"] = i
        loc["message"] = {"text": "the assumption it fails"}
    if rel:
        res["relatedLocations"] = rel


def _checker(r: RepairRow) -> str:
    """What checked the repair ``r``: Z3, the property tests (a code repair), or what its ``checked_by`` names."""
    by = r.checked_by
    return "Z3" if r.kind != "code" else "The property tests" if "hypothesis" in by or not by else by[:1].upper() + by[1:]


__all__ = ["attach_diagnoses"]
