"""The head of the report, defined once: :class:`Meta`, :class:`Summary` (with :class:`DiagnosisBrief`) and
:class:`SystemView` (with :class:`SystemNode`).

``meta`` says where the report comes from (report/build.py, its
``strict_ok`` set by the ``--strict`` gate); ``summary`` is the one-screen
summary the passes of report/build.py grow (report/assemble.py: the second
solver's counts, the least confidence, the diagnoses in short); ``system``
is the system model as the report draws it (model/system/model.py
``view``).

The rules (docs/decisions.md, "One definition per record"):

* These classes are the only statement of the three parts' fields.
  report/build.py builds :class:`Meta` and :class:`SystemView` and writes
  their :meth:`~rclverify.records.row.Row.to_json`; the summary, grown pass
  by pass, is decoded into :class:`Summary` once every pass has added its
  part (report/assemble.py ``with_diagnoses``), so the report holds no key
  the class does not declare (:class:`msgspec.ValidationError`
  otherwise: a bug of the build).  ``summary.confidence`` is absent when no
  formal requirement has one (``UNSET``, left out of the JSON).
* The ``meta``, ``summary`` and ``system`` parts of
  docs/assurance.schema.json are generated from them
  (records/schema_gen.py); tests/records/test_record_shapes.py fails when
  the file and the classes differ.
"""
from __future__ import annotations

from typing import Annotated, Any, Literal

import msgspec

from rclverify.records.shared_rows import ItemRow
from rclverify.records.row import DOC, Row
from rclverify.records.statuses import EVIDENCE_STATUSES, EvidenceStatus

_DOC = DOC  # a field's description, as the generated JSON Schema shows it


class Meta(Row, frozen=True, forbid_unknown_fields=True):
    """Where the report comes from."""

    tool: Annotated[Literal["rclverify"], _DOC(description="Always 'rclverify'.")]
    version: Annotated[str, _DOC(description="rclverify's version.")]
    workspace: Annotated[str, _DOC(description="The plan's name, else the workspace folder's name.")]
    plan: Annotated[str, _DOC(description="The plan file, relative to the workspace.")]
    contracts: Annotated[list[str], _DOC(description="The contract files the plan lists.")]
    z3_version: Annotated[str, _DOC(description="Z3's version.")]
    strict_ok: Annotated[bool, _DOC(description="Whether `--strict` passes: everything discharged, met or proved, "
                                                "and no finding of severity error or warning (docs/ci.md).")]
    inputs_sha256: Annotated[str, _DOC(description="sha256 over every input the report is built from: equal "
                                                   "digests, equal inputs.")]


class DiagnosisBrief(ItemRow, frozen=True, forbid_unknown_fields=True):
    """A diagnosis in short."""

    kind: Annotated[str, _DOC(description="What kind of item it is.")]
    sentence: Annotated[str, _DOC(description="One sentence for a reader.")]
    repairs: Annotated[int, _DOC(description="How many repairs Z3 checked.")]


class Summary(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True, kw_only=True):
    """The one-screen summary."""

    status: Annotated[EvidenceStatus, _DOC(description="Worst status of the requirements, nodes and derived "
                                                       "properties.")]
    counts: Annotated[dict[EvidenceStatus, Annotated[int, _DOC(ge=1)]], _DOC(
        description="Obligations per status.", extra_json_schema={"propertyNames": {"enum": list(EVIDENCE_STATUSES)}})]
    problems: Annotated[list[str], _DOC(description="Every problem as one line (the problem rows group them by "
                                                    "root cause).")]
    headline: Annotated[str, _DOC(description="One line: obligations per status, unverified guarantees, side "
                                              "conditions discharged, health problems.")]
    solvers: Annotated[dict[str, int], _DOC(description="How many items two solvers, one solver, ... decided "
                                                        "(docs/second-solver.md).")]
    confidence: Annotated[Annotated[float, _DOC(ge=0, le=1)] | msgspec.UnsetType, _DOC(
        description="The least confidence of the formal requirements (absent when there is none).")] = msgspec.UNSET
    diagnoses: Annotated[list[DiagnosisBrief], _DOC(description="One line per diagnosis (docs/diagnosis.md).")]


class SystemNode(Row, frozen=True, forbid_unknown_fields=True):
    """A node of the system and its status."""

    name: Annotated[str, _DOC(description="The name as the contracts declare it.")]
    status: Annotated[EvidenceStatus, _DOC(description="Its status.")]


class SystemView(Row, frozen=True, forbid_unknown_fields=True):
    """The system model: nodes, links, loops."""

    nodes: Annotated[list[SystemNode], _DOC(description="The nodes and their statuses.")]
    connections: Annotated[list[dict[str, Any]], _DOC(description="Links from an output to an input.")]
    environment_inputs: Annotated[list[dict[str, Any]], _DOC(description="Inputs nothing produces.")]
    loops: Annotated[list[list[str]], _DOC(description="Feedback loops, as node lists.")]
    loop_components: Annotated[list[list[str]], _DOC(description="Strongly connected components.")]


__all__ = ["DiagnosisBrief", "Meta", "Summary", "SystemNode", "SystemView"]
