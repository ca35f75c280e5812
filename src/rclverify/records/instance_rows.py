"""The plan's instances in the report, defined once: :class:`InstancesRow` (with
:class:`InstanceRow`, :class:`InstanceNameRow`, :class:`InstanceInputRow`,
:class:`InstanceObligationRow`, :class:`InstanceRequirementRow` and :class:`InstanceEnvRow`).

``instances`` is the instances stage's record (artifacts/instances/index.json,
stages/instances.py; docs/plan.md "Instances in the report") as the report shows it: each
instance with its resolved names, the feeder of each input and its contract's obligations
with their current status, and every requirement about instanced contracts decided per
namespace; ``stale`` when the record was made from another plan or contracts, ``altered``
when its seal does not hold; ``null`` for a plan without ``instances:``.

These classes are the only statement of the part's fields; the ``instances`` part of
docs/assurance.schema.json is generated from them (records/schema_gen.py).
"""
from __future__ import annotations

from typing import Annotated, Any

import msgspec

from rclverify.records.row import DOC, Row

_DOC = DOC  # a field's description, as the generated JSON Schema shows it


class InstanceNameRow(Row, frozen=True, forbid_unknown_fields=True):
    """A topic, service or action name of the contract and the name it resolves to in the instance's namespace."""

    name: Annotated[str, _DOC(description="The name as the contract writes it.")]
    resolved: Annotated[str, _DOC(description="The fully qualified name, as rcl resolves it for the instance.")]
    type: Annotated[str, _DOC(description="The message type (a service or action: its kind and type).")]


class InstanceInputRow(Row, frozen=True, forbid_unknown_fields=True):
    """An input of the instance and what feeds it in the fleet's system model."""

    var: Annotated[str, _DOC(description="The input.")]
    source: Annotated[str | None, _DOC(
        description="The output feeding it (Node.out.var), null when it is the environment's.")]
    via: Annotated[str | None, _DOC(description="How the link was found (instance, topic, name, plan), or null.")]


class InstanceObligationRow(Row, frozen=True, forbid_unknown_fields=True):
    """An obligation of the instance's contract: one obligation, every instance."""

    id: Annotated[str, _DOC(description="The obligation's id.")]
    status: Annotated[str, _DOC(description="Its evidence's current status.")]


class InstanceRow(Row, frozen=True, forbid_unknown_fields=True):
    """One instance: a contract run as a node of its own under a namespace."""

    node: Annotated[str, _DOC(description="The instance's node in the system (Relay_r1).")]
    contract: Annotated[str, _DOC(description="The contract it runs.")]
    namespace: Annotated[str, _DOC(description="Its ROS namespace.")]
    ros_node: Annotated[str, _DOC(description="Its ROS node's fully qualified name.")]
    source: Annotated[str, _DOC(description="Where the plan gives it (file:line:col).")]
    names: Annotated[list[InstanceNameRow], _DOC(description="Each name of the contract, resolved.")]
    inputs: Annotated[list[InstanceInputRow], _DOC(description="Each input and its feeder.")]
    obligations: Annotated[list[InstanceObligationRow], _DOC(
        description="The contract's obligations and their status: the evidence is the type's.")]


class InstanceRequirementRow(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """A requirement naming instanced contracts, decided for one namespace."""

    id: Annotated[str, _DOC(description="The requirement.")]
    namespace: Annotated[str, _DOC(description="The namespace it is asked in.")]
    nodes: Annotated[dict[str, str], _DOC(description="Each instanced contract named and its instance there.")]
    verdict: Annotated[str, _DOC(
        description="proved, refuted, inconclusive or error, from Z3 over the fleet's system model.")]
    formal: Annotated[str | msgspec.UnsetType, _DOC(description="The statement asked, over the instances.")] = msgspec.UNSET
    cone: Annotated[list[str] | msgspec.UnsetType, _DOC(description="The nodes whose guarantees it was decided from.")] = msgspec.UNSET
    counterexample: Annotated[list[dict[str, Any]] | msgspec.UnsetType, _DOC(
        description="Refuted: values per node that meet the guarantees and break the statement.")] = msgspec.UNSET
    failed_to_prevent: Annotated[list[dict[str, Any]] | msgspec.UnsetType, _DOC(
        description="Refuted: the guarantees that did not prevent it.")] = msgspec.UNSET
    missing: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="The contracts with no instance in the namespace.")] = msgspec.UNSET
    unfed: Annotated[list[str] | msgspec.UnsetType, _DOC(
        description="Not proved: the inputs of its cone no node feeds in the fleet (Node.in.var).")] = msgspec.UNSET
    reason: Annotated[str | msgspec.UnsetType, _DOC(description="Why it is not decided.")] = msgspec.UNSET
    explanation: Annotated[str | msgspec.UnsetType, _DOC(description="Z3's verdict in words, when given.")] = msgspec.UNSET


class InstanceEnvRow(Row, frozen=True, forbid_unknown_fields=True):
    """An input of the fleet's system model that no node feeds."""

    node: Annotated[str, _DOC(description="The node.")]
    var: Annotated[str, _DOC(description="The input.")]
    type: Annotated[str, _DOC(description="Its RCL type.")]


class InstancesRow(Row, frozen=True, forbid_unknown_fields=True, omit_defaults=True):
    """The instances stage's record (artifacts/instances/index.json) as the report shows it."""

    instances: Annotated[list[InstanceRow], _DOC(description="Every instance, in plan order.")]
    requirements: Annotated[list[InstanceRequirementRow], _DOC(
        description="Each requirement naming an instanced contract, per namespace.")]
    environment_inputs: Annotated[list[InstanceEnvRow], _DOC(
        description="The fleet's inputs no node feeds.")]
    inputs: Annotated[dict[str, str], _DOC(description="The sha256 of each file the record was made from.")]
    stale: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why the record is not current (made from other files).")] = msgspec.UNSET
    altered: Annotated[str | msgspec.UnsetType, _DOC(
        description="Why the record is not believed (its seal does not hold).")] = msgspec.UNSET


__all__ = ["InstanceEnvRow", "InstanceInputRow", "InstanceNameRow", "InstanceObligationRow", "InstanceRequirementRow",
           "InstanceRow", "InstancesRow"]
