"""Helpers of the real-ROS 2 test tier: rclpy nodes on ROS 2's default
middleware (rmw_fastrtps_cpp, Fast DDS), run in the ROS 2 Python that
``scripts/setup.sh --tests`` installs beside the project (``.venv-ros2``,
ROS 2's PyPI wheels; docs/ros2.md), or the one ``RCLVERIFY_ROS2_PYTHON``
names (an apt installation's ``python3`` with its ``setup.bash`` sourced).

Everything stays on loopback: ROS 2's own ``ROS_AUTOMATIC_DISCOVERY_RANGE=
LOCALHOST`` for the rclpy nodes, Cyclone's loopback configuration
(tests/dds_ros2.py) for the monitor, and a random ``ROS_DOMAIN_ID`` so that
parallel test workers do not hear each other.  Every node is a process in a
session of its own, stopped by :func:`_procs.stop` in the test's
``finally``.
"""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any, Iterator

import pytest

from _procs import stop, wait_for
from dds_ros2 import dds_env

REPO = Path(__file__).resolve().parents[1]


def ros2_python() -> Path:
    """The ROS 2 Python to run rclpy nodes with; skips the test, with the
    reason, where there is none (the wheels could not be installed)."""
    named = os.environ.get("RCLVERIFY_ROS2_PYTHON")
    exe = Path(named) if named else REPO / ".venv-ros2" / "bin" / "python"
    if not exe.exists():
        pytest.skip(f"no ROS 2 Python at {exe.name} (scripts/setup.sh --tests installs ROS 2's wheels into "
                    ".venv-ros2; RCLVERIFY_ROS2_PYTHON names another)")
    probe = subprocess.run([str(exe), "-c", "import rclpy, rmw_fastrtps_cpp"], capture_output=True, timeout=60)
    if probe.returncode != 0:
        pytest.skip(f"the ROS 2 Python cannot import rclpy and rmw_fastrtps_cpp: "
                    f"{probe.stderr.decode(errors='replace').strip().splitlines()[-1:]}")
    return exe


def ros2_env(tmp: Path, rmw: str = "rmw_fastrtps_cpp") -> dict[str, str]:
    """The environment of one test's ROS 2 system and monitor: this
    process's, with a loopback Cyclone configuration and a random domain
    (:func:`dds_ros2.dds_env`), discovery kept on the host, and ``rmw`` as
    the nodes' middleware.  rclverify's own modules are not on the path."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    env.update(dds_env(tmp))
    env.update(ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION=rmw, PYTHONUNBUFFERED="1",
               ROS_LOG_DIR=str(tmp / "ros_log"), RCUTILS_LOGGING_BUFFERED_STREAM="0")
    return env


#: std_srvs/SetBool, the service the live call tests use, for a workspace whose contracts read it.
SETBOOL = "bool data\n---\nbool success\nstring message\n"


#: The part of a test robot's rclpy script (its node ``n`` made) that spins it on ``ex`` with a ``spin(seconds)``
#: helper, prints ``ready``, waits until the monitor publishes its verdicts and gives the monitor's readers
#: 1.5 s to match its publishers; the script goes on with its rounds.
AWAIT_MONITOR = """\
ex = SingleThreadedExecutor()
ex.add_node(n)

def spin(seconds):
    until = time.monotonic() + seconds
    while time.monotonic() < until:
        ex.spin_once(timeout_sec=0.002)

spin(0.5)
print("ready", flush=True)
until = time.monotonic() + 30
while time.monotonic() < until and n.count_publishers("/rclverify/verdict") < 1:
    spin(0.05)
spin(1.5)  # the monitor's readers match the publishers
"""


def live_workspace(tmp: Path, rcl: str, mapping: str | None = None, setbool: bool = False) -> Path:
    """A workspace ``tmp/ws`` for one live test: ``rcl`` as
    ``contracts/sys.rcl`` in a plan of its own, ``mapping`` (YAML text) as
    ``mapping.yaml`` when given, and std_srvs/SetBool's definition under
    ``interfaces/`` when ``setbool``; returns the workspace's path."""
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/sys.rcl").write_text(rcl)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/sys.rcl]\n")
    if mapping is not None:
        (ws / "mapping.yaml").write_text(mapping)
    if setbool:
        (ws / "interfaces/std_srvs/srv").mkdir(parents=True)
        (ws / "interfaces/std_srvs/srv/SetBool.srv").write_text(SETBOOL)
    return ws


def start_node(tmp: Path, name: str, source: str, env: dict[str, str], ready: str | None = "ready",
               timeout: float = 30) -> subprocess.Popen[bytes]:
    """Write ``source`` (dedented) to ``tmp/<name>.py`` and run it in the
    ROS 2 Python, its output in ``tmp/<name>.log``; waits until the log
    holds ``ready`` (skipped when ``None``).  The caller stops it with
    :func:`_procs.stop`."""
    script = tmp / f"{name}.py"
    script.write_text(textwrap.dedent(source))
    log = tmp / f"{name}.log"
    with open(log, "wb") as fh:
        p = subprocess.Popen([str(ros2_python()), str(script)], cwd=tmp, env=env, stdout=fh,
                             stderr=subprocess.STDOUT, start_new_session=True)
    if ready is not None:
        try:
            wait_for(log, ready, timeout)
        except AssertionError:
            stop(p)
            raise
    return p


def rclverify(args: list[str], env: dict[str, str], cwd: Path, log: Path) -> subprocess.Popen[bytes]:
    """Start ``rclverify ARGS`` (this Python, the project's sources) in a
    session of its own, output in ``log``."""
    env = dict(env, PYTHONPATH=str(REPO / "src"))
    with open(log, "wb") as fh:
        return subprocess.Popen([sys.executable, "-m", "rclverify.cli.commands", *args], cwd=cwd, env=env, stdout=fh,
                                stderr=subprocess.STDOUT, start_new_session=True)


def colcon_build(ws: Path, tmp: Path) -> tuple[float, bytes]:
    """``colcon build`` the packages under ``ws/src`` in the ROS 2 Python
    (its venv as the CMake and ament prefix); returns (seconds, colcon's
    output).  Fails the test with colcon's last lines when the build fails.  Bounded at 10 minutes: one
    system's generated packages took up to 274 s of wall time to build on a loaded 2-core machine (load
    about 11; docs/ci.md, "Round fifteen")."""
    import time
    py = ros2_python()
    venv = py.parent.parent
    env = ros2_env(tmp)
    env.update(PATH=f"{py.parent}:{env['PATH']}", CMAKE_PREFIX_PATH=str(venv), AMENT_PREFIX_PATH=str(venv))
    t0 = time.monotonic()
    r = subprocess.run([str(py), "-m", "colcon", "build", "--base-paths", "src"], cwd=ws, env=env,
                       capture_output=True, timeout=600)
    seconds = time.monotonic() - t0
    assert r.returncode == 0, r.stdout.decode()[-3000:] + r.stderr.decode()[-3000:]
    return seconds, r.stdout + r.stderr


def install_env(ws: Path, env: dict[str, str]) -> dict[str, str]:
    """``env`` with what sourcing colcon's ``ws/install/setup.sh`` sets
    (PYTHONPATH, LD_LIBRARY_PATH, AMENT_PREFIX_PATH, ...)."""
    dump = subprocess.run(["bash", "-c", ". install/setup.sh && env -0"], cwd=ws, env=env, capture_output=True,
                          timeout=60, check=True).stdout
    return dict(kv.split("=", 1) for kv in dump.decode().split("\0") if "=" in kv)


def stopping(*procs: subprocess.Popen[bytes]) -> Iterator[None]:
    """A generator for ``contextlib.contextmanager``-style use in fixtures:
    stops every process of ``procs`` when resumed."""
    try:
        yield
    finally:
        for p in procs:
            stop(p)


def robot_run(tmp: Path, seed: int, nodes: int, seconds: float, defect: bool, **how: Any) -> dict[str, Any]:
    """Generated robot ``seed`` of ``nodes`` nodes (``defect``: with its seeded defect) run live and
    offline for ``seconds`` of sensing under ``tmp``: bench/_robot_run.py's ``run_one`` (``how``: its
    keyword arguments), whose result it returns; bench/ must be on ``sys.path``.  Skipped, saying why,
    without ROS 2's Python (``_robot_run.ros2_python`` probes it once per process)."""
    import _robot_run
    ros2, why = _robot_run.ros2_python()
    if ros2 is None:
        pytest.skip(why)
    return _robot_run.run_one(seed, nodes, seconds, defect, tmp, ros2, **how)


def clock_node(factor: float = 1.0) -> str:
    """The text of an rclpy node publishing ``rosgraph_msgs/Clock`` on ``/clock`` every 10 ms of the wall
    clock from a simulated 100 s, advancing ``factor`` times as fast as the wall clock (its real-time
    factor); it prints ``ready`` once its publisher is made."""
    return CLOCK_NODE.replace("FACTOR", repr(factor))


CLOCK_NODE = """\
import time
import rclpy
from rclpy.node import Node
from builtin_interfaces.msg import Time
from rosgraph_msgs.msg import Clock

rclpy.init()
n = Node("sim")
pub = n.create_publisher(Clock, "/clock", 10)
print("ready", flush=True)
sim_ns, step = 100 * 10**9, round(10 * 10**6 * FACTOR)
next_t = time.monotonic()
while True:
    pub.publish(Clock(clock=Time(sec=sim_ns // 10**9, nanosec=sim_ns % 10**9)))
    sim_ns += step
    next_t += 0.01
    time.sleep(max(0.0, next_t - time.monotonic()))
"""
