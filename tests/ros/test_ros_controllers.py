"""ros2_control controllers as nodes (issue 65): a controller class exported
with ``pluginlib_export_plugin_description_file(controller_interface ...)``
runs on a node of its own, named by the controller manager's parameter file
(``<name>: type: pkg/Class``); its ``get_node()`` endpoints are that node's
(``~/x`` under its name, an absolute ``/tf`` kept), the realtime publisher
that wraps a publisher is no second endpoint; a controller no file names is
a located note per endpoint, never an edge; a ``type`` no scanned package
exports is a located note.  Self-written packages."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.ros.graph.scan import scan

FILES = {'rig_bringup/CMakeLists.txt': 'cmake_minimum_required(VERSION 3.8)\nproject(rig_bringup)\n', 'rig_bringup/config/controllers.yaml': 'controller_manager:\n  ros__parameters:\n    update_rate: 100\n    speed_limiter:\n      type: rig_control/SpeedLimiter\n    state_reporter:\n      type: rig_control/Missing\n\nspeed_limiter:\n  ros__parameters:\n    limit: 1.5\n', 'rig_bringup/package.xml': '<?xml version="1.0"?>\n<package format="3"><name>rig_bringup</name><version>0.1.0</version><description>d</description>\n<maintainer email="dev@example.org">a</maintainer><license>MIT</license>\n<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend><depend>std_srvs</depend>\n<export><build_type>ament_cmake</build_type></export></package>\n', 'rig_control/CMakeLists.txt': 'cmake_minimum_required(VERSION 3.8)\nproject(rig_control)\nfind_package(controller_interface REQUIRED)\nadd_library(rig_control SHARED src/speed_limiter.cpp src/watchdog.cpp)\npluginlib_export_plugin_description_file(controller_interface rig_control.xml)\n', 'rig_control/package.xml': '<?xml version="1.0"?>\n<package format="3"><name>rig_control</name><version>0.1.0</version><description>d</description>\n<maintainer email="dev@example.org">a</maintainer><license>MIT</license>\n<buildtool_depend>ament_cmake</buildtool_depend><depend>rclcpp</depend><depend>std_msgs</depend><depend>std_srvs</depend>\n<export><build_type>ament_cmake</build_type></export></package>\n', 'rig_control/rig_control.xml': '<library path="rig_control">\n  <class name="rig_control/SpeedLimiter" type="rig_control::SpeedLimiter" base_class_type="controller_interface::ControllerInterface">\n    <description>Limits speed.</description>\n  </class>\n  <class name="rig_control/Watchdog" type="rig_control::Watchdog" base_class_type="controller_interface::ControllerInterface">\n    <description>Watches.</description>\n  </class>\n</library>\n', 'rig_control/src/speed_limiter.cpp': '#include <controller_interface/controller_interface.hpp>\n#include <realtime_tools/realtime_publisher.hpp>\n#include <geometry_msgs/msg/twist_stamped.hpp>\n#include <tf2_msgs/msg/tf_message.hpp>\n#include <std_srvs/srv/trigger.hpp>\n\nnamespace rig_control\n{\nconstexpr auto LIMITED_TOPIC = "~/limited";\nconstexpr auto TF_TOPIC = "/tf";\n\nclass SpeedLimiter : public controller_interface::ControllerInterface\n{\npublic:\n  controller_interface::CallbackReturn on_configure(const rclcpp_lifecycle::State &) override\n  {\n    limited_ = get_node()->create_publisher<geometry_msgs::msg::TwistStamped>(LIMITED_TOPIC, 10);\n    rt_limited_ = std::make_shared<realtime_tools::RealtimePublisher<geometry_msgs::msg::TwistStamped>>(limited_);\n    tf_ = get_node()->create_publisher<tf2_msgs::msg::TFMessage>(TF_TOPIC, 10);\n    cmd_ = get_node()->create_subscription<geometry_msgs::msg::TwistStamped>(\n      "~/cmd", 10, [](geometry_msgs::msg::TwistStamped::SharedPtr) {});\n    reset_ = get_node()->create_service<std_srvs::srv::Trigger>("~/reset", [](auto, auto) {});\n    return controller_interface::CallbackReturn::SUCCESS;\n  }\n  rclcpp::Publisher<geometry_msgs::msg::TwistStamped>::SharedPtr limited_;\n  std::shared_ptr<realtime_tools::RealtimePublisher<geometry_msgs::msg::TwistStamped>> rt_limited_;\n  rclcpp::Publisher<tf2_msgs::msg::TFMessage>::SharedPtr tf_;\n  rclcpp::Subscription<geometry_msgs::msg::TwistStamped>::SharedPtr cmd_;\n  rclcpp::Service<std_srvs::srv::Trigger>::SharedPtr reset_;\n};\n}  // namespace rig_control\n\n#include <pluginlib/class_list_macros.hpp>\nPLUGINLIB_EXPORT_CLASS(rig_control::SpeedLimiter, controller_interface::ControllerInterface)\n', 'rig_control/src/watchdog.cpp': '#include <controller_interface/controller_interface.hpp>\n#include <std_msgs/msg/bool.hpp>\n\nnamespace rig_control\n{\nclass Watchdog : public controller_interface::ControllerInterface\n{\npublic:\n  controller_interface::CallbackReturn on_configure(const rclcpp_lifecycle::State &) override\n  {\n    alive_ = get_node()->create_publisher<std_msgs::msg::Bool>("~/alive", 10);\n    return controller_interface::CallbackReturn::SUCCESS;\n  }\n  rclcpp::Publisher<std_msgs::msg::Bool>::SharedPtr alive_;\n};\n}  // namespace rig_control\n'}


@pytest.fixture(scope="module")
def graph(tmp_path_factory):  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("controllers")
    for rel, text in FILES.items():
        (root / "src" / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / "src" / rel).write_text(text)
    return scan([root], [], base=root).graph


def test_a_named_controller_is_a_node_with_its_endpoints(graph) -> None:  # type: ignore[no-untyped-def]
    assert set(graph.nodes) == {"/speed_limiter"}
    n = graph.nodes["/speed_limiter"]
    got = {(r, e.topic, e.msg_type) for r in ("pub", "sub", "service_servers") for e in n.edges_of(r)}
    assert got == {("pub", "/speed_limiter/limited", "geometry_msgs/msg/TwistStamped"),
                   ("pub", "/tf", "tf2_msgs/msg/TFMessage"),
                   ("sub", "/speed_limiter/cmd", "geometry_msgs/msg/TwistStamped"),
                   ("service_servers", "/speed_limiter/reset", "std_srvs/srv/Trigger")}
    assert n.lifecycle and n.declared_at.file == "src/rig_bringup/config/controllers.yaml"


def test_an_unnamed_controller_is_a_note_per_endpoint(graph) -> None:  # type: ignore[no-untyped-def]
    said = [n for n in graph.notes if n.src.file == "src/rig_control/src/watchdog.cpp"]
    assert [(n.src.line, n.message.split(" exported in ")[0]) for n in said] == [
        (11, "publisher of plugin rig_control::Watchdog (a controller_interface::ControllerInterface")]
    assert "no controller manager's parameter file names it ('<name>: type: rig_control/Watchdog')" in said[0].message


def test_a_type_nobody_exports_is_a_note(graph) -> None:  # type: ignore[no-untyped-def]
    said = [n for n in graph.notes if n.src.file.endswith("controllers.yaml")]
    assert [(n.src.line, n.message) for n in said] == [
        (7, "controller state_reporter is a rig_control/Missing, which no scanned package exports "
            "(pluginlib_export_plugin_description_file or a package.xml export): its endpoints are unknown")]
