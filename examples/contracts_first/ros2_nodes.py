"""The thermostat as real ROS 2 nodes (rclpy), one process per node; run by
``record_live.py`` in a ROS 2 Python (rclpy, std_msgs and the colcon-built
``thermo_msgs``; no rclverify).

``python ros2_nodes.py TempSensor`` (or ``HeaterControl``) runs that node:
its callback calls the node's hand-written ``step`` from
``gen/<pkg>/<pkg>/logic.py`` (loaded from the file, as it stands), waits the
node's latency (the figures of the old simulator, ``record_run.py``) and
publishes the answer.  ``python ros2_nodes.py probe`` is the environment:
it waits until every node and the monitor are connected, then publishes
the 14 readings on ``probe``, one every 0.1 s, and prints ``done``.
"""
import importlib.util
import sys
import time
from pathlib import Path

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Bool, Float64
from thermo_msgs.msg import Probe

HERE = Path(__file__).resolve().parent
#: s: from receiving a message to publishing the answer (as record_run.py simulates)
LATENCY = {"TempSensor": 0.004, "HeaterControl": 0.002}
#: the probe's readings (K), one every 0.1 s: around 18 degC (291.15 K), both ways
KELVIN = [285.0, 288.4, 290.15, 291.0, 291.15, 291.3, 293.5, 296.0, 292.0, 291.2, 290.9, 287.65, 273.15, 310.0]
PERIOD = 0.1
#: topic -> subscribers expected before the first reading: the nodes' and the monitor's
READERS = {"probe": 2, "temperature": 2, "heat": 1}


def step_of(pkg):
    sys.dont_write_bytecode = True  # nothing written under gen/
    spec = importlib.util.spec_from_file_location(f"{pkg}_logic", HERE / "gen" / pkg / pkg / "logic.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.step


def temp_sensor(node):
    step = step_of("temp_sensor")
    pub = node.create_publisher(Float64, "temperature", 10)

    def on_probe(msg):
        out = Float64(data=float(step(kelvin=msg.kelvin)["celsius"]))
        time.sleep(LATENCY["TempSensor"])
        pub.publish(out)
    node.create_subscription(Probe, "probe", on_probe, 10)


def heater_control(node):
    step = step_of("heater_control")
    pub = node.create_publisher(Bool, "heat", 10)

    def on_temperature(msg):
        out = Bool(data=bool(step(celsius=msg.data)["heat"]))
        time.sleep(LATENCY["HeaterControl"])
        pub.publish(out)
    node.create_subscription(Float64, "temperature", on_temperature, 10)


def probe(node, executor):
    pub = node.create_publisher(Probe, "probe", 10)
    until = time.monotonic() + 20
    while any(node.count_subscribers(t) < n for t, n in READERS.items()):
        if time.monotonic() > until:
            print("not connected:", {t: node.count_subscribers(t) for t in READERS}, flush=True)
            return 1
        executor.spin_once(timeout_sec=0.05)
    time.sleep(1.0)  # every reader discovered; let the writers match them
    t0 = time.monotonic()
    for k, kelvin in enumerate(KELVIN):
        time.sleep(max(0.0, t0 + PERIOD * (k + 1) - time.monotonic()))
        pub.publish(Probe(kelvin=kelvin))
    time.sleep(0.5)
    print("done", len(KELVIN), flush=True)
    return 0


def main():
    role = sys.argv[1]
    rclpy.init()
    node = Node({"probe": "probe_driver"}.get(role, role))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        if role == "probe":
            return probe(node, executor)
        {"TempSensor": temp_sensor, "HeaterControl": heater_control}[role](node)
        print("ready", role, flush=True)
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.2)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
