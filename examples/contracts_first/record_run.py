"""THE SIMULATOR, to rebuild the run without ROS 2: the committed
``runs/run.jsonl`` is a recording of real rclpy nodes by ``rclverify monitor
--live --ros2`` (``record_live.py``, README.md), and this script overwrites it.

Record a run of the thermostat's hand-written logic (each node's ``step`` in
``gen/<pkg>/<pkg>/logic.py``, as it stands) in the monitor's log format
(ROSMonitoring JSON lines, one message per line: ``topic``, ``time`` in
seconds, the message's fields; docs/monitors.md).

The two nodes run on a simulated clock, as the generated ``node.py`` runs
them: a message on ``probe`` (``thermo_msgs/Probe``, field ``kelvin``)
makes TempSensor call its ``step`` and publish ``temperature``
(``std_msgs/Float64``, ``data``) after its latency; that message makes
HeaterControl call its ``step`` and publish ``heat`` (``std_msgs/Bool``).
The numbers are what the Python functions compute, in double arithmetic,
as the nodes would publish them.  ``python3 record_run.py`` rewrites
``runs/run.jsonl``; the run is deterministic.  The plan's ``monitors``
entries check it (``doit verify``).
"""
from __future__ import annotations

import heapq
import importlib.util
import json
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
#: s: from receiving a message to publishing the answer
LATENCY = {"TempSensor": 0.004, "HeaterControl": 0.002}
#: the probe's readings (K), one every 0.1 s: around 18 degC (291.15 K), both ways
KELVIN = [285.0, 288.4, 290.15, 291.0, 291.15, 291.3, 293.5, 296.0, 292.0, 291.2, 290.9, 287.65, 273.15, 310.0]


def _step(pkg: str) -> Any:
    spec = importlib.util.spec_from_file_location(f"{pkg}_logic", HERE / "gen" / pkg / pkg / "logic.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.step


def record() -> list[dict[str, Any]]:
    """The run: every message with its topic, time (s) and fields, in time order."""
    temp_sensor, heater_control = _step("temp_sensor"), _step("heater_control")
    queue: list[tuple[float, int, str, dict[str, Any]]] = []
    for k, kelvin in enumerate(KELVIN):
        queue.append((round(0.1 * (k + 1), 6), k, "probe", {"kelvin": kelvin}))
    heapq.heapify(queue)
    seq = len(queue)
    log = []
    while queue:
        t, _, topic, msg = heapq.heappop(queue)
        log.append({"topic": topic, "time": t, **msg})
        if topic == "probe":
            out, node, answer = temp_sensor(kelvin=msg["kelvin"]), "TempSensor", "temperature"
            fields = {"data": out["celsius"]}
        elif topic == "temperature":
            out, node, answer = heater_control(celsius=msg["data"]), "HeaterControl", "heat"
            fields = {"data": out["heat"]}
        else:
            continue
        seq += 1
        heapq.heappush(queue, (round(t + LATENCY[node], 6), seq, answer, fields))
    return log


def main() -> int:
    path = HERE / "runs" / "run.jsonl"
    text = "".join(json.dumps(m) + "\n" for m in record())
    tmp = path.with_suffix(".tmp")
    tmp.write_text(text)
    tmp.replace(path)  # atomic
    print(f"{path.relative_to(HERE)}: {text.count(chr(10))} messages")
    return 0


if __name__ == "__main__":
    sys.exit(main())
