"""Interfaces where CMake says they are (issue 65): every path given to
``rosidl_generate_interfaces`` is read, also outside ``msg/ srv/ action/``
(``srvs/Pause.srv``, through a variable), and a type named without a package
in a ``.srv`` or ``.action`` is the same package's message (``pkg/msg/T``),
never ``pkg/srv/msg/T``.  Self-written packages."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.interfaces import generated_interfaces

PKG = ('<?xml version="1.0"?>\n<package format="3"><name>rig_msgs</name><version>0.1.0</version>'
       '<description>d</description><maintainer email="dev@example.org">a</maintainer><license>MIT</license>'
       '<buildtool_depend>ament_cmake</buildtool_depend><export><build_type>ament_cmake</build_type></export>'
       '</package>\n')
CMAKE = """cmake_minimum_required(VERSION 3.8)
project(rig_msgs)
find_package(rosidl_default_generators REQUIRED)
set(srv_files "srvs/Pause.srv")
rosidl_generate_interfaces(${PROJECT_NAME}
  "msg/Span.msg"
  ${srv_files}
  "${CMAKE_CURRENT_SOURCE_DIR}:actions/Hold.action"
  "srvs/Missing.srv"
  DEPENDENCIES builtin_interfaces
)
"""


@pytest.fixture(scope="module")
def ws(tmp_path_factory) -> Path:  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("ifaces")
    d = root / "src" / "rig_msgs"
    for rel, text in {"package.xml": PKG, "CMakeLists.txt": CMAKE, "msg/Span.msg": "float64 seconds\n",
                      "srvs/Pause.srv": "Span span\nbool now\n---\nbool ok\n",
                      "srvs/Unlisted.srv": "---\n",
                      "actions/Hold.action": "Span span\n---\nbool done\n---\nSpan left\n"}.items():
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).write_text(text)
    return root


def test_every_path_rosidl_is_given_is_read(ws: Path) -> None:
    got = [p.relative_to(ws / "src" / "rig_msgs").as_posix()
           for p in generated_interfaces(ws / "src" / "rig_msgs", "rig_msgs")]
    assert got == ["msg/Span.msg", "srvs/Pause.srv", "actions/Hold.action"]  # a missing file is not listed


def test_unqualified_types_resolve_in_their_own_package(ws: Path) -> None:
    g = scan([ws], []).graph
    fields = {k: [(f["name"], f["type"]) for f in v["fields"]] for k, v in g.types.items()}
    assert fields["rig_msgs/srv/Pause_Request"] == [("span", "rig_msgs/msg/Span"), ("now", "bool")]
    assert fields["rig_msgs/action/Hold_Feedback"] == [("left", "rig_msgs/msg/Span")]
    assert "rig_msgs/srv/Unlisted_Request" not in fields  # neither in srv/ nor given to rosidl
    assert not [n for n in g.notes if n.severity == "error"]
