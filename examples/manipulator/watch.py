"""Watch the manipulator live, once: ``robot.py`` (in the ROS 2 Python) under
``rclverify monitor --live --ros2 --strict`` (in the project's Python),
optionally with CPU-burning processes beside it, everything on loopback.

Used by tests/examples/test_example_manipulator.py and bench/manipulator_live.py::

    from watch import watch
    result = watch(tmp, ros2_python, env, source="rclpy", defects="", record=True, burners=2)

``env`` is the processes' environment (it must keep them on loopback in a
DDS domain of their own: ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, a
Cyclone configuration on the loopback interface, a ``ROS_DOMAIN_ID``);
:func:`loopback_env` makes one.  Returns ``{"tmp", "code", "out", "robot",
"record"}``: the monitor's exit code, its output, the robot's output and
the evidence record; the log is ``tmp/live.jsonl``, the bag (with
``record``) ``tmp/bag``.  Raises ``RuntimeError`` with the end of the
output of the part that failed (``ros2_recording.Failed`` with the log's
end when the monitor's log never holds the robot's calls judged).  Every
process started is stopped.
"""
from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from ros2_recording import CYCLONE, logged, stop  # noqa: E402

SRC = HERE.parents[1] / "src"
#: a process that keeps one core busy for at most this many seconds
BURN = "import time\nend = time.monotonic() + 120\nwhile time.monotonic() < end:\n    pass\n"


_HELD: list[int] = []  # the lock files of the domains this process took, open until it exits


def free_domain() -> int:
    """A ``ROS_DOMAIN_ID`` (1..230) no other process of this machine holds
    (the test suite's lock files, in the temporary directory), held until
    this process exits: a run that shares its domain hears another's nodes."""
    import fcntl
    import tempfile
    for d in random.SystemRandom().sample(range(1, 231), 230):
        fd = os.open(os.path.join(tempfile.gettempdir(), f"rclverify-test-dds-domain-{d}.lock"), os.O_CREAT | os.O_RDWR)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        _HELD.append(fd)
        return d
    raise RuntimeError("no free DDS domain: all 230 are held")


def loopback_env(tmp: Path) -> dict[str, str]:
    """This process's environment with a loopback Cyclone configuration
    (written to ``tmp``), localhost discovery, Fast DDS and a DDS domain of
    its own (:func:`free_domain`)."""
    (tmp / "cyclonedds.xml").write_text(CYCLONE)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    env.update(CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(), ROS_DOMAIN_ID=str(free_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
               PYTHONUNBUFFERED="1", ROS_LOG_DIR=str(tmp / "ros_log"))
    return env


def _wait(path: Path, text: str, timeout: float, proc: subprocess.Popen[bytes]) -> None:
    until = time.monotonic() + timeout
    while not (path.exists() and text in path.read_text(errors="replace")):
        if proc.poll() is not None or time.monotonic() > until:
            raise RuntimeError(f"{path.name} never said {text!r}:\n{path.read_text(errors='replace')[-2000:]}")
        time.sleep(0.05)


#: the calls robot.py makes once its rounds are published: six of /estop, three goals of /arm
CALLS = 9


def _judged(log: list[dict[str, Any]]) -> bool:
    """The robot's last calls in the monitor's log: each /estop response and /arm result with its verdict,
    and each /estop call's deadline line."""
    ends = [x["where"] for x in log if x.get("kind") == "call" and x.get("part") in ("response", "result")]
    judged = {x["verdict"].get("where") for x in log if x.get("topic") == "rclverify/verdict"}
    return len(ends) >= CALLS and set(ends) <= judged and sum(x.get("kind") == "deadline" for x in log) >= 6


def watch(tmp: Path, ros2_python: Path, env: dict[str, str], *, source: str, defects: str = "",
          record: bool = False, burners: int = 2, rounds: int = 40,
          after: Callable[[], Any] | None = None) -> dict[str, Any]:
    """One live run (module docstring): the monitor is stopped once the robot says ``done`` and the
    monitor's log holds each of its calls judged (:func:`_judged`); ``after()``, when given, is called
    then, while the robot's nodes still run, and what it returns is the result's ``"after"``."""
    procs: list[subprocess.Popen[bytes]] = []

    def start(cmd: list[str], out: str, extra: dict[str, str] | None = None) -> subprocess.Popen[bytes]:
        with open(tmp / out, "wb") as fh:
            p = subprocess.Popen(cmd, cwd=tmp, env=dict(env, **(extra or {})), stdout=fh, stderr=subprocess.STDOUT,
                                 start_new_session=True)
        procs.append(p)
        return p
    try:
        robot = start([str(ros2_python), str(HERE / "robot.py"), "--defects", defects, "--rounds", str(rounds)],
                      "robot.log")
        _wait(tmp / "robot.log", "ready", 60, robot)
        monitor = start([sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(HERE), "--live",
                         "--ros2", "--mapping", "contracts/mapping.yaml", "--status", "0", "--duration", "120",
                         "--source", source, "--ros2-python", str(ros2_python), "--strict",
                         "--log", str(tmp / "live.jsonl"), "--evidence", str(tmp / "live.json"),
                         *(["--record", str(tmp / "bag")] if record else [])], "monitor.out", {"PYTHONPATH": str(SRC)})
        _wait(tmp / "robot.log", "rounds", 60, robot)
        burning = [start([sys.executable, "-c", BURN], f"burn{k}.out") for k in range(burners)]
        _wait(tmp / "robot.log", "done", 90, robot)
        logged(tmp / "live.jsonl", _judged, 30)
        stop(monitor, signal.SIGINT)
        for p in burning:
            stop(p)
        if not (tmp / "live.json").exists():
            raise RuntimeError("the monitor wrote no evidence:\n" + (tmp / "monitor.out").read_text()[-2000:])
        extra = after() if after is not None else None
        return {"tmp": tmp, "code": monitor.returncode, "out": (tmp / "monitor.out").read_text(),
                "robot": (tmp / "robot.log").read_text(), "record": json.loads((tmp / "live.json").read_text()),
                "after": extra}
    finally:
        for p in reversed(procs):
            stop(p)


def node_status(record: dict[str, Any]) -> dict[str, str]:
    """Each contract node's status over its topics, calls and goals (a failed call makes the node failed)."""
    status = {n["node"]: n["status"] for n in record["nodes"]}
    for n in record.get("calls", {}).get("nodes", []):
        if n["status"] == "failed" or status.get(n["node"]) in (None, "pending"):
            status[n["node"]] = n["status"]
    return status
