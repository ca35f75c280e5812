"""Values of the recovered ROS computation graph and their JSON form.

The JSON form is documented by ``docs/ros-graph.schema.json`` (docs/ros.md).
Message types are kept in ROS 2's three-part form (``pkg/msg/Type``), the
form rosbags' type system uses; :func:`canon_type` maps ROS 1's ``pkg/Type``
and C++'s ``pkg::msg::Type`` to it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TYPE_CHECKING

if TYPE_CHECKING:
    from rclverify.records.stage_records import SourceRef
    from rclverify.ros.extract.shapes import (BagJson, EdgeJson, GraphJson, NodeJson, NoteJson, PackageJson,
                                              ServiceJson, TopicJson, TypeJson)

SCHEMA_ID = "rclverify-ros-graph/1"


#: topics every ROS 2 node's client library makes (rcl: ``/rosout`` for logging,
#: ``/parameter_events`` for parameter changes; ROS 2 design "Parameters"): the
#: library's, never a contract's inputs or outputs (docs/ros.md)
LIBRARY_TOPICS = frozenset({"/parameter_events", "/rosout"})

#: message and service types that libraries' helpers, not a node's own code, put on
#: the graph (tf2_ros broadcasters and listeners, bond, diagnostic_updater,
#: interactive_markers, parameter and lifecycle events), by the library's name
LIBRARY_TYPES = {
    "tf2_msgs/msg/TFMessage": "tf", "bond/msg/Status": "bond",
    "diagnostic_msgs/msg/DiagnosticArray": "diagnostics",
    "visualization_msgs/msg/InteractiveMarkerUpdate": "interactive markers",
    "visualization_msgs/msg/InteractiveMarkerFeedback": "interactive markers",
    "visualization_msgs/msg/InteractiveMarkerInit": "interactive markers",
    "visualization_msgs/srv/GetInteractiveMarkers": "interactive markers",
    "rcl_interfaces/msg/ParameterEvent": "parameter events", "rcl_interfaces/msg/Log": "logging",
    "lifecycle_msgs/msg/TransitionEvent": "lifecycle",
}


def library_of(topic: str, msg_type: str | None) -> str | None:
    """The library an endpoint is made by (``tf``, ``bond``, ``diagnostics``, ...)
    when its topic or type is one of :data:`LIBRARY_TOPICS`/:data:`LIBRARY_TYPES`,
    else ``None``: such endpoints are listed apart from a skeleton's inputs and
    outputs and a contract need not name them."""
    if topic in LIBRARY_TOPICS:
        return "client library"
    return LIBRARY_TYPES.get(canon_type(msg_type) or "") if msg_type else None

@dataclass(frozen=True)
class Src:
    """A location in a scanned file: path as given, 1-based line and column."""

    file: str
    line: int = 1
    col: int = 1

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"

    def to_json(self) -> SourceRef:
        return {"file": self.file, "line": self.line, "col": self.col}


@dataclass(frozen=True)
class Endpoint:
    """One publisher or subscriber in code: ``topic`` as written (before
    resolution), ``msg_type`` canonical or ``None`` when unknown.

    ``param``: when the code takes the name from a parameter, that parameter's
    name as ROS resolves it for the node (``~topic`` private, ``topic``
    relative, ``/topic`` global; ROS 2 parameters are always ``~name``), and
    ``topic`` is then the code's default (``""`` when it gives none); the
    launch file's value for the parameter wins (docs/ros.md, "Reading real code");
    ``affix``: the literal text before and after the parameter's value when the
    name is built around it (``'/%s/pose' % get_param('~turtle')``), read only
    where a launch file sets the parameter, else ``unread`` (a :class:`Note`) is given.

    ``handle``: the namespaces of the node handle the name is created through
    (``("~",)`` for a private ``ros::NodeHandle``, ``("left",)``; resolved, and
    remapped, by the graph: :mod:`namespaces`).  ``unit``: the class (or free
    function) whose code creates it; ``func``: the function (method) that does.  ``pending``: what the file alone cannot
    read, for the linker (:mod:`link`): ``(name value, handle value, callback,
    function key, name as written, where the name is written)``, or ``None``."""

    kind: str  # "pub" | "sub" | one of ``SERVICE_ROLES``
    topic: str  # the topic, service or action name as written
    msg_type: str | None
    src: Src
    param: str | None = None
    handle: tuple[str, ...] = ()
    unit: str | None = None
    pending: Any = None
    func: str | None = None
    affix: tuple[str, str] = ("", "")  # text around the parameter's value ('/' + value + '/pose')
    unread: Any = None  # the located note to give when no launch file sets that parameter
    via: Src | None = None  # the call of the helper whose argument names it (of several such calls)


# The four service/action roles an :class:`Endpoint` may have besides "pub"/"sub", each the
# name of the :class:`GraphNode` list it lands in.  A service's type is ``pkg/srv/Type``, an
# action's ``pkg/action/Type`` (docs/ros.md, "Services and actions").
SERVICE_ROLES = ("service_servers", "service_clients", "action_servers", "action_clients")


@dataclass(frozen=True)
class Note:
    """A located warning: something that could not be resolved statically."""

    src: Src
    message: str
    code: str = "ROS-UNRESOLVED"
    severity: str = "warning"  # "error" for a file that could not be read at all

    def __str__(self) -> str:
        return f"{self.src}: {self.severity}: {self.message}"

    def to_json(self) -> NoteJson:
        return {**self.src.to_json(), "severity": self.severity, "message": self.message, "code": self.code}


@dataclass
class GraphEdge:
    """A resolved publication/subscription of one node."""

    topic: str  # fully resolved, leading '/'
    msg_type: str | None
    src: Src  # where the code creates it
    remapped_at: Src | None = None
    written: str = ""  # the name as the code writes it, before resolution and remapping
    param: str | None = None  # the parameter the code takes the name from (resolved), if any
    param_set_at: Src | None = None  # the launch file's value of that parameter, when it sets one
    via: Src | None = None  # the call of the helper function whose argument gives the name, of several

    def to_json(self) -> EdgeJson:
        d: EdgeJson = {"topic": self.topic, "type": self.msg_type, "as_written": self.written or self.topic,
                             "at": self.src.to_json()}
        if self.remapped_at is not None:
            d["remapped_at"] = self.remapped_at.to_json()
        if self.param is not None:
            d["param"] = self.param
        if self.param_set_at is not None:
            d["param_set_at"] = self.param_set_at.to_json()
        if self.via is not None:
            d["via"] = self.via.to_json()
        return d


@dataclass
class GraphNode:
    """A node of the computation graph (fully resolved name, e.g. ``/rover/sensor``)."""

    name: str
    namespace: str
    package: str | None
    executable: str | None
    sources: list[str] = field(default_factory=list)
    declared_at: Src | None = None  # launch file line, or the init call in code
    publishes: list[GraphEdge] = field(default_factory=list)
    subscribes: list[GraphEdge] = field(default_factory=list)
    origin: str = "launch"  # "launch" | "source" | "master"
    # services and actions: GraphEdge.topic is the resolved service/action name, msg_type its
    # pkg/srv/Type or pkg/action/Type (None when the code does not say it statically)
    service_servers: list[GraphEdge] = field(default_factory=list)
    service_clients: list[GraphEdge] = field(default_factory=list)
    action_servers: list[GraphEdge] = field(default_factory=list)
    action_clients: list[GraphEdge] = field(default_factory=list)
    # a managed (lifecycle) node: rclcpp_lifecycle / rclpy.lifecycle make its management
    # services and transition events (:mod:`lifecycle`), which are not edges of its code
    lifecycle: bool = False

    def edges_of(self, kind: str) -> list[GraphEdge]:
        """The list an :class:`Endpoint` of ``kind`` ("pub", "sub" or one of ``SERVICE_ROLES``)
        lands in. Raises ``KeyError`` for another kind."""
        if kind == "pub":
            return self.publishes
        if kind == "sub":
            return self.subscribes
        if kind not in SERVICE_ROLES:
            raise KeyError(kind)
        lst: list[GraphEdge] = getattr(self, kind)
        return lst

    def to_json(self) -> NodeJson:
        d: NodeJson = {
            "name": self.name, "namespace": self.namespace, "package": self.package,
            "executable": self.executable, "sources": list(self.sources), "origin": self.origin,
            "declared_at": self.declared_at.to_json() if self.declared_at else None,
            "publishes": _edges(self.publishes), "subscribes": _edges(self.subscribes),
            "service_servers": _edges(self.service_servers), "service_clients": _edges(self.service_clients),
            "action_servers": _edges(self.action_servers), "action_clients": _edges(self.action_clients),
        }
        if self.lifecycle:
            d["lifecycle"] = True
        return d


def _edges(edges: list[GraphEdge]) -> list[EdgeJson]:
    return [e.to_json() for e in sorted(edges, key=_ek)]


def _ek(e: GraphEdge) -> tuple[str, str]:
    return (e.topic, e.msg_type or "")


@dataclass
class Graph:
    """The whole recovered graph; see docs/ros.md for each part."""

    packages: dict[str, PackageJson] = field(default_factory=dict)
    nodes: dict[str, GraphNode] = field(default_factory=dict)
    types: dict[str, TypeJson] = field(default_factory=dict)
    notes: list[Note] = field(default_factory=list)
    files: dict[str, str] = field(default_factory=dict)  # path -> sha256
    bags: list[BagJson] = field(default_factory=list)
    # every declared program and what it is in the graph (ros/graph/accounting.py): package,
    # kind, name, declared, nodes, unaccounted (why it is no node, or null)
    programs: list[dict[str, Any]] = field(default_factory=list)

    def unaccounted(self) -> list[dict[str, Any]]:
        """The :attr:`programs` that are no node of the graph."""
        return [p for p in self.programs if p.get("unaccounted")]

    def topics(self) -> dict[str, TopicJson]:
        """``{topic: {"types": [...], "publishers": [...], "subscribers": [...]}}``."""
        out: dict[str, TopicJson] = {}
        for n in sorted(self.nodes.values(), key=lambda n: n.name):
            for kind, edges in (("publishers", n.publishes), ("subscribers", n.subscribes)):
                for e in edges:
                    t = out.setdefault(e.topic, {"types": [], "publishers": [], "subscribers": []})
                    if e.msg_type and e.msg_type not in t["types"]:
                        t["types"].append(e.msg_type)
                    names = t["publishers"] if kind == "publishers" else t["subscribers"]
                    if n.name not in names:
                        names.append(n.name)
        for b in self.bags:
            for bt in b["topics"]:
                t = out.setdefault(bt["name"], {"types": [], "publishers": [], "subscribers": []})
                if bt["type"] not in t["types"]:
                    t["types"].append(bt["type"])
                t.setdefault("recorded_in", []).append(b["path"])
        for t in out.values():
            t["types"].sort()
        return dict(sorted(out.items()))

    def services(self, kind: str = "service") -> dict[str, ServiceJson]:
        """``{name: {"types": [...], "servers": [...], "clients": [...]}}`` of the graph's
        services (``kind="service"``) or actions (``kind="action"``), node names sorted."""
        out: dict[str, ServiceJson] = {}
        for n in sorted(self.nodes.values(), key=lambda n: n.name):
            for role in ("servers", "clients"):
                for e in getattr(n, f"{kind}_{role}"):
                    t = out.setdefault(e.topic, {"types": [], "servers": [], "clients": []})
                    if e.msg_type and e.msg_type not in t["types"]:
                        t["types"].append(e.msg_type)
                    names = t["servers"] if role == "servers" else t["clients"]
                    if n.name not in names:
                        names.append(n.name)
        for t in out.values():
            t["types"].sort()
        return dict(sorted(out.items()))

    def to_json(self) -> GraphJson:
        return {
            "schema": SCHEMA_ID,
            "packages": [self.packages[k] for k in sorted(self.packages)],
            "nodes": [self.nodes[k].to_json() for k in sorted(self.nodes)],
            "topics": [{"name": k, **v} for k, v in self.topics().items()],
            "services": [{"name": k, **v} for k, v in self.services("service").items()],
            "actions": [{"name": k, **v} for k, v in self.services("action").items()],
            "types": {k: self.types[k] for k in sorted(self.types)},
            "unresolved": [n.to_json() for n in self.notes],
            "bags": self.bags,
            "files": [{"path": k, "sha256": v} for k, v in sorted(self.files.items())],
            "programs": self.programs,
        }

    def edges(self, with_services: bool = False) -> set[tuple[str, str, str, str | None]]:
        """``{(node, kind, name, type)}``: the graph's shape, for comparisons; ``kind`` is
        "pub"/"sub", and with ``with_services`` also one of ``SERVICE_ROLES``."""
        kinds = ("pub", "sub") + (SERVICE_ROLES if with_services else ())
        return {(n.name, kind, e.topic, e.msg_type)
                for n in self.nodes.values() for kind in kinds for e in n.edges_of(kind)}


def canon_type(name: str | None, kind: str = "msg") -> str | None:
    """``pkg/Type``, ``pkg::Type``, ``pkg::msg::Type``, ``pkg.msg.Type`` -> ``pkg/msg/Type``;
    with ``kind="srv"`` or ``"action"`` a two-part name becomes ``pkg/srv/Type`` or
    ``pkg/action/Type`` (a three-part name keeps its middle part).

    ``Header`` alone is ``std_msgs/msg/Header`` (ROS 1 .msg rule). Returns
    ``None`` for ``None`` or an empty name.
    """
    if not name:
        return None
    n = name.strip().replace("::", "/").replace(".", "/")
    for suffix in ("/ConstPtr", "/Ptr", "/SharedPtr", "/UniquePtr", "/ConstSharedPtr"):
        if n.endswith(suffix):
            n = n[: -len(suffix)]
    n = n.strip("/")
    parts = [p for p in n.split("/") if p]
    if len(parts) == 1:
        return "std_msgs/msg/Header" if parts[0] == "Header" else parts[0]
    if len(parts) == 2 and kind in ("srv", "action"):
        return f"{parts[0]}/{kind}/{parts[1]}"
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return "/".join(parts[-3:])


def short_type(name: str | None) -> str:
    """``pkg/msg/Type`` -> ``pkg/Type`` (the form RCL contracts use)."""
    if not name:
        return "?"
    p = name.split("/")
    return f"{p[0]}/{p[-1]}" if len(p) == 3 else name
