"""ROS 2's rules for the names a generated node uses on the ROS graph (docs/generate.md, "ROS names").

The rules are rmw's and rcl's documented validation, which ``rclpy`` and
``rclcpp`` apply when a node, publisher, subscription, service or action is
created (rmw ``validate_node_name.h``, ``validate_namespace.h``,
``validate_full_topic_name.h``; rcl ``validate_topic_name.h``; the ROS 2
design article "Topic and Service name mapping to DDS"):

* a **node name** is not empty, holds letters, digits and ``_`` only, does
  not start with a digit and has at most :data:`NODE_NAME_MAX` (255)
  characters;
* a **namespace** is ``/``, or a fully qualified name by the rules below of
  at most :data:`NAMESPACE_MAX` (245) characters;
* a **fully qualified topic or service name** starts with ``/`` and does not
  end with one, holds letters, digits, ``_`` and ``/`` only, has no ``//``
  and no token (between two ``/``) that starts with a digit, and has at most
  :data:`TOPIC_NAME_MAX` (247) characters: 255 less 8 that rmw keeps for
  the middleware's prefix (``rt/``, ``rq/``, ``rr/``).  rcl/rmw accept
  ``__`` and a trailing ``_`` in a name (the design article discourages
  them; no ROS 2 library refuses them), so they are not refused here.

A generated node runs in the root namespace (its launch files set none):
its relative names resolve to ``/<name>``, and its private namespace
``/<node>`` holds its verdict topic (``~/contract_verdict``) and the
parameter services every ``rclpy`` and ``rclcpp`` node offers
(:data:`PARAMETER_SERVICES`); an action ``a`` is the services and topics
``/a/_action/...`` of rcl_action (:data:`ACTION_PARTS`).
:func:`graph_names` lists every fully qualified name a generated node
creates, each with the RCL name it comes from.
"""
from __future__ import annotations

import re

#: rmw's largest node name (``RMW_NODE_NAME_MAX_NAME_LENGTH``)
NODE_NAME_MAX = 255
#: rmw's largest fully qualified topic or service name: 255, less 8 for the middleware's prefix
TOPIC_NAME_MAX = 255 - 8
#: rmw's largest namespace: room for the shortest name in it (``/x``)
NAMESPACE_MAX = TOPIC_NAME_MAX - 2
#: the topic a generated node publishes its verdicts on, in its private namespace (contract.py, the C++ node)
VERDICT_TOPIC = "contract_verdict"
#: the services rclpy and rclcpp create for every node, in its private namespace (the parameter services, and
#: the type description service of recent distributions)
PARAMETER_SERVICES = ("describe_parameters", "get_parameter_types", "get_parameters", "list_parameters",
                      "set_parameters", "set_parameters_atomically", "get_type_description")
#: the services and topics rcl_action makes of an action's name, the longest first
ACTION_PARTS = ("_action/cancel_goal", "_action/get_result", "_action/send_goal", "_action/feedback",
                "_action/status")

_NODE_CHARS = re.compile(r"[A-Za-z0-9_]*")
_NAME_CHARS = re.compile(r"[A-Za-z0-9_/]*")


def _bad_character(name: str, allowed: re.Pattern[str]) -> str:
    m = allowed.match(name)
    end = m.end() if m else 0
    return "" if end == len(name) else repr(name[end])


def node_name_problem(name: str) -> str:
    """Why ``name`` is no ROS 2 node name (rmw's rules, module docstring), ``""`` when it is one."""
    if not name:
        return "a node name must not be empty"
    bad = _bad_character(name, _NODE_CHARS)
    if bad:
        return f"a node name holds letters, digits and '_' only, not {bad}"
    if name[0].isdigit():
        return "a node name must not start with a digit"
    if len(name) > NODE_NAME_MAX:
        return f"it has {len(name)} characters; a node name has at most {NODE_NAME_MAX}"
    return ""


def full_name_problem(fqn: str, what: str = "topic", most: int = TOPIC_NAME_MAX) -> str:
    """Why ``fqn`` is no fully qualified ROS 2 topic or service name (``what``: the word used),
    ``""`` when it is one; ``most`` its largest length (:data:`NAMESPACE_MAX` for a namespace)."""
    if not fqn:
        return f"a {what} name must not be empty"
    if not fqn.startswith("/"):
        return f"a fully qualified {what} name starts with '/'"
    if fqn.endswith("/"):
        return f"a {what} name must not end with '/'"
    bad = _bad_character(fqn, _NAME_CHARS)
    if bad:
        return f"a {what} name holds letters, digits, '_' and '/' only, not {bad}"
    if "//" in fqn:
        return f"a {what} name must not hold '//'"
    if any(token[:1].isdigit() for token in fqn.split("/")):
        return f"no token of a {what} name may start with a digit"
    if len(fqn) > most:
        return f"fully qualified it has {len(fqn)} characters, and a fully qualified {what} name has at most {most}"
    return ""


def namespace_problem(namespace: str) -> str:
    """Why ``namespace`` is no ROS 2 namespace (rmw's rules), ``""`` when it is one."""
    return "" if namespace == "/" else full_name_problem(namespace, "namespace", NAMESPACE_MAX)


def graph_names(node: str, ends: list[tuple[str, str]]) -> list[tuple[str, str, int]]:
    """The fully qualified names a generated node ``node`` creates: ``(name, what, i)``, ``i`` the
    index in ``ends`` (``(kind, RCL name)``, kind ``topic``, ``service`` or ``action``) of the end
    the name comes from, ``-1`` for the node's own (its verdict topic and parameter services)."""
    own = f"/{node}"
    out = [(f"{own}/{VERDICT_TOPIC}", "topic", -1)]
    out += [(f"{own}/{s}", "service", -1) for s in PARAMETER_SERVICES]
    for i, (kind, name) in enumerate(ends):
        if kind == "action":
            out += [(f"/{name}/{p}", "service" if p.rsplit("/", 1)[1] in ("send_goal", "cancel_goal", "get_result")
                     else "topic", i) for p in ACTION_PARTS]
        else:
            out.append((f"/{name}", kind, i))
    return out


__all__ = ["ACTION_PARTS", "NAMESPACE_MAX", "NODE_NAME_MAX", "PARAMETER_SERVICES", "TOPIC_NAME_MAX",
           "VERDICT_TOPIC", "full_name_problem", "graph_names", "namespace_problem", "node_name_problem"]
