"""The sealed records the stages write, as types: one TypedDict per stage record.

The check and compose stages' records are in :mod:`.composition_records`,
the second solver's in :mod:`.crosscheck_records`; the rest are here.

Each stage of the pipeline (app/pipeline.py and the stages it calls) writes
one JSON record under ``artifacts/`` (records/sealed.py seals it) and
returns it; these TypedDicts are the static reading of those records, key
by key, with each key's JSON type.  A key a producer writes only in some
cases is ``NotRequired``.  The inner shape of a record that belongs to one
tool (an obligation's backend ``data``, a temporal requirement's run, a
deadline's counterexample) stays ``dict[str, Any]``, as in
:mod:`rclverify.records.report_schema`.  The parts several folders share are
here too (the diagnoses' culprits, counterexample rows and repairs; a side
condition's in-context record; cvc5's answer; a temporal requirement's
verdict on a recorded run), since records/ is below every folder that
writes or reads them.

Producers: ``check`` app/pipeline.py ``stage_check``; ``compose``
calculus/compose.py ``composition_json`` and calculus/side_condition.py;
``health`` app/pipeline.py ``stage_health`` (its findings are
:class:`rclverify.records.findings.HealthFinding`, defined there once); ``export``
app/pipeline.py ``stage_export`` (an obligation is records/records.py
``Obligation``, defined there once); ``deadlines``
calculus/deadlines.py ``DeadlineResult.to_json`` with stages/deadlines.py;
``requirements`` calculus/requirements/check.py, temporal_check.py and
stages/requirements.py; ``crosscheck`` stages/crosscheck/stage.py;
``ground`` app/ros_stage.py; ``nodl`` stages/nodl.py; ``diagnosis`` diagnosis/build.py with
stages/diagnoses.py.  tests/records/test_stage_records.py checks every
record the case study's stages return against these types.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Any, NotRequired, TypedDict


class SourceRef(TypedDict):
    """A place in a file: 1-based line and column."""
    file: str
    line: int
    col: int


class DeadlineHop(TypedDict):
    """One timed guarantee on a deadline's path (rule D1); times exact (``within_s``) and as written."""
    node: str
    guarantee: int
    trigger: str
    outputs: list[str]
    within_s: str
    within: str
    loc: str


class DeadlineStamp(TypedDict):
    """One event of the worst path's timeline; ``t_s`` a fraction of seconds as text."""
    event: str
    t_s: str


class DeadlineCheck(TypedDict):
    """One end-to-end deadline decided with Z3 (rule D3), as its decision gives it
    (calculus/deadlines.py ``DeadlineResult.to_json``): :class:`DeadlineRecord` without the stage's keys."""
    requirement: str
    path: list[str]
    within_s: str
    status: str
    reason: str
    within: str
    chain: list[DeadlineHop]
    total_s: str | None
    total: str | None
    stamps: list[DeadlineStamp]
    worst_path: list[str]
    loc: str


class DeadlineRecord(DeadlineCheck):
    """One end-to-end deadline decided with Z3 (rule D3; ``artifacts/deadlines/index.json``): its decision
    with the query's path (``smt2``, ``""`` without one) and the sha256 of its ``inputs`` (stages/deadlines.py)."""
    smt2: str
    inputs: dict[str, str]


class Premise(TypedDict):
    """A premise a requirement's check used (a guarantee, an assumption, a fact, an initial value);
    ``node`` ``None`` for a premise of the requirement's own ``assuming``."""
    label: str
    kind: str
    node: str | None
    index: int
    text: str
    source: str


class Traced(TypedDict):
    """A guarantee the plan traces a requirement to."""
    node: str
    guarantee: int


class Witness(TypedDict):
    """One operand of a temporal statement at one step of a trace."""
    step: int
    time: float
    where: str
    operand: str
    holds: bool | None
    values: dict[str, str]
    unreadable: NotRequired[list[str]]
    semantics: NotRequired[str]


class TraceVerdictJson(TypedDict):
    """A temporal statement's verdict on one trace (backends/monitors/temporal_trace.py ``TraceVerdict``)."""
    verdict: str
    steps: int
    reason: str
    step: int | None
    time: float | None
    where: str
    witness: list[Witness]
    #: a bounded ``eventually`` or response judged ``true``: the steps to spare (docs/semantics.md, "Margins in steps")
    spare: NotRequired[int]


class TraceFailure(TypedDict):
    """A trace that could not be checked: ``verdict`` ``error`` and the located message."""
    verdict: str
    reason: str


class TraceRow(TypedDict):
    """One recorded run checked against a temporal requirement (backends/monitors/temporal_evidence.py
    ``trace_rows``): the trace, its mapping (``None``: the default), its sha256, the evidence status
    and the verdict on it."""
    trace: str
    mapping: str | None
    sha256: str
    status: str
    verdict: TraceVerdictJson | TraceFailure


class RequirementBase(TypedDict):
    """The keys of a requirement's record that come from the plan alone (calculus/requirements/check.py
    ``_base``): ``source`` ``file:line:col``, the statements as RCL text."""
    id: str
    text: str
    origin: str
    source: str
    formal: str | None
    assuming: list[str]
    ranking: str | None
    invariant: str | None
    traced: list[Traced]


class RequirementCheck(RequirementBase):
    """A requirement decided from the composed contracts, as its check gives it
    (calculus/requirements/check.py ``check_requirement``): :class:`RequirementRecord` without
    what the stage adds (``smt2`` and the side queries' ``*_smt2`` are then the scripts' text)."""
    verdict: str
    cone: list[str]
    used: list[Premise]
    traced_not_needed: list[Premise]
    explanation: NotRequired[str]
    reason: NotRequired[str]
    premises: NotRequired[int]
    premises_of: NotRequired[list[str]]
    smt2: NotRequired[str]
    duration_s: NotRequired[float]
    counterexample: NotRequired[list[dict[str, Any]]]
    failed_to_prevent: NotRequired[list[dict[str, Any]]]
    temporal: NotRequired[dict[str, Any]]
    traces: NotRequired[list[TraceRow]]
    consistency: NotRequired[str]
    consistency_reason: NotRequired[str]
    consistency_duration_s: NotRequired[float]
    consistency_smt2: NotRequired[str]
    inconsistent_core: NotRequired[list[Premise]]
    vacuity: NotRequired[str]
    vacuity_core: NotRequired[list[Premise]]
    vacuity_reason: NotRequired[str]
    vacuity_duration_s: NotRequired[float]
    vacuity_smt2: NotRequired[str]


class RequirementRecord(RequirementCheck):
    """One requirement decided from the composed contracts (``artifacts/requirements/``): its check with the
    ``fingerprint`` it was made from and the sha256 of its ``inputs`` (stages/requirements.py); ``smt2`` and
    the side queries' ``*_smt2`` name the scripts kept beside it."""
    fingerprint: str
    inputs: dict[str, str]


#: A function value's finite table (diagnosis/table.py ``function_table``): ``rows`` ``[args, value]``,
#: ``more`` the rows left out, ``else`` the value elsewhere.
FunctionTable = TypedDict("FunctionTable", {"rows": list[list[str]], "more": int, "else": str})


class CexRow(TypedDict):
    """One symbol of a counterexample as a diagnosis shows it (diagnosis/table.py ``counterexample_table``)."""
    node: str
    variable: str
    value: str
    table: FunctionTable | None


class Culprit(TypedDict):
    """What a diagnosis names to repair: ``what`` in words, ``source`` ``file:line:col``, ``text`` as written."""
    what: str
    source: str
    text: str


class EditJson(TypedDict):
    """A repair's edit of one file (diagnosis/edits.py ``Edit.to_json``): 1-based span, the text put in and taken out."""
    file: str
    line: int
    col: int
    end_line: int
    end_col: int
    inserted: str
    deleted: str


class Repair(TypedDict):
    """One repair Z3 checked (diagnosis/repairs.py ``_record``): the ``edit`` and its unified ``diff``, the
    ``checks`` Z3 answered and the ``cost`` (status changes), each ``{"check"/"item", "status", ...}``;
    ``sha256`` the hex sha256 of the file's text the edit was computed on (``rclverify repair --apply``
    writes the edit only over that text)."""
    kind: str
    summary: str
    file: str
    edit: EditJson
    diff: str
    checks: list[dict[str, str]]
    cost: list[dict[str, str]]
    proves: str
    not_shown: str
    checked_by: str
    sha256: str


class DiagnosisEntry(TypedDict):
    """One problem of the report explained (diagnosis/build.py ``diagnose``; docs/diagnosis.md): the
    culprits by source location, the counterexample as a table, the repairs Z3 checked; ``not_offered``
    the repairs Z3 showed do not work (side conditions), ``joins`` and ``lint`` the findings a unit
    mismatch explains, ``passes_through`` and ``consequence_of`` the side conditions and problems a
    refuted requirement rests on, ``requirement`` the requirement of a deadline's record."""
    id: str
    kind: str
    node: str
    status: str
    sentence: str
    culprits: list[Culprit]
    counterexample: list[CexRow]
    repairs: list[Repair]
    guarantee: int | None
    related: list[str]
    not_offered: NotRequired[list[str]]
    joins: NotRequired[list[str]]
    lint: NotRequired[str]
    passes_through: NotRequired[list[str]]
    consequence_of: NotRequired[list[str]]
    requirement: NotRequired[str]


class DiagnosisRecord(TypedDict):
    """``artifacts/diagnosis/index.json``: the diagnoses of the report dict whose digest is ``report_sha256``
    (stages/diagnoses.py)."""
    report_sha256: str
    diagnoses: list[DiagnosisEntry]


class GroundingFinding(TypedDict):
    """One finding of grounding the contracts in the ROS graph (ros/ground/ground.py ``Finding``)."""
    code: str
    severity: str
    message: str
    node: str | None
    topic: str | None
    rcl: SourceRef | None
    ros: SourceRef | None


class GroundedNode(TypedDict):
    """A node of the computation graph and the topics it publishes and subscribes to."""
    name: str
    publishes: list[str]
    subscribes: list[str]


class PackageVersion(TypedDict):
    """A scanned package and its version."""
    name: str
    version: str


class FileDigest(TypedDict):
    """A file the graph was read from and its sha256."""
    path: str
    sha256: str


class GroundingContext(TypedDict):
    """What the graph was read from, for the GSN argument: the packages, the files, the launch files."""
    packages: list[PackageVersion]
    files: list[FileDigest]
    launch: list[str]


class GroundingRecord(TypedDict):
    """``artifacts/ros/grounding.json``: the contracts grounded in the computation graph (``graph``:
    ``{"nodes": [...]}``)."""
    findings: list[GroundingFinding]
    counts: dict[str, int]
    graph: dict[str, list[GroundedNode]]
    context: GroundingContext
    drawing: dict[str, str | None]
    matched: dict[str, str]
    inputs: dict[str, str]


class NodlPlace(TypedDict):
    """A place a NoDL finding involves: workspace-relative file, line and column (1-based)."""
    file: str
    line: int
    col: int


class NodlFinding(TypedDict):
    """One finding of the NoDL check (model/nodl/findings.py ``Finding.to_json``): its code, ``error``
    or ``warning``, the message and every place it involves, most important first."""
    code: str
    severity: str
    message: str
    places: list[NodlPlace]


class NodlSideCondition(TypedDict):
    """A parameter's declared constraints against one conjunct its node assumes of the input it sets
    (model/nodl/param_assume.py ``Side``): Z3's ``status`` and, refuted, the counterexample."""
    node: str
    parameter: str
    conjunct: str
    status: str
    model: dict[str, str]


class NodlRecord(TypedDict):
    """``artifacts/nodl/index.json``: the workspace's NoDL documents checked against its contracts and
    each other (stages/nodl.py): the files of each node's document (``documents``), the parts read
    only through ``include``, the findings, their ``counts`` per severity, the parameters' side
    conditions and the sha256 of the files it was made from (``inputs``)."""
    documents: dict[str, list[str]]
    parts: list[str]
    findings: list[NodlFinding]
    counts: dict[str, int]
    side_conditions: list[NodlSideCondition]
    inputs: dict[str, str]


__all__ = ["DeadlineRecord", "DiagnosisRecord", "GroundingRecord",
           "NodlRecord", "RequirementRecord"]
