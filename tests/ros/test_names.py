"""ROS 2 names as rcl resolves them (model/names.py), in process: the design article's table, the
remap rules' scope, one clear message for a bad rule.  tests/ros/test_names_rcl.py holds the same
rules against rcl itself."""
from __future__ import annotations

import pytest

from rclverify.model import names

#: ROS 2 design, "Topic and Service Names": each input under node ``my_node`` in ``/`` and in ``/my_ns``.
TABLE = [("ping", "/ping", "/my_ns/ping"), ("/ping", "/ping", "/ping"), ("~", "/my_node", "/my_ns/my_node"),
         ("~/ping", "/my_node/ping", "/my_ns/my_node/ping"), ("{node}/x", "/my_node/x", "/my_ns/my_node/x"),
         ("{ns}", "/", "/my_ns")]


def test_design_article_table() -> None:
    for name, root, in_ns in TABLE:
        assert names.expand(name, "my_node", "/") == root
        assert names.expand(name, "my_node", "/my_ns") == in_ns


def test_bad_remap_rule_is_one_message() -> None:
    with pytest.raises(names.BadName, match=r"remap rule 'odom=x'"):
        names.Remap.parse("odom=x")
    with pytest.raises(names.BadName, match=r"node name '1n'"):
        names.Remap.parse("1n:odom:=x")
    assert names.node_fqn("/r1", "relay") == "/r1/relay" and names.node_fqn("/", "relay") == "/relay"
    assert names.split_fqn("/r1/relay") == ("/r1", "relay") and names.split_fqn("/relay") == ("/", "relay")


def test_refusals_name_the_name_and_the_reason() -> None:
    with pytest.raises(names.BadName, match=r"unknown substitution \{robot\}"):
        names.expand("{robot}/odom", "relay", "/r1")
    with pytest.raises(names.BadName, match=r"'\{ns\}/x' resolves to '//x'.*'//'"):
        names.resolve("{ns}/x", "relay", "/")
    assert names.resolve("{ns}/x", "relay", "/r1") == "/r1/x"  # control: in a namespace it resolves
    with pytest.raises(names.BadName, match=r"'~' is followed by '/'"):
        names.expand("~odom", "relay", "/r1")
    assert names.expand("~o", "relay", "/r1") == "/r1/relayo"  # rcl's own leniency for a two-character name
    assert names.node_identity("relay", "/", [names.Remap.parse("relay:__node:=relay2"),
                                              names.Remap.parse("__ns:=/r2")]) == ("relay2", "/r2")
    assert names.node_identity("other", "/", [names.Remap.parse("relay:__node:=relay2")]) == ("other", "/")


def test_the_code_scan_resolves_through_the_one_resolver() -> None:
    """ros/extract/names.resolve (the scan's, ground's) gives rcl's answer for every name rcl accepts
    (the table, with the scan's ``~x`` for ``~/x``; ``{node}`` substituted, where a plain join kept it),
    and the plain rule for a name rcl refuses (control: a doubled ``/``, a program kept apart)."""
    from rclverify.ros.extract import names as scan_names
    for name, root, in_ns in TABLE[:-1]:  # the last: '{ns}' in '/' is '/', no topic
        assert scan_names.resolve(name, "/", "/my_node") == root
        assert scan_names.resolve(name, "/my_ns", "/my_ns/my_node") == in_ns
    assert scan_names.resolve("~ping", "/my_ns", "/my_ns/my_node") == "/my_ns/my_node/ping"
    assert scan_names.resolve("{node}/cmd", "/r2", "/r2/relay") == "/r2/relay/cmd"
    assert scan_names.resolve("a//b/", "/r2", "/r2/relay") == "/r2/a/b"
    assert scan_names.resolve("~status", "/", "/talker@pkg.exe") == "/talker@pkg.exe/status"
    with pytest.raises(names.BadName):
        names.expand("a//b/", "relay", "/r2")
