"""ROS names as users write them in RCL (docs/rcl-language.md, "Topic and service names"): a topic in a
namespace (``safety/stop``) or a global one (``/safety/stop``) is read, kept as written, and keyed by the
system model and the monitors by its full name; a private name (``~/stop``) is a located error.
In-process and cheap: parsing, type checking, the system model and the online monitor engine."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.backends.monitors.node_topics import node_topics
from rclverify.backends.monitors.online import OnlineEngine
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import to_rcl
from rclverify.lang.typecheck import check, load
from rclverify.model.system.model import build

SYSTEM = """\
node Button {
  inputs( )
  outputs( pressed : BOOL )
  topics( std_msgs/Bool safety/stop matches(out.pressed) )
  guarantee( out.pressed or not out.pressed )
}
node Base {
  inputs( stop : BOOL )
  outputs( halted : BOOL )
  topics( std_msgs/Bool /safety/stop matches(in.stop), std_msgs/Bool base/halted matches(out.halted) )
  services( std_srvs/SetBool safety/estop serves(in.stop, out.halted) )
  guarantee( in.stop -> out.halted )
}
"""


@pytest.fixture(scope="module")
def checked(tmp_path_factory: pytest.TempPathFactory) -> object:
    path = tmp_path_factory.mktemp("names") / "names.rcl"
    path.write_text(SYSTEM, encoding="utf-8")
    return load([path])


def test_namespaced_and_global_names_are_read_as_written(checked: object) -> None:
    base = checked.nodes["Base"].node  # type: ignore[attr-defined]
    assert [t.field for t in base.topics] == ["/safety/stop", "base/halted"]
    assert [t.key for t in base.topics] == ["safety/stop", "base/halted"]
    assert [lk.name for lk in base.links] == ["safety/estop"]
    stop = base.topics[0]
    assert (stop.name_loc.line, stop.name_loc.col) == (10, 25)
    # the canonical form prints them as written
    printed = to_rcl(parse_text(SYSTEM, "names.rcl"))
    assert "std_msgs/Bool /safety/stop matches(in.stop)" in printed and "safety/estop serves" in printed


def test_the_system_model_joins_a_relative_and_a_global_name_of_one_topic(checked: object) -> None:
    model = build(checked)  # type: ignore[arg-type]
    [link] = [l for l in model.links if l.to_node == "Base" and l.to_var == "stop"]
    assert (link.from_node, link.from_var, link.via) == ("Button", "pressed", "topic")


def test_the_monitors_key_the_topic_by_its_full_name(checked: object) -> None:
    nodes = checked.nodes  # type: ignore[attr-defined]
    assert list(node_topics(nodes["Base"])[0]) == ["safety/stop", "base/halted", "safety/estop/request",
                                                   "safety/estop/response"]
    got: list = []
    eng = OnlineEngine(checked, list(nodes.values()), {}, 2.0, on_verdict=got.append)
    eng.push("/safety/stop", {"data": True}, 1.0)  # as ROS 2 names it on the wire
    eng.push("/base/halted", {"data": False}, 1.1)
    eng.tick(5.0)
    eng.finish()
    [verdict] = [v for v in got if v.node == "Base"]
    assert verdict.verdict == "violated" and verdict.values == {"in.stop": "TRUE", "out.halted": "FALSE"}


@pytest.mark.parametrize("name", ["~/stop", "safety/stop"])
def test_a_private_name_is_a_located_error(name: str) -> None:
    src = SYSTEM.replace("/safety/stop matches(in.stop)", f"{name} matches(in.stop)")
    if name == "safety/stop":  # the control: the relative name checks
        check([parse_text(src, "names.rcl")])
        return
    with pytest.raises(RclError) as info:
        check([parse_text(src, "names.rcl")])
    [d] = info.value.diagnostics
    assert (d.loc.line, d.loc.col, d.code) == (10, 25, "E-topic-name"), str(d)
    assert "a private name resolves against the running node's own name" in d.message
    assert "/<node name>/stop" in d.message


def test_a_name_that_is_no_ros_name_is_a_syntax_error() -> None:
    with pytest.raises(RclError) as info:
        parse_text(SYSTEM.replace("/safety/stop matches", "/safety/2stop matches"), "names.rcl")
    [d] = info.value.diagnostics
    assert d.loc.line == 10, str(d)
