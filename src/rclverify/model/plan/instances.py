"""The plan's ``instances`` key read: which contract runs as which nodes under which namespaces
(docs/plan.md, "Instances"; what an instance is to the rest of the tool: :mod:`rclverify.model.instances`).

``instances: {Relay: [/r1, /r2]}`` or ``{Relay: {node: relay, namespaces: [/r1, /r2]}}``: each
namespace one instance, its ROS node ``node`` (default: the contract's name in snake case), its
namespace checked by rcl's rules (:mod:`rclverify.model.names`).

One instance by name, with its own remap rules: ``{R1: {type: Relay, namespace: /r1, node: relay,
remap: {odom: /shared/odom}}}``: the instance ``R1`` (an RCL identifier) of contract ``Relay``, each
``from: to`` a remap rule ``from:=to`` given to that node (as ``--ros-args -r`` or a launch file's
``remappings`` give it), parsed and applied as rcl applies it (:class:`rclverify.model.names.Remap`,
:func:`rclverify.model.names.resolve`: a name is remapped when it expands to what ``from`` expands
to in the node's namespace, the first rule that matches).  The node's name and namespace are the
plan's ``node`` and ``namespace``: a ``__node`` or ``__ns`` rule is refused there.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast

if TYPE_CHECKING:
    from rclverify.model import names


@dataclass(frozen=True)
class Instance:
    """One node a contract runs as: ``contract`` the contract's node, ``namespace`` its ROS
    namespace, ``node`` its ROS node name, ``name`` the instance's node in the system (an RCL
    identifier), ``loc`` where the plan gives it, ``remaps`` its remap rules."""

    contract: str
    namespace: str
    node: str
    name: str
    loc: ast.Loc = ast.Loc("<plan>", 1, 1)
    #: the node's remap rules, in the plan's order (module docstring)
    remaps: tuple[names.Remap, ...] = ()

    @property
    def fqn(self) -> str:
        """The ROS node's fully qualified name (``/r1/relay``)."""
        from rclverify.model import names  # deferred: start-up (loaded only by a plan that names instances)
        return names.node_fqn(self.namespace, self.node)


def snake(contract: str) -> str:
    """A contract's node name as ROS writes node names: ``OdomSource`` -> ``odom_source``."""
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])", "_", contract).lower()


def instance_name(contract: str, namespace: str) -> str:
    """The instance's node in the system: ``Relay``, ``/r1`` -> ``Relay_r1``; ``/`` -> ``Relay``."""
    return contract if namespace == "/" else "_".join([contract, *namespace.strip("/").split("/")])


def read_instances(data: Any, locs: Mapping[tuple[Any, ...], ast.Loc],
                   plan_rel: str) -> tuple[dict[str, tuple[Instance, ...]], list[tuple[ast.Loc, str]]]:
    """The plan's ``instances`` value (schema-checked: contract -> list of namespaces, or ``{node,
    namespaces}``) as ``{contract: instances}`` and its problems, each ``(location, message)``
    (a namespace or node name rcl refuses, a namespace given twice, two instances of one name)."""
    out: dict[str, tuple[Instance, ...]] = {}
    problems: list[tuple[ast.Loc, str]] = []
    seen: dict[str, str] = {}

    def at(*path: Any) -> ast.Loc:
        return locs.get(("instances", *path), locs.get(("instances",), ast.Loc(plan_rel, 1, 1)))
    for contract, spec in (data or {}).items():
        from rclverify.model import names  # deferred: start-up (loaded only by a plan that names instances)
        if isinstance(spec, dict) and "type" in spec:  # one instance by name (module docstring)
            inst = _named(str(contract), spec, at, seen, problems)
            if inst is not None:
                out[inst.contract] = (*out.get(inst.contract, ()), inst)
            continue
        spaces = spec if isinstance(spec, list) else spec.get("namespaces", [])
        base: tuple[Any, ...] = (contract,) if isinstance(spec, list) else (contract, "namespaces")
        node = snake(contract) if isinstance(spec, list) else str(spec.get("node") or snake(contract))
        why = names.node_name_problem(node)
        if why is not None:
            l = at(contract, "node") if isinstance(spec, dict) else at(contract)
            problems.append((l, f"instances of {contract}: node name {node!r}: {why}"))
            continue
        got: list[Instance] = []
        for k, raw in enumerate(spaces):
            l = at(*base, k)
            ns = str(raw).rstrip("/") or "/"
            why = names.namespace_problem(ns)
            name = instance_name(contract, ns)
            if why is not None:
                problems.append((l, f"instances of {contract}: namespace {raw!r}: {why}"))
            elif any(i.namespace == ns for i in got):
                problems.append((l, f"instances of {contract}: namespace {ns} is given twice"))
            elif name in seen:
                problems.append((l, f"instances of {contract}: the instance in {ns} is "
                                f"named {name}, as {seen[name]} is"))
            else:
                seen[name] = f"{contract} in {ns}"
                got.append(Instance(contract, ns, node, name, l))
        out[contract] = (*out.get(contract, ()), *got)
    return out, problems


_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def _named(name: str, spec: Mapping[str, Any], at: Any, seen: dict[str, str],
           problems: list[tuple[ast.Loc, str]]) -> Instance | None:
    """The instance ``name: {type, namespace, node, remap}`` (module docstring), ``None`` with its
    problems added (a name that is not an identifier or is taken, a node name or namespace rcl
    refuses, a remap rule rcl refuses or one renaming the node)."""
    from rclverify.model import names  # deferred: start-up (loaded only by a plan that names instances)
    contract, raw = str(spec["type"]), str(spec["namespace"])
    ns = raw.rstrip("/") or "/"
    node = str(spec.get("node") or snake(contract))
    wrong = len(problems)
    if not _IDENT.match(name):
        problems.append((at(name), f"instance {name!r}: its name is a node of the system, an identifier "
                                   f"(letters, digits, '_')"))
    elif name in seen:
        problems.append((at(name), f"instance {name}: the name is taken by {seen[name]}"))
    for what, why in (("node name", names.node_name_problem(node)), ("namespace", names.namespace_problem(ns))):
        if why is not None:
            problems.append((at(name, "node" if what == "node name" else "namespace"),
                             f"instance {name} of {contract}: {what} {node if what == 'node name' else raw!r}: {why}"))
    rules: list[names.Remap] = []
    for src, dst in (spec.get("remap") or {}).items():
        try:
            rule = names.Remap.parse(f"{src}:={dst}")
        except names.BadName as exc:
            problems.append((at(name, "remap", src), f"instance {name} of {contract}: {exc}"))
            continue
        if rule.source in ("__node", "__ns"):
            problems.append((at(name, "remap", src), f"instance {name} of {contract}: the rule {src}:={dst} "
                                                    f"renames the node; write node: or namespace: instead"))
            continue
        rules.append(rule)
    if len(problems) > wrong:
        return None
    seen[name] = f"{contract} in {ns}"
    return Instance(contract, ns, node, name, at(name), tuple(rules))


__all__ = ["Instance", "instance_name", "read_instances", "snake"]
