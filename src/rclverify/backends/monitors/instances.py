"""A contract run as several instances, judged on a recorded run per instance (docs/plan.md,
"Instances"; docs/monitors.md, "Instances and lifecycle nodes in the pipeline").

A plan with ``instances:`` runs one contract as several nodes under namespaces
(:mod:`rclverify.model.instances`).  A run recorded of the fleet holds each instance's messages
under its own names (``/r1/level``, ``/r2/level``), so the monitors backend judges each trace once
per instance: :func:`per_instance` makes, of each of the entry's per-trace obligations, one per
instance (its id and ``instance`` the trace's and the instance's node, ``Battery_r1``; its statement
naming the ROS node, ``/r1/battery``; its ``data`` the instance's ``name``, ``namespace`` and
``node``), and :func:`instance_target` gives the run of such an obligation the instance's contract:
every topic, service and action name resolved in its namespace as rcl resolves it
(:func:`rclverify.model.instances.instance_node`), a lifecycle node's transition topic included, so
its lifecycle gate follows that instance's states.  The obligation's ``node`` stays the contract's:
the evidence is the type's, naming the instance (one obligation per instance and run).  A
run-set target (``target:``) is the type's, over its traces, not per instance.
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Sequence

from rclverify.records.records import Obligation, make_obligation_id

if TYPE_CHECKING:
    from rclverify.backends.base import NodeTarget


def per_instance(target: "NodeTarget", obligations: Sequence[Obligation]) -> list[Obligation]:
    """``obligations`` (the entry's per-trace ones) as one per trace and instance of ``target``'s
    contract (module docstring); unchanged when the contract has no instance."""
    insts = tuple(getattr(target, "instances", ()) or ())
    if not insts:
        return list(obligations)
    out: list[Obligation] = []
    for ob in obligations:
        for inst in insts:
            part = f"{ob.instance}_{inst.name}"
            out.append(dataclasses.replace(
                ob, id=make_obligation_id(ob.node, ob.guarantee, ob.backend, part), instance=part,
                statement=ob.statement.replace(f"the contract of {ob.node}",
                                               f"the contract of {ob.node} as {inst.fqn} (instance {inst.name})", 1),
                data={**ob.data, "instance": {"name": inst.name, "namespace": inst.namespace, "node": inst.fqn}}))
    return out


def instance_target(target: "NodeTarget", obligation: Obligation) -> "NodeTarget":
    """The target a per-instance ``obligation`` is judged with: ``target`` with its node replaced by
    the instance's (module docstring); ``target`` itself for an obligation of no instance.  Raises
    :class:`ValueError` when the plan no longer gives the instance."""
    want = obligation.data.get("instance")
    if not isinstance(want, dict):
        return target
    from rclverify.model.instances import instance_node  # deferred: only a fleet's run needs it
    for inst in getattr(target, "instances", ()) or ():
        if inst.name == want.get("name"):
            return dataclasses.replace(target, node=instance_node(target.node, inst))
    raise ValueError(f"the plan no longer runs {obligation.node} as {want.get('name')}")


__all__ = ["instance_target", "per_instance"]
