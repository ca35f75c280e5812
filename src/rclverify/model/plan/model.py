"""The loaded verification plan as values (docs/plan.md): the plan, its
requirements and their tracing, connections, environment facts and evidence
entries.  Below the loader (:mod:`.load`) and the modules it calls
(:mod:`.doorstop`, :mod:`.expected`), which all make or read these values.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast
from rclverify.model.plan.acknowledged import Acknowledgement
from rclverify.model.plan.instances import Instance
from rclverify.model.plan.state import StateVar
from rclverify.model.plan.standards.choice import StandardChoice

if TYPE_CHECKING:
    from rclverify.model.plan.formal import Source
    from rclverify.model.plan.target_text import Target

Path_ = tuple[Any, ...]


@dataclass(frozen=True)
class Support:
    """One ``supported_by`` row: a node and 1-based guarantee indices."""

    node: str
    guarantees: tuple[int, ...]
    loc: ast.Loc


@dataclass(frozen=True)
class Requirement:
    """A requirement of the plan (or of a Doorstop item, :mod:`.doorstop`).

    ``formal`` is its formal statement (``None``: informal, traced only) and
    ``assuming`` its own environment assumptions, both RCL over
    ``Node.in.x``/``Node.out.y`` (:mod:`.formal`); ``origin`` is ``"plan"``
    or the Doorstop item's workspace-relative file; ``ranking`` and
    ``invariant`` the sources of a liveness statement's ranking function
    and invariant (:mod:`.ranking`; ``None`` when not given); ``strength``
    the least evidence strength the guarantees its proof uses must have
    (:data:`rclverify.report.argument.strength.KINDS`; ``--strict`` enforces it).
    """

    id: str
    text: str
    support: tuple[Support, ...]
    loc: ast.Loc
    formal: Source | None = None
    assuming: tuple[Source, ...] = ()
    origin: str = "plan"
    ranking: Source | None = None
    invariant: Source | None = None
    #: the least evidence strength the guarantees its proof uses must have (docs/confidence.md), or ``None``
    strength: str | None = None
    #: the violation probability its recorded runs must bound (docs/statistics.md), or ``None``
    target: Target | None = None


@dataclass(frozen=True)
class DeadlineSpec:
    """A requirement's ``deadline: {path: [A, B], within: 500 ms}``:
    ``within`` in seconds (exact), ``loc`` the entry's location."""

    requirement: str
    path: tuple[str, ...]
    within: Fraction
    loc: ast.Loc


@dataclass(frozen=True)
class Connection:
    """An explicit connection ``from: Producer.var`` -> ``to: Consumer.var``."""

    from_node: str
    from_var: str
    to_node: str
    to_var: str
    loc: ast.Loc


@dataclass(frozen=True)
class Fact:
    """An environment fact: an RCL formula over one node's inputs/outputs."""

    node: str
    text: str
    expr: ast.Expr
    loc: ast.Loc


@dataclass(frozen=True)
class EvidenceEntry:
    """``nodes.<Node>.evidence[index]``: a backend and its configuration."""

    node: str
    index: int
    backend: str
    config: Mapping[str, Any]
    loc: ast.Loc


@dataclass(frozen=True)
class Plan:
    """A loaded plan.  Paths are workspace-relative strings.

    ``instances`` maps a node to the inclusive NATURAL range ``(lo, hi)``
    used by the health checks to instantiate quantified formulas.
    """

    file: str
    root: Path
    contracts: tuple[str, ...]
    requirements: tuple[Requirement, ...]
    connections: tuple[Connection, ...]
    facts: Mapping[str, tuple[Fact, ...]]
    instances: Mapping[str, tuple[int, int]]
    evidence: Mapping[str, tuple[EvidenceEntry, ...]]
    replacements: Mapping[str, tuple[str, ast.Loc]] = field(default_factory=dict)
    locs: Mapping[Path_, ast.Loc] = field(default_factory=dict)
    name: str = ""
    #: the ``ros:`` section as written (grounding, docs/ros.md; its readers decode it once into
    #: :class:`~rclverify.model.plan.ros_section.RosSection`); empty when absent
    ros: Mapping[str, Any] = field(default_factory=dict)
    #: ``requirements_from: {doorstop: DIR}``: Doorstop document trees read for
    #: more requirements (:func:`.doorstop.read_requirements`), with the entry's location.
    requirements_from: tuple[tuple[str, ast.Loc], ...] = ()
    #: the requirements' end-to-end deadlines (rule D3, calculus/deadlines.py)
    deadlines: tuple[DeadlineSpec, ...] = ()
    #: declared state variables of nodes (``state:``, :mod:`.state`), read by temporal requirements
    states: tuple[StateVar, ...] = ()
    #: warnings answered with a reason (``acknowledged:``, :mod:`.acknowledged`)
    acknowledged: tuple[Acknowledgement, ...] = ()
    #: every path the plan names, checked to lie inside the workspace, and what it resolved to then
    #: (``{value: absolute path}``, :func:`.paths.check_plan_paths`): a reuse of this plan resolves them again
    path_targets: Mapping[str, str] = field(default_factory=dict)
    #: the safety standards the evidence is mapped onto (``standards:``, docs/standards.md)
    standards: tuple[StandardChoice, ...] = ()
    #: the contracts run as several nodes under namespaces (``instances:``, :mod:`.instances`;
    #: docs/plan.md, "Instances"), per contract
    node_instances: Mapping[str, tuple[Instance, ...]] = field(default_factory=dict)
    #: ``design: DIR``: an Autoware System Designer design folder whose monitoring fields the design stage
    #: decides against the contracts (docs/nodl.md, "The design stage"); empty when the plan names none
    design: str = ""
