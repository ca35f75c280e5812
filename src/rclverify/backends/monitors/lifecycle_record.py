"""A judged run's lifecycle part, as its reader decodes it: :class:`LifecycleRun`.

A run of managed nodes judged through the lifecycle gate (the live run,
:meth:`rclverify.runtime.live.LiveRun.stop`, or a recorded run replayed
through it, :func:`rclverify.cli.lifecycle_runs.judge_recorded`) carries
its node verdicts (``nodes``) and the gate's ``lifecycle`` record
(:meth:`rclverify.backends.monitors.lifecycle.LifecycleGate.record`: per
managed node its state, transitions, outputs judged, violations and
transition deadlines, and the inputs held back as no question).  The gate
writes it as JSON (the run's evidence file, ``--json``); ``rclverify
monitor`` prints it from these classes, which declare the keys it reads.

The rules: a key the classes do not declare is ignored (the run's record
keeps many of its own: counts, silences, the log's digest); a declared key
missing, or a value of another type, raises
:class:`msgspec.ValidationError`; a violation row stays the gate's mapping
(only their number is read).
"""
from __future__ import annotations

from typing import Any, Literal, Mapping

import msgspec


class TransitionDeadline(msgspec.Struct, frozen=True):
    """One transition a deadline bounds, judged (:meth:`~rclverify.backends.monitors.lifecycle.LifecycleGate.transitions`):
    ``start`` and ``end`` (s; ``end`` ``None`` when no end was heard), ``within`` (s), its status and
    reason; ``stated``: where the contract states the deadline (``file:line:col``), absent for one given
    on the command line."""

    transition: str
    start: float
    end: float | None
    seconds: float | None
    within: float
    status: Literal["met", "missed", "open"]
    reason: str
    stated: str | None = None


class ManagedNode(msgspec.Struct, frozen=True):
    """A managed node's lifecycle in the run: its contract's name and ROS name, latest state, the
    states its guarantees are asked in (``scope``), transitions heard, outputs judged, the outputs
    published outside active (``violations``) and its transition deadlines judged."""

    node: str
    ros_node: str
    state: str
    scope: list[str]
    transitions: int
    outputs_judged: int
    violations: list[dict[str, Any]]
    status: Literal["discharged", "failed", "inconclusive"]
    deadlines: list[TransitionDeadline] = []


class LifecycleRecord(msgspec.Struct, frozen=True):
    """The gate's record: outputs judged, the inputs held back as no question (topic -> count), the
    managed nodes."""

    outputs_judged: int
    not_questions: dict[str, int]
    nodes: list[ManagedNode]


class NodeVerdict(msgspec.Struct, frozen=True):
    """A monitored node's verdict in the run: its evidence status and the explanation."""

    node: str
    status: str
    explanation: str


class LifecycleRun(msgspec.Struct, frozen=True):
    """A judged run of managed nodes: its node verdicts and the gate's record."""

    nodes: list[NodeVerdict]
    lifecycle: LifecycleRecord

    @classmethod
    def of(cls, record: Mapping[str, Any]) -> LifecycleRun:
        """``record`` (a judged run's record, :func:`~rclverify.cli.lifecycle_runs.judge_recorded`)
        decoded; raises :class:`msgspec.ValidationError` for one of another shape."""
        return msgspec.convert(record, cls)


__all__ = ["LifecycleRecord", "LifecycleRun", "ManagedNode", "NodeVerdict", "TransitionDeadline"]
