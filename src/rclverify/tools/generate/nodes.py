"""One ament_python package per node of the contracts, and the launch files of the system.

The node's ROS interface is read from its contract (docs/rcl-language.md):
a ``topics(...)`` entry matching an input is a subscription, one matching an
output a publication (the topic's name is the entry's name, its type the
entry's type); ``services(...)`` ``serves`` is a service server, ``calls`` a
client; ``actions(...)`` the same with action servers and clients.  The
ROS node name is the contract's node name.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.lang.types import Checked, CheckedNode
from rclverify.tools.generate.interfaces import split_type
from rclverify.targets.names import msg_name, package_name, py_name, snake

#: names node.py defines or imports at module level (an interface class of such a name is aliased)
NODE_PY_NAMES = frozenset({"threading", "rclpy", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup",
                           "ExternalShutdownException", "MultiThreadedExecutor", "Node", "String", "ActionServer",
                           "ActionClient", "contract", "logic", "QOS_DEPTH", "THREADS", "SPIN_TIMEOUT", "main"})

#: Default QoS depth of the generated publishers and subscriptions (rclpy's keep-last history).
QOS_DEPTH = 10


@dataclass(frozen=True)
class Endpoint:
    """A publisher, subscription, service or action end of a node.

    ``role`` is ``pub``/``sub``/``service_server``/``service_client``/``action_server``/
    ``action_client``; ``ros_type`` is ``pkg/Name``; ``var`` the contract variable (``in.x``)."""

    role: str
    name: str
    ros_type: str
    var: str

    @property
    def pkg(self) -> str:
        """The interface package of the type."""
        return split_type(self.ros_type)[0]

    @property
    def cls(self) -> str:
        """The Python class of the type."""
        return split_type(self.ros_type)[1]

    @property
    def kind(self) -> str:
        """``msg``, ``srv`` or ``action`` (the Python module the class is imported from)."""
        return "msg" if self.role in ("pub", "sub") else "srv" if self.role.startswith("service") else "action"

    @property
    def attr(self) -> str:
        """The attribute of the node object holding the end."""
        return f"{self.role}_{snake(self.name)}"


@dataclass
class NodePackage:
    """A node's package: ``package`` (Python package name), ``ros_name`` and its ends."""

    ros_name: str
    package: str
    endpoints: list[Endpoint] = field(default_factory=list)
    contract_file: str = ""
    #: ``step``'s parameter per input, RCL name -> Python name (``x'`` -> ``x_prime``: :func:`.names.py_name`)
    params: dict[str, str] = field(default_factory=dict)
    #: ``(variable, topic)`` of each further variable on a topic an end already carries: the end carries its
    #: first variable only; the generated mapping says so (planfrag.py)
    unwired: list[tuple[str, str]] = field(default_factory=list)

    @property
    def step(self) -> str:
        """The function of ``logic.py`` the property tests call with the inputs' RCL names:
        ``step``, or ``step_rcl`` (which renames them) when Python cannot spell one as a parameter."""
        return "step" if all(k == v for k, v in self.params.items()) else "step_rcl"

    def imports(self) -> list[tuple[str, str, list[str]]]:
        """``(pkg, kind, [classes])`` for the ``from pkg.kind import ...`` lines, sorted; a class
        imported under another name is ``Name as alias`` (:meth:`py_class`)."""
        by: dict[tuple[str, str], set[str]] = {}
        for e in self.endpoints:
            alias = self.py_class(e)
            by.setdefault((e.pkg, e.kind), set()).add(e.cls if alias == e.cls else f"{e.cls} as {alias}")
        return [(p, k, sorted(c)) for (p, k), c in sorted(by.items())]

    def py_class(self, e: Endpoint) -> str:
        """The name ``node.py`` gives the type of end ``e``: its class, or ``pkg_kind_Class`` when
        two of the node's types share the class name (``geometry_msgs/Pose``, ``my_msgs/Pose``) or
        the name is one ``node.py`` defines or imports itself (``Node``, ``String``, the node's
        class): an import would rebind it.  Injective: the class has no ``_``, the kind is fixed."""
        if (e.pkg, e.kind, e.cls) == ("std_msgs", "msg", "String"):
            return e.cls  # node.py's own import of the verdicts' type
        twins = {(o.pkg, o.kind) for o in self.endpoints if o.cls == e.cls}
        taken = NODE_PY_NAMES | {msg_name(self.ros_name) + "Node"}
        return f"{e.pkg}_{e.kind}_{e.cls}" if len(twins) > 1 or e.cls in taken else e.cls

    def depends(self) -> list[str]:
        """Interface packages the node uses."""
        return sorted({e.pkg for e in self.endpoints})

    def has(self, *roles: str) -> bool:
        """Whether some end has one of ``roles``."""
        return any(e.role in roles for e in self.endpoints)


def node_package(cn: CheckedNode) -> NodePackage:
    """The package of node ``cn`` (one end per topic entry with a ``matches`` clause and per link)."""
    np = NodePackage(cn.name, package_name(cn.name), contract_file=cn.node.loc.file,
                     params={n: py_name(n) for n in cn.inputs})
    seen: set[tuple[str, str]] = set()
    for t in cn.node.topics:
        if t.match is None or t.match.prefix not in ("in", "out"):
            continue
        role = "sub" if t.match.prefix == "in" else "pub"
        if (role, t.field) in seen:
            np.unwired.append((f"{t.match.prefix}.{t.match.name}", t.field.lstrip("/")))
            continue
        seen.add((role, t.field))
        np.endpoints.append(Endpoint(role, t.field, t.msg_type, f"{t.match.prefix}.{t.match.name}"))
    for link in cn.node.links:
        role = f"{link.kind}_{'server' if link.role == 'serves' else 'client'}"
        if (role, link.name) in seen:
            continue
        seen.add((role, link.name))
        np.endpoints.append(Endpoint(role, link.name, link.ros_type,
                                     ", ".join(f"{p.prefix}.{p.name}" for p in link.parts)))
    return np


def node_packages(checked: Checked) -> list[NodePackage]:
    """One package per node, in source order; raises ``ValueError`` when two nodes share a package name."""
    out = [node_package(cn) for cn in checked.nodes.values()]
    names = [p.package for p in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"two nodes give the same package name {dup[0]!r}")
    return out
