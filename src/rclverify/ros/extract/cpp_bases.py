"""Node base classes as C++ constructors initialise them (docs/ros.md,
"Reading real code").

A ROS 2 node class names its node in its constructor's initialiser list, by
initialising its base class: ``Node("talker")``,
``rclcpp_lifecycle::LifecycleNode("brake", options)``.  Real stacks put a
base of their own between the class and rclcpp's, in a helper package
(``class Monitor : public pkg_util::LifecycleNode`` constructed with
``pkg_util::LifecycleNode("monitor", "", options)``), itself deriving from
``rclcpp_lifecycle::LifecycleNode`` and passing the name on.

Rule: in a constructor's initialiser list a qualified name (``a::B(...)``)
can only be a base class (a member is initialised by its bare name), so an
initialiser whose last part is ``LifecycleNode`` or, in a ROS 2 file, ``Node``
initialises a node base: its first argument is the node's name, its second
(when a string) the namespace.  Source of the rule: the C++ standard's
mem-initializer-id ([class.base.init]: a qualified id names a base class);
rclcpp's ``Node(const std::string & node_name, const std::string & namespace_,
const NodeOptions & options)`` and rclcpp_lifecycle's ``LifecycleNode`` of the
same signature (ROS 2 API documentation).
"""
from __future__ import annotations

_NODE_BASES = ("Node", "LifecycleNode")


def node_base(head: str, ros2: bool) -> str | None:
    """The kind of node an initialiser named ``head`` (as written, template
    arguments included) makes: ``"lifecycle"``, ``"node"``, or ``None`` when it is
    not a node base.

    ``ros2``: whether the file is ROS 2 code (mentions ``rclcpp``).  Unqualified
    ``Node``/``LifecycleNode`` and any ``rclcpp*::`` one are node bases; a name
    qualified with another namespace (``pkg_util::LifecycleNode``) is one when it
    ends in ``LifecycleNode``, or in ``Node`` in a ROS 2 file.  Never raises."""
    name = head.split("<")[0].strip().lstrip(":")
    last = name.split("::")[-1]
    if last not in _NODE_BASES:
        return None
    if "::" in name and "rclcpp" not in name and not (last == "LifecycleNode" or ros2):
        return None
    return "lifecycle" if last == "LifecycleNode" else "node"
