"""A contract's ROS endpoints against its node's NoDL document, and a NoDL document written from a contract.

A contract names its node's endpoints (docs/rcl-language.md): a
``topics(...)`` entry matching an input (``matches(in.x)``, or a bare name
of an input) is a subscription, one matching an output a publisher, and an
entry without ``matches`` a topic of either direction; ``services(...)``
``serves`` is a service server, ``calls`` a client; ``actions(...)`` the
same for actions.  The node's ROS name is the contract's node name (as
``rclverify generate`` makes it).

A contract's endpoint name is an RCL name (no ``/``), so it is compared
with a document's name as the grounding compares it with the code's
(:func:`rcl_name_of`: ``/robot/cmd`` is ``robot_cmd``, ``~/status`` is
``status``); messages show names fully qualified, the node in the root
namespace (where a generated node runs): ``x`` is ``/x``, ``~/x`` is
``/<node>/x``.  Types are compared by package and name: ``std_msgs/Bool``
is ``std_msgs/msg/Bool`` (NoDL lets the middle part be implied by use).
"""
from __future__ import annotations

from dataclasses import dataclass

import yaml

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.lang.types import CheckedNode
from rclverify.model.nodl.document import ENDPOINT_LISTS, Document, Endpoint
from rclverify.model.nodl.findings import Finding

#: The QoS a generated node gives its publishers and subscriptions: rclpy's and rclcpp's
#: ``create_publisher(..., 10)`` (keep last 10; rmw's default reliability and durability).
GENERATED_QOS = {"history": "KEEP_LAST", "depth": 10, "reliability": "RELIABLE", "durability": "VOLATILE"}
#: A topic entry without a direction: it may be either list.
TOPIC = "topics"


@dataclass(frozen=True)
class ContractEnd:
    """An endpoint the contract names: ``kind`` a list of :data:`ENDPOINT_LISTS` (or :data:`TOPIC`
    for a topic of unknown direction), ``name`` and ``type`` as written, ``loc`` its entry."""

    kind: str
    name: str
    type: str
    loc: ast.Loc


def full_name(name: str, node: str) -> str:
    """``name`` fully qualified for node ``node`` in the root namespace (module docstring)."""
    if name == "~":
        return f"/{node}"
    if name.startswith("~/"):
        return f"/{node}/{name[2:]}"
    return name if name.startswith("/") else f"/{name}"


def rcl_name_of(name: str) -> str:
    """The name a contract gives ROS name ``name``: a leading ``/`` or ``~`` dropped, each ``/``
    written ``_`` (an RCL name holds no ``/``), as the grounding reads contract names
    (docs/ros.md, "Names in skeletons"): ``/robot/cmd`` and ``robot/cmd`` are ``robot_cmd``,
    ``~/status`` is ``status``."""
    return name.strip("/~").replace("/", "_").replace("~", "")


def type_key(ros_type: str) -> tuple[str, str]:
    """``(package, Name)`` of ``pkg/Name`` or ``pkg/kind/Name`` (``("", Name)`` without a package)."""
    parts = ros_type.split("/")
    return (parts[0] if len(parts) > 1 else "", parts[-1])


def full_type(ros_type: str, kind: str) -> str:
    """``pkg/<msg|srv|action>/Name`` of ``ros_type`` used in list ``kind``."""
    pkg, name = type_key(ros_type)
    return f"{pkg}/{ENDPOINT_LISTS.get(kind, 'msg')}/{name}"


def contract_ends(cn: CheckedNode) -> list[ContractEnd]:
    """The endpoints contract ``cn`` names, first entry per (list, name), in source order."""
    out: list[ContractEnd] = []
    seen: set[tuple[str, str]] = set()
    for t in cn.node.topics:
        kind = TOPIC
        if t.match is not None:
            side = t.match.prefix or ("in" if t.match.name in cn.inputs else
                                      "out" if t.match.name in cn.outputs else None)
            kind = {"in": "subscriptions", "out": "publishers"}.get(side or "", TOPIC)
        if (kind, t.field) not in seen:
            seen.add((kind, t.field))
            out.append(ContractEnd(kind, t.field, t.msg_type, t.loc))
    for link in cn.node.links:
        kind = f"{link.kind}_{'servers' if link.role == 'serves' else 'clients'}"
        if (kind, link.name) not in seen:
            seen.add((kind, link.name))
            out.append(ContractEnd(kind, link.name, link.ros_type, link.loc))
    return out


def _word(kind: str) -> str:
    return {"publishers": "publishes", "subscriptions": "subscribes to", "service_servers": "serves the service",
            "service_clients": "calls the service", "action_servers": "serves the action",
            "action_clients": "calls the action", TOPIC: "names the topic"}[kind]


def compare(cn: CheckedNode, doc: Document) -> list[Finding]:
    """The differences between contract ``cn`` and its node's document ``doc``: an endpoint
    the document lacks (``nodl-missing``, at the contract's entry and the document's top), one
    the contract lacks (``nodl-extra``, a warning: the contract does not constrain it; at the
    document's entry and the contract's node), and
    one both name with different types (``nodl-type``, at both)."""
    node = cn.name
    top = ast.Loc(doc.file, 1, 1)
    by_name: dict[str, list[Endpoint]] = {}
    for e in doc.endpoints:
        by_name.setdefault(rcl_name_of(e.name), []).append(e)
    used: set[int] = set()
    out: list[Finding] = []
    for c in contract_ends(cn):
        fqn = full_name(c.name, node)
        kinds = ("publishers", "subscriptions") if c.kind == TOPIC else (c.kind,)
        named = by_name.get(rcl_name_of(c.name), [])
        same = [e for e in named if e.kind in kinds]
        if not same:
            other = [f"{e.name} as a {e.kind.replace('_', ' ')[:-1]}" for e in named]
            hint = f"; the document has {' and '.join(other)}" if other else ""
            out.append(Finding("nodl-missing", f"node {node} {_word(c.kind)} {fqn} ({c.type}) in its contract, and "
                                               f"its NoDL document {doc.file} does not declare it{hint}",
                               (c.loc, named[0].loc if other else top)))
            continue
        for e in same:
            used.add(id(e))
            if type_key(e.type) != type_key(c.type):
                out.append(Finding("nodl-type", f"node {node}: {fqn} has type {c.type} in the contract and "
                                                f"{e.type} in the NoDL document", (c.loc, e.type_loc)))
    for e in doc.endpoints:
        if id(e) not in used:
            fqn = full_name(e.name, node)
            out.append(Finding("nodl-extra", f"node {node}'s NoDL document declares {fqn} ({e.type}) in "
                                             f"{e.kind}, and its contract names no such endpoint",
                               (e.loc, cn.node.loc), "warning"))
    return out


def document_of(description: str, ends: list[tuple[str, str, str]]) -> dict[str, object]:
    """A NoDL v2 document (keys in the schema's order) of ``ends``: ``(list, name, type)``, the list
    one of :data:`ENDPOINT_LISTS`; each type written ``pkg/<kind>/Name``, topics with the QoS a
    generated node gives them (:data:`GENERATED_QOS`)."""
    data: dict[str, object] = {"nodl_version": 2, "description": description}
    lists: dict[str, list[dict[str, object]]] = {k: [] for k in ENDPOINT_LISTS}
    for kind, name, ros_type in ends:
        entry: dict[str, object] = {"name": name, "type": full_type(ros_type, kind)}
        if ENDPOINT_LISTS[kind] == "msg":
            entry["qos"] = dict(GENERATED_QOS)
        lists[kind].append(entry)
    data.update({k: v for k, v in lists.items() if v})
    return data


def document_data(cn: CheckedNode, contract_file: str) -> dict[str, object]:
    """The NoDL v2 document of contract ``cn``'s endpoints (:func:`contract_ends`, :func:`document_of`).
    Raises :class:`RclError` (located, ``E-nodl-write``) for a topic entry whose direction the
    contract leaves open or a type without a package: NoDL cannot say either."""
    ends: list[tuple[str, str, str]] = []
    diags = []
    for c in contract_ends(cn):
        if c.kind == TOPIC:
            diags.append(error(c.loc, f"topic {c.name} matches no input or output of {cn.name}: a NoDL document "
                                      "needs its direction (write matches(in.x) or matches(out.y))", "E-nodl-write"))
        elif not type_key(c.type)[0]:
            diags.append(error(c.loc, f"type {c.type} has no package: a NoDL document names pkg/Name",
                               "E-nodl-write"))
        else:
            ends.append((c.kind, c.name, c.type))
    if diags:
        raise RclError(diags)
    return document_of(f"Node {cn.name}: the interface its RCL contract ({contract_file}) names, written by "
                       "rclverify", ends)


def yaml_text(data: dict[str, object], header: str = "") -> str:
    """A document as YAML text (NoDL's first form; ``ament_nodl_register`` installs YAML), after
    ``header`` as a comment line when given."""
    body = yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)
    return (f"# {header}\n" if header else "") + "---\n" + body


def document_text(cn: CheckedNode, contract_file: str, header: str = "") -> str:
    """:func:`document_data` as YAML text (:func:`yaml_text`)."""
    return yaml_text(document_data(cn, contract_file), header)


__all__ = ["ContractEnd", "GENERATED_QOS", "TOPIC", "compare", "contract_ends", "document_data", "document_of",
           "document_text", "full_name", "full_type", "rcl_name_of", "type_key", "yaml_text"]
