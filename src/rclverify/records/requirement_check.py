"""A requirement's check record as the report's readers decode it: :class:`RequirementCheckRow`.

The report's ``requirements[].check`` is the requirements stage's record
(calculus/requirements/check.py, temporal_check.py and stages/requirements.py;
its keys typed in :class:`rclverify.records.stage_records.RequirementCheck`),
kept in :class:`rclverify.records.requirement_rows.RequirementRow` as its
JSON object because its shape belongs to that stage.  A reader that reads it
by attribute decodes it with :meth:`RequirementCheckRow.of`.

The rules:

* The classes declare the keys their readers read, each at the default a
  record without it has (``None``, ``[]``, ``{}``; a check's key written
  ``null`` reads as its default too); a key they do not declare is
  ignored, not refused (the record keeps keys of its own: the premises
  used, the side queries, the declarations).  A value of another type
  raises :class:`msgspec.ValidationError`.
* A number is kept as the record wrote it (an ``int`` stays an ``int``, a
  ``float`` a ``float``), so that a reader printing it prints the text the
  record had.
* The temporal check's own record (``temporal``: its trace, lasso and the
  gaps it rests on, :class:`rclverify.calculus.shapes.Gaps`) stays a
  mapping, read as that stage writes it.

Readers: the diagnosis of a refuted requirement (diagnosis/requirement.py); the
GSN argument (report/argument/build.py: the Z3 proof's script, the premises used, the
declarations with their evidence, the ``assuming`` formulas; defeaters.py: the second solver).
"""
from __future__ import annotations

from typing import Any

import msgspec

from rclverify.records.row import View
from rclverify.records.solvers_rows import Solvers


class CexNodeRow(msgspec.Struct, frozen=True):
    """One node's values in Z3's counterexample of a requirement (calculus/requirements/check.py):
    ``values`` by ``in.x`` / ``out.y``, each as Z3's model gives it."""

    node: str
    values: dict[str, Any] = {}


class WitnessRow(msgspec.Struct, frozen=True):
    """One operand of a temporal statement at one step of a recorded run
    (backends/monitors/temporal_trace.py; :class:`rclverify.records.stage_records.Witness`)."""

    operand: str | None = None
    holds: bool | None = None
    step: int | None = None
    where: str | None = None
    values: dict[str, Any] | None = None


class TraceVerdictRow(msgspec.Struct, frozen=True):
    """A temporal statement's verdict on one recorded run, or the run's failure to be checked
    (:class:`rclverify.records.stage_records.TraceVerdictJson`, ``TraceFailure``): ``time`` in seconds."""

    verdict: str | None = None
    reason: str | None = ""
    step: int | None = None
    time: int | float | None = None
    where: str | None = None
    witness: list[WitnessRow] | None = None


class TraceCheckRow(msgspec.Struct, frozen=True):
    """One recorded run checked against a temporal requirement
    (:class:`rclverify.records.stage_records.TraceRow`): the trace, its sha256 (the run's identity, by
    which the statistics count it once), the evidence status, the verdict."""

    trace: str | None = None
    sha256: str | None = None
    status: str | None = None
    verdict: TraceVerdictRow | None = None


class PremiseRow(msgspec.Struct, frozen=True):
    """A premise the check used (:class:`rclverify.records.stage_records.Premise`): its label, its kind
    (``guarantee``, ``assumption``, ``fact``, ``initial value``, ``progress`` ...), its node (``None`` for
    the requirement's own ``assuming``), 1-based index, its text (RCL) and ``file:line:col``; a key the
    premise lacks is at its default (a core's premise is printed by its label, text and place only)."""

    label: str
    kind: str = ""
    node: str | None = None
    index: int = 0
    text: str = ""
    source: str = ""


class DeclarationRow(msgspec.Struct, frozen=True):
    """A declaration the proof used, with its evidence
    (calculus/requirements/rollup.py ``declaration_evidence``): the evidence status and its words."""

    label: str
    node: str
    status: str
    source: str = ""
    text: str = ""
    words: str = ""


class RequirementCheckRow(View, frozen=True):
    """A requirement's check record (``requirements[].check``, or the stage's record the roll-up reads,
    calculus/requirements/rollup.py), the keys its readers read: Z3's verdict, its reason and the verdict
    recorded before the second solver or the seal changed it; the formal statement and its
    ``file:line:col``, the cone, Z3's counterexample (with the note on values outside the assumptions),
    the temporal check's record and the recorded runs checked; the proof's script
    (``smt2``), the ``assuming`` formulas, the premises used, those traced but not needed, the cores (of
    an inconsistency, of a vacuous premise), the guarantees that did not prevent a counterexample, the
    declarations with their evidence, the second solver's agreement and the check's time; whether the
    premises used are consistent and whether the requirement's premise can hold (vacuity), each with
    its reason."""

    verdict: str | None = None
    reason: str | None = None
    recorded_verdict: str | None = None
    formal: str | None = None
    source: str | None = None
    cone: list[str] = []
    counterexample: list[CexNodeRow] = []
    temporal: dict[str, Any] | None = None
    traces: list[TraceCheckRow] = []
    smt2: str | None = None
    assuming: list[str] = []
    used: list[PremiseRow] = []
    traced_not_needed: list[PremiseRow] = []
    inconsistent_core: list[PremiseRow] = []
    vacuity_core: list[PremiseRow] = []
    failed_to_prevent: list[PremiseRow] = []
    counterexample_note: str | None = None
    consistency: str | None = None
    consistency_reason: str | None = None
    vacuity: str | None = None
    vacuity_reason: str | None = None
    duration_s: int | float = 0  #: Z3's time on the check, seconds (as written: an int stays an int)
    declarations: list[DeclarationRow] = []
    solvers: Solvers | None = None


__all__ = ["CexNodeRow", "DeclarationRow", "PremiseRow", "RequirementCheckRow", "TraceCheckRow", "TraceVerdictRow", "WitnessRow"]
