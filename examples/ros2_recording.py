"""What the examples' live recorders share: an example's nodes and its
scenario run as real rclpy processes on ROS 2's default middleware
(rmw_fastrtps_cpp, Fast DDS) while ``rclverify monitor --live --ros2``
watches the bus and writes its log (and, if asked, its bag); docs/ros2.md.

Two sides, one file:

* the **project's Python** (the one rclverify is installed in) runs
  :func:`record`: it finds the ROS 2 Python (:func:`ros2_python`), builds the
  example's interface packages with colcon once into ``<example>/.ros2/``
  (:func:`build`), starts the monitor, one process per node and the scenario,
  and stops every process it started;
* the **ROS 2 Python** runs each example's ``ros2_nodes.py``, whose ``main``
  may be :func:`serve` (rclpy is imported there only, so the project's side
  imports this module without ROS 2).

Everything stays on this host: the nodes discover on localhost only
(``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), the monitor's Cyclone DDS uses
the loopback interface, and the domain is a random one.  Each example's
``record_live.py`` says what it records and how its trace is made.
"""
from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable

#: the monitor's Cyclone DDS: the loopback interface, unicast to 127.0.0.1, no multicast
CYCLONE = """<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">
  <General><Interfaces><NetworkInterface name="lo" multicast="false"/></Interfaces>
    <AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>
    <Peers><Peer address="127.0.0.1"/></Peers></Discovery>
</Domain></CycloneDDS>
"""


class Failed(Exception):
    """A part of the recording failed; the message says which."""


class NotConnected(Failed):
    """The driver's ROS 2 endpoints never all matched within its wait (it printed ``not connected:`` and what
    was missing): the middleware's discovery failed, so nothing of the robot was run or judged (docs/ros2.md,
    "Type objects the monitor announces")."""


def ros2_python(named: str | None, here: Path) -> Path:
    """The ROS 2 Python: ``named`` (``--ros2-python``), else
    ``$RCLVERIFY_ROS2_PYTHON``, else the ``.venv-ros2/bin/python`` of the
    nearest folder above ``here`` (ROS 2's PyPI wheels, docs/ros2.md).
    Raises :class:`Failed` when there is none."""
    if named or os.environ.get("RCLVERIFY_ROS2_PYTHON"):
        exe = Path(named or os.environ["RCLVERIFY_ROS2_PYTHON"])
        if not exe.is_file():
            raise Failed(f"no ROS 2 Python at {exe}")
        return exe
    for d in here.parents:
        if (d / ".venv-ros2" / "bin" / "python").exists():
            return d / ".venv-ros2" / "bin" / "python"
    raise Failed("no ROS 2 Python: give --ros2-python (a Python with rclpy and rmw_fastrtps_cpp)")


def build(py: Path, env: dict[str, str], here: Path, interfaces: list[str]) -> dict[str, str]:
    """colcon-build the interface packages ``interfaces`` (folders relative to
    the example ``here``) into ``here/.ros2/`` (once) and return ``env`` with
    its ``install/setup.sh`` sourced.  Raises :class:`Failed` with colcon's
    last lines when the build fails."""
    ws = here / ".ros2"
    if not all((ws / "install" / Path(p).name).is_dir() for p in interfaces):
        shutil.rmtree(ws, ignore_errors=True)
        ws.mkdir()
        venv = py.parent.parent
        benv = dict(env, PATH=f"{py.parent}:{env['PATH']}", CMAKE_PREFIX_PATH=str(venv), AMENT_PREFIX_PATH=str(venv))
        r = subprocess.run([str(py), "-m", "colcon", "build", "--base-paths", *[str(here / p) for p in interfaces]],
                           cwd=ws, env=benv, capture_output=True, timeout=300)
        if r.returncode != 0:
            shutil.rmtree(ws / "install", ignore_errors=True)
            raise Failed("colcon build failed:\n" + r.stdout.decode(errors="replace")[-3000:])
    dump = subprocess.run(["bash", "-c", ". install/setup.sh && env -0"], cwd=ws, env=env, capture_output=True,
                          timeout=60, check=True).stdout
    return dict(kv.split("=", 1) for kv in dump.decode().split("\0") if "=" in kv)


def wait_for(path: Path, text: str, timeout: float, proc: subprocess.Popen[bytes]) -> None:
    """Wait until the file ``path`` holds ``text``; :class:`Failed` with its
    end when ``proc`` ended first or ``timeout`` seconds passed."""
    until = time.monotonic() + timeout
    while not (path.exists() and text in path.read_text(errors="replace")):
        if proc.poll() is not None or time.monotonic() > until:
            raise Failed(f"{path.name} never said {text!r}:\n{path.read_text(errors='replace')[-2000:]}")
        time.sleep(0.05)


def start(cmd: list[str], env: dict[str, str], log: Path, cwd: Path) -> subprocess.Popen[bytes]:
    """Start ``cmd`` in ``cwd``, in a session of its own, its output in ``log``."""
    with open(log, "wb") as fh:
        return subprocess.Popen(cmd, cwd=cwd, env=env, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True)


def stop(p: subprocess.Popen[bytes], sig: int = signal.SIGTERM) -> None:
    """Send ``sig`` to ``p``'s process group unless it ended; SIGKILL after 10 s."""
    if p.poll() is None:
        os.killpg(p.pid, sig)
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(5)


def record(here: Path, py: Path, tmp: Path, *, interfaces: list[str], nodes: list[str], script: str,
           monitor: list[str], driver: str = "scenario", timeout: float = 30.0, until_done: bool = False,
           scripts: dict[str, Path] | None = None, env: dict[str, str] | None = None,
           heard: Callable[[list[dict[str, Any]]], bool] | None = None) -> float:
    """Run the monitor (extra arguments ``monitor``), one ROS 2 process of
    ``script`` (relative to ``here``) per node of ``nodes`` and then the
    ``driver`` (``script ROLE``; with ``scripts``, the program ``scripts[ROLE]``
    with no argument instead: one program per node); the monitor's log is
    ``tmp/run.jsonl`` (and whatever else ``monitor`` asks it to write).
    ``env`` is the processes' environment when given (it must keep them on
    loopback in a domain of their own), else this one's with :data:`CYCLONE`,
    localhost discovery, Fast DDS and a random domain.  The run ends when the driver exits, or
    with ``until_done`` when it prints ``done`` (its nodes are then stopped
    at once, so that timers do not add messages).  The monitor is then
    stopped once its log holds what ``heard`` asks of its lines (the run's
    last answers, whatever the machine's load; at most 30 s), or without
    ``heard`` 0.5 s later.  Returns the seconds it took; raises
    :class:`Failed` (the scenario or the monitor failed, or not
    within ``timeout`` seconds).  Every process started is stopped."""
    t0 = time.monotonic()
    if env is None:
        (tmp / "cyclonedds.xml").write_text(CYCLONE)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
        env.update(CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(), ROS_DOMAIN_ID=str(random.randint(1, 230)),
                   ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
                   PYTHONUNBUFFERED="1", ROS_LOG_DIR=str(tmp / "ros_log"))
    nenv = build(py, env, here, interfaces)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        mon = start([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", ".", "--live", "--ros2", *monitor,
                     "--reorder-window", "0", "--status", "0", "--silence", "0", "--duration", str(timeout),
                     "--log", str(tmp / "run.jsonl"), "--evidence", str(tmp / "evidence.json")],
                    env, tmp / "monitor.out", here)
        procs.append(mon)
        wait_for(tmp / "monitor.out", "monitoring", 15, mon)
        command = (lambda role: [str(py), str(scripts[role])]) if scripts else (lambda role: [str(py), script, role])
        for name in nodes:
            procs.append(start(command(name), nenv, tmp / f"{name}.out", here))
        for name, p in zip(nodes, procs[1:]):
            wait_for(tmp / f"{name}.out", "ready", 15, p)
        drv = start(command(driver), nenv, tmp / "driver.out", here)
        procs.append(drv)
        left = max(1.0, timeout - (time.monotonic() - t0))
        if until_done:
            try:
                wait_for(tmp / "driver.out", "done", left, drv)
            except Failed:
                said = (tmp / "driver.out").read_text(errors="replace")
                raise (NotConnected if "not connected:" in said else Failed)(
                    "the scenario failed:\n" + said[-2000:]) from None
            for p in procs[1:-1]:  # the nodes, all at once
                if p.poll() is None:
                    os.killpg(p.pid, signal.SIGTERM)
        else:
            drv.wait(left)
            if drv.returncode != 0:
                raise Failed("the scenario failed:\n" + (tmp / "driver.out").read_text(errors="replace")[-2000:])
        if heard is not None:
            logged(tmp / "run.jsonl", heard, 30)
        else:
            time.sleep(0.5)  # the last answers reach the monitor
        stop(mon, signal.SIGINT)
        if mon.returncode not in (0, 1):  # 1: a contract failed, as the seeded defects make it
            raise Failed("the monitor failed:\n" + (tmp / "monitor.out").read_text(errors="replace")[-2000:])
    except subprocess.TimeoutExpired:
        raise Failed(f"not done within {timeout} s") from None
    finally:
        for p in reversed(procs):
            stop(p)
    return time.monotonic() - t0


def logged(path: Path, heard: Callable[[list[dict[str, Any]]], bool], timeout: float) -> None:
    """Wait until ``heard`` holds of the complete lines of the monitor's log
    ``path``; :class:`Failed` with the log's end after ``timeout`` seconds."""
    until = time.monotonic() + timeout
    text = ""
    while time.monotonic() < until:
        text = path.read_text(errors="replace") if path.exists() else ""
        if heard([json.loads(x) for x in text[:text.rfind("\n") + 1].splitlines() if x.strip()]):
            return
        time.sleep(0.1)
    raise Failed(f"{path.name} never held the run's last answers:\n{text[-2000:]}")


def read_log(path: Path) -> list[dict[str, Any]]:
    """The lines of the monitor's log ``path``."""
    return [json.loads(x) for x in path.read_text().splitlines() if x.strip()]


def messages_span(log: list[dict[str, Any]]) -> tuple[int, float]:
    """``(messages, seconds from the first to the last)`` of a log's message lines (not rclverify's own)."""
    times = [x["time"] for x in log if not str(x.get("topic", "")).startswith("rclverify/")]
    return len(times), round(max(times) - min(times), 3) if times else 0.0


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file renamed into place."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.with_suffix(".tmp").write_text(text)
    path.with_suffix(".tmp").replace(path)


def serve(nodes: dict[str, Callable[[Any], Any]], scenario: Callable[[Any, Any], int]) -> int:
    """The ``main`` of an example's ``ros2_nodes.py`` (in the ROS 2 Python):
    ``ros2_nodes.py scenario`` runs ``scenario(node, executor)``;
    ``ros2_nodes.py ROLE...`` makes one rclpy node per role with
    ``nodes[role](node)`` (which may return a wait for its servers), spins
    them on a multi-threaded executor, prints ``ready`` and runs until
    SIGTERM/SIGINT.  Returns the exit code."""
    import threading

    import rclpy
    from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
    from rclpy.node import Node
    roles = sys.argv[1:]
    rclpy.init()
    executor = MultiThreadedExecutor(num_threads=4)
    made = []
    try:
        if roles == ["scenario"]:
            node = Node("scenario")
            made.append(node)
            executor.add_node(node)
            return scenario(node, executor)
        waits = []
        for role in roles:
            node = Node(role)
            made.append(node)
            waits.append(nodes[role](node))
            executor.add_node(node)
        threading.Thread(target=lambda: executor.spin(), daemon=True).start()
        if not all(w() for w in waits if w is not None):
            print("the service or action server did not come", flush=True)
            return 1
        print("ready", *roles, flush=True)
        while rclpy.ok():
            time.sleep(0.2)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        for node in made:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
