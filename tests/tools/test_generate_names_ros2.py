"""Hostile RCL names on real ROS 2 (issue 63 row 10; docs/generate.md, "Names").

A node named ``class`` whose inputs are ``x'`` and ``lambda`` and whose output is ``class``:
``rclverify generate ros2`` renames what Python, C, C++ and rosidl cannot spell (package
``class_node``, fields ``x_prime``, ``lambda_field``, ``class_field``, ``step(x_prime,
lambda_)``) and keeps the ROS names (node ``class``).  The tree is built with colcon in the
ROS 2 Python (rosidl's C, C++ and Python generators and typesupports compile the renamed
fields), the node is started from its installed entry point and driven by a real rclpy client
on Fast DDS: it answers with ``class_field = 2 * x_prime`` and its carried contract layer
reports a broken assumption on ``/class/contract_verdict`` with the RCL names (``in.x'``).
The build runs once for the module (its wall time is printed)."""
from __future__ import annotations

import json
import subprocess

import pytest

from _procs import stop, wait_for
from _ros2 import colcon_build, install_env, ros2_env, ros2_python, start_node
from rclverify.cli.commands import main

CONTRACT = """\
node class {
  inputs( x' : REAL, lambda : BOOL )
  outputs( class : REAL )
  topics( hostile_msgs/Reading reading matches(in.x'), hostile_msgs/Flag flag matches(in.lambda),
          hostile_msgs/Out result matches(out.class) )
  assume( in.x' >= 0 )
  guarantee( out.class == 2 * in.x' )
}
"""

STUB = "``{output name: value}``.\"\"\"\n    return {}\n"

CLIENT = """\
import json, time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from std_msgs.msg import String
from hostile_msgs.msg import Flag, Out, Reading

rclpy.init()
n = rclpy.create_node('probe')
got = {'result': [], 'verdicts': []}
n.create_subscription(Out, 'result', lambda m: got['result'].append(m.class_field), 10)
n.create_subscription(String, '/class/contract_verdict', lambda m: got['verdicts'].append(json.loads(m.data)), 10)
reading = n.create_publisher(Reading, 'reading', 10)
flag = n.create_publisher(Flag, 'flag', 10)
ex = SingleThreadedExecutor()
ex.add_node(n)


def spin_until(cond, timeout):
    end = time.monotonic() + timeout
    while not cond() and time.monotonic() < end:
        ex.spin_once(timeout_sec=0.1)
    return cond()


out = {}
out['matched'] = spin_until(lambda: reading.get_subscription_count() > 0 and flag.get_subscription_count() > 0
                            and n.count_publishers('/class/contract_verdict') > 0, 20)
time.sleep(0.5)
flag.publish(Flag(lambda_field=True))
time.sleep(0.3)
reading.publish(Reading(x_prime=1.5))
out['answered'] = spin_until(lambda: got['result'], 15)
reading.publish(Reading(x_prime=-1.0))
spin_until(lambda: got['verdicts'], 15)
spin_until(lambda: 'class' in n.get_node_names(), 5)
out['nodes'] = n.get_node_names()
out.update(got)
print('RESULT ' + json.dumps(out), flush=True)
n.destroy_node()
rclpy.try_shutdown()
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The hostile contract generated, its step written, the tree colcon-built in the ROS 2 Python."""
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("names2")
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "sys.rcl").write_text(CONTRACT)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "src"), "--system", "hostile"]) == 0
    logic = ws / "src" / "class_node" / "class_node" / "logic.py"
    text = logic.read_text()
    assert "def step(x_prime, lambda_):" in text and text.count(STUB) == 1
    logic.write_text(text.replace(STUB, STUB.replace("return {}", "return {'class': 2 * x_prime}")))
    seconds, output = colcon_build(ws, tmp)
    assert b"reserved keyword" not in output  # rosidl_generator_py's warning: no keyword field
    print(f"colcon build of hostile_msgs and class_node: {seconds:.1f} s")
    return {"ws": ws, "tmp": tmp, "env": install_env(ws, ros2_env(tmp))}


def test_the_hostile_node_runs_on_ros2_under_its_rcl_names(built: dict) -> None:
    ws, env = built["ws"], built["env"]
    exe = ws / "install" / "class_node" / "lib" / "class_node" / "class_node"  # setup.py's console script
    assert exe.is_file()
    log = built["tmp"] / "class.log"
    with open(log, "wb") as fh:
        node = subprocess.Popen([str(exe)], cwd=ws, env=env, stdout=fh, stderr=subprocess.STDOUT,
                                start_new_session=True)
    try:
        wait_for(log, "contract layer ready", 30)
        client = start_node(built["tmp"], "probe", CLIENT, env, ready=None)
        try:
            client.wait(timeout=60)
        finally:
            stop(client)
        text = (built["tmp"] / "probe.log").read_text()
        lines = [ln for ln in text.splitlines() if ln.startswith("RESULT ")]
        assert lines, text
        res = json.loads(lines[0][len("RESULT "):])
        assert res["matched"] and "class" in res["nodes"], res
        assert res["answered"] and res["result"][0] == 3.0, res  # class_field = 2 * x_prime
        v = res["verdicts"][0]  # the broken assumption, judged in the node, by the RCL names
        assert (v["node"], v["verdict"], v["values"]["in.x'"]) == ("class", "assumption violated", "-1.0"), v
    finally:
        stop(node)
    assert node.returncode == 0, (node.returncode, log.read_text())
    assert "Traceback" not in log.read_text(), log.read_text()
