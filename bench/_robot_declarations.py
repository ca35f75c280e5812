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
  The period is judged on the messages' header stamps, else their source times, and the run's end on
  the trace's times (docs/monitors.md, "Periodic outputs"): a stamped sensor is declared periodic only
  on the wall clock with its driver's stamps on it (``sim_clock`` off, ``driver_offset_s`` 0), where
  its stamps and the run's times are one clock; an unstamped one (its source times, the wall clock) on
  every clock.
* an **alarm**, a **relay** stamping with its own clock: ``progress( within 2 steps )``; it answers
  every input after 0-30 % of the input's period, an answer due within a stamped sensor's publication
  window just after it (so at most one input comes between an input and its answer), and one step more
  for a stall of the loaded machine.
* a **relay copying its reading's stamp**: ``progress( within K steps )``, ``K = ceil(delay / period) +
  2``: its answer may come up to ``delay`` after its reading, after that many readings.
* a **fuse**: ``progress( within 3 steps )``: its second input, half a period before the first, is a
  step of its own that it does not answer (it answers each reading of its first input), so an answered
  row is two steps, one more for a deferred answer and one for a stall.
* a **service** or **action** server: none (its steps are calls, which a bag's reader gives the call
  checks only: its declarations would be ``pending`` on the bag).

With ``defect``, the node seeded with a defect (:func:`defect_kind`) may break a declaration instead of
its guarantee: a sensor skipping one publication for longer than its declared period (``"skip"``,
``periodic`` false at that sensor; never a fuse's leading sensor, :func:`can_skip`) or an alarm answering none of K + 2 readings in a row once
(``"mute"``: K + 1 accepted steps unanswered in a row even when the answer before them was deferred past
the first, so ``progress`` false, and the readings' deadlines, at that alarm).
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


def declared_period_ms(period_ms: int) -> int:
    """The ``periodic`` bound (ms) declared for a sensor publishing every ``period_ms`` ms."""
    return PERIOD_FACTOR * period_ms + PERIOD_SLACK_MS


def progress_steps(n: dict[str, Any], by: dict[str, dict[str, Any]]) -> int | None:
    """The ``progress( within K steps )`` bound K of node spec ``n`` (``by``: specs by name), or None
    when it declares no progress (a sensor, a server)."""
    if n["kind"] == "alarm":
        return ANSWER_STEPS
    if n["kind"] == "fuse":
        return FUSE_STEPS
    if n["kind"] == "relay":
        if not n["copy"]:
            return ANSWER_STEPS
        return math.ceil(n["delay_ms"] / by[n["source"]]["period_ms"]) + ANSWER_STEPS
    return None


def declare(spec: dict[str, Any]) -> None:
    """Mark in every node of ``spec`` the declarations its node keeps (module docstring): a sensor
    ``"initially": True`` and, where its period can be judged, ``"periodic_ms"``; an alarm, relay or
    fuse ``"progress_steps"``.  The contract's text is rendered from them (bench/robot_generator.py)."""
    by = {n["name"]: n for n in spec["nodes"]}
    other_clock = bool(spec.get("clock")) or bool(spec.get("driver_offset_s"))
    for n in spec["nodes"]:
        if n["kind"] == "sensor":
            n["initially"] = True
            if n["sensor_kind"] not in ("range", "scan") or not other_clock:
                n["periodic_ms"] = declared_period_ms(n["period_ms"])
            continue
        k = progress_steps(n, by)
        if k is not None:
            n["progress_steps"] = k


def can_skip(n: dict[str, Any], spec: dict[str, Any]) -> bool:
    """Whether sensor ``n`` may be seeded with ``"skip"``: it is declared periodic and leads no fuse (a
    fuse answers only its leading input's readings, so while that sensor is silent the other input's
    readings are steps left unanswered: its ``progress`` would be red at the fuse, not at the sensor)."""
    return bool(n.get("periodic_ms")) and not any(f.get("a_source") == n["name"] for f in spec["nodes"])


def defect_kind(victim: dict[str, Any], spec: dict[str, Any]) -> str:
    """Which defect the node ``victim`` of ``spec`` is seeded with: ``"skip"`` (a sensor that
    :func:`can_skip`, one time in two), ``"beyond"`` (a sensor publishing just beyond its band),
    ``"mute"`` (an alarm, one time in two), else ``"wrong"`` (the node's guarantee broken as
    bench/robot_generator.py's docstring says).  The node itself is drawn as before declarations
    were drawn (a sensor with a value beyond its band, or any other node), so a seed's victim stays.
    Deterministic in the spec's seed and node count."""
    rng = random.Random(f"defect-kind-{spec['seed']}-{len(spec['nodes'])}")
    if victim["kind"] == "sensor":
        return "skip" if can_skip(victim, spec) and rng.random() < 0.5 else "beyond"
    if victim["kind"] == "alarm" and rng.random() < 0.5:
        return "mute"
    return "wrong"


__all__ = ["ANSWER_STEPS", "FUSE_STEPS", "PERIOD_FACTOR", "PERIOD_SLACK_MS", "can_skip", "declare",
           "declared_period_ms", "defect_kind", "progress_steps"]
