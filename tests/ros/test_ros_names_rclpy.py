"""The ROS name rules of ``rclverify generate ros2`` (tools/generate/rosnames.py) held against
rclpy itself: its validators (rcl's and rmw's) answer as the rules do on every name below, and a
node of the longest accepted name starts with its verdict publisher, one character more does not
(its parameter services).  Runs in ROS 2's Python (tests/_ros2.py); skipped without it."""
from __future__ import annotations

import json
import subprocess

from rclverify.tools.generate import rosnames

from _ros2 import ros2_env, ros2_python

NODES = ["a", "_a", "a__b_", "1a", "a-b", "a'", "", "n" * 255, "n" * 256]
TOPICS = ["/a", "/a/b", "/a__b_/c_", "a", "/a/", "/", "/a//b", "/a/1b", "/a'", "/a b", "/" + "t" * 246, "/" + "t" * 247]
NAMESPACES = ["/", "/a", "/a/b", "/a/", "a", "/1a", "/" + "s" * 244, "/" + "s" * 245]

PROBE = """
import json, sys
import rclpy
from rclpy.validate_node_name import validate_node_name
from rclpy.validate_full_topic_name import validate_full_topic_name
from rclpy.validate_namespace import validate_namespace
from rclpy.node import Node
from std_msgs.msg import String
names = json.loads(sys.argv[1])
def ok(f, n):
    try:
        f(n)
        return True
    except Exception:
        return False
out = {k: [ok(f, n) for n in names[k]] for k, f in (("nodes", validate_node_name),
       ("topics", validate_full_topic_name), ("namespaces", validate_namespace))}
rclpy.init()
starts = []
for n in names["started"]:
    try:
        node = Node(n)
        node.create_publisher(String, "~/contract_verdict", 10)
        node.destroy_node()
        starts.append(True)
    except Exception:
        starts.append(False)
rclpy.shutdown()
out["started"] = starts
print(json.dumps(out))
"""


def test_the_rules_answer_as_rclpy_does(tmp_path) -> None:
    longest = rosnames.TOPIC_NAME_MAX - len("/") - len("/set_parameters_atomically")
    names = {"nodes": NODES, "topics": TOPICS, "namespaces": NAMESPACES,
             "started": ["n" * longest, "n" * (longest + 1)]}
    p = subprocess.run([str(ros2_python()), "-c", PROBE, json.dumps(names)], capture_output=True, text=True,
                       timeout=120, env=ros2_env(tmp_path), cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    said = json.loads(p.stdout.strip().splitlines()[-1])
    assert said["nodes"] == [not rosnames.node_name_problem(n) for n in NODES]
    assert said["topics"] == [not rosnames.full_name_problem(n) for n in TOPICS]
    assert said["namespaces"] == [not rosnames.namespace_problem(n) for n in NAMESPACES]
    assert said["started"] == [True, False]
    ours = [not any(rosnames.full_name_problem(f) for f, _, i in rosnames.graph_names(n, []) if i < 0)
            for n in names["started"]]
    assert ours == [True, False]
