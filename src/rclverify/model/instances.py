"""One contract run as several nodes under namespaces: the plan's ``instances`` (docs/plan.md,
"Instances").

``instances: {Relay: [/r1, /r2]}`` says the node whose contract is ``Relay`` runs twice, as
``/r1/relay`` and ``/r2/relay``; ``{Relay: {node: relay_node, namespaces: [/r1, /r2]}}`` names the
ROS node when it is not the contract's name in snake case (``OdomSource`` -> ``odom_source``).

* Each instance is a node of its own, named ``<Contract>_<namespace tokens joined by _>``
  (``Relay_r1``; ``/fleet/r1`` gives ``Relay_fleet_r1``; the root namespace keeps the contract's
  name): :func:`rclverify.model.plan.instances.instance_name`, read from the plan by
  :func:`~rclverify.model.plan.instances.read_instances`.
* Its topic, service and action names are the contract's resolved for the ROS node in its
  namespace as rcl resolves them (:func:`rclverify.model.names.resolve`: ``odom`` under ``/r1`` is
  ``/r1/odom``; ``/odom`` stays ``/odom``, shared by every instance).
* :func:`instantiate` gives the checked contracts with every instanced contract replaced by its
  instances (in its place, in namespace order), the rest unchanged; :func:`instance_connections`
  the links an instance's inputs get first: the producer of the same resolved topic, else the one
  output of the same name in the same namespace, so that no instance is fed by another robot by
  name alone (:func:`fleet_system` makes such an input the environment's; a consumer outside the
  fleet reading ``odom`` finds several producers and is asked for a connection, as any ambiguous
  input is).

The system as it runs is what the monitors (``rclverify monitor``), the NoDL matching
(:func:`namespaces_of`) and the fleet's system model (:func:`fleet_system`) see; the proofs of the
contract (Hoare, Dafny, property tests) are about its code, one for every instance.
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any, Mapping, Sequence

from rclverify.lang.types import Checked, CheckedNode
from rclverify.model.plan.instances import Instance, instance_name, read_instances, snake
from rclverify.model.plan.model import Connection

if TYPE_CHECKING:
    from rclverify.model import names


def _resolved(text: str, inst: Instance) -> str:
    from rclverify.model import names  # deferred: start-up (loaded only by a plan that names instances)
    return names.resolve(text, inst.node, inst.namespace, inst.remaps)


def instance_node(cn: CheckedNode, inst: Instance) -> CheckedNode:
    """``cn`` as instance ``inst``: named ``inst.name``, each topic, service and action name
    resolved for the ROS node in its namespace (module docstring).  Raises
    :class:`~rclverify.model.names.BadName` for a name rcl refuses there."""
    n = cn.node
    node = dataclasses.replace(
        n, name=inst.name,
        topics=tuple(dataclasses.replace(t, field=_resolved(t.field, inst)) for t in n.topics),
        links=tuple(dataclasses.replace(lk, name=_resolved(lk.name, inst)) for lk in n.links))
    return dataclasses.replace(cn, node=node)


def instantiate(checked: Checked, instances: Mapping[str, Sequence[Instance]]) -> Checked:
    """``checked`` with each contract of ``instances`` replaced by its instances (module docstring);
    a contract given no instance, or absent from ``checked``, is left as it is.  Raises
    :class:`~rclverify.model.names.BadName` for a name rcl refuses in an instance's namespace."""
    nodes: dict[str, CheckedNode] = {}
    for name, cn in checked.nodes.items():
        insts = instances.get(name) or ()
        if not insts:
            nodes[name] = cn
        for inst in insts:
            nodes[inst.name] = instance_node(cn, inst)
    return Checked(checked.env, nodes, checked.specs)


def _namespace_of(instances: Mapping[str, Sequence[Instance]]) -> dict[str, str]:
    return {i.name: i.namespace for insts in instances.values() for i in insts}


def instance_connections(inst_checked: Checked, instances: Mapping[str, Sequence[Instance]]) -> tuple[Connection, ...]:
    """The links of each instance's inputs in ``inst_checked`` (:func:`instantiate`'s result): the
    one output bound to the same resolved topic and message type, else the one output of the same
    name and type of a node in the same namespace (module docstring); an input with neither is left
    to the system model's own search.  Each is a :class:`Connection` located at the instance."""
    ns_of = _namespace_of(instances)
    loc_of = {i.name: i.loc for insts in instances.values() for i in insts}
    out: list[Connection] = []
    for n, cn in inst_checked.nodes.items():
        if n not in ns_of:
            continue
        for var, typ in cn.inputs.items():
            keys = {(t.msg_type, t.key) for t in cn.node.topics
                    if t.match is not None and t.match.name == var and t.match.prefix in (None, "in")}
            by_topic = [(m, t.match.name) for m, other in inst_checked.nodes.items() if m != n
                        for t in other.node.topics
                        if t.match is not None and (t.msg_type, t.key) in keys and t.match.prefix in (None, "out")
                        and other.outputs.get(t.match.name) == typ]
            by_name = [(m, var) for m, other in inst_checked.nodes.items()
                       if m != n and ns_of.get(m, "/") == ns_of[n] and other.outputs.get(var) == typ]
            cands = by_topic or by_name
            if len(cands) == 1:
                out.append(Connection(cands[0][0], cands[0][1], n, var, loc_of[n]))
    return tuple(out)


def namespaces_of(instances: Mapping[str, Sequence[Instance]]) -> dict[str, list[str]]:
    """The namespaces each contract's NoDL document is matched in
    (:func:`rclverify.model.nodl.match.match_instances`'s ``namespaces``): ``{contract: [ns]}``."""
    return {c: [i.namespace for i in insts] for c, insts in instances.items() if insts}


def fleet_system(checked: Checked, instances: Mapping[str, Sequence[Instance]],
                 connections: Sequence[Connection] = ()) -> tuple[Checked, Any]:
    """The system as it runs: ``(instantiated contracts, system model)``, the model built
    (:func:`rclverify.model.system.model.build`) with the plan's ``connections`` that name no
    instanced contract, then :func:`instance_connections` (their links ``via = "instance"``); an
    instance's input the system model's name rule would feed from another namespace is an
    environment input instead (one robot is not fed by another by a name alone).  Raises what
    ``build`` raises (an ambiguous input, located) and :class:`~rclverify.model.names.BadName`."""
    from rclverify.model.system.model import Link, build  # deferred: the system model is only built for a fleet
    inst = instantiate(checked, instances)
    kept = [c for c in connections if c.from_node in inst.nodes and c.to_node in inst.nodes]
    explicit = {(c.to_node, c.to_var) for c in kept}
    more = [c for c in instance_connections(inst, instances) if (c.to_node, c.to_var) not in explicit]
    model = build(inst, [*kept, *more])
    ours, ns_of = {(c.to_node, c.to_var) for c in more}, _namespace_of(instances)
    links, env = [], list(model.env_inputs)
    for l in model.links:
        if l.via == "name" and l.to_node in ns_of and ns_of.get(l.from_node, "/") != ns_of[l.to_node]:
            env.append((l.to_node, l.to_var, str(inst.nodes[l.to_node].inputs[l.to_var])))
        else:
            links.append(Link(l.from_node, l.from_var, l.to_node, l.to_var, "instance")
                         if (l.to_node, l.to_var) in ours else l)
    return inst, dataclasses.replace(model, links=tuple(links), env_inputs=tuple(env), loops=_loops(model.nodes, links))


def _loops(nodes: Sequence[str], links: Sequence[Any]) -> tuple[tuple[str, ...], ...]:
    """The strongly connected components with a cycle, each and all sorted (as the system model's)."""
    from rclverify.model.system.cycles import strongly_connected_components  # deferred: as fleet_system's
    succ: dict[str, set[str]] = {n: set() for n in nodes}
    for l in links:
        succ[l.from_node].add(l.to_node)
    comps = strongly_connected_components(list(nodes), {n: sorted(ws) for n, ws in succ.items()})
    return tuple(sorted(tuple(sorted(c)) for c in comps if len(c) > 1 or c[0] in succ[c[0]]))


__all__ = ["Instance", "fleet_system", "instance_connections", "instance_name", "instance_node", "instantiate",
           "namespaces_of", "read_instances", "snake"]  # the plan's reader re-exported: one face for instances
