"""What a ROS 2 managed (lifecycle) node offers besides its code's endpoints
(docs/ros.md, "Lifecycle nodes").

A node of class ``rclcpp_lifecycle::LifecycleNode`` (C++) or
``rclpy.lifecycle.Node`` / ``LifecycleNode`` (Python) is read like any node:
its ``create_publisher`` (a ``LifecyclePublisher``), ``create_subscription``,
services and actions are edges at their call sites, and
``create_lifecycle_publisher`` (rclpy) is a publisher.  The library also makes,
for every such node, its management interface (ROS 2 design "Managed nodes";
``rclcpp_lifecycle``'s ``LifecycleNodeInterface``):

| name | role | type |
| --- | --- | --- |
| ``~/change_state`` | service server | ``lifecycle_msgs/srv/ChangeState`` |
| ``~/get_state`` | service server | ``lifecycle_msgs/srv/GetState`` |
| ``~/get_available_states`` | service server | ``lifecycle_msgs/srv/GetAvailableStates`` |
| ``~/get_available_transitions`` | service server | ``lifecycle_msgs/srv/GetAvailableTransitions`` |
| ``~/get_transition_graph`` | service server | ``lifecycle_msgs/srv/GetAvailableTransitions`` |
| ``~/transition_event`` | publisher | ``lifecycle_msgs/msg/TransitionEvent`` |

Decision: these are not edges of the graph (no line of the node's code
creates them, as none creates a node's parameter services or ``/rosout``);
the node is marked ``lifecycle`` and the grounding counts them as served
and published (:func:`implicit`), so a contract of a lifecycle manager that
calls ``/talker/change_state`` is not told that nobody serves it.
"""
from __future__ import annotations

from rclverify.ros.extract.model import GraphEdge, GraphNode, Src

_SRV = "lifecycle_msgs/srv/"
MANAGEMENT: tuple[tuple[str, str, str], ...] = (
    ("service_servers", "change_state", _SRV + "ChangeState"),
    ("service_servers", "get_state", _SRV + "GetState"),
    ("service_servers", "get_available_states", _SRV + "GetAvailableStates"),
    ("service_servers", "get_available_transitions", _SRV + "GetAvailableTransitions"),
    ("service_servers", "get_transition_graph", _SRV + "GetAvailableTransitions"),
    ("pub", "transition_event", "lifecycle_msgs/msg/TransitionEvent"),
)


def implicit(node: GraphNode, role: str) -> list[GraphEdge]:
    """The management edges of role ``role`` (``"pub"`` or ``"service_servers"``)
    that the lifecycle library makes for ``node`` (none for a node that is not
    a lifecycle node), located where the node is declared."""
    if not node.lifecycle:
        return []
    at = node.declared_at or Src(node.name)
    return [GraphEdge(f"{node.name.rstrip('/')}/{name}", t, at, None, f"~/{name}")
            for r, name, t in MANAGEMENT if r == role]
