"""A contract-health finding, defined once: :class:`HealthFinding` and the report's :class:`FindingRow`.

:class:`HealthFinding` is the record the health checks make
(calculus/health/: consistency and vacuity, paper lines 740-768; shape,
definedness, realizability, replacement refinement) and calculus/scale.py
makes for a probable scale mismatch; the health stage seals a list of them
(``artifacts/health/<Node>.json``, app/pipeline.py ``stage_health``) and the
report decodes the sealed record back into them (report/records.py).
:class:`FindingRow` extends it with what only the report adds: the second
solver's agreement (stages/crosscheck/apply.py) and a warning's
acknowledgement marks (model/plan/acknowledged.py).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of a finding's fields.  Records are
  written with :func:`msgspec.to_builtins` (:meth:`HealthFinding.to_json`)
  and read with :func:`msgspec.convert`; a key a class does not declare is
  refused (``forbid_unknown_fields``).  Every field is in the JSON, at its
  default when there is nothing to say (``null``, ``""``, ``0``): a key
  present in one run and absent in the next would make two reports of the
  same inputs differ.
* ``smt2`` and ``witness_smt2`` hold a query's SMT-LIB2 *text* as a check
  returns it and the workspace-relative *path* of the script the health
  stage keeps (``artifacts/health/<id>.smt2``, ``<id>.witness.smt2``) in
  every record: the stage writes the text and puts the path in its place.
  Neither is compared (:meth:`HealthFinding.__eq__` ignores them: Z3 may
  number the same query's terms differently from run to run).
* The ``findings[]`` items of docs/assurance.schema.json are generated from
  :class:`FindingRow` (records/schema_gen.py); tests/records/test_record_shapes.py
  fails when the file and the classes differ.
* Every field of :class:`FindingRow` is read by a renderer of the report's
  finding rows (report/templates/parts/findings.*.j2) or named in
  :data:`INTERNAL` with the reason it is not shown, and read by each
  renderer written in Python (SARIF, JUnit, ``rclverify explain``) or named
  in its table of :data:`INTERNAL_TO`; tests/records/test_record_shapes.py
  fails otherwise.
"""
from __future__ import annotations

from typing import Annotated, Any, Iterable, Mapping

import msgspec

from rclverify.records.solvers_rows import Solvers
from rclverify.records.statuses import HealthStatus

_DOC = msgspec.Meta  # a field's description, as the generated JSON Schema shows it


class HealthFinding(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One health finding of one node (module docstring for the rules)."""

    id: Annotated[str, _DOC(description="The item's stable id (the anchor the HTML report, SARIF and "
                                        "`rclverify explain` use): <Node>.g<k>.<check> or <Node>.<check>.")]
    node: Annotated[str, _DOC(description="The node's name as the contracts declare it.")]
    check: Annotated[str, _DOC(description="The check that made it (contract-consistent, non-vacuous, "
                                           "tautology, realizable, probable-scale-mismatch, ...).")]
    guarantee: Annotated[int | None, _DOC(description="The guarantee it concerns (1-based), null for the "
                                                      "whole contract.")]
    status: Annotated[HealthStatus, _DOC(description="Its status.")]
    message: Annotated[str, _DOC(description="The problem or outcome in one sentence.")]
    explanation: Annotated[str, _DOC(description="What the tool found, in words.")]
    model: Annotated[dict[str, str] | None, _DOC(
        description="A witness or counterexample in RCL terms (name -> value), null when none.")] = None
    core: Annotated[list[str] | None, _DOC(
        description="An unsatisfiable core (RCL clauses), null when none.")] = None
    duration_s: Annotated[float, _DOC(description="The solver's wall-clock time, seconds (0 when no solver ran).")] = 0.0
    instances: Annotated[dict[str, str] | None, _DOC(
        description="The verdict per instance of a quantified premise, null when none.")] = None
    smt2: Annotated[str, _DOC(description="Path of its SMT-LIB2 query (\"\" when none was kept).")] = ""
    witness: Annotated[dict[str, str] | None, _DOC(
        description="A realizable contract's witness: output name -> RCL term answering every admissible "
                    "input (calculus/health/realizer.py), null when none.")] = None
    witness_smt2: Annotated[str, _DOC(
        description="Path of the quantifier-free query showing the witness (\"\" when none).")] = ""

    def __eq__(self, other: object) -> bool:
        """Equal when every field but the two queries is (module docstring)."""
        if not isinstance(other, HealthFinding) or type(other) is not type(self):
            return NotImplemented
        return _compared(self) == _compared(other)

    def __hash__(self) -> int:
        return hash(repr(_compared(self)))

    def to_json(self) -> dict[str, Any]:
        """The finding as its JSON object (every field)."""
        out: dict[str, Any] = msgspec.to_builtins(self)
        return out


def _compared(f: HealthFinding) -> tuple[Any, ...]:
    return tuple(getattr(f, k) for k in f.__struct_fields__ if k not in ("smt2", "witness_smt2"))


class Acknowledged(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The plan's acknowledgement that answers a warning (docs/plan.md, ``acknowledged``)."""

    reason: Annotated[str, _DOC(description="Why, in one sentence.")]
    at: Annotated[str, _DOC(description="file:line:col of the RCL or plan text (1-based line and column)")]


class FindingRow(HealthFinding, frozen=True, forbid_unknown_fields=True):
    """A contract health finding as the report shows it (``findings[]``; docs/semantics.md, health checks)."""

    solvers: Annotated[Solvers | None, _DOC(
        description="The second solver's agreement (docs/second-solver.md), null when it decided nothing.")] = None
    flagged: Annotated[str, _DOC(description="The flagged text of a warning (what an acknowledgement binds), "
                                             "\"\" for a finding that is no warning.")] = ""
    sha256: Annotated[str, _DOC(description="The sha256 of the flagged text, hex (\"\" for a finding that is "
                                            "no warning).")] = ""
    acknowledged: Annotated[Acknowledged | None, _DOC(
        description="The plan acknowledgement that answers this warning, null when none.")] = None

    @classmethod
    def of(cls, finding: HealthFinding | Mapping[str, Any]) -> FindingRow:
        """``finding`` (a record, a row, or either's JSON object) as a row.
        Raises :class:`msgspec.ValidationError` for a key no field declares
        or a value of another type."""
        data = finding.to_json() if isinstance(finding, HealthFinding) else dict(finding)
        return msgspec.convert(data, cls)


def rows_of(findings: Iterable[FindingRow | Mapping[str, Any]]) -> list[FindingRow]:
    """The report's ``findings[]`` (JSON objects, as built or as read back
    from ``reports/assurance.json``, or records already decoded) decoded, in order, so that a reader
    reads attributes mypy checks.  Raises :class:`msgspec.ValidationError`
    for a key no field declares or a value of another type."""
    return [FindingRow.of(f) for f in findings]


#: The fields of :class:`FindingRow` no finding renderer shows, each with the reason.
INTERNAL: dict[str, str] = {
    "flagged": "the text an acknowledgement binds; the row shows its sha256 and the finding's own message",
}


#: For each renderer written in Python rather than a template (``sarif``: report/sarif.py, ``junit``:
#: report/junit.py, ``explain``: report/explain.py), the fields of :class:`FindingRow` it does not show,
#: each with the reason; every other field it reads off the decoded row (tests/records/test_record_shapes.py).
INTERNAL_TO: dict[str, dict[str, str]] = {
    "sarif": {
        "duration_s": "a SARIF result carries no timing; the JUnit case and explain show it",
        "smt2": "the path of a kept query; a SARIF result is located at the RCL text, explain names the query",
        "witness": "SARIF lists only findings that are not ok, and a witness belongs to a realizable (ok) contract",
        "witness_smt2": "the query of a witness, which belongs to an ok finding SARIF does not list",
        "flagged": INTERNAL["flagged"],
    },
    "junit": {
        "node": "the test suite is the node's, named after it",
        "instances": "a verdict per instance; the case's message and text are the finding's own, explain lists "
                     "them",
        "smt2": "the path of a kept query; explain names it",
        "witness": "the witness of a realizable contract, whose case passes with nothing to say; explain shows it",
        "witness_smt2": "the query of a witness, whose case passes; explain names it",
        "flagged": INTERNAL["flagged"],
        "sha256": "what an acknowledgement binds; a CI reader acknowledges from explain, which prints the line "
                  "to add to the plan",
    },
    "explain": {
        "flagged": "the text an acknowledgement binds; explain prints its sha256 in the line to add to the plan",
    },
}


__all__ = ["Acknowledged", "FindingRow", "HealthFinding", "INTERNAL", "INTERNAL_TO", "rows_of"]
