"""The verification plan's sections as typed values, read once where the plan is loaded (docs/plan.md).

:class:`PlanDocument` is the plan file's document after its JSON schema
(``plan.schema.json``) has passed: one msgspec Struct per section, with the
field names and shapes the schema gives, built by :func:`plan_document`
(``msgspec.convert``).  The plan's readers (:mod:`.load`, :mod:`.state`,
:mod:`.acknowledged`, :mod:`.paths`, :mod:`.standards.choice`,
:mod:`.fret.requirements`) read its attributes, never the data's string
keys.  A section whose value is each backend's own (an evidence entry's
settings), each profile's own (a ``standards:`` entry's level key), or read
by a reader of its own shapes (``instances:``, ``ros:``) is kept as written.

The locations of the values stay in the loader's location map (value path
-> ``file:line:col``, :func:`.yamlguard.to_data`): every located error of a
reader points at the value it read in the plan file.
"""
from __future__ import annotations

import re
from typing import Any, Mapping

import msgspec

from rclverify.lang import ast
from rclverify.model.plan.errors import PlanError, plan_error


class _Section(msgspec.Struct, frozen=True, kw_only=True):
    """A section of the plan: frozen, its fields by name."""


class PersonEntry(_Section, frozen=True, kw_only=True):
    """A ``people:`` entry: a person's ``name`` and every other name (``aliases``, ``emails``) that is theirs."""

    name: str
    aliases: tuple[str, ...] = ()
    emails: tuple[str, ...] = ()


class Acknowledged(_Section, frozen=True, kw_only=True):
    """An ``acknowledged:`` entry as written (:mod:`.acknowledged` gives each field's meaning and checks)."""

    warning: str
    reason: str
    file: str | None = None
    node: str | None = None
    text: str | None = None
    sha256: str | None = None


class FretFunction(_Section, frozen=True, kw_only=True):
    """``fret.functions.<name>``: a model function's parameters and its RCL term."""

    args: tuple[str, ...] = ()
    rcl: str


class Fret(_Section, frozen=True, kw_only=True):
    """The ``fret:`` section: FRET components -> nodes, the step (a duration's text), each variable's idType
    the export leaves out, the model functions (docs/requirements.md)."""

    components: dict[str, str] = msgspec.field(default_factory=dict)
    step: str | None = None
    variables: dict[str, str] = msgspec.field(default_factory=dict)
    functions: dict[str, FretFunction] = msgspec.field(default_factory=dict)


class Deadline(_Section, frozen=True, kw_only=True):
    """A requirement's ``deadline:``: the ``path`` of nodes and ``within`` (a duration's text, or a number)."""

    path: tuple[str, ...]
    within: str | int | float


class SupportedBy(_Section, frozen=True, kw_only=True):
    """A requirement's ``supported_by`` row: a node and its 1-based guarantee indices."""

    node: str
    guarantees: tuple[int, ...]


class RequirementEntry(_Section, frozen=True, kw_only=True):
    """A ``requirements:`` entry as written; a formula's text is ``None`` when it is not given."""

    id: str
    text: str
    formal: str | None = None
    ranking: str | None = None
    invariant: str | None = None
    deadline: Deadline | None = None
    strength: str | None = None
    target: str | None = None
    #: one formula, a list of them, or ``None`` (not given)
    assuming: str | tuple[str, ...] | None = None
    supported_by: tuple[SupportedBy, ...] = ()


class StateDecl(_Section, frozen=True, kw_only=True):
    """``state.<Node>.<var>``: the variable's type name, its first value and its next value (RCL texts)."""

    type: str
    init: str
    next: str


class ConnectionEntry(_Section, frozen=True, kw_only=True):
    """A ``connections:`` entry: ``from: Producer.var``, ``to: Consumer.var``."""

    source: str = msgspec.field(name="from")
    to: str


class EnvironmentEntry(_Section, frozen=True, kw_only=True):
    """``environment.<Node>`` written as a mapping: its ``facts`` and the ``instances`` range ``[lo, hi]``."""

    facts: tuple[str, ...] = ()
    instances: tuple[int, int] | None = None


class NodeEntry(_Section, frozen=True, kw_only=True):
    """``nodes.<Node>``: its evidence entries (each backend's settings, as written) and its ``replacement``."""

    evidence: tuple[dict[str, Any], ...] = ()
    replacement: str | None = None


class PlanDocument(_Section, frozen=True, kw_only=True):
    """The plan file's sections (``plan.schema.json``), each as written when absent: empty, or ``None``
    where the schema admits ``null``."""

    name: str = ""
    contracts: tuple[str, ...] = ()
    design: str = ""
    #: each entry as written: its level key is the profile's own (:mod:`.standards.choice` checks them)
    standards: tuple[dict[str, Any], ...] = ()
    people: tuple[PersonEntry, ...] = ()
    acknowledged: tuple[Acknowledged, ...] = ()
    #: ``doorstop`` / ``fret`` -> the folder or export read, in the order written
    requirements_from: dict[str, str] = msgspec.field(default_factory=dict)
    fret: Fret | None = None
    requirements: tuple[RequirementEntry, ...] = ()
    state: dict[str, dict[str, StateDecl]] | None = None
    #: as written: :func:`.instances.read_instances` reads its three shapes
    instances: Any = None
    connections: tuple[ConnectionEntry, ...] | None = None
    #: a node's facts written as a list, or as a mapping with its instance range
    environment: dict[str, tuple[str, ...] | EnvironmentEntry] | None = None
    #: as written: the grounding's settings (docs/ros.md)
    ros: Any = None
    nodes: dict[str, NodeEntry] | None = None

    @property
    def fret_export(self) -> str | None:
        """``requirements_from.fret``: the workspace-relative FRET export the plan reads requirements from
        (``None``: none)."""
        return self.requirements_from.get("fret")


#: A place msgspec names in its message: ``$.requirements[0].id`` or ``key`` in ``$.nodes``.
_WHERE = re.compile(r"at `(?:key` in `)?\$((?:\.[^.\[`]+|\[\d+\])*)`")


def _path(where: str) -> tuple[Any, ...]:
    """The value path of msgspec's ``$``-path text (``.nodes.Mover[0]`` is ``("nodes", "Mover", 0)``)."""
    return tuple(int(p[1:-1]) if p.startswith("[") else p[1:] for p in re.findall(r"\.[^.\[]+|\[\d+\]", where))


def plan_document(data: Mapping[str, Any], locs: Mapping[tuple[Any, ...], ast.Loc] | None = None,
                  file: str = "contracts/plan.yaml") -> PlanDocument:
    """The plan's ``data`` (a mapping its schema admits: ``read_plan_data``'s) as a :class:`PlanDocument`.

    ``locs`` (value path -> location) and ``file`` locate a value the document does not admit: a
    :class:`PlanError` (``E-plan``) at the nearest located value, naming what was expected.  A plan its
    schema admits always converts (an integer written ``1.0`` reads as ``1``, as JSON Schema's integer
    admits it); the error is met by data no schema checked (a mapping a caller builds)."""
    try:
        # not strict: a number the schema calls an integer may be written 1.0 (JSON Schema's integer)
        return msgspec.convert(data, PlanDocument, strict=False)
    except msgspec.ValidationError as exc:
        m = _WHERE.search(str(exc))
        path = _path(m.group(1)) if m else ()
        where = dict(locs or {})
        while path and path not in where:
            path = path[:-1]
        l = where.get(path, ast.Loc(file, 1, 1))
        raise plan_error(l.file, l.line, l.col, f"the plan's value at {'.'.join(map(str, path)) or 'plan'} "
                         f"cannot be read: {str(exc).split(' - at ')[0]}") from None


__all__ = ["Acknowledged", "ConnectionEntry", "Deadline", "EnvironmentEntry", "Fret", "FretFunction", "NodeEntry",
           "PersonEntry", "PlanDocument", "PlanError", "RequirementEntry", "StateDecl", "SupportedBy", "plan_document"]
