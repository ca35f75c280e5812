"""The system model's JSON, as types: ``artifacts/system/model.json`` and the view the report draws.

:meth:`rclverify.model.system.model.SystemModel.to_json` writes
:class:`ModelJson` (the check stage seals its text, every stage hashes it);
:meth:`~rclverify.model.system.model.SystemModel.view` gives
:class:`ModelView`, the same with each node's status and the loops twice
(the graph's cycles, and the components rule R4 is applied to).
"""
# No ``from __future__ import annotations``: the keys are read from evaluated annotations.
from typing import TypedDict


class LinkJson(TypedDict):
    """A connection: the producer's output ``from_node.from_var`` feeds ``to_node.to_var``; ``via`` how it was found."""
    from_node: str
    from_var: str
    to_node: str
    to_var: str
    via: str


class EnvironmentInput(TypedDict):
    """An input no node produces: the node, the variable and its RCL type."""
    node: str
    var: str
    type: str


class ModelJson(TypedDict):
    """The system model: the nodes in source order, the connections, the environment inputs, the loops."""
    nodes: list[str]
    connections: list[LinkJson]
    environment_inputs: list[EnvironmentInput]
    loops: list[list[str]]


class NodeStatus(TypedDict):
    """A node of the drawn model and its roll-up status."""
    name: str
    status: str


class ModelView(TypedDict):
    """:class:`ModelJson` as the report and the diagram show it: each node with its status, ``loops`` the
    graph's cycles, ``loop_components`` the strongly connected components rule R4 is applied to."""
    nodes: list[NodeStatus]
    connections: list[LinkJson]
    environment_inputs: list[EnvironmentInput]
    loops: list[list[str]]
    loop_components: list[list[str]]
