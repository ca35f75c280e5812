"""A generator of correct robots (issue 106): random ROS 2 systems of real rclpy nodes, each node
written for the RCL contract generated with it, judged live by ``rclverify monitor --live --ros2``
and offline on the run's log and bag, the three compared verdict by verdict (bench/_robot_verdicts.py).

Given a seed, :func:`generate` draws a system of N nodes from five templates (the spec is plain data):

* **sensor**: a periodic publisher (200-400 ms) of ``std_msgs/Float32`` or ``std_msgs/UInt8``
  (unstamped), ``sensor_msgs/Range`` (float32, stamped by the sensor 0-30 ms before it is
  published), ``std_msgs/Float32MultiArray`` (a float32 sequence, unstamped) or
  ``sensor_msgs/LaserScan`` (a stamped float32 sequence); its guarantee keeps every value in its
  band ``[LO, HI]``, both named constants, both values published exactly;
* **alarm**: a ``std_msgs/Bool`` answer to one sensor, ``out.low <=> (in.x <= K)`` (float32 K read
  as the field carries it: the node compares with ``numpy.float32(K)``), ``out.high <=> (in.n >= K)``
  (uint8) or ``out.low <=> exists(v in in.cells | v < K)``, its deadline ``triggered by`` the input;
  the sensor publishes K itself and its float32 neighbours, so the boundary is hit;
* **relay**: a ``sensor_msgs/Range`` copy of a float32 reading, ``out.r == in.x``, either copying
  the input's header stamp (its processing delay up to twice the input's period) or stamped with its
  own clock when it publishes (delay under a third of the period);
* **fuse**: two inputs, ``out.alert <=> (in.a <= KA and in.b >= KB)`` (float32 and uint8) or
  ``out.low <=> (in.x <= K or exists(v in in.cells | v < K2))``, answering each ``in.a``; its second
  sensor is its own, publishing half a period before the first (every ``in.a`` finds a value of
  ``in.b``);
* **service**: a ``std_srvs/SetBool`` server, ``out.ok == in.on`` within a deadline, with or without
  service introspection, called one call at a time by a client in the same process.

Each node declares what it keeps (bench/_robot_declarations.py): a sensor ``initially`` its band and
``periodic( out.x, P ms )`` (P two periods and 1 s, in its node's clock: a stamped sensor's on a
``/clock`` times the real-time factor), an alarm, a relay and a fuse ``progress( within K steps )`` (one
alarm or relay in two as ``periodic( out.y, K + 1 steps )``), a server ``progress( eventually )`` or
``progress( within 1 steps )``; every sensor publishes until the robot is stopped (after the monitor),
every client stops calling when the sensing ends, its last call answered.

Nodes get a namespace at random.  ``defect=True`` seeds one defect in one node: ``<`` for ``<=``
(``>`` for ``>=``, ``<=`` for ``<``), a relay adding 0.5 to every fourth reading, a server
answering every third call wrongly, a sensor publishing just beyond its band or skipping one
publication for longer than its declared period, an alarm answering none of K + 2 readings; the runner
(``bench/_robot_run.py``) checks it is red at that node and only there.

:func:`write_workspace` renders the workspace from the jinja2 templates of
``bench/templates/robot_generator/``: ``contracts/robot.rcl`` (a ``context`` of the named
constants), ``contracts/plan.yaml``, ``mapping.yaml``, ``interfaces/`` (SetBool) and ``robot.py``
(every node in one rclpy process, run in ROS 2's Python).

``sim_clock=True`` (``--clock``) adds a clock node publishing ``rosgraph_msgs/Clock`` on ``/clock``
every 20 ms at a real-time factor drawn from 0.5-2, from a simulated start of 0, 100 or 5000 s, and
runs every other node with ``use_sim_time`` (their header stamps come from ``/clock``), the mapping
declaring so (``use_sim_time: true``; ``--undeclared-sim-time`` leaves it unsaid, and the monitor decides
a deadline only where the wall clock and ``/clock`` time agree).  Its times are then ``/clock``'s
(:func:`sim_answers`): every sensor publishes on its simulated timer every 1.6-2 simulated s (silent
while the clock is paused), and every alarm, relay and fuse answers after 0.55-0.65 of its deadline
(1.1 or 1.2 simulated s) measured on its node's own ROS clock: in time in simulated time at every
factor (the 0.35 d left is the real latency at a factor of 2), before the next reading, and at a
factor of 0.5 past its deadline in the wall clock.  A server answers at once, its deadline twice the
wall clock's.  Its seeded defect may be ``"late"`` (an alarm, a fuse, a relay stamping with its own
clock): its answers :data:`LATE_FACTOR` deadlines after its input in simulated time, false at every
factor, though at a factor of 2 its wall-clock delay is within the deadline.
``clock_change=True`` (``--clock-change``, implies ``--clock``) makes that factor change once or twice
mid-run (1.5-6.4 s after the sensing starts, each new factor within 0.5-2) and, one time in two, pauses
the clock for 0.5-1 s (``/clock`` stops, as a paused simulator's does), :func:`clock_changes`.

``actions=True`` (``--actions``) turns each SetBool server, one time in two, into a
``test_msgs/Fibonacci`` action server (with or without introspection, as drawn for the server),
``out.final >= in.order - 1`` on the result's last number (equal at orders 2-4, always sent); its
defect answers one short.

CLI (from the repository root)::

    python3 bench/robot_generator.py --seeds 0-49 --nodes 5-8 --seconds 10 --burn
    python3 bench/robot_generator.py --seeds 0-9 --source rclpy --clock
    python3 bench/robot_generator.py --seeds 0-9 --clock-change --burn
    python3 bench/robot_generator.py --seeds 0-9 --clock --undeclared-sim-time
    python3 bench/robot_generator.py --seeds 3 --defect
    python3 bench/robot_generator.py --write DIR --seeds 7     # the workspace alone

``--smoke``: generates and type-checks the workspaces of 20 seeds (with and without a defect); no
live run (tests/bench/test_robot_generator.py runs the live seeds).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import functools
import json
import math
import random
import sys
from pathlib import Path
from typing import Any

import numpy as np
from _robot_declarations import CLOCK_STEP_MS, STAMP_BEHIND_S, declare, defect_kind  # bench/ is on sys.path (run as a script, the tests)

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = ROOT / "bench" / "templates" / "robot_generator"
#: message type, field, RCL variable type and stamped-ness of each sensor kind
SENSORS: dict[str, tuple[str, str, str, bool]] = {
    "f32": ("std_msgs/Float32", "data", "REAL", False),
    "u8": ("std_msgs/UInt8", "data", "INTEGER", False),
    "range": ("sensor_msgs/Range", "range", "REAL", True),
    "arr": ("std_msgs/Float32MultiArray", "data", "seq(REAL)", False),
    "scan": ("sensor_msgs/LaserScan", "ranges", "seq(REAL)", True),
}
SETBOOL = "bool data\n---\nbool success\nstring message\n"
#: sensor_msgs/Range as ROS 2 Kilted defines it (with ``variance``): the monitor's DDS reader is told the
#: robot's layout (``--interfaces interfaces``), whose type hash differs from the older definition's
RANGE = ("std_msgs/Header header\nuint8 ULTRASOUND=0\nuint8 INFRARED=1\nuint8 radiation_type\n"
         "float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\nfloat32 variance\n")
FIBONACCI = "int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n"
#: the orders a Fibonacci action's client draws its goals from (2, 3 and 4 are always sent)
FIB_ORDERS = (1, 2, 3, 4, 5, 6, 7, 8)
#: the horizon (s) of a question (the mapping's ``horizon``: an answer later than that is ``inconclusive``)
HORIZON = 1.0
#: ... on a ``/clock`` robot: an answer waits up to 0.65 of 1.2 simulated s, 1.56 s of the wall clock at a
#: factor of 0.5, and a pause of up to 1 s more
CLOCK_HORIZON = 4.0
#: a SetBool server's deadline (ms) on the wall clock
SERVER_DEADLINE_MS = 800
#: the most (s) a sensor's driver may stamp behind within the run's clock: an answer leaves up to 30 % of a
#: 200 ms period after its reading, a stamp up to 30 ms before its publication, and the next reading's stamp
#: must come after the answer (generated seeds 955-958, 0.2 s behind: the alarms and relays judged, rightly,
#: against the next reading)
MAX_BEHIND_S = 0.05
#: the real-time factors a ``/clock`` robot draws from: simulated seconds per wall-clock second
CLOCK_RATES = (0.5, 0.75, 1.0, 1.5, 2.0)
#: the periods (simulated ms) a ``/clock`` robot's sensors publish at, each on its node's simulated timer: a
#: deadline's answer (at most 0.65 of :data:`SIM_DEADLINES_MS` and the real latency at factor 2 after its
#: reading) and the seeded ``"late"`` answer (:data:`LATE_FACTOR`) come before the next reading in simulated
#: time, at every factor and through a pause (rule D1, docs/semantics.md "Deadlines": each reading is owed
#: an answer of its own, and an alarm answers from the reading in force when its answer leaves)
SIM_PERIODS_MS = (1600, 1800, 2000)
#: the deadlines (simulated ms) of a ``/clock`` robot's alarms, relays and fuses
SIM_DEADLINES_MS = (1100, 1200)
#: a ``/clock`` robot's answering node waits this share of its deadline, on its node's simulated clock: from
#: 0.55 (at a factor of 0.5 its wall-clock delay, 1.1 d or more, is past the deadline in the wall clock)
#: to 0.65 (the 0.35 d left, 385 simulated ms or more, is the real latency of its reading's delivery and of
#: its answer, up to 190 ms of the wall clock at a factor of 2)
SIM_DELAY_SHARE = (0.55, 0.65)
#: the seeded ``"late"`` defect of a ``/clock`` robot: its answer this many deadlines after its reading in
#: simulated time (false at every factor; at a factor of 2 its wall-clock delay, 0.65 d, is within it)
LATE_FACTOR = 1.3
#: the largest real-time factor a ``/clock`` robot runs at (:data:`CLOCK_RATES`): a server answering at once
#: on a ``/clock`` robot declares its wall-clock deadline (800 ms) this many times over, in simulated time
SIM_RATE_TOP = 2.0
#: the wall-clock seconds after the sensing starts at which a changing ``/clock`` may change (``--clock-change``):
#: each change or pause at one of these, 0-0.4 s later, so two never overlap (a pause lasts at most 1 s)
CLOCK_CHANGE_SLOTS = (1.5, 3.0, 4.5, 6.0)


def clock_changes(seed: int, nodes: int, rate: float) -> list[list[float]]:
    """The segments of a ``/clock`` that changes its rate mid-run (``--clock-change``), from a clock at
    ``rate`` (its real-time factor before the first change): ``[[at_s, rate], ...]`` in order, ``at_s`` in
    wall-clock seconds after the sensing starts, each segment's rate from :data:`CLOCK_RATES` other than
    the one before, one or two changes of factor, and one time in two a pause (rate 0: ``/clock`` stops
    for 0.5-1 s, then goes on at the factor it had).  The last segment's rate is never 0.  Deterministic in
    (seed, nodes, rate)."""
    rng = random.Random(f"clock-change-{seed}-{nodes}")
    changes = rng.randint(1, 2)
    pause = rng.random() < 0.5
    slots = sorted(rng.sample(CLOCK_CHANGE_SLOTS, changes + pause))
    at_pause = rng.choice(slots) if pause else None
    out: list[list[float]] = []
    now = rate
    for slot in slots:
        at = round(slot + rng.uniform(0.0, 0.4), 2)
        if slot == at_pause:
            out += [[at, 0.0], [round(at + rng.uniform(0.5, 1.0), 2), now]]
            continue
        now = rng.choice([r for r in CLOCK_RATES if r != now])
        out.append([at, now])
    return out


def sim_timed(n: dict[str, Any], spec: dict[str, Any]) -> bool:
    """Whether sensor ``n`` of ``spec`` publishes on its simulated clock's timer (a driver under
    ``use_sim_time``: it stops while ``/clock`` is paused): every sensor of a ``/clock`` robot (its
    period in simulated ms, :data:`SIM_PERIODS_MS`; its consumers answer on the same clock, each before
    the next reading at every factor, :func:`sim_answers`)."""
    return bool(spec.get("clock")) and n["kind"] == "sensor"


def sim_answers(nodes: list[dict[str, Any]], seed: int, count: int) -> None:
    """Put the nodes of a ``/clock`` robot on its simulated clock (in place): every sensor's
    ``"period_ms"`` and ``"phase_ms"`` (under half the period) in simulated ms (:data:`SIM_PERIODS_MS`; a fuse's second sensor
    at its first's period, half a period before it); each alarm's, relay's and fuse's ``"deadline_ms"``
    (:data:`SIM_DEADLINES_MS`) and ``"delay_ms"``, the wait on its node's clock before it answers
    (:data:`SIM_DELAY_SHARE` of the deadline); a server's ``"deadline_ms"`` its wall-clock deadline times
    :data:`SIM_RATE_TOP` (it answers at once).  Drawn from a generator of its own, so the nodes drawn
    do not change; deterministic in (seed, count)."""
    rng = random.Random(f"sim-answers-{seed}-{count}")
    by = {n["name"]: n for n in nodes}
    for n in nodes:
        if n["kind"] == "sensor":
            n["period_ms"] = rng.choice(SIM_PERIODS_MS)
            n["phase_ms"] = rng.randrange(0, n["period_ms"] // 2)
    for n in nodes:
        if n["kind"] == "fuse":
            a, b = by[n["a_source"]], by[n["b_source"]]
            b.update(period_ms=a["period_ms"], phase_ms=a["phase_ms"] - a["period_ms"] // 2)
        if n["kind"] in ("alarm", "relay", "fuse"):
            d = rng.choice(SIM_DEADLINES_MS)
            n["deadline_ms"] = d
            n["delay_ms"] = rng.randint(math.ceil(SIM_DELAY_SHARE[0] * d), math.floor(SIM_DELAY_SHARE[1] * d))
        elif n["kind"] == "service":
            n["deadline_ms"] = int(SERVER_DEADLINE_MS * SIM_RATE_TOP)


def deadline_ms(n: dict[str, Any]) -> int:
    """The deadline (ms, in its node's clock) of an alarm's, a relay's, a fuse's or a server's node spec
    ``n``: drawn on a ``/clock`` robot (:func:`sim_answers`), else its delay and 500 ms (an alarm, a relay,
    a fuse) or :data:`SERVER_DEADLINE_MS`."""
    if "deadline_ms" in n:
        return int(n["deadline_ms"])
    return SERVER_DEADLINE_MS if n["kind"] == "service" else int(n["delay_ms"]) + 500


def horizon_of(spec: dict[str, Any]) -> float:
    """The horizon (s) of robot ``spec``'s questions: :data:`CLOCK_HORIZON` on a ``/clock``, else
    :data:`HORIZON`."""
    return CLOCK_HORIZON if spec.get("clock") else HORIZON


def settle_s(spec: dict[str, Any]) -> float:
    """How long (wall-clock s) robot ``spec`` waits, once the monitor's verdict topic is up, before its
    sensing (and its clients' calls) begin: the monitor's readers match every writer, and a request writer
    it has heard for less than the horizon leaves the replies of the DDS source's order pairing undecided
    (docs/monitors.md, "Services and actions over DDS": nothing missed), so a run lets the horizon pass first, as its advice says
    ("start the monitor before the clients call")."""
    return max(2.5, horizon_of(spec) + 1.0)


def late_ms(n: dict[str, Any]) -> int:
    """The wait (simulated ms) of a node seeded ``"late"``: :data:`LATE_FACTOR` times its deadline."""
    return math.ceil(LATE_FACTOR * deadline_ms(n))


def f32(v: float) -> float:
    """``v`` rounded to the nearest float32, as a Python float."""
    return float(np.float32(v))


def _float_band(rng: random.Random) -> tuple[str, str, list[str]]:
    lo = rng.choice(["0", "0.1", "0.25", "0.5"])
    hi = f"{float(lo) + rng.choice([1.5, 2.2, 3.0, 4.7]):.2f}".rstrip("0").rstrip(".")
    ks = sorted({f"{rng.uniform(float(lo) + 0.05, float(hi) - 0.05):.2f}" for _ in range(3)})
    return lo, hi, ks


def _float_values(rng: random.Random, lo: str, hi: str, ks: list[str], n: int) -> list[float]:
    """Float32 readings within [lo, hi]: both ends, each threshold and its float32 neighbours, and
    random values; each as the float32 a field carries."""
    pool = [f32(float(lo)), f32(float(hi))]
    for k in ks:
        x = np.float32(float(k))
        pool += [float(x), float(np.nextafter(x, np.float32(-np.inf))), float(np.nextafter(x, np.float32(np.inf)))]
    pool = [v for v in pool if f32(float(lo)) <= v <= f32(float(hi))]
    out = [rng.choice(pool) if rng.random() < 0.6 else f32(rng.uniform(float(lo), float(hi))) for _ in range(n)]
    return _with_all(rng, out, pool)


def _with_all(rng: random.Random, values: list[Any], must: list[Any]) -> list[Any]:
    """``values`` with every item of ``must`` put in at a random place (each boundary is hit)."""
    out = list(values)
    for v in must:
        if v not in out:
            out.insert(rng.randrange(len(out) + 1), v)
    return out


def _sensor(rng: random.Random, i: int, kinds: tuple[str, ...], kind: str | None = None) -> dict[str, Any]:
    kind = kind or rng.choice(kinds)
    # at least 200 ms: a robot stalled by a loaded machine (100 ms seen with both cores busy) must still
    # answer each reading before the next, or rule D1 rightly fails the reading's deadline
    period = rng.choice([200, 250, 300, 400])
    s: dict[str, Any] = {"kind": "sensor", "name": f"Sensor{i}", "ros_name": f"sensor{i}", "topic_base": f"s{i}",
                         "sensor_kind": kind, "period_ms": period, "phase_ms": rng.randrange(0, period),
                         "back_ms": rng.choice([0, 5, 10, 30]) if SENSORS[kind][3] else 0}
    if kind == "u8":
        lo, hi = rng.randrange(0, 20), rng.randrange(150, 256)
        ks = sorted({rng.randrange(lo + 2, hi - 2) for _ in range(3)})
        pool = [lo, hi] + [v for k in ks for v in (k - 1, k, k + 1)]
        s.update(lo=str(lo), hi=str(hi), thresholds=[str(k) for k in ks],
                 values=_with_all(rng, [rng.choice(pool) if rng.random() < 0.6 else rng.randrange(lo, hi + 1)
                                        for _ in range(16)], pool),
                 beyond=hi + 1 if hi < 255 else None)
        if s["beyond"] is None:  # a uint8 cannot leave [lo, 255] above: the defect goes below
            s["beyond"] = lo - 1 if lo > 0 else None
        return s
    lo_t, hi_t, ks_t = _float_band(rng)
    over = float(np.nextafter(np.float32(float(hi_t)), np.float32(np.inf)))
    if kind in ("f32", "range"):
        vals: list[Any] = _float_values(rng, lo_t, hi_t, ks_t, 16)
        beyond: Any = over
    else:
        cells = _float_values(rng, lo_t, hi_t, ks_t, 80)
        vals = [rng.sample(cells, rng.randint(3, 6)) for _ in range(12)]
        for k in ks_t:  # readings whose least cell is the threshold itself, and one just below it
            x = np.float32(float(k))
            for least in (float(x), float(np.nextafter(x, np.float32(-np.inf)))):
                above = [c for c in cells if c > least][:rng.randint(2, 5)] or [least]
                vals.insert(rng.randrange(len(vals) + 1), rng.sample(above + [least], len(above) + 1))
        beyond = [f32(float(lo_t)), over, f32(float(hi_t))]
    s.update(lo=lo_t, hi=hi_t, thresholds=ks_t, values=vals, beyond=beyond)
    return s


def generate(seed: int, nodes: int = 5, defect: bool = False,
             kinds: tuple[str, ...] = tuple(SENSORS), sim_clock: bool = False,
             actions: bool = False, driver_offset_s: float = 0.0, clock_change: bool = False,
             undeclared_sim_time: bool = False) -> dict[str, Any]:
    """The spec of generated robot ``seed``: ``{"seed", "defect", "clock", "nodes": [node spec, ...]}``,
    ``nodes`` contract nodes (at least 2: a sensor and one consumer); with ``defect``, exactly one node's
    spec holds ``"defect": True``; ``kinds``: the sensor kinds drawn from (keys of :data:`SENSORS`);
    ``sim_clock``: ``"clock"`` is ``{"rate", "start_s"}`` (a ``/clock`` node, :data:`CLOCK_RATES`),
    else ``None``; ``actions``: each SetBool server becomes, one time in two, a Fibonacci action server
    (its client sending :data:`FIB_ORDERS` goals one at a time); ``driver_offset_s``: every sensor's
    header stamps run that many seconds off its clock (a driver's clock, negative: behind), its
    ``"driver_offset_s"``; within the run's clock at most :data:`MAX_BEHIND_S` behind (else
    ``ValueError``, saying why); ``clock_change`` (with ``sim_clock``): the clock's ``"segments"``
    (:func:`clock_changes`: its factor changes once or twice mid-run, and it may pause).  With
    ``sim_clock`` every sensor publishes on its simulated timer (``"sim_timer"``, :func:`sim_timed`) and
    every node with a deadline answers on its node's simulated clock (:func:`sim_answers`), and
    ``"use_sim_time"`` is True (the mapping declares that every node keeps ``/clock`` time) unless
    ``undeclared_sim_time`` (the mapping leaves it unsaid; ``"use_sim_time"`` False).  The nodes drawn
    depend on no option but those times.  Deterministic in (seed, nodes, defect, kinds, sim_clock,
    actions, driver_offset_s, clock_change, undeclared_sim_time)."""
    if -STAMP_BEHIND_S <= driver_offset_s < -MAX_BEHIND_S:
        raise ValueError(f"a driver {-driver_offset_s:g} s behind stamps within the run's clock (at most "
                         f"{STAMP_BEHIND_S:g} s behind): its next reading is current, by its stamp, before an answer "
                         f"to the last one can be heard, so no generated node answers it correctly; use at most "
                         f"{MAX_BEHIND_S:g} s, or more than {STAMP_BEHIND_S:g} s (another clock)")
    rng = random.Random(f"robot-{seed}-{nodes}" + ("" if kinds == tuple(SENSORS) else "-" + ",".join(kinds)))
    out: list[dict[str, Any]] = []
    sensors: list[dict[str, Any]] = []
    spaces = [None, None, "ns1", "ns2", "arm/ns3"]

    def new_sensor(kind: str | None = None) -> dict[str, Any]:
        s = _sensor(rng, len(out), kinds, kind)
        s["namespace"] = rng.choice(spaces)
        out.append(s)
        sensors.append(s)
        return s
    new_sensor(rng.choice([k for k in ("f32", "range") if k in kinds]))
    while len(out) < nodes:
        i = len(out)
        roll = rng.random()
        ns = rng.choice(spaces)
        base = {"name": "", "ros_name": "", "namespace": ns}
        if roll < 0.2 or len(sensors) == 0:
            new_sensor()
            continue
        if roll < 0.5:
            src = rng.choice(sensors)
            kind = src["sensor_kind"]
            op = "ge" if kind == "u8" else ("exists_lt" if kind in ("arr", "scan") else "le")
            out.append({**base, "kind": "alarm", "name": f"Alarm{i}", "ros_name": f"alarm{i}", "topic_base": f"a{i}",
                        "source": src["name"], "in_kind": kind, "op": op, "k": rng.choice(src["thresholds"]),
                        "delay_ms": rng.randrange(0, int(src["period_ms"] * 0.3) + 1),
                        "assume_band": rng.random() < 0.5})
            continue
        scalars = [s for s in sensors if s["sensor_kind"] in ("f32", "range")]
        if roll < 0.7 and scalars:
            src = rng.choice(scalars)
            copy = src["sensor_kind"] == "range" and rng.random() < 0.7
            top = 2 * src["period_ms"] if copy else int(src["period_ms"] * 0.3)
            out.append({**base, "kind": "relay", "name": f"Relay{i}", "ros_name": f"relay{i}", "topic_base": f"r{i}",
                        "source": src["name"], "in_kind": src["sensor_kind"], "copy": copy,
                        "delay_ms": rng.randrange(0, top + 1)})
            continue
        if roll < 0.85 and scalars and len(out) + 2 <= nodes:
            a = rng.choice(scalars)
            b = _sensor(rng, i, kinds, rng.choice([k for k in ("u8", "arr", "scan") if k in kinds] or ["u8"]))
            b.update(namespace=rng.choice(spaces), period_ms=a["period_ms"],
                     phase_ms=a["phase_ms"] - a["period_ms"] // 2)
            out.append(b)
            sensors.append(b)
            j = len(out)
            out.append({**base, "kind": "fuse", "name": f"Fuse{j}", "ros_name": f"fuse{j}", "topic_base": f"f{j}",
                        "a_source": a["name"], "a_kind": a["sensor_kind"], "ka": rng.choice(a["thresholds"]),
                        "b_source": b["name"], "b_kind": b["sensor_kind"], "kb": rng.choice(b["thresholds"]),
                        "op_b": "ge" if b["sensor_kind"] == "u8" else "exists_lt",
                        "delay_ms": rng.randrange(0, int(a["period_ms"] * 0.3) + 1)})
            continue
        period = rng.choice([150, 200, 300])
        out.append({**base, "kind": "service", "name": f"Switch{i}", "ros_name": f"switch{i}", "topic_base": f"srv{i}",
                    "introspection": rng.random() < 0.5, "period_ms": period, "phase_ms": rng.randrange(0, period),
                    "pattern": [rng.random() < 0.5 for _ in range(7)]})
    if actions:
        arng = random.Random(f"actions-{seed}-{nodes}")
        for k, n in enumerate(out):
            if n["kind"] == "service" and arng.random() < 0.5:
                i = n["name"].removeprefix("Switch")
                out[k] = {"name": f"Fib{i}", "ros_name": f"fib{i}", "namespace": n["namespace"], "kind": "action",
                          "topic_base": f"fib{i}", "introspection": n["introspection"], "period_ms": n["period_ms"],
                          "phase_ms": n["phase_ms"], "orders": _with_all(arng, [arng.choice(FIB_ORDERS)
                                                                             for _ in range(4)], [2, 3, 4])}
    by_name = {n["name"]: n for n in out}
    for n in out:  # resolved names: the ROS topic (absolute), its RCL spelling, and each input's topic
        ns = n.get("namespace")
        rel = f"{ns}/{n['topic_base']}" if ns else n["topic_base"]
        n["rcl_topic"] = rel
        if n["kind"] in ("service", "action"):
            n["service"] = "/" + rel
        else:
            n["topic"] = "/" + rel
    for n in out:
        if n["kind"] in ("alarm", "relay"):
            n["in_topic"] = by_name[n["source"]]["topic"]
        if n["kind"] == "fuse":
            n["a_topic"], n["b_topic"] = by_name[n["a_source"]]["topic"], by_name[n["b_source"]]["topic"]
    clock: dict[str, Any] | None = None
    if sim_clock:
        crng = random.Random(f"clock-{seed}-{nodes}")
        clock = {"rate": crng.choice(CLOCK_RATES), "start_s": float(crng.choice([0, 100, 5000]))}
        if clock_change:
            clock["segments"] = clock_changes(seed, nodes, clock["rate"])
    if sim_clock:
        sim_answers(out, seed, nodes)
    spec = {"seed": seed, "defect": defect, "clock": clock, "nodes": out, "driver_offset_s": driver_offset_s,
            "use_sim_time": bool(sim_clock and not undeclared_sim_time)}
    for n in out:
        if sim_timed(n, spec):
            n["sim_timer"] = True
    declare(spec)
    if defect:
        candidates = [n for n in out if n["kind"] != "sensor" or n.get("beyond") is not None]
        # a node whose defect shows on the values the run carries: an alarm or fuse is wrong only at its threshold
        rng = random.Random(f"defect-{seed}-{nodes}")
        victim = rng.choice(candidates)
        while victim["kind"] == "fuse" and not fuse_defect_shows(victim, by_name):  # drawn again (generated seed 966)
            candidates.remove(victim)
            victim = rng.choice(candidates)
        victim["defect"] = True
        victim["defect_kind"] = defect_kind(victim, spec)
    return spec


#: the readings of a fuse's leading input within which its seeded defect must change an answer
FUSE_DEFECT_WITHIN = 12


def fuse_defect_shows(f: dict[str, Any], by: dict[str, dict[str, Any]], within: int = FUSE_DEFECT_WITHIN) -> bool:
    """Whether fuse ``f``'s seeded defect (the strict comparison for the other on its second input, as
    robot.py's ``decide`` makes it) changes one of its first ``within`` answers: its k-th reading of the
    leading input meets the k-th of the other, which publishes half a period before it with the same
    period.  The defect is wrong only where the other input sits at its threshold and the leading one
    does not decide the answer alone (``and``: at or below KA; ``or``: above it), which the drawn
    readings may never pair (generated seed 966: Fuse2's defect changed none of its answers)."""
    a, b = by[f["a_source"]], by[f["b_source"]]
    ka = f32(float(f["ka"]))
    kb: float = int(f["kb"]) if f["op_b"] == "ge" else f32(float(f["kb"]))
    for k in range(within):
        x, y = a["values"][k % len(a["values"])], b["values"][k % len(b["values"])]
        if f["op_b"] == "ge":
            if x <= ka and (y >= kb) != (y > kb):
                return True
        elif x > ka and any(c < kb for c in y) != any(c <= kb for c in y):
            return True
    return False


def _consts(spec: dict[str, Any]) -> tuple[list[dict[str, str]], dict[str, dict[str, str]]]:
    """The context's named constants and, per node, its own names for them."""
    consts: list[dict[str, str]] = []
    names: dict[str, dict[str, str]] = {}

    def const(node: str, role: str, text: str, integer: bool) -> None:
        name = f"{node.upper()}_{role}"
        consts.append({"name": name, "type": "INTEGER" if integer else "REAL", "text": text})
        names.setdefault(node, {})[role] = name
    for n in spec["nodes"]:
        if n["kind"] == "sensor":
            u8 = n["sensor_kind"] == "u8"
            const(n["name"], "LO", n["lo"], u8)
            const(n["name"], "HI", n["hi"], u8)
        elif n["kind"] == "alarm":
            const(n["name"], "K", n["k"], n["in_kind"] == "u8")
        elif n["kind"] == "fuse":
            const(n["name"], "KA", n["ka"], False)
            const(n["name"], "KB", n["kb"], n["b_kind"] == "u8")
    return consts, names


def _answer_var(n: dict[str, Any]) -> str:
    """The one output of alarm or relay spec ``n`` (its answer)."""
    return "r" if n["kind"] == "relay" else ("high" if n["op"] == "ge" else "low")


def _contract(n: dict[str, Any], by: dict[str, dict[str, Any]], names: dict[str, dict[str, str]]) -> dict[str, Any]:
    """One node's contract as the template's fields (inputs, outputs, topics, services, assume, guarantees)."""
    c: dict[str, Any] = {"name": n["name"], "topics": [], "services": [], "actions": [], "assume": "TRUE",
                         "inputs": [], "outputs": [], "declarations": (
                             ["progress( eventually )"] if n.get("eventually") else
                             [f"periodic( out.{_answer_var(n)}, {n['period_steps']} steps )"] if n.get("period_steps")
                             else [f"progress( within {n['progress_steps']} steps )"] if n.get("progress_steps")
                             else [])}
    k = names.get(n["name"], {})

    def band(var: str, s: dict[str, Any]) -> str:
        lo, hi = names[s["name"]]["LO"], names[s["name"]]["HI"]
        if s["sensor_kind"] in ("arr", "scan"):
            return f"forall(v in {var} | {lo} <= v and v <= {hi})"
        return f"{lo} <= {var} and {var} <= {hi}"
    if n["kind"] == "sensor":
        typ, _f, rcl, stamped = SENSORS[n["sensor_kind"]]
        var = "cells" if rcl.startswith("seq") else ("n" if rcl == "INTEGER" else "x")
        c["outputs"] = [f"{var} : {rcl}"]
        c["topics"] = [f"{typ} {n['rcl_topic']} matches(out.{var})"]
        c["guarantees"] = [{"formula": band(f"out.{var}", n), "trigger": ""}]
        c["declarations"] = ([f"initially( {band(f'out.{var}', n)} )"] if n.get("initially") else []) + (
            [f"periodic( out.{var}, {n['periodic_ms']} ms )"] if n.get("periodic_ms") else [])
        c["comment"] = (f"a sensor publishing every {n['period_ms']} ms, {'stamped' if stamped else 'unstamped'}"
                        + (f", its stamp {n['back_ms']} ms before it publishes" if n["back_ms"] else "")
                        + (" [seeded defect: skips one publication for longer than its declared period]"
                           if n.get("defect") and n.get("defect_kind") == "skip" else
                           " [seeded defect: publishes beyond its band]" if n.get("defect") else ""))
        return c
    if n["kind"] == "service":
        c["inputs"], c["outputs"] = ["on : BOOL"], ["ok : BOOL"]
        c["services"] = [f"std_srvs/SetBool {n['rcl_topic']} serves(in.on, out.ok)"]
        c["guarantees"] = [{"formula": "out.ok == in.on", "trigger": f"triggered by in.on within {deadline_ms(n)} ms"}]
        c["comment"] = (f"a SetBool server, {'with' if n['introspection'] else 'without'} introspection"
                        + (" [seeded defect: every third answer wrong]" if n.get("defect") else ""))
        return c
    if n["kind"] == "action":
        c["inputs"], c["outputs"] = ["order : INTEGER"], ["last : INTEGER", "final : INTEGER"]
        c["actions"] = [f"test_msgs/Fibonacci {n['rcl_topic']} serves(in.order, out.last, out.final)"]
        c["assume"] = "in.order >= 1"
        # F(order) >= order - 1, equal at orders 2, 3 and 4 (every run sends them): the boundary is hit
        c["guarantees"] = [{"formula": "out.final >= in.order - 1", "trigger": ""}]
        c["comment"] = (f"a test_msgs/Fibonacci action server, {'with' if n['introspection'] else 'without'} "
                        "introspection" + (" [seeded defect: its result one short]" if n.get("defect") else ""))
        return c
    deadline = deadline_ms(n)
    clocked = "deadline_ms" in n  # on a /clock robot: its wait and deadline in simulated ms
    wait = f"{n['delay_ms']} {'simulated ' if clocked else ''}ms"
    late = (f" [seeded defect: answers {late_ms(n)} simulated ms after its input, past its deadline]"
            if n.get("defect") and n.get("defect_kind") == "late" else "")
    if n["kind"] in ("alarm", "relay"):
        s = by[n["source"]]
        typ, _f, rcl, _st = SENSORS[s["sensor_kind"]]
        var = "cells" if rcl.startswith("seq") else ("n" if rcl == "INTEGER" else "x")
        c["inputs"] = [f"{var} : {rcl}"]
        c["topics"] = [f"{typ} {s['rcl_topic']} matches(in.{var})"]
        if n["kind"] == "relay":
            c["outputs"] = ["r : REAL"]
            c["topics"].append(f"sensor_msgs/Range {n['rcl_topic']} matches(out.r)")
            c["guarantees"] = [{"formula": f"out.r == in.{var}", "trigger": f"triggered by in.{var} within {deadline} ms"}]
            c["comment"] = (f"a relay {'copying the header stamp' if n['copy'] else 'stamping with its own clock'}, "
                            f"after {wait}" + late + (" [seeded defect: adds 0.5 to every fourth reading]"
                                                      if n.get("defect") and n.get("defect_kind") == "wrong" else ""))
        else:
            out, cond = {"le": ("low", f"in.x <= {k['K']}"), "ge": ("high", f"in.n >= {k['K']}"),
                         "exists_lt": ("low", f"exists(v in in.cells | v < {k['K']})")}[n["op"]]
            c["outputs"] = [f"{out} : BOOL"]
            c["topics"].append(f"std_msgs/Bool {n['rcl_topic']} matches(out.{out})")
            c["guarantees"] = [{"formula": f"out.{out} <=> ({cond})", "trigger": f"triggered by in.{var} within {deadline} ms"}]
            c["comment"] = (f"an alarm at a threshold, answering after {wait}" + late
                            + (f" [seeded defect: answers none of {n['progress_steps'] + 2} readings in a row once]"
                               if n.get("defect") and n.get("defect_kind") == "mute" else
                               " [seeded defect: the strict comparison for the other]"
                               if n.get("defect") and n.get("defect_kind") == "wrong" else ""))
        if n.get("assume_band"):
            c["assume"] = band(f"in.{var}", s)
        return c
    a, b = by[n["a_source"]], by[n["b_source"]]
    ta, tb = SENSORS[a["sensor_kind"]][0], SENSORS[b["sensor_kind"]][0]
    if n["op_b"] == "ge":
        c["inputs"], c["outputs"] = ["a : REAL", "b : INTEGER"], ["alert : BOOL"]
        c["topics"] = [f"{ta} {a['rcl_topic']} matches(in.a)", f"{tb} {b['rcl_topic']} matches(in.b)",
                       f"std_msgs/Bool {n['rcl_topic']} matches(out.alert)"]
        g = f"out.alert <=> (in.a <= {k['KA']} and in.b >= {k['KB']})"
    else:
        c["inputs"], c["outputs"] = ["x : REAL", "cells : seq(REAL)"], ["low : BOOL"]
        c["topics"] = [f"{ta} {a['rcl_topic']} matches(in.x)", f"{tb} {b['rcl_topic']} matches(in.cells)",
                       f"std_msgs/Bool {n['rcl_topic']} matches(out.low)"]
        g = f"out.low <=> (in.x <= {k['KA']} or exists(v in in.cells | v < {k['KB']}))"
    trig = "in.a" if n["op_b"] == "ge" else "in.x"
    c["guarantees"] = [{"formula": g, "trigger": f"triggered by {trig} within {deadline} ms"}]
    c["comment"] = (f"two inputs, answering each {trig} after {wait}" + late
                    + (" [seeded defect: the strict comparison for the other]"
                       if n.get("defect") and n.get("defect_kind") == "wrong" else ""))
    return c


@functools.lru_cache(maxsize=1)
def _templates() -> Any:
    import jinja2
    return jinja2.Environment(loader=jinja2.FileSystemLoader(str(TEMPLATES)), keep_trailing_newline=True,
                              undefined=jinja2.StrictUndefined, autoescape=False)


def render(spec: dict[str, Any]) -> dict[str, str]:
    """The workspace's files (relative path -> text) of ``spec``, rendered from the jinja2 templates."""
    env = _templates()
    by = {n["name"]: n for n in spec["nodes"]}
    consts, names = _consts(spec)
    contracts = [_contract(n, by, names) for n in spec["nodes"]]
    fields: list[tuple[str, str]] = []
    for n in spec["nodes"]:
        if n["kind"] == "sensor":
            fields.append((n["rcl_topic"], SENSORS[n["sensor_kind"]][1]))
        elif n["kind"] == "service":
            fields += [(f"{n['rcl_topic']}/request", "data"), (f"{n['rcl_topic']}/response", "success")]
        elif n["kind"] == "action":  # the last number of the feedback's and the result's sequence
            fields += [(f"{n['rcl_topic']}/feedback", '"sequence[-1]"'), (f"{n['rcl_topic']}/result", '"sequence[-1]"')]
        elif n["kind"] == "relay":
            fields.append((n["rcl_topic"], "range"))
        else:
            fields.append((n["rcl_topic"], "data"))
    robot_spec = {"nodes": [{**n, "late_ms": late_ms(n)} if n.get("defect_kind") == "late" else n
                            for n in spec["nodes"]],
                  "clock": spec.get("clock"), "clock_step_ms": CLOCK_STEP_MS,
                  "driver_offset_s": spec.get("driver_offset_s", 0.0), "settle_s": settle_s(spec)}
    return {
        "contracts/robot.rcl": env.get_template("contracts.rcl.j2").render(
            seed=spec["seed"], defect=spec["defect"], constants=consts, nodes=contracts),
        "contracts/plan.yaml": env.get_template("plan.yaml.j2").render(seed=spec["seed"], nodes=spec["nodes"]),
        "mapping.yaml": env.get_template("mapping.yaml.j2").render(fields=fields, horizon=horizon_of(spec),
                                                                    use_sim_time=bool(spec.get("use_sim_time"))),
        "interfaces/std_srvs/srv/SetBool.srv": SETBOOL,
        "interfaces/sensor_msgs/msg/Range.msg": RANGE,
        "interfaces/test_msgs/action/Fibonacci.action": FIBONACCI,
        "robot.py": env.get_template("robot.py.j2").render(
            seed=spec["seed"], count=len(spec["nodes"]), spec_json=json.dumps(robot_spec, sort_keys=True)),
        "spec.json": json.dumps(spec, indent=1, sort_keys=True) + "\n",
    }


def write_workspace(spec: dict[str, Any], ws: Path) -> Path:
    """Write the workspace of ``spec`` under ``ws`` (created; files written atomically); returns ``ws``."""
    from rclverify.core.atomic import atomic_write_text
    for rel, text in render(spec).items():
        path = ws / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, text)
    return ws


def check_workspace(ws: Path) -> list[str]:
    """The project's parser and type checker on ``ws/contracts/robot.rcl`` and its plan: the names of the
    contracts checked.  Raises what the front end raises on an ill-formed contract."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.lang.typecheck import load
    from rclverify.model.plan.load import load_plan
    load_plan(ws)
    load_mapping(ws, "mapping.yaml")
    return list(load([ws / "contracts" / "robot.rcl"]).nodes)


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        out += list(range(int(lo), int(hi or lo) + 1))
    return out


def main(argv: list[str] | None = None) -> int:
    import argparse
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", default="0-4", help="seeds, e.g. 0-49 or 3,7,9 (default 0-4)")
    p.add_argument("--nodes", default="5", help="contract nodes per system, N or LO-HI (drawn per seed)")
    p.add_argument("--seconds", type=float, default=10.0, help="seconds of sensing per run")
    p.add_argument("--defect", action="store_true", help="seed one defect per system; check it is red at its node")
    p.add_argument("--without", action="append", default=[], choices=list(SENSORS),
                   help="leave this sensor kind out (repeatable)")
    p.add_argument("--source", choices=("dds", "rclpy"), default="dds",
                   help="how the monitor hears the robot (rclverify monitor --source; default dds)")
    p.add_argument("--clock", action="store_true",
                   help="a /clock node at a real-time factor of 0.5-2 (drawn per seed), every node on use_sim_time")
    p.add_argument("--clock-change", action="store_true",
                   help="with --clock implied: the /clock's factor changes once or twice mid-run (within 0.5-2), and "
                        "one time in two the clock pauses for 0.5-1 s; stamped sensors feeding no fuse on its timer")
    p.add_argument("--undeclared-sim-time", action="store_true",
                   help="with --clock: the mapping leaves use_sim_time unsaid (every node still runs under it), so a "
                        "deadline is decided only where the wall clock and /clock time agree")
    p.add_argument("--actions", action="store_true",
                   help="a Fibonacci action server in place of a SetBool server, one time in two")
    p.add_argument("--driver-offset", type=float, default=0.0, metavar="S",
                   help="every sensor stamps its headers S seconds off its clock (a driver's clock; negative: behind)")
    p.add_argument("--burn", action="store_true", help="one CPU-burning process beside each run (both cores busy)")
    p.add_argument("--write", metavar="DIR", help="write the workspaces under DIR/seed-N and stop (no live run)")
    p.add_argument("--keep", metavar="DIR", help="keep each run's workspace, log and bag under DIR/seed-N")
    p.add_argument("--src", metavar="SRC", help="the rclverify sources to judge with (default: this tree's src/)")
    p.add_argument("--smoke", action="store_true", help="CI: generate and type-check 20 workspaces, no live run")
    a = p.parse_args(argv)
    a.clock = a.clock or a.clock_change
    if a.undeclared_sim_time and not a.clock:
        p.error("--undeclared-sim-time needs --clock or --clock-change (a robot without /clock keeps the wall clock)")
    lo, _, hi = a.nodes.partition("-")
    sizes = (int(lo), int(hi or lo))
    if a.smoke:
        return _smoke()
    try:
        generate(0, 2, driver_offset_s=a.driver_offset)
    except ValueError as exc:
        p.error(str(exc))
    seeds = _seeds(a.seeds)
    kinds = tuple(k for k in SENSORS if k not in a.without)
    if a.write:
        for seed in seeds:
            n = random.Random(seed).randint(*sizes)
            ws = write_workspace(generate(seed, n, a.defect, kinds, a.clock, a.actions, a.driver_offset,
                                          a.clock_change, a.undeclared_sim_time), Path(a.write) / f"seed-{seed}")
            print(f"seed {seed}: {n} nodes: {ws}")
        return 0
    sys.path.insert(0, str(ROOT / "bench"))
    from _robot_run import run_many
    return run_many(seeds, sizes, a.seconds, a.defect, a.burn, Path(a.keep) if a.keep else None, kinds,
                    Path(a.src).resolve() if a.src else ROOT / "src", a.source, a.clock, a.actions, a.driver_offset,
                    a.clock_change, a.undeclared_sim_time)


def _smoke() -> int:
    import tempfile
    import time
    t0 = time.perf_counter()
    checked = 0
    with tempfile.TemporaryDirectory() as d:
        for seed in range(10):
            for defect in (False, True):
                n = 5 + seed % 12
                ws = write_workspace(generate(seed, n, defect), Path(d) / f"seed-{seed}-{defect}")
                checked += len(check_workspace(ws))
    print(f"robot generator smoke: 20 workspaces generated and type-checked, {checked} contracts, "
          f"{time.perf_counter() - t0:.2f} s")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT / "bench"))
    from _live import exit_on_sigterm  # SIGTERM stops what the bench started (bench/_live.py)
    exit_on_sigterm()
    sys.exit(main())
