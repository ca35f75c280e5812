"""Packages from ``rclverify generate ros2`` are real ROS 2 packages (issue 62): generated from
a contract with an interface of its own (a message and a service), built with colcon in the ROS 2
Python (ROS 2's PyPI wheels: ament_cmake and the rosidl generators, no rclverify), the node
started there from its installed entry point and driven by a real rclpy client on Fast DDS:

* it answers a message and a service call, and a callback of it that waits on the node's OWN
  service gets the answer (no deadlock: callback groups on a MultiThreadedExecutor);
* its contract layer, carried in the package, judges inside the running node: a broken
  assumption comes out on ``/Doubler/contract_verdict`` in the monitor's format, and nothing of
  the node writes on the monitor's ``/rclverify/verdict``;
* SIGTERM stops it with exit status 0 and no traceback.

The build runs once for the module (its wall time is printed)."""
from __future__ import annotations

import json
import subprocess

import pytest

from _procs import stop, wait_for
from _ros2 import colcon_build, install_env, ros2_env, ros2_python, start_node
from rclverify.cli.commands import main

CONTRACT = """\
node Doubler {
  inputs( x : REAL [m], q : REAL [m] )
  outputs( y : REAL [m], ok : BOOL )
  topics( demo_msgs/Reading reading matches(in.x), std_msgs/Float64 doubled matches(out.y) )
  services( demo_msgs/Check check serves(in.q, out.ok) )
  assume( in.x >= 0 )
  guarantee( out.y == 2 * in.x )
  guarantee( out.ok <=> in.q >= 0 )
}
"""

# the hand-written logic: on each reading it asks the node's own service (synchronously, inside
# the subscription's callback) before publishing its step's outputs
LOGIC = """\
from demo_msgs.srv import Check

INPUTS = ['x', 'q']


def step(x, q):
    return {'y': 2 * x, 'ok': q >= 0}


def setup(node):
    node.own_check = node.create_client(Check, 'check', callback_group=node.group_clients)


def _run(node):
    if not all(f'in.{n}' in node.values for n in INPUTS):
        return {}
    return step(**{n: node.values[f'in.{n}'] for n in INPUTS})


def on_input(node, var, msg):
    req = Check.Request()
    req.q = msg.x
    resp = node.call('own_check', req, timeout_sec=5.0)
    node.get_logger().info(f'own service answered: {None if resp is None else resp.ok}')
    for name, value in _run(node).items():
        node.publish_value(f'out.{name}', value)


def on_request(node, service, request, response):
    for name, value in _run(node).items():
        if node.carries(f'out.{name}', service):
            node.fill(f'out.{name}', response, value)
    return response


def on_goal(node, action, goal_handle):
    goal_handle.abort()
    return None
"""

CLIENT = """\
import json, time
import rclpy
from rclpy.executors import SingleThreadedExecutor
from std_msgs.msg import Float64, String
from demo_msgs.msg import Reading
from demo_msgs.srv import Check

rclpy.init()
n = rclpy.create_node('probe')
got = {'doubled': [], 'verdicts': []}
n.create_subscription(Float64, 'doubled', lambda m: got['doubled'].append(m.data), 10)
n.create_subscription(String, '/Doubler/contract_verdict', lambda m: got['verdicts'].append(json.loads(m.data)), 10)
pub = n.create_publisher(Reading, 'reading', 10)
cli = n.create_client(Check, 'check')
ex = SingleThreadedExecutor()
ex.add_node(n)


def spin_until(cond, timeout):
    end = time.monotonic() + timeout
    while not cond() and time.monotonic() < end:
        ex.spin_once(timeout_sec=0.1)
    return cond()


out = {}
out['matched'] = spin_until(lambda: pub.get_subscription_count() > 0 and cli.service_is_ready()
                            and n.count_publishers('/Doubler/contract_verdict') > 0, 20)
time.sleep(0.5)
pub.publish(Reading(x=1.5))
out['answered'] = spin_until(lambda: got['doubled'], 15)
req = Check.Request()
req.q = -2.0
fut = cli.call_async(req)
spin_until(fut.done, 10)
out['service'] = fut.result().ok if fut.done() else None
pub.publish(Reading(x=-1.0))
spin_until(lambda: got['verdicts'], 15)
out['verdict_writers'] = [i.node_name for i in n.get_publishers_info_by_topic('/rclverify/verdict')]
out.update(got)
print('RESULT ' + json.dumps(out), flush=True)
n.destroy_node()
rclpy.try_shutdown()
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The contract generated, its logic written, and the tree colcon-built in the ROS 2 Python."""
    ros2_python()  # skips, with the reason, without a ROS 2 Python
    tmp = tmp_path_factory.mktemp("gen2")
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts" / "demo.rcl").write_text(CONTRACT)
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/demo.rcl]\n")
    assert main(["generate", "ros2", "-w", str(ws), "-o", str(ws / "src"), "--system", "demo"]) == 0
    (ws / "src" / "doubler" / "doubler" / "logic.py").write_text(LOGIC)
    seconds, _output = colcon_build(ws, tmp)
    print(f"colcon build of demo_msgs and doubler: {seconds:.1f} s")
    return {"ws": ws, "tmp": tmp, "env": install_env(ws, ros2_env(tmp)), "seconds": seconds}


def test_the_generated_package_needs_no_rclverify(built: dict) -> None:
    """Nothing the node imports is rclverify's: the built package's modules import in the ROS 2
    Python (which has no rclverify) and the contract layer judges there."""
    code = ("import importlib.util, sys; assert importlib.util.find_spec('rclverify') is None; "
            "from doubler import contract; "
            "v = contract.judge({'in.x': 0.1, 'in.q': 1.0, 'out.y': 0.2, 'out.ok': True}); print(v['verdict'])")
    r = subprocess.run([str(ros2_python()), "-c", code], env=built["env"], capture_output=True, timeout=60)
    assert r.returncode == 0, r.stderr.decode()
    assert r.stdout.decode().strip() == "satisfied"


def test_the_built_node_answers_and_stops_cleanly(built: dict) -> None:
    ws, env = built["ws"], built["env"]
    exe = ws / "install" / "doubler" / "lib" / "doubler" / "doubler"  # setup.py's console script
    assert exe.is_file()
    log = built["tmp"] / "doubler.log"
    with open(log, "wb") as fh:
        node = subprocess.Popen([str(exe)], cwd=ws, env=env, stdout=fh, stderr=subprocess.STDOUT,
                                start_new_session=True)
    try:
        wait_for(log, "contract layer ready", 30)
        assert "/Doubler/contract_verdict" in log.read_text()
        client = start_node(built["tmp"], "probe", CLIENT, env, ready=None)
        try:
            client.wait(timeout=60)
        finally:
            stop(client)
        text = (built["tmp"] / "probe.log").read_text()
        lines = [ln for ln in text.splitlines() if ln.startswith("RESULT ")]
        assert lines, text
        res = json.loads(lines[0][len("RESULT "):])
        assert res["matched"], res
        # the reading answered after the node's callback heard its own service's answer
        assert res["answered"] and res["doubled"][0] == 3.0, res
        assert "own service answered: True" in log.read_text()
        assert res["service"] is False, res  # q = -2: ok is FALSE
        # the broken assumption (x = -1) judged inside the node, in the monitor's format
        v = res["verdicts"][0]
        assert (v["node"], v["verdict"], v["values"]["in.x"]) == ("Doubler", "assumption violated", "-1.0"), v
        assert set(v) == {"node", "verdict", "event", "time", "where", "topic", "decided_at", "guarantee",
                          "values", "reason", "semantics"}
        assert res["verdict_writers"] == [], res  # the monitor's verdict topic is the monitor's alone
    finally:
        stop(node)
    assert node.returncode == 0, (node.returncode, log.read_text())
    assert "Traceback" not in log.read_text(), log.read_text()
