"""``rclverify ros diff --ros2`` against REAL rclpy nodes on Fast DDS
(issue 62; docs/ros.md, "Expected against observed").

The code side is a small ament_python workspace written into the test's
directory: ``talker`` (publishes ``chatter``, subscribes to ``cmd``, serves
``reset`` and the action ``count``), ``camera``
(``rclpy.create_node('camera', namespace='sensors')``: its namespace is in
the code), ``viewer`` (subscribes reliably to ``/sensors/image``, calls
``/robot/reset`` and the action ``/robot/count``) and ``planner``
(``Node.__init__(..., namespace='nav')``), started by a Python launch file that puts ``talker`` and ``planner`` under
``/robot`` (launch_ros' namespace replaces the code's) and remaps
``talker``'s ``cmd`` to ``/teleop/cmd``.

The running side is rclpy on rmw_fastrtps_cpp in the ROS 2 Python
(tests/_ros2.py), on loopback and a random domain: ``talker`` and ``viewer``
run the workspace's own code with the arguments launch_ros gives them
(``--ros-args -r __node:=... -r __ns:=... -r from:=to``); one more process
runs a ``/sensors/camera`` that publishes ``/sensors/image`` best-effort
(the reliable ``viewer`` gets nothing from it) and a ``/intruder`` the code
does not have; ``planner`` is not started.  The diff must report exactly:
``/robot/planner`` missing (at its launch line), ``/intruder`` extra, the
QoS conflict on ``/sensors/image`` between the running viewer and camera,
the camera running best-effort where its code asks for reliable (at its
``create_publisher`` call), and nothing about the nodes that run as the
code says; exit 1.  An independent oracle checks the reading itself: ROS 2's
own graph API (rclpy in a process of its own) must list the same nodes,
publishers, subscribers, service servers and clients, action servers and
clients, with their types, as rclverify read from DDS.

The static tests beside it check, without ROS 2, the namespaces the scan
gives (code namespaces in Python and C++, launch namespaces in Python and
XML launch files) and the QoS read from the code (ros/extract/code_qos.py).
"""
from __future__ import annotations

import json
import subprocess
import textwrap
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop, wait_for
from _ros2 import rclverify, ros2_env, ros2_python, start_node

PKG = {
    "package.xml": """\
        <?xml version="1.0"?>
        <package format="3">
          <name>demo_pkg</name>
          <version>0.1.0</version>
          <description>the code side of the real ROS 2 diff test</description>
          <maintainer email="dev@example.org">dev</maintainer>
          <license>MIT</license>
          <exec_depend>rclpy</exec_depend>
          <exec_depend>std_msgs</exec_depend>
          <export><build_type>ament_python</build_type></export>
        </package>
        """,
    "setup.py": """\
        from setuptools import setup
        setup(name='demo_pkg', version='0.1.0', packages=['demo_pkg'],
              entry_points={'console_scripts': ['talker = demo_pkg.talker:main', 'camera = demo_pkg.camera:main',
                                                'viewer = demo_pkg.viewer:main',
                                                'planner = demo_pkg.planner:main']})
        """,
    "resource/demo_pkg": "",
    "demo_pkg/__init__.py": "",
    "demo_pkg/talker.py": """\
        import rclpy
        from rclpy.action import ActionServer
        from rclpy.node import Node
        from std_msgs.msg import String
        from std_srvs.srv import Trigger
        from test_msgs.action import Fibonacci


        class Talker(Node):
            def __init__(self):
                super().__init__('talker')
                self.pub = self.create_publisher(String, 'chatter', 10)
                self.create_subscription(String, 'cmd', lambda m: None, 10)
                self.create_service(Trigger, 'reset', self.on_reset)
                self.count = ActionServer(self, Fibonacci, 'count', self.execute)

            def on_reset(self, request, response):
                response.success = True
                return response

            def execute(self, goal):
                goal.succeed()
                return Fibonacci.Result()


        def main():
            rclpy.init()
            rclpy.spin(Talker())
        """,
    "demo_pkg/camera.py": """\
        import rclpy
        from std_msgs.msg import String


        def main():
            rclpy.init()
            node = rclpy.create_node('camera', namespace='sensors')
            node.create_publisher(String, 'image', 10)
            rclpy.spin(node)
        """,
    "demo_pkg/viewer.py": """\
        import rclpy
        from rclpy.action import ActionClient
        from rclpy.node import Node
        from std_msgs.msg import String
        from std_srvs.srv import Trigger
        from test_msgs.action import Fibonacci


        class Viewer(Node):
            def __init__(self):
                super().__init__('viewer')
                self.create_subscription(String, '/sensors/image', self.show, 10)
                self.reset = self.create_client(Trigger, '/robot/reset')
                self.count = ActionClient(self, Fibonacci, '/robot/count')

            def show(self, msg):
                self.get_logger().info(msg.data)


        def main():
            rclpy.init()
            rclpy.spin(Viewer())
        """,
    "demo_pkg/planner.py": """\
        import rclpy
        from rclpy.node import Node
        from std_msgs.msg import String


        class Planner(Node):
            def __init__(self):
                super().__init__('planner', namespace='nav')
                self.create_subscription(String, '/sensors/image', lambda m: None, 10)
                self.create_publisher(String, 'plan', 10)


        def main():
            rclpy.init()
            rclpy.spin(Planner())
        """,
    "launch/demo.launch.py": """\
        from launch import LaunchDescription
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                Node(package='demo_pkg', executable='talker', name='talker', namespace='robot',
                     remappings=[('cmd', '/teleop/cmd')]),
                Node(package='demo_pkg', executable='camera', name='camera'),
                Node(package='demo_pkg', executable='viewer', name='viewer'),
                Node(package='demo_pkg', executable='planner', name='planner', namespace='robot'),
            ])
        """,
}
PLANNER_LINE = 11  # its Node(...) in launch/demo.launch.py

#: runs one of the workspace's nodes as launch_ros starts it: its entry point, with ``--ros-args``
RUN = """\
    import importlib, sys
    sys.path.insert(0, {pkg!r})
    sys.argv = ['{mod}', '--ros-args'] + {remaps!r}
    import rclpy
    spin = rclpy.spin
    def announced(node, *a, **k):
        print('ready', flush=True)
        spin(node, *a, **k)
    rclpy.spin = announced
    importlib.import_module('demo_pkg.{mod}').main()
    """

#: what runs besides the code: a best-effort camera (the viewer requests reliable), a node the code lacks and a
#: ROS 2 tool's hidden node
OTHERS = """\
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String
    rclpy.init()
    camera = rclpy.create_node('camera', namespace='/sensors')
    camera.create_publisher(String, 'image', QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT))
    intruder = rclpy.create_node('intruder')
    intruder.create_publisher(String, '/debug', 10)
    tool = rclpy.create_node('_ros2cli_probe')  # hidden, as ROS 2's command line tools name their nodes
    tool.create_subscription(String, '/debug', lambda m: None, 10)
    ex = SingleThreadedExecutor()
    for n in (camera, intruder, tool):
        ex.add_node(n)
    print('ready', flush=True)
    ex.spin()
    """


#: ROS 2's own view of the graph (rclpy's graph API over rmw_dds_common's graph cache), as JSON on stdout once
#: every node of ``want`` is seen and the view has stayed the same for 1.5 s (at most 20 s in all: a node's
#: endpoints are discovered after the node, later on a loaded machine): per node its publishers,
#: subscribers, service servers and clients, action servers and clients, each ``[name, [types]]``
PROBE = """\
    import json, sys, time
    import rclpy
    from rclpy.action import get_action_client_names_and_types_by_node as aclients
    from rclpy.action import get_action_server_names_and_types_by_node as aservers
    want = set(sys.argv[1:])
    rclpy.init()
    me = rclpy.create_node('_graph_probe')

    def view():
        nodes = [(n, ns) for n, ns in me.get_node_names_and_namespaces() if n != '_graph_probe']
        return {ns.rstrip('/') + '/' + n: {
            'pub': me.get_publisher_names_and_types_by_node(n, ns),
            'sub': me.get_subscriber_names_and_types_by_node(n, ns),
            'service_servers': me.get_service_names_and_types_by_node(n, ns),
            'service_clients': me.get_client_names_and_types_by_node(n, ns),
            'action_servers': aservers(me, n, ns), 'action_clients': aclients(me, n, ns)}
            for n, ns in sorted(set(nodes))}

    end = time.monotonic() + 20
    out, since = view(), time.monotonic()
    while time.monotonic() < end:
        rclpy.spin_once(me, timeout_sec=0.1)
        now = view()
        if now != out:
            out, since = now, time.monotonic()
        elif want <= set(out) and time.monotonic() - since >= 1.5:
            break
    print(json.dumps(out), flush=True)
    """


def write_ws(root: Path) -> Path:
    """The workspace of the code side under ``root``; returns the package directory."""
    pkg = root / "src" / "demo_pkg"
    for rel, text in PKG.items():
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text(textwrap.dedent(text))
    return pkg


def _run(pkg: Path, mod: str, node: str, ns: str | None = None, remaps: tuple[str, ...] = ()) -> str:
    args = ["-r", f"__node:={node}"] + (["-r", f"__ns:={ns}"] if ns else [])
    for r in remaps:
        args += ["-r", r]
    return RUN.format(pkg=str(pkg), mod=mod, remaps=args)


@pytest.fixture(scope="module")
def diff(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    tmp = tmp_path_factory.mktemp("ros2diff")
    pkg = write_ws(tmp / "ws")
    env = ros2_env(tmp)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        for name, src in (("talker", _run(pkg, "talker", "talker", "/robot", ("cmd:=/teleop/cmd",))),
                          ("viewer", _run(pkg, "viewer", "viewer")), ("others", OTHERS)):
            procs.append(start_node(tmp, name, src, env, ready=None))  # started together, waited for below
        for name in ("talker", "viewer", "others"):
            wait_for(tmp / f"{name}.log", "ready", 30)
        out, log = tmp / "diff.json", tmp / "diff.log"
        p = rclverify(["ros", "diff", "src", "--launch", "src/demo_pkg/launch/demo.launch.py", "--ros2",
                       "--wait", "2", "--json", str(out), "--record-graph", str(tmp / "graph_dds.json")], env,
                      tmp / "ws", log)
        procs.append(p)
        code = p.wait(60)
        # the same diff with the graph read through rclpy's graph API (docs/ros2.md, "Two sources")
        out_r, log_r = tmp / "diff_rclpy.json", tmp / "diff_rclpy.log"
        pr = rclverify(["ros", "diff", "src", "--launch", "src/demo_pkg/launch/demo.launch.py", "--ros2",
                        "--source", "rclpy", "--ros2-python", str(ros2_python()), "--wait", "2", "--json",
                        str(out_r), "--record-graph", str(tmp / "graph_rclpy.json")], env, tmp / "ws", log_r)
        procs.append(pr)
        code_r = pr.wait(90)
        probe = subprocess.Popen([str(ros2_python()), "-c", textwrap.dedent(PROBE), *RUNNING], cwd=tmp, env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, start_new_session=True)
        procs.append(probe)
        ours = _read_running(env)  # rclverify's reading of the same graph, meanwhile
        seen = json.loads(probe.communicate(timeout=40)[0] or b"{}")
        yield {"code": code, "json": json.loads(out.read_text()), "log": log.read_text(), "domain": env["ROS_DOMAIN_ID"],
               "rclpy": {"code": code_r, "json": json.loads(out_r.read_text()) if out_r.exists() else None,
                         "log": log_r.read_text()},
               "ros2": seen, "ours": ours, "ws": tmp / "ws",
               "recorded": {"dds": tmp / "graph_dds.json", "rclpy": tmp / "graph_rclpy.json"}}
    finally:
        for p in procs:
            stop(p)


#: the nodes that run (their names as ROS 2 gives them)
RUNNING = ("/robot/talker", "/viewer", "/sensors/camera", "/intruder", "/_ros2cli_probe")


def _read_running(env: dict[str, str]) -> dict[str, dict[str, list[tuple[str, str | None]]]]:
    """rclverify's graph of the running system (:func:`read_dds_graph`), per node and edge kind."""
    from rclverify.ros.live.diff_dds import read_dds_graph
    mp = pytest.MonkeyPatch()
    mp.setenv("CYCLONEDDS_URI", env["CYCLONEDDS_URI"])
    try:
        g, disc, _s, dp = read_dds_graph(2.0, int(env["ROS_DOMAIN_ID"]))
        disc.close()
        dp.__del__()
    finally:
        mp.undo()
    kinds = ("pub", "sub", "service_servers", "service_clients", "action_servers", "action_clients")
    return {name: {k: sorted((e.topic, e.msg_type) for e in n.edges_of(k)) for k in kinds}
            for name, n in g.nodes.items() if not name.endswith("/_graph_probe")}


def _ros2_view(seen: dict[str, Any]) -> dict[str, dict[str, list[tuple[str, str | None]]]]:
    """ROS 2's view with what docs/ros.md says the diff leaves out taken out: /rosout and
    /parameter_events, each node's parameter and type-description services, an action's
    hidden topics and services (its server and client are the action graph API's)."""
    from rclverify.ros.live.diff_dds import INFRA_SERVICE_SUFFIXES, INFRA_TOPICS
    out = {}
    for name, kinds in seen.items():
        if name.endswith("/_graph_probe"):
            continue
        out[name] = {k: sorted((t, types[0] if len(types) == 1 else None) for t, types in v
                               if t not in INFRA_TOPICS and "/_action/" not in t
                               and not (k.startswith("service") and t.endswith(INFRA_SERVICE_SUFFIXES)))
                     for k, v in kinds.items()}
    return out


def _items(d: dict[str, Any], side: str, category: str | None = None) -> list[dict[str, Any]]:
    return [i for i in d["json"][side] if category is None or i["category"] == category]


def test_the_node_not_started_is_missing_at_its_launch_line(diff: dict[str, Any]) -> None:
    missing = _items(diff, "missing", "node")
    assert [i["name"] for i in missing] == ["/robot/planner"], diff["log"]
    assert missing[0]["at"]["file"].endswith("demo.launch.py") and missing[0]["at"]["line"] == PLANNER_LINE
    assert diff["code"] == 1 and diff["json"]["observed"] == {"kind": "dds", "source": f"DDS domain {diff['domain']}"}


def test_the_node_the_code_lacks_is_the_one_extra(diff: dict[str, Any]) -> None:
    extra = _items(diff, "extra")
    assert [(i["category"], i["name"]) for i in extra] == [("node", "/intruder")], diff["log"]
    assert "publishes /debug" in extra[0]["message"]
    # the hidden node of a ROS 2 tool is no difference, and is said to be left out
    assert [c for c in diff["json"]["not_compared"] if c.startswith("1 hidden node(s)")], diff["json"]["not_compared"]


def test_the_qos_conflict_names_both_nodes(diff: dict[str, Any]) -> None:
    qos = [i for i in _items(diff, "missing", "qos") if i["at"] is None]  # between running endpoints
    assert len(qos) == 1 and qos[0]["name"] == "/sensors/image", diff["log"]
    assert "node /viewer subscribes with reliable" in qos[0]["message"]
    assert "node /sensors/camera publishes with best_effort" in qos[0]["message"]
    assert len(diff["json"]["missing"]) == 3  # the planner, the conflict and the camera's drift: nothing else


def test_a_publisher_running_with_other_qos_than_its_code_is_located_at_the_call(diff: dict[str, Any]) -> None:
    drift = [i for i in _items(diff, "missing", "qos") if i["at"] is not None]
    assert [(i["node"], i["name"]) for i in drift] == [("/sensors/camera", "/sensors/image")], diff["log"]
    assert drift[0]["at"]["file"].endswith("demo_pkg/camera.py") and drift[0]["at"]["line"] == 8
    assert "reliability: reliable in the code, best_effort running" in drift[0]["message"]
    assert any(c.startswith("the reliability and durability the code asks for") for c in diff["json"]["compared"])


def test_namespaced_nodes_are_found_with_their_namespace(diff: dict[str, Any]) -> None:
    # /robot/talker (the launch file's namespace, cmd remapped to /teleop/cmd) and /sensors/camera (the
    # code's namespace) run as the code has them: no item names them, and every endpoint found its node
    everything = diff["json"]["missing"] + diff["json"]["extra"]
    assert not [i for i in everything if i["node"] in ("/robot/talker", "/viewer")]
    assert [i["category"] for i in everything if i["node"] == "/sensors/camera"] == ["qos"]  # its drift only
    assert not [i for i in everything if i["category"] == "node" and i["name"] != "/robot/planner"
                and i["name"] != "/intruder"]
    assert "in no ROS 2 node" not in diff["log"] and "may be incomplete" not in diff["log"], diff["log"]


def test_the_running_graph_is_the_one_ros2_itself_sees(diff: dict[str, Any]) -> None:
    """Oracle: rclpy's graph API (rmw_fastrtps, rmw_dds_common's graph cache) in
    a process of its own; every node, publisher, subscriber, service server and
    client, action server and client, with its type, must be what rclverify read."""
    ros2 = _ros2_view(diff["ros2"])
    assert set(ros2) == set(RUNNING), ros2  # the probe saw the whole system
    assert diff["ours"] == ros2
    assert ros2["/robot/talker"]["action_servers"] == [("/robot/count", "test_msgs/action/Fibonacci")]


@pytest.mark.parametrize("source", ["dds", "rclpy"])
def test_a_recording_of_the_running_graph_gives_the_live_diff(diff: dict[str, Any], source: str, tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """``ros diff --graph FILE`` on the graph each source recorded while it compared (``--record-graph``), read
    with no node needed: the live diff's JSON exactly (the same missing and extra items, at the same places,
    the source named as live); the recording with the camera's publisher made reliable (a seeded graph
    difference) loses the QoS conflict and the camera's drift from its code, and nothing else."""
    from rclverify.cli.commands import main
    live = diff["json"] if source == "dds" else diff["rclpy"]["json"]
    assert live is not None and live["missing"] and live["extra"]
    monkeypatch.chdir(diff["ws"])  # the code's places are shown from the workspace, as the live diff's were
    out = tmp_path / "recorded.json"
    args = ["ros", "diff", "src", "--launch", "src/demo_pkg/launch/demo.launch.py", "--json", str(out)]
    assert main([*args, "--graph", str(diff["recorded"][source])]) == 1
    assert json.loads(out.read_text()) == live
    data = json.loads(diff["recorded"][source].read_text())
    [cam] = data["endpoints"]["/sensors/image"]["pubs"]
    cam["reliable"] = True
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(data))
    main([*args, "--graph", str(edited)])
    seeded = json.loads(out.read_text())
    assert seeded["extra"] == live["extra"]
    gone = [i for i in live["missing"] if i not in seeded["missing"]]
    assert seeded["missing"] == [i for i in live["missing"] if i not in gone]
    assert sorted(i["category"] for i in gone) == ["qos", "qos"] and all(i["name"] == "/sensors/image" for i in gone)


# -- the namespaces of the static scan (no ROS 2 needed) ---------------------------------------

def _scan(ws: Path, *launch: str) -> dict[str, Any]:
    from rclverify.ros.graph.scan import scan
    g = scan([ws / "src"], [ws / x for x in launch])
    return {n.name: sorted(e.topic for e in n.publishes + n.subscribes) for n in g.graph.nodes.values()}


def test_the_code_namespace_without_a_launch_file(tmp_path: Path) -> None:
    write_ws(tmp_path)
    assert _scan(tmp_path) == {"/talker": ["/chatter", "/cmd"], "/sensors/camera": ["/sensors/image"],
                               "/viewer": ["/sensors/image"], "/nav/planner": ["/nav/plan", "/sensors/image"]}


def test_the_launch_namespace_replaces_the_code_one(tmp_path: Path) -> None:
    write_ws(tmp_path)
    assert _scan(tmp_path, "src/demo_pkg/launch/demo.launch.py") == {
        "/robot/talker": ["/robot/chatter", "/teleop/cmd"], "/sensors/camera": ["/sensors/image"],
        "/viewer": ["/sensors/image"], "/robot/planner": ["/robot/plan", "/sensors/image"]}
    # the services and actions the live test compares (no item about them there means the running side has them)
    from rclverify.ros.graph.scan import scan
    g = scan([tmp_path / "src"], [tmp_path / "src/demo_pkg/launch/demo.launch.py"]).graph
    kinds = ("service_servers", "service_clients", "action_servers", "action_clients")
    assert {n: {k: [(e.topic, e.msg_type) for e in g.nodes[n].edges_of(k)] for k in kinds
                if g.nodes[n].edges_of(k)} for n in ("/robot/talker", "/viewer")} == {
        "/robot/talker": {"service_servers": [("/robot/reset", "std_srvs/srv/Trigger")],
                          "action_servers": [("/robot/count", "test_msgs/action/Fibonacci")]},
        "/viewer": {"service_clients": [("/robot/reset", "std_srvs/srv/Trigger")],
                    "action_clients": [("/robot/count", "test_msgs/action/Fibonacci")]}}


def test_xml_launch_and_rclcpp_namespaces(tmp_path: Path) -> None:
    pkg = tmp_path / "src" / "cpp_pkg"
    (pkg / "src").mkdir(parents=True)
    (pkg / "launch").mkdir()
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>cpp_pkg</name><version>0.1.0</version>'
        '<description>d</description><maintainer email="dev@example.org">dev</maintainer><license>MIT</license>'
        '<depend>rclcpp</depend><depend>std_msgs</depend><export><build_type>ament_cmake</build_type></export>'
        '</package>\n')
    (pkg / "CMakeLists.txt").write_text("cmake_minimum_required(VERSION 3.8)\nproject(cpp_pkg)\n"
                                        "add_executable(odom src/odom.cpp)\nadd_executable(lidar src/lidar.cpp)\n")
    (pkg / "src" / "odom.cpp").write_text(textwrap.dedent("""\
        #include <rclcpp/rclcpp.hpp>
        #include <std_msgs/msg/string.hpp>
        class Odom : public rclcpp::Node {
        public:
          Odom() : Node("odom", "base") { pub_ = create_publisher<std_msgs::msg::String>("odometry", 10); }
          rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
        };
        int main(int argc, char ** argv) { rclcpp::init(argc, argv); rclcpp::spin(std::make_shared<Odom>()); }
        """))
    (pkg / "src" / "lidar.cpp").write_text(textwrap.dedent("""\
        #include <rclcpp/rclcpp.hpp>
        #include <std_msgs/msg/string.hpp>
        int main(int argc, char ** argv) {
          rclcpp::init(argc, argv);
          auto node = rclcpp::Node::make_shared("lidar", "sensors");
          auto pub = node->create_publisher<std_msgs::msg::String>("scan", 10);
          rclcpp::spin(node);
        }
        """))
    (pkg / "launch" / "sys.launch.xml").write_text(
        '<launch>\n  <node pkg="cpp_pkg" exec="odom" name="odom"/>\n'
        '  <node pkg="cpp_pkg" exec="lidar" name="lidar" namespace="front"/>\n</launch>\n')
    assert _scan(tmp_path) == {"/base/odom": ["/base/odometry"], "/sensors/lidar": ["/sensors/scan"]}
    assert _scan(tmp_path, "src/cpp_pkg/launch/sys.launch.xml") == {"/base/odom": ["/base/odometry"],
                                                                     "/front/lidar": ["/front/scan"]}


def test_the_qos_the_code_asks_for(tmp_path: Path) -> None:
    from rclverify.ros.extract.code_qos import read
    from rclverify.ros.extract.model import Src
    py = tmp_path / "n.py"
    py.write_text(textwrap.dedent("""\
        from rclpy.qos import QoSProfile, ReliabilityPolicy, DurabilityPolicy, qos_profile_sensor_data
        import rclpy.qos
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        n.create_publisher(String, 'a', 10)
        n.create_publisher(String, 'b', qos_profile_sensor_data)
        n.create_publisher(String, 'c', QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT))
        n.create_publisher(String, 'd', latched)
        n.create_subscription(String, 'e', cb, rclpy.qos.qos_profile_system_default)
        n.create_subscription(String, 'f', cb, qos_profile=QoSProfile(depth=1, reliability=pick()))
        n.create_subscription(String, 'g', cb, 3)
        """))
    got = {line: read(Src(str(py), line, 1), "pub" if line < 8 else "sub") for line in range(4, 11)}
    assert {k: (v.reliability, v.durability) if v else None for k, v in got.items()} == {
        4: ("reliable", "volatile"), 5: ("best_effort", "volatile"), 6: ("best_effort", "volatile"),
        7: ("reliable", "transient_local"), 8: (None, None), 9: (None, "volatile"), 10: ("reliable", "volatile")}
    cpp = tmp_path / "n.cpp"
    cpp.write_text(textwrap.dedent("""\
        auto qos = rclcpp::QoS(rclcpp::KeepLast(1)).transient_local();
        void f() {
          a_ = create_publisher<std_msgs::msg::String>("a", 10);
          b_ = node->create_publisher<std_msgs::msg::String>("b", rclcpp::SensorDataQoS());
          c_ = create_publisher<std_msgs::msg::String>(
              "c", rclcpp::QoS(5).best_effort());
          d_ = create_publisher<std_msgs::msg::String>("d", qos);
          e_ = create_subscription<std_msgs::msg::String>("e", rclcpp::SystemDefaultsQoS(),
                                                          [this](const std_msgs::msg::String & m) { on(m, 1); });
          g_ = create_subscription<std_msgs::msg::String>("g", rclcpp::QoS(1).reliability(
              rclcpp::ReliabilityPolicy::BestEffort), std::bind(&N::cb, this, _1));
        }
        """))
    got = {line: read(Src(str(cpp), line, 3), "pub" if line < 8 else "sub") for line in (3, 4, 5, 7, 8, 10)}
    assert {k: (v.reliability, v.durability) if v else None for k, v in got.items()} == {
        3: ("reliable", "volatile"), 4: ("best_effort", "volatile"), 5: ("best_effort", "volatile"),
        7: ("reliable", "transient_local"), 8: (None, None), 10: ("best_effort", "volatile")}


def test_a_namespace_computed_at_run_time_is_a_located_warning(tmp_path: Path) -> None:
    pkg = write_ws(tmp_path)
    cam = pkg / "demo_pkg" / "camera.py"
    cam.write_text(cam.read_text().replace("import rclpy\n", "import os\nimport rclpy\n")
                   .replace("namespace='sensors'", "namespace=os.environ['ROBOT']"))
    from rclverify.ros.graph.scan import scan
    g = scan([tmp_path / "src"], base=tmp_path)
    notes = [str(n) for n in g.graph.notes if "namespace of node 'camera'" in n.message]
    assert notes == ["src/demo_pkg/demo_pkg/camera.py:8:12: warning: namespace of node 'camera' is not a string "
                     "literal: not resolved statically (the root namespace is shown unless a launch file gives one)"]


def test_the_rclpy_source_reads_the_same_diff(diff: dict[str, Any]) -> None:
    """``ros diff --ros2 --source rclpy``: the running graph read through rclpy's graph API gives the same
    missing and extra items (topics, services, the QoS conflict, the code's QoS) and exit code as DDS."""
    r = diff["rclpy"]
    assert "source: rclpy" in r["log"] and r["json"] is not None, r["log"]

    def items(d: dict[str, Any]) -> list[tuple[Any, ...]]:
        return sorted((side, i["category"], str(i.get("node")), str(i.get("name")), str(i.get("type")))
                      for side in ("missing", "extra") for i in d[side])
    assert items(r["json"]) == items(diff["json"]), (r["json"], diff["json"])
    assert r["code"] == diff["code"] == 1
