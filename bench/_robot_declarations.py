"""The declarations of a generated robot (bench/robot_generator.py): each true by construction of the
node it is drawn for, judged by the rules of docs/monitors.md, "Declarations on recorded and live runs"
(``backends/monitors/declarations.py``, ``periods.py``).

:func:`declare` adds to each node spec the declarations its node keeps, as RCL text
(``"declarations": [...]``):

* a **sensor**: ``initially( F )``, F its band (``SENSOR0_LO <= out.x and out.x <= SENSOR0_HI``, a
  ``forall`` over a sequence).  A sensor has no input, so its first message always comes before any
  input event of the node: the monitor judges F on it (``true``); a node that answers an input is never
  given ``initially``, since its first message follows an input and the monitor rightly says
  ``inconclusive`` (not decidable on a run).  And ``periodic( out.x, P ms )`` with
  ``P = PERIOD_FACTOR * period + PERIOD_SLACK_MS``: the sensor publishes on a fixed schedule
  (``due + period``, never drifting; after a stall the next slot of it, never a burst of the readings
  missed, each of which would be a step its consumers leave unanswered), so a gap between two messages
  is its period plus one stall of the robot's one executor, and the run's last event comes at most a
  period plus the monitor's stop (its final lines) after the sensor's last message: every sensor
  publishes until the robot is stopped, after the monitor (every one, declared periodic or not: a
  fuse's leading sensor stopping while its other input goes on would leave that input's readings
  unanswered, generated seed 847).  ``P`` leaves a period and 1 s over its
  period (1.4-1.8 s for the 200-400 ms sensors): the longest stall measured with both cores busy and
  other test runs beside was 0.85 s (every sensor of one robot 1.1 s apart at one instant, generated
  seed 821 with ``P`` a second smaller).
  The period is the node's clock's (docs/monitors.md, "Periodic outputs"): a stamped sensor's gaps are
  judged on its header stamps, which on a ``/clock`` run in simulated time (the judge sets them aside
  as another clock, measures its rate and carries the run's end into it), so its ``P`` is in that
  clock: the bound above times the real-time factor, and two ``/clock`` ticks more (its stamps move by
  one tick, :data:`CLOCK_STEP_MS` of the wall clock); its robot's schedule stays the wall clock.  A
  On a ``/clock`` whose factor changes mid-run (``--clock-change``) the factor is the largest it runs
  at.  Every sensor of a ``/clock`` robot publishes on its simulated timer (every ``period`` simulated
  ms, silent while the clock is paused): a stamped one's gap is its period and a stall of the wall clock
  at that factor, within the same bound (a factor of at least 0.5 makes the bound's two periods cover
  one simulated period); an unstamped one's gaps are the wall clock's, its period at the slowest factor
  (:func:`slowest_rate`) and a pause (:data:`PAUSE_MS`), so its ``P`` is two such periods, 1 s and the
  longest pause when the clock pauses.  A
  driver's offset leaves its gaps as they are; one within the bounds of the run's clock (at most 1 s
  behind, 0.1 s ahead: its stamps are then the message's times) delays its last stamp, so a driver
  behind adds its offset to ``P``.  An unstamped sensor carries no clock but the run's (its source
  times, the wall clock): ``P`` as above on every clock.  :func:`period_rate` is the factor the
  declared clock runs at against the wall clock, its largest on a changing clock (the seeded ``skip``
  lasts as long as that clock takes to pass the period, and a period more).
* an **alarm**, a **relay** stamping with its own clock: ``progress( within 2 steps )``; it answers
  every input after 0-30 % of the input's period, an answer due within a stamped sensor's publication
  window just after it (so at most one input comes between an input and its answer), and one step more
  for a stall of the loaded machine.
* a **relay copying its reading's stamp**: ``progress( within K steps )``, ``K = ceil(delay / period) +
  2``: its answer may come up to ``delay`` after its reading, after that many readings.
* one alarm or relay in two (:func:`in_steps`) declares the same bound as a period in steps instead,
  ``periodic( out.y, K + 1 steps )`` (as ``within K steps``, only a message of ``out.y`` answering: its
  one output).
* a **fuse**: ``progress( within 3 steps )``: its second input, half a period before the first, is a
  step of its own that it does not answer (it answers each reading of its first input), so an answered
  row is two steps, one more for a deferred answer and one for a stall; on a ``/clock`` robot 4 (its
  answer, 0.55-0.65 of its deadline after its trigger, may follow its second input's next reading).
  On a ``/clock`` robot an alarm's and a relay's answer (on its node's simulated clock) comes before
  the next reading at every factor (bench/robot_generator.py ``SIM_PERIODS_MS``), so their bounds stay.
* a **service** or **action** server: its steps are its calls (a request, a goal), answered by the
  response, the feedback or the result; its client sends one call at a time, the next once the last is
  answered, and stops calling when the sensing ends, before the robot says ``done``, so the run's last
  call is answered: ``progress( eventually )`` one server in two (:func:`in_steps`), else
  ``progress( within 1 steps )``.  A bag's reader gives calls to the call checks only, so a server's
  declarations are ``pending`` on the bag, and judged on the live run and its log (the runner counts
  that ``pending`` apart, bench/_robot_verdicts.py); through the rclpy source without introspection no
  call is heard and they are ``pending`` on every path.

With ``defect``, the node seeded with a defect (:func:`defect_kind`) may break a declaration instead of
its guarantee: a sensor skipping one publication for longer than its declared period in its clock (the
wall-clock skip is as long as its clock takes to pass the period, and one period more; ``"skip"``, ``periodic``
false at that sensor; never a fuse's leading sensor, :func:`can_skip`) or an alarm answering none of
K + 2 readings in a row once (``"mute"``: K + 1 accepted steps unanswered in a row even when the answer
before them was deferred past the first, so its ``progress`` or period in steps false, and the
readings' deadlines, at that alarm).  On a ``/clock`` robot an alarm, a fuse or a relay stamping with
its own clock is seeded ``"late"`` instead (:func:`can_be_late`): its deadlines false, its declarations
kept (its late answer still comes before the next reading); a sensor is seeded ``"beyond"`` there, its
first reading beyond its band, never ``"skip"`` (:func:`can_skip`).
"""
from __future__ import annotations

import math
import random
from typing import Any

#: a sensor's declared period: this many times its period ...
PERIOD_FACTOR = 2
#: ... plus this many milliseconds
PERIOD_SLACK_MS = 1000
#: the bound of an alarm's and an own-stamp relay's ``progress( within K steps )``
ANSWER_STEPS = 2
#: the bound of a fuse's (its second input is a step it does not answer)
FUSE_STEPS = 3
#: the bound of a server's ``progress( within K steps )`` (its client calls once the last call is answered)
SERVER_STEPS = 1
#: how often a ``/clock`` robot's clock node publishes (wall-clock ms; bench/robot_generator.py)
CLOCK_STEP_MS = 20
#: the longest a changing ``/clock`` pauses (ms of the wall clock; bench/robot_generator.py ``clock_changes``)
PAUSE_MS = 1000
#: a stamp at most this far behind (s) or ahead of its source time is the run's clock (traces/event_time.py)
STAMP_BEHIND_S, STAMP_AHEAD_S = 1.0, 0.1


def declared_period_ms(period_ms: int) -> int:
    """The ``periodic`` bound (ms) declared for a sensor publishing every ``period_ms`` ms."""
    return PERIOD_FACTOR * period_ms + PERIOD_SLACK_MS


def progress_steps(n: dict[str, Any], by: dict[str, dict[str, Any]]) -> int | None:
    """The ``progress( within K steps )`` bound K of an alarm's, a relay's or a fuse's node spec ``n``
    (``by``: specs by name), or None for another node (a sensor; a server's is :data:`SERVER_STEPS`).
    On a ``/clock`` robot (``n`` has a ``"deadline_ms"``) a fuse's answer may come after its second
    input's next reading, half a period after its trigger: one step more."""
    if n["kind"] == "alarm":
        return ANSWER_STEPS
    if n["kind"] == "fuse":
        return FUSE_STEPS + ("deadline_ms" in n)
    if n["kind"] == "relay":
        if not n["copy"]:
            return ANSWER_STEPS
        return int(math.ceil(n["delay_ms"] / by[n["source"]]["period_ms"])) + ANSWER_STEPS
    return None


def in_steps(n: dict[str, Any], seed: int) -> bool:
    """Whether node ``n`` of robot ``seed`` declares its bound the other way (module docstring): an alarm
    or relay as ``periodic( out.y, K + 1 steps )``, a server as ``progress( eventually )``.  Drawn from
    a generator of its own, so the nodes drawn do not change."""
    return random.Random(f"declare-{seed}-{n['name']}").random() < 0.5


def period_rate(n: dict[str, Any], spec: dict[str, Any]) -> float:
    """The rate (its s per wall-clock s) of the clock sensor ``n``'s declared period is in: the
    real-time factor for a stamped sensor on a ``/clock`` (the largest it runs at, on a clock whose factor
    changes mid-run: a gap of the wall clock is at most that many simulated seconds), else 1."""
    clock = spec.get("clock")
    if not clock or n["sensor_kind"] not in ("range", "scan"):
        return 1.0
    return max([float(clock["rate"])] + [float(r) for _, r in clock.get("segments") or []])


def slowest_rate(spec: dict[str, Any]) -> float:
    """The smallest real-time factor but a pause a ``/clock`` robot's clock runs at (1 without one)."""
    clock = spec.get("clock")
    if not clock:
        return 1.0
    return min([float(clock["rate"])] + [float(r) for _, r in clock.get("segments") or [] if r])


def pauses(spec: dict[str, Any]) -> bool:
    """Whether the ``/clock`` of ``spec`` pauses (a segment at rate 0)."""
    return any(not r for _, r in (spec.get("clock") or {}).get("segments") or [])


def declared_sensor_period_ms(n: dict[str, Any], spec: dict[str, Any]) -> int:
    """The ``periodic`` bound (ms, in the node's clock) of sensor ``n`` of ``spec`` (module docstring)."""
    base = declared_period_ms(n["period_ms"])
    if n["sensor_kind"] not in ("range", "scan"):
        if n.get("sim_timer"):  # its period in simulated ms, its gaps judged in the wall clock's
            return (math.ceil(PERIOD_FACTOR * int(n["period_ms"]) / slowest_rate(spec)) + PERIOD_SLACK_MS
                    + (PAUSE_MS if pauses(spec) else 0))
        return base
    rate = period_rate(n, spec)
    if spec.get("clock"):
        return math.ceil(rate * (base + 2 * CLOCK_STEP_MS))
    off = float(spec.get("driver_offset_s") or 0.0)
    if -STAMP_BEHIND_S <= off < 0:  # within the run's clock: its last stamp that much before its publication
        return base + math.ceil(-off * 1000)
    return base


def declare(spec: dict[str, Any]) -> None:
    """Mark in every node of ``spec`` the declarations its node keeps (module docstring): a sensor
    ``"initially": True``, ``"periodic_ms"`` and ``"periodic_rate"`` (:func:`period_rate`); an alarm,
    relay or fuse ``"progress_steps"`` and, for one alarm or relay in two, ``"period_steps"`` (its bound
    as a period in steps); a server ``"progress_steps"`` or ``"eventually": True``.  The contract's text
    is rendered from them (bench/robot_generator.py)."""
    by = {n["name"]: n for n in spec["nodes"]}
    for n in spec["nodes"]:
        if n["kind"] == "sensor":
            n["initially"] = True
            n["periodic_ms"] = declared_sensor_period_ms(n, spec)
            n["periodic_rate"] = period_rate(n, spec)
            continue
        if n["kind"] in ("service", "action"):
            if in_steps(n, spec["seed"]):
                n["eventually"] = True
            else:
                n["progress_steps"] = SERVER_STEPS
            continue
        k = progress_steps(n, by)
        if k is not None:
            n["progress_steps"] = k
            if n["kind"] in ("alarm", "relay") and in_steps(n, spec["seed"]):
                n["period_steps"] = k + 1


def can_skip(n: dict[str, Any], spec: dict[str, Any]) -> bool:
    """Whether sensor ``n`` may be seeded with ``"skip"``: it is declared periodic and leads no fuse (a
    fuse answers only its leading input's readings, so while that sensor is silent the other input's
    readings are steps left unanswered: its ``progress`` would be red at the fuse, not at the sensor), on
    a robot without ``/clock`` (on one, its period of 1.6-2 simulated s, at a factor of 0.5 up to 4 s of
    the wall clock, leaves no room in a run of seconds for a silence past its declared period)."""
    return (bool(n.get("periodic_ms")) and not spec.get("clock")
            and not any(f.get("a_source") == n["name"] for f in spec["nodes"]))


def can_be_late(n: dict[str, Any]) -> bool:
    """Whether node ``n`` may be seeded ``"late"``: an alarm, a fuse or a relay stamping with its own clock on
    a ``/clock`` robot (its ``"deadline_ms"`` drawn).  Not a relay copying its reading's stamp: its answer is
    stamped with its trigger, in time by its stamp however late it leaves (docs/semantics.md, "Deadlines"),
    nor a server (it answers in its call's callback)."""
    return "deadline_ms" in n and (n["kind"] in ("alarm", "fuse") or (n["kind"] == "relay" and not n["copy"]))


def defect_kind(victim: dict[str, Any], spec: dict[str, Any]) -> str:
    """Which defect the node ``victim`` of ``spec`` is seeded with: ``"skip"`` (a sensor that
    :func:`can_skip`, one time in two), ``"beyond"`` (a sensor publishing just beyond its band),
    ``"mute"`` (an alarm, one time in two), else ``"wrong"`` (the node's guarantee broken as
    bench/robot_generator.py's docstring says); on a ``/clock`` robot a node that :func:`can_be_late` is
    seeded ``"late"`` (its answers on its node's simulated clock past its deadline,
    bench/robot_generator.py ``LATE_FACTOR``): its readings, 1.6-2 simulated s apart, are too few in a run
    of seconds at a slow factor to meet a threshold or to leave K + 2 of them unanswered.  The node itself is drawn as before declarations
    were drawn (a sensor with a value beyond its band, or any other node), so a seed's victim stays.
    Deterministic in the spec's seed and node count."""
    rng = random.Random(f"defect-kind-{spec['seed']}-{len(spec['nodes'])}")
    if can_be_late(victim):
        return "late"
    if victim["kind"] == "sensor":
        return "skip" if can_skip(victim, spec) and rng.random() < 0.5 else "beyond"
    if victim["kind"] == "alarm" and rng.random() < 0.5:
        return "mute"
    return "wrong"


__all__ = ["ANSWER_STEPS", "CLOCK_STEP_MS", "FUSE_STEPS", "PAUSE_MS", "PERIOD_FACTOR", "PERIOD_SLACK_MS",
           "SERVER_STEPS", "can_be_late", "can_skip", "declare", "declared_period_ms", "declared_sensor_period_ms", "defect_kind",
           "in_steps", "pauses", "period_rate", "progress_steps", "slowest_rate"]
