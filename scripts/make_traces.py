"""Regenerate the bundled recorded runs of the case study (backends/monitors/traces/).

Each run is written twice, with the same events: as a ROSMonitoring
JSON-lines log (``<name>.jsonl``) and as a ROS 2 bag (``<name>_bag/``,
sqlite3 storage, written with rosbags' writer and the workspace's
``gazebo_radiation_plugin/Snapshot`` definition).  Runs:

* ``nominal``       the rover visits waypoints 1-6, inspects each, every
                    radiation reading is classified correctly;
* ``sensor_fault``  the same, but at waypoint 4 the Radiation Sensor reports
                    ``orange`` for a reading of 300 (its guarantee says ``red``);
* ``env_fault``     the same, but at waypoint 3 the radiation probe delivers
                    -5.0, which breaks the sensor's assumption ``0 <= in.r``.

Usage: ``python3 scripts/make_traces.py [--bag-only-mcap] [WORKSPACE]``.
Deterministic: same events, byte-identical logs.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path
from typing import Any, Iterator

FIELDS = {"command": "", "posx": 0.0, "posy": 0.0, "id": 0, "level": "", "value": 0.0}
WAYPOINTS = [(0.0, 0.0), (2.0, 1.0), (4.0, 1.5), (6.0, 3.0), (7.5, 5.0), (9.0, 6.5), (10.0, 8.0),
             (11.0, 9.5), (12.5, 10.0), (13.0, 12.0), (14.5, 13.0), (15.0, 14.5), (16.0, 16.0)]
READINGS = [40.0, 95.0, 130.0, 180.0, 60.0, 245.0]


def _msg(**kw: Any) -> dict[str, Any]:
    m = dict(FIELDS)
    m.update(kw)
    return m


def status(r: float) -> str:
    """The Radiation Sensor's correct classification (its guarantee, thresholds 120 and 250)."""
    return "green" if r < 120 else "orange" if r < 250 else "red"


def events(run: str) -> Iterator[tuple[float, str, dict[str, Any]]]:
    """(time in s, topic, Snapshot fields) of a run, in time order."""
    t = 0.0
    for i, (x, y) in enumerate(WAYPOINTS):
        yield t, "wayPNow", _msg(posx=x, posy=y, id=i)
        t += 0.01
    yield t, "radiationStatus", _msg(level="green")
    yield t + 0.01, "position", _msg(posx=0.0, posy=0.0)
    t += 0.5
    for i in range(1, 7):
        x, y = WAYPOINTS[i]
        r = READINGS[i - 1]
        if run == "sensor_fault" and i == 4:
            r = 300.0
        if run == "env_fault" and i == 3:
            r = -5.0
        reported = "orange" if (run == "sensor_fault" and i == 4) else status(max(r, 0.0))
        yield t, "command", _msg(command="move", posx=x, posy=y)
        t += 3.0
        yield t, "position", _msg(posx=x, posy=y)
        yield t + 0.01, "currentLoc", _msg(posx=x, posy=y)
        yield t + 0.02, "at", _msg(posx=x, posy=y)
        t += 0.5
        yield t, "command", _msg(command="inspect", id=i)
        yield t + 0.1, "r", _msg(value=r)
        yield t + 0.2, "inspected", _msg(id=i)
        yield t + 0.3, "radiationStatus", _msg(level=reported)
        t += 1.0


def write_log(path: Path, run: str) -> None:
    with path.open("w", encoding="utf-8") as fh:
        for t, topic, fields in events(run):
            fh.write(json.dumps({"topic": topic, "time": round(t, 3), **fields}, sort_keys=False) + "\n")


def write_bag(path: Path, run: str, msg_dir: Path, mcap: bool = False) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from rclverify.traces.bag import typestore
    store = typestore([msg_dir])
    Snapshot = store.types["gazebo_radiation_plugin/msg/Snapshot"]
    if path.exists():
        shutil.rmtree(path)
    plugin = StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        conns: dict[str, Any] = {}
        for t, topic, fields in events(run):
            if topic not in conns:
                conns[topic] = writer.add_connection("/" + topic, "gazebo_radiation_plugin/msg/Snapshot",
                                                     typestore=store)
            data = store.serialize_cdr(Snapshot(**fields), "gazebo_radiation_plugin/msg/Snapshot")
            writer.write(conns[topic], int(round(t * 1000)) * 1_000_000, data)


def write_bag1(path: Path, run: str, msg_dir: Path) -> None:
    """The run as a ROS 1 ``.bag`` (rosbags' rosbag1 writer)."""
    from rosbags.rosbag1 import Writer
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from rclverify.traces.bag import typestore
    store = typestore([msg_dir])
    Snapshot = store.types["gazebo_radiation_plugin/msg/Snapshot"]
    if path.exists():
        path.unlink()
    with Writer(path) as writer:
        conns: dict[str, Any] = {}
        for t, topic, fields in events(run):
            if topic not in conns:
                conns[topic] = writer.add_connection("/" + topic, "gazebo_radiation_plugin/msg/Snapshot",
                                                     typestore=store)
            data = store.serialize_ros1(Snapshot(**fields), "gazebo_radiation_plugin/msg/Snapshot")
            writer.write(conns[topic], int(round(t * 1000)) * 1_000_000 + 1_000_000_000, data)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("workspace", nargs="?", default=str(Path(__file__).resolve().parents[1]))
    args = ap.parse_args(argv)
    ws = Path(args.workspace)
    out = ws / "backends" / "monitors" / "traces"
    out.mkdir(parents=True, exist_ok=True)
    for run in ("nominal", "sensor_fault", "env_fault"):
        write_log(out / f"{run}.jsonl", run)
        write_bag(out / f"{run}_bag", run, ws / "backends" / "monitors" / "msg")
        print(f"wrote {out / run}.jsonl and {out / run}_bag/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
