"""Endpoints that C++ library helpers create for the node (docs/ros.md,
"Reading real code"): the helper object is made (declared with arguments,
a member initialised in a constructor, ``new``, ``std::make_shared``/
``make_unique``) or one of its methods called, and the helper's own code
creates ROS topics or services.  What each creates (from each library's
documented API and source):

| helper | endpoints |
| --- | --- |
| ``tf2_ros::TransformBroadcaster`` / ``tf::TransformBroadcaster`` | publishes ``/tf`` (``tf2_msgs/msg/TFMessage``) |
| ``tf2_ros::StaticTransformBroadcaster`` | publishes ``/tf_static`` |
| ``tf2_ros::TransformListener`` / ``tf::TransformListener`` | subscribes ``/tf`` and ``/tf_static``; ROS 2's ``TransformListener(buffer[, spin_thread])``, given no node, on tf2's own node (:func:`own_node`) |
| ``message_filters::Subscriber<T>(h, name, ...)`` / ``.subscribe(h, name, ...)`` | subscribes ``name`` (``T``) |
| ``image_transport::SubscriberFilter(h, name, ...)`` / ``.subscribe(h, name, ...)`` | subscribes ``name`` (``sensor_msgs/msg/Image``) |
| ``image_transport::ImageTransport`` ``advertise``/``subscribe``; ROS 2 ``image_transport::create_publisher``/``create_subscription`` | ``name`` (``sensor_msgs/msg/Image``); the ``Camera`` forms add ``camera_info`` beside it (``sensor_msgs/msg/CameraInfo``) |
| ``interactive_markers::InteractiveMarkerServer(ns, ...)`` | ROS 1: publishes ``ns/update``, ``ns/update_full``, subscribes ``ns/feedback``; ROS 2: publishes ``ns/update``, subscribes ``ns/feedback``, serves ``ns/get_interactive_markers`` |
| ``rclcpp::ParameterEventHandler``, ``on_parameter_event`` | subscribes ``/parameter_events`` (``rcl_interfaces/msg/ParameterEvent``) |
| ``ros::topic::waitForMessage<T>(name, ...)`` | subscribes ``name`` |
| ``rclcpp::create_publisher<T>(node, name, ...)`` / ``create_subscription<T>`` (free functions) | ``name`` |
| ``diagnostic_updater::Updater`` (ROS 1 and 2) | publishes ``/diagnostics`` (``diagnostic_msgs/msg/DiagnosticArray``) |
| ``dynamic_reconfigure::Server<Config>([mutex,] [h])`` | through ``h`` (default ``~``): serves ``set_parameters`` (``dynamic_reconfigure/srv/Reconfigure``), publishes ``parameter_descriptions`` (``dynamic_reconfigure/msg/ConfigDescription``) and ``parameter_updates`` (``dynamic_reconfigure/msg/Config``) |
| ``dynamic_reconfigure::Client<Config>(name, ...)`` | calls ``name/set_parameters``, subscribes ``name/parameter_descriptions`` and ``name/parameter_updates`` |
| ``self_test::TestRunner([h, [ph]])`` | serves ``self_test`` (``diagnostic_msgs/srv/SelfTest``) through ``ph`` (default ``~``) |
| ``camera_info_manager::CameraInfoManager(h, ...)`` | serves ``set_camera_info`` (``sensor_msgs/srv/SetCameraInfo``) through ``h`` |
| ``bond::Bond(topic, id, ...)`` (bondcpp, ROS 1 and 2) | publishes and subscribes ``topic`` (``bond/msg/Status``): the heartbeat |
| Autoware's ``InterProcessPollingSubscriber<T>(node, name, ...)`` (``autoware_utils``, ``tier4_autoware_utils``; also a default member initializer ``{this, name}``) | subscribes ``name`` (``T``) on ``node`` |
| ``realtime_tools::RealtimePublisher<T>(h, name, ...)`` / ``.init(h, name, ...)`` (ROS 1) | publishes ``name`` (``T``) through ``h``; ROS 2's ``RealtimePublisher<T>(publisher)`` wraps a publisher already read |

Each spec is ``(role, name value, type, handle value)``; a handle is the
node handle the helper was given (its namespace applies to the name).
"""
from __future__ import annotations

from typing import Any, Callable

from rclverify.ros.extract import symbols
from rclverify.ros.extract.cpp_types import message_type, split_template

Spec = tuple[str, symbols.Val, "str | None", symbols.Val]
Value = Callable[[Any], symbols.Val]

TF = "tf2_msgs/msg/TFMessage"
IMAGE = "sensor_msgs/msg/Image"
INFO = "sensor_msgs/msg/CameraInfo"
VIS = "visualization_msgs/msg/"
BOND = "bond/msg/Status"
EVENTS = ("sub", symbols.lit("/parameter_events"), "rcl_interfaces/msg/ParameterEvent", None)

DIAGNOSTICS = ("pub", symbols.lit("/diagnostics"), "diagnostic_msgs/msg/DiagnosticArray", None)
PRIVATE: symbols.Val = ("nh", (("ns", symbols.lit("~")),))
RECONF = "dynamic_reconfigure/"

#: helper classes whose construction creates endpoints, by last name part
CONSTRUCTED = {"TransformBroadcaster", "StaticTransformBroadcaster", "TransformListener", "Subscriber",
               "InteractiveMarkerServer", "ParameterEventHandler", "CameraPublisher", "CameraSubscriber",
               "Updater", "Server", "Client", "TestRunner", "RealtimePublisher", "CameraInfoManager", "Bond",
               "SubscriberFilter", "InterProcessPollingSubscriber"}
#: helper methods that create endpoints, by the receiver's class (last name part)
METHODS = {"ImageTransport": {"advertise", "subscribe", "advertiseCamera", "subscribeCamera"},
           "Subscriber": {"subscribe"}, "SubscriberFilter": {"subscribe"}, "AsyncParametersClient": {"on_parameter_event"},
           "SyncParametersClient": {"on_parameter_event"}, "RealtimePublisher": {"init"}}


def info_topic(image: symbols.Val) -> symbols.Val:
    """The ``camera_info`` topic beside image topic ``image`` (:func:`symbols.camera_info`)."""
    return symbols.camera_info(image)


def _image(kind: str, camera: bool, name: symbols.Val, h: symbols.Val) -> list[Spec]:
    out: list[Spec] = [(kind, name, IMAGE, h)]
    if camera:
        out.append((kind, info_topic(name), INFO, h))
    return out


def _markers(ns: symbols.Val, h: symbols.Val, ros2: bool) -> list[Spec]:
    def under(s: str) -> symbols.Val:
        return symbols.cat([ns, symbols.lit("/" + s)]) if ns is not None else None
    out: list[Spec] = [("pub", under("update"), VIS + "InteractiveMarkerUpdate", h),
                       ("sub", under("feedback"), VIS + "InteractiveMarkerFeedback", h)]
    if ros2:
        out.append(("service_servers", under("get_interactive_markers"),
                    "visualization_msgs/srv/GetInteractiveMarkers", h))
    else:
        out.append(("pub", under("update_full"), VIS + "InteractiveMarkerInit", h))
    return out


#: what is said at a ``tf2_ros::TransformListener`` made without a node (:func:`own_node`)
OWN_NODE_SAID = ("tf2_ros::TransformListener made without a node subscribes /tf and /tf_static on tf2's own node "
                 "(transform_listener_impl_...), not on this one")


def own_node_of_values(type_text: str, args: list[Any]) -> bool:
    """:func:`own_node` for a member initialised in a constructor the linker
    reads (``args`` are argument values, the member's type from its class's
    header): the buffer alone."""
    head, _ = split_template(type_text.replace(" ", "").replace("\n", ""))
    return head.split("::")[-1] == "TransformListener" and "tf2_ros" in head and len(args) == 1


def own_node(type_text: str, args: list[Any], ros2: bool) -> bool:
    """Whether a ROS 2 ``tf2_ros::TransformListener`` made with syntax nodes
    ``args`` creates its own node for ``/tf`` and ``/tf_static``: given the
    buffer alone or with the ``spin_thread`` flag (``true``/``false``), tf2_ros
    makes a node of its own (``transform_listener_impl_...``, tf2_ros'
    ``transform_listener.h``); given a node, it subscribes on that node."""
    head, _ = split_template(type_text.replace(" ", "").replace("\n", ""))
    if not ros2 or head.split("::")[-1] != "TransformListener" or "tf2_ros" not in head or not args:
        return False
    rest = [a for a in args[1:] if getattr(a, "type", None) not in ("comment",)]
    return len(rest) == 0 or (len(rest) == 1 and getattr(rest[0], "type", "") in ("true", "false"))


def constructed(type_text: str, args: list[Any], val: Value, ros2: bool,
                aliases: dict[str, str] | None = None) -> list[Spec] | None:
    """The endpoints a helper of class ``type_text`` creates when made with
    ``args`` (syntax nodes; ``val`` gives their values); ``None`` when the class
    is no endpoint-creating helper."""
    t = type_text.replace(" ", "").replace("\n", "")
    if ">" in t and "::" in t[t.rindex(">"):]:
        return None  # a nested type of a helper (Server<C>::CallbackType), not the helper
    head, targs = split_template(t)
    if aliases and "::" not in head and head in aliases:  # typedef dynamic_reconfigure::Server<C> Srv;
        head, targs = split_template(aliases[head].replace(" ", ""))
    last = head.split("::")[-1]
    if last not in CONSTRUCTED:
        return None
    if last in ("Updater", "Server", "Client", "TestRunner"):
        return _ros1_tools(head, last, [val(a) for a in args])
    if last == "RealtimePublisher":
        return _realtime(head, targs, args, val, aliases)
    if last == "CameraInfoManager" and head.startswith("camera_info_manager") and args:
        h = val(args[0])
        return [("service_servers", symbols.lit("set_camera_info"), "sensor_msgs/srv/SetCameraInfo",
                 h if h is not None and h[0] == "nh" else None)]
    if last == "Bond" and head.startswith("bond") and args:  # bondcpp: Bond(topic, id, [node, ...])
        return [("pub", val(args[0]), BOND, None), ("sub", val(args[0]), BOND, None)]
    if last == "TransformBroadcaster" and ("tf" in head or not head.count("::")):
        return [("pub", symbols.lit("/tf"), TF, None)]
    if last == "StaticTransformBroadcaster":
        return [("pub", symbols.lit("/tf_static"), TF, None)]
    if last == "TransformListener":
        return [("sub", symbols.lit("/tf"), TF, None), ("sub", symbols.lit("/tf_static"), TF, None)]
    if last == "Subscriber" and head.startswith("message_filters"):
        if len(args) < 2:
            return []  # made empty: .subscribe(...) names the topic
        return [("sub", val(args[1]), message_type(targs[0], aliases) if targs else None, val(args[0]))]
    if last == "InterProcessPollingSubscriber" and "autoware" in head + type_text and len(args) >= 2:
        return [("sub", val(args[1]), message_type(targs[0], aliases) if targs else None, None)]
    if last == "InteractiveMarkerServer" and args:
        return _markers(val(args[0]), None, ros2)
    if last == "ParameterEventHandler" and "rclcpp" in head:
        return [EVENTS]
    if last in ("CameraPublisher", "CameraSubscriber") and head.startswith("image_transport") and len(args) >= 2:
        return _image("pub" if last == "CameraPublisher" else "sub", True, val(args[1]), val(args[0]))
    if last == "SubscriberFilter" and head.startswith("image_transport"):
        return _image("sub", False, val(args[1]), val(args[0])) if len(args) >= 2 else []
    return None


def _ros1_tools(head: str, last: str, vals: list[symbols.Val]) -> list[Spec] | None:
    """diagnostic_updater, dynamic_reconfigure and self_test helpers made with
    argument values ``vals`` (see the module table)."""
    handles = [v for v in vals if v is not None and v[0] == "nh"]
    if last == "Updater" and head.startswith("diagnostic_updater"):
        return [DIAGNOSTICS]
    if last == "Server" and head.startswith("dynamic_reconfigure"):
        return reconfigure_server(handles[-1] if handles else PRIVATE)
    if last == "Client" and head.startswith("dynamic_reconfigure") and vals:
        return reconfigure_client(vals[0], handles[-1] if handles else None)
    if last == "TestRunner" and head.startswith("self_test"):
        return [("service_servers", symbols.lit("self_test"), "diagnostic_msgs/srv/SelfTest",
                 handles[1] if len(handles) >= 2 else PRIVATE)]
    return None


def _realtime(head: str, targs: list[str], args: list[Any], val: Value,
              aliases: dict[str, str] | None) -> list[Spec] | None:
    """``realtime_tools::RealtimePublisher<T>(h, name, queue[, latched])`` (ROS 1), or its
    ``init`` with the same arguments; made with one argument (ROS 2: an existing
    publisher) or none, it creates nothing of its own."""
    if "realtime_tools" not in head and "::" in head:
        return None
    if len(args) < 2 or not targs:
        return []
    return [("pub", val(args[1]), message_type(targs[0], aliases), val(args[0]))]


def reconfigure_server(h: symbols.Val) -> list[Spec]:
    """A dynamic_reconfigure server's endpoints through handle ``h``."""
    return [("service_servers", symbols.lit("set_parameters"), RECONF + "srv/Reconfigure", h),
            ("pub", symbols.lit("parameter_descriptions"), RECONF + "msg/ConfigDescription", h),
            ("pub", symbols.lit("parameter_updates"), RECONF + "msg/Config", h)]


def reconfigure_client(name: symbols.Val, h: symbols.Val) -> list[Spec]:
    """A dynamic_reconfigure client's endpoints for the server named ``name``."""
    def under(s: str) -> symbols.Val:
        return symbols.cat([name, symbols.lit("/" + s)]) if name is not None else None
    return [("service_clients", under("set_parameters"), RECONF + "srv/Reconfigure", h),
            ("sub", under("parameter_descriptions"), RECONF + "msg/ConfigDescription", h),
            ("sub", under("parameter_updates"), RECONF + "msg/Config", h)]


def method(recv_type: str, name: str, args: list[Any], targs: list[str], val: Value, handle: symbols.Val,
           aliases: dict[str, str] | None = None) -> list[Spec] | None:
    """The endpoints a helper's method call creates (receiver of class ``recv_type``,
    made with node handle ``handle``); ``None`` when it is none of :data:`METHODS`."""
    head, rtargs = split_template(recv_type.replace(" ", "").replace("&", "").replace("*", ""))
    while head.split("::")[-1] in ("shared_ptr", "unique_ptr") and rtargs:  # a helper held by pointer
        head, rtargs = split_template(rtargs[0].replace("const", ""))
    for ptr in ("::SharedPtr", "::UniquePtr", "::Ptr", "::ConstSharedPtr"):
        head = head[: -len(ptr)] if head.endswith(ptr) else head
    last = head.split("::")[-1]
    if name not in METHODS.get(last, ()):
        return None
    if last == "RealtimePublisher":
        return _realtime(head, rtargs, args, val, aliases)
    if last == "ImageTransport" and args:
        kind = "pub" if name.startswith("advertise") else "sub"
        return _image(kind, name.endswith("Camera"), val(args[0]), handle)
    if last == "Subscriber" and head.startswith("message_filters") and len(args) >= 2:
        return [("sub", val(args[1]), message_type(rtargs[0], aliases) if rtargs else None, val(args[0]))]
    if last == "SubscriberFilter" and head.startswith("image_transport") and len(args) >= 2:
        return _image("sub", False, val(args[1]), val(args[0]))
    if name == "on_parameter_event":
        return [EVENTS]
    return []


def free(name: str, targs: list[str], args: list[Any], val: Value,
         aliases: dict[str, str] | None = None) -> list[Spec] | None:
    """The endpoints a free function call creates (``name`` qualified as written);
    ``None`` when it is none of the helpers above."""
    last = name.split("::")[-1]
    t = message_type(targs[0], aliases) if targs else None
    if name.endswith("topic::waitForMessage") and args:
        return [("sub", val(args[0]), t, val(args[1]) if len(args) >= 2 else None)]
    if name.startswith("image_transport::") and last in ("create_publisher", "create_subscription",
                                                          "create_camera_publisher", "create_camera_subscription"):
        if len(args) < 2:
            return []
        return _image("pub" if "publisher" in last else "sub", "camera" in last, val(args[1]), None)
    if name in ("rclcpp::create_publisher", "rclcpp::create_subscription") and len(args) >= 2:
        return [("pub" if last == "create_publisher" else "sub", val(args[1]), t, None)]
    if last == "on_parameter_event" and "ParametersClient" in name:
        return [EVENTS]
    return None
