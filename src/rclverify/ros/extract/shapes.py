"""The JSON shapes of the recovered ROS graph's records, as TypedDicts.

The static reading of ``docs/ros-graph.schema.json`` (docs/ros.md) part by
part: a place in a file, a note, an edge, a node, a package, a message
type, a recorded bag, a declared program, a topic's and a service's
summary, and the whole graph (:meth:`rclverify.ros.extract.model.Graph.to_json`).
A place in a file is :class:`rclverify.records.stage_records.SourceRef`.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import Mapping, NotRequired, Sequence, TypedDict

from rclverify.records.stage_records import SourceRef


class NoteJson(TypedDict):
    """A located warning (``Note.to_json``): the place's keys, ``severity``, ``message``, ``code``."""
    file: str
    line: int
    col: int
    severity: str
    message: str
    code: str


class EdgeJson(TypedDict):
    """One resolved endpoint of a node (``GraphEdge.to_json``); ``type`` None when unknown."""
    topic: str
    type: str | None
    as_written: str
    at: SourceRef
    remapped_at: NotRequired[SourceRef]
    param: NotRequired[str]
    param_set_at: NotRequired[SourceRef]
    via: NotRequired[SourceRef]


class NodeJson(TypedDict):
    """One node of the graph (``GraphNode.to_json``); ``lifecycle`` only when true."""
    name: str
    namespace: str
    package: str | None
    executable: str | None
    sources: list[str]
    origin: str
    declared_at: SourceRef | None
    publishes: list[EdgeJson]
    subscribes: list[EdgeJson]
    service_servers: list[EdgeJson]
    service_clients: list[EdgeJson]
    action_servers: list[EdgeJson]
    action_clients: list[EdgeJson]
    lifecycle: NotRequired[bool]


class PackageJson(TypedDict):
    """One package (``Package.to_json``): ``ros`` 1 or 2, ``manifest`` the path shown."""
    name: str
    version: str
    build_type: str
    ros: int
    manifest: str


class FieldJson(TypedDict):
    """A message field's type (``interfaces.describe``): ``array`` None, ``[]``, ``[N]`` or ``[<=N]``."""
    type: str
    array: str | None


class BagTopic(TypedDict):
    """One topic of a recorded bag with its message count; ``graph``: the nodes of the bag's recorded
    graph that publish it (``count`` 0: a topic of the recorded graph, ``ros/graph/bag.py``)."""
    name: str
    type: str
    count: int
    graph: NotRequired[list[str]]


class BagJson(TypedDict):
    """A recorded bag's topics (``ros/graph/bag.py``); ``path`` as shown."""
    path: str
    topics: list[BagTopic]


class TopicJson(TypedDict):
    """A topic's summary (``Graph.topics``): node names sorted; ``recorded_in`` the bags that hold it."""
    types: list[str]
    publishers: list[str]
    subscribers: list[str]
    recorded_in: NotRequired[list[str]]


class ServiceJson(TypedDict):
    """A service's or action's summary (``Graph.services``)."""
    types: list[str]
    servers: list[str]
    clients: list[str]


class FileJson(TypedDict):
    """A file the graph was read from and its sha256."""
    path: str
    sha256: str


class TypeField(TypedDict):
    """One field of a message type: its name, type, array form and, for workspace files, its line."""
    name: str
    type: str
    array: str | None
    line: NotRequired[int]


class TypeConstant(TypedDict):
    """One constant of a message type; a value that is no JSON scalar is its text."""
    name: str
    type: str
    value: int | float | str | bool


class TypeJson(TypedDict):
    """One message type (``TypeInfo.to_json``): where it came from and its fields and constants."""
    origin: str
    file: str | None
    fields: list[TypeField]
    constants: list[TypeConstant]


class NamedTopic(TopicJson):
    """A topic's summary with its name, as the graph's JSON lists it."""
    name: str


class NamedService(ServiceJson):
    """A service's or action's summary with its name."""
    name: str


class GraphJson(TypedDict):
    """The whole recovered graph (``Graph.to_json``; docs/ros-graph.schema.json); ``programs`` as
    ros/graph/accounting.py writes them."""
    schema: str
    packages: list[PackageJson]
    nodes: list[NodeJson]
    topics: list[NamedTopic]
    services: list[NamedService]
    actions: list[NamedService]
    types: dict[str, TypeJson]
    unresolved: list[NoteJson]
    bags: list[BagJson]
    files: list[FileJson]
    programs: Sequence[Mapping[str, object]]


class DiffItemJson(TypedDict):
    """One difference between the code's graph and the running side (ros/live/diff.py ``Item``)."""
    category: str
    name: str
    node: str | None
    type: str | None
    observed_type: str | None
    at: SourceRef | None
    observed: str
    message: str


class ObservedJson(TypedDict):
    """The running side compared: ``kind`` ``master`` or ``bag``, ``source`` its URI or path."""
    kind: str
    source: str


class DiffJson(TypedDict):
    """``rclverify ros diff``'s JSON (docs/ros.md, "Expected against observed")."""
    schema: str
    observed: ObservedJson
    equal: bool
    compared: list[str]
    not_compared: list[str]
    incomplete: list[str]
    missing: list[DiffItemJson]
    extra: list[DiffItemJson]


class QosJson(TypedDict):
    """A DDS endpoint's QoS as the evidence says it (ros/live/dds_qos.py ``QosProfile.to_json``);
    times in ns."""
    reliability: str
    durability: str
    history: str
    deadline_ns: int
    liveliness: str
    lease_ns: int
    ownership: str
    partitions: list[str]


class LinkJson(TypedDict):
    """A contract node's link for the drawing: ``kind`` (service, action), ``name``, ``role``."""
    kind: str
    name: str
    role: str


class FieldTypeJson(TypedDict):
    """A field's type in a ROS 2 type description (REP-2011, what the RIHS01 hash is taken of)."""
    type_id: int
    capacity: int
    string_capacity: int
    nested_type_name: str


class FieldDescription(TypedDict):
    """A field of a ROS 2 type description: its name and type."""
    name: str
    type: FieldTypeJson


class TypeDescription(TypedDict):
    """A ROS 2 type description (REP-2011): the type's name and its fields."""
    type_name: str
    fields: list[FieldDescription]
