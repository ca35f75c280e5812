"""The plan's ``ros:`` section read as its record (model/plan/ros_section.py): each reader decodes the
section as written once and reads attributes; a key or a value the plan's schema refuses is refused."""
from __future__ import annotations

import msgspec
import pytest

from rclverify.model.plan.ros_section import RosSection

SECTION = {"workspaces": ["ros"], "launch": ["ros/a.launch"], "args": {"sim": True, "rate": 10, "name": "r1"},
           "bags": ["bags/run1"], "mapping": "traces/mapping.yaml", "nodes": {"Planner": "/planner"},
           "fields": {"cmd": ["linear.x"]}, "ignore": ["/rosout"], "external": ["/clock"]}


def test_the_section_as_written_reads_typed() -> None:
    ros = RosSection.of(SECTION)
    assert (ros.workspaces, ros.launch, ros.bags, ros.mapping) == (("ros",), ("ros/a.launch",), ("bags/run1",),
                                                                   "traces/mapping.yaml")
    assert ros.args == {"sim": True, "rate": 10, "name": "r1"} and ros.nodes == {"Planner": "/planner"}
    assert ros.fields == {"cmd": ["linear.x"]} and (ros.ignore, ros.external) == (("/rosout",), ("/clock",))
    assert RosSection.of(ros) is ros
    # control: no section (absent, null or empty) reads as every field empty
    for none in (None, {}):
        empty = RosSection.of(none)
        assert (empty.workspaces, empty.mapping, empty.nodes, empty.args) == ((), "", {}, {})


@pytest.mark.parametrize("bad, where", [({"workspace": ["ros"]}, "workspace"), ({"bags": "run1"}, r"\$\.bags"),
                                        ({"nodes": {"Planner": 3}}, r"\$\.nodes")])
def test_a_key_or_value_the_schema_refuses_is_refused(bad: dict[str, object], where: str) -> None:
    with pytest.raises(msgspec.ValidationError, match=where):
        RosSection.of(bad)
