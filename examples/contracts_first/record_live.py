"""Record ``runs/run.jsonl`` from real ROS 2 nodes: the thermostat's two
nodes and its probe run as rclpy processes (``ros2_nodes.py``) on ROS 2's
default middleware (rmw_fastrtps_cpp, Fast DDS) while ``rclverify monitor
--live --ros2`` watches the bus and writes its log (docs/monitors.md, "ROS 2
over DDS").  Everything stays on this host: the nodes discover on localhost
only (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), the monitor's Cyclone
DDS uses the loopback interface, and the domain is a random one.

Run it with the project's Python (the one rclverify is installed in)::

    python3 record_live.py [--ros2-python PATH] [--out runs/run.jsonl]

The ROS 2 Python is ``--ros2-python``, else ``$RCLVERIFY_ROS2_PYTHON``, else
the ``.venv-ros2/bin/python`` of the nearest folder above this one (ROS 2's
PyPI wheels, docs/ros2.md).  The interface package ``gen/thermo_msgs`` is
built with colcon into ``.ros2/`` the first time (a few seconds).  Exit 0
with the log's figures; 1 with the reason when a part failed (the old log is
kept then).  ``record_run.py`` is the simulator this replaced: it rebuilds
the run without ROS 2, on a simulated clock, and is not the committed run.
"""
from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
NODES = ["TempSensor", "HeaterControl"]
DRIVER = "probe"
INTERFACES = ["gen/thermo_msgs"]
MONITOR = ["--mapping", "gen/rclverify_mapping.yaml", "--interfaces", "gen"]
CYCLONE = """<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any">
  <General><Interfaces><NetworkInterface name="lo" multicast="false"/></Interfaces>
    <AllowMulticast>false</AllowMulticast></General>
  <Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>
    <Peers><Peer address="127.0.0.1"/></Peers></Discovery>
</Domain></CycloneDDS>
"""
TIMEOUT = 30.0  # s, the whole recording


class Failed(Exception):
    """A part of the recording failed; the message says which."""


def ros2_python(named: str | None) -> Path:
    if named or os.environ.get("RCLVERIFY_ROS2_PYTHON"):
        exe = Path(named or os.environ["RCLVERIFY_ROS2_PYTHON"])
        if not exe.is_file():
            raise Failed(f"no ROS 2 Python at {exe}")
        return exe
    for d in HERE.parents:
        if (d / ".venv-ros2" / "bin" / "python").exists():
            return d / ".venv-ros2" / "bin" / "python"
    raise Failed("no ROS 2 Python: give --ros2-python (a Python with rclpy and rmw_fastrtps_cpp)")


def build(py: Path, env: dict[str, str]) -> dict[str, str]:
    """colcon-build the interface packages into .ros2/ (once) and return ``env`` with its setup sourced."""
    ws = HERE / ".ros2"
    if not all((ws / "install" / Path(p).name).is_dir() for p in INTERFACES):
        shutil.rmtree(ws, ignore_errors=True)
        ws.mkdir()
        venv = py.parent.parent
        benv = dict(env, PATH=f"{py.parent}:{env['PATH']}", CMAKE_PREFIX_PATH=str(venv), AMENT_PREFIX_PATH=str(venv))
        r = subprocess.run([str(py), "-m", "colcon", "build", "--base-paths", *[str(HERE / p) for p in INTERFACES]],
                           cwd=ws, env=benv, capture_output=True, timeout=300)
        if r.returncode != 0:
            shutil.rmtree(ws / "install", ignore_errors=True)
            raise Failed("colcon build failed:\n" + r.stdout.decode(errors="replace")[-3000:])
    dump = subprocess.run(["bash", "-c", ". install/setup.sh && env -0"], cwd=ws, env=env, capture_output=True,
                          timeout=60, check=True).stdout
    return dict(kv.split("=", 1) for kv in dump.decode().split("\0") if "=" in kv)


def wait_for(path: Path, text: str, timeout: float, proc: subprocess.Popen[bytes]) -> None:
    until = time.monotonic() + timeout
    while not (path.exists() and text in path.read_text(errors="replace")):
        if proc.poll() is not None or time.monotonic() > until:
            raise Failed(f"{path.name} never said {text!r}:\n{path.read_text(errors='replace')[-2000:]}")
        time.sleep(0.05)


def start(cmd: list[str], env: dict[str, str], log: Path) -> subprocess.Popen[bytes]:
    with open(log, "wb") as fh:
        return subprocess.Popen(cmd, cwd=HERE, env=env, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True)


def stop(p: subprocess.Popen[bytes], sig: int = signal.SIGTERM) -> None:
    if p.poll() is None:
        os.killpg(p.pid, sig)
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(5)


def record(py: Path, tmp: Path, out: Path) -> dict[str, object]:
    t0 = time.monotonic()
    (tmp / "cyclonedds.xml").write_text(CYCLONE)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    env.update(CYCLONEDDS_URI=(tmp / "cyclonedds.xml").as_uri(), ROS_DOMAIN_ID=str(random.randint(1, 230)),
               ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RMW_IMPLEMENTATION="rmw_fastrtps_cpp",
               PYTHONUNBUFFERED="1", ROS_LOG_DIR=str(tmp / "ros_log"))
    nenv = build(py, env)
    procs: list[subprocess.Popen[bytes]] = []
    try:
        monitor = start([sys.executable, "-m", "rclverify.cli", "monitor", "-w", ".", "--live", "--ros2", *MONITOR,
                         "--reorder-window", "0", "--status", "0", "--silence", "0", "--duration", str(TIMEOUT),
                         "--log", str(tmp / "run.jsonl"), "--evidence", str(tmp / "evidence.json")],
                        env, tmp / "monitor.out")
        procs.append(monitor)
        wait_for(tmp / "monitor.out", "monitoring", 15, monitor)
        for name in NODES:
            procs.append(start([str(py), "ros2_nodes.py", name], nenv, tmp / f"{name}.out"))
        for name, p in zip(NODES, procs[1:]):
            wait_for(tmp / f"{name}.out", "ready", 15, p)
        driver = start([str(py), "ros2_nodes.py", DRIVER], nenv, tmp / "driver.out")
        procs.append(driver)
        driver.wait(max(1.0, TIMEOUT - (time.monotonic() - t0)))
        if driver.returncode != 0:
            raise Failed("the scenario failed:\n" + (tmp / "driver.out").read_text(errors="replace")[-2000:])
        time.sleep(0.5)  # the last answers reach the monitor
        stop(monitor, signal.SIGINT)
        if monitor.returncode not in (0, 1):  # 1: a contract failed, as the seeded defects make it
            raise Failed("the monitor failed:\n" + (tmp / "monitor.out").read_text(errors="replace")[-2000:])
    except subprocess.TimeoutExpired:
        raise Failed(f"not done within {TIMEOUT} s") from None
    finally:
        for p in reversed(procs):
            stop(p)
    lines = [json.loads(x) for x in (tmp / "run.jsonl").read_text().splitlines() if x.strip()]
    messages = [x for x in lines if not str(x.get("topic", "")).startswith("rclverify/")]
    times = [x["time"] for x in messages]
    out.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(tmp / "run.jsonl", out.with_suffix(".tmp"))
    out.with_suffix(".tmp").replace(out)
    return {"lines": len(lines), "messages": len(messages), "calls": sum(x.get("kind") == "call" for x in lines),
            "span_s": round(max(times) - min(times), 3) if times else 0.0, "seconds": round(time.monotonic() - t0, 1)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ros2-python", help="the ROS 2 Python (rclpy, rmw_fastrtps_cpp)")
    ap.add_argument("--keep", help="keep the processes' outputs in this folder (else a temporary one)")
    ap.add_argument("--out", default="runs/run.jsonl", help="the log to write (relative to this folder)")
    args = ap.parse_args(argv)
    try:
        py = ros2_python(args.ros2_python)
        if args.keep:
            Path(args.keep).mkdir(parents=True, exist_ok=True)
            figures = record(py, Path(args.keep).resolve(), HERE / args.out)
        else:
            with tempfile.TemporaryDirectory(prefix="record_live_") as tmp:
                figures = record(py, Path(tmp), HERE / args.out)
    except (Failed, OSError, subprocess.SubprocessError) as exc:
        print(f"record_live.py: error: {exc}", file=sys.stderr)
        return 1
    print(f"{args.out}: {json.dumps(figures)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
