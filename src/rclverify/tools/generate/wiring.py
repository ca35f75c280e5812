"""Which message field carries each contract variable of a generated node (docs/generate.md).

A node's end (``nodes.Endpoint``) carries one variable (a topic) or several
(a service's request and response, an action's goal, feedback and result,
in the contract's order: paper lines 1864-1866 leave the field choice to the
generator).  The field is

* for a type generated from the contracts: the variable's field (``names.field_name(name)``);
* for ``std_msgs``' one-value messages (``Float64``, ``Bool``, ...): ``data``;
* for any other standard type: the one field the monitors' mapping gives the
  topic (``cmd_vel: {fields: [linear.x]}``, docs/monitors.md), else none: the
  generated node then leaves that variable to the hand-written logic and its
  check reads the value the logic gives.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from rclverify.tools.generate.interfaces import is_standard
from rclverify.tools.generate.nodes import NodePackage
from rclverify.targets.names import field_name
from rclverify.traces.mapping import TopicRule, rule_for

#: std_msgs messages holding one value in field ``data``
STD_DATA = frozenset({"Bool", "Byte", "Char", "Float32", "Float64", "Int8", "Int16", "Int32", "Int64", "UInt8",
                      "UInt16", "UInt32", "UInt64", "String"})


@dataclass(frozen=True)
class Wire:
    """Variable ``var`` (``in.x``) on end ``attr`` of the node, in ``part`` of its message
    (``msg``, ``request``/``response``, ``goal``/``feedback``/``result``) at field path
    ``path`` (``linear.x``; ``""``: no field known)."""

    var: str
    attr: str
    role: str
    part: str
    path: str

    def var_topic(self, np: NodePackage) -> str:
        """The topic the monitors read this variable on: the end's name, ``name/request`` and
        so on for a service's or action's part (the monitors' LINK_TOPICS)."""
        end = next(e for e in np.endpoints if e.attr == self.attr)
        return end.name.lstrip("/") if self.part == "msg" else f"{end.name.lstrip('/')}/{self.part}"

    @property
    def side(self) -> str:
        """``in`` or ``out``."""
        return self.var.split(".", 1)[0]

    @property
    def name(self) -> str:
        """The RCL variable's name."""
        return self.var.split(".", 1)[1]


def _path(ros_type: str, var: str, topic: str, rules: Mapping[str, TopicRule]) -> str:
    pkg, cls = ros_type.split("/")[0], ros_type.split("/")[-1]
    if not is_standard(ros_type):
        return field_name(var.split(".", 1)[1])
    if pkg == "std_msgs" and cls in STD_DATA:
        return "data"
    fields = list(rule_for(rules, topic.lstrip("/"), var).fields) if rules else []
    return fields[0] if len(fields) == 1 else ""


def wires(np: NodePackage, rules: Mapping[str, TopicRule] | None = None) -> list[Wire]:
    """Every variable the node's ends carry, in end order.  ``rules``: the monitors' mapping
    rules by topic (``traces.mapping.TopicRule``), used for standard types only."""
    rules = rules or {}
    out: list[Wire] = []
    for e in np.endpoints:
        vs = [v.strip() for v in e.var.split(",")]
        if e.role in ("pub", "sub"):
            parts = ["msg"]
        elif e.role.startswith("service"):
            parts = ["request", "response"]
        else:
            parts = ["goal", "feedback", "result"]
        for v, part in zip(vs, parts):
            if not v.startswith(("in.", "out.")):
                continue
            topic = e.name if part == "msg" else f"{e.name}/{part}"
            out.append(Wire(v, e.attr, e.role, part, _path(e.ros_type, v, topic, rules)))
    return out
