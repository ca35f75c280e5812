"""``rclverify monitor TRACE`` for managed nodes: a recorded run judged as the live run judges it
(docs/monitors.md, "Lifecycle nodes in a recorded run").

When a monitored node is managed (its contract names its ``lifecycle_msgs/TransitionEvent
<node>/transition_event`` topic, :func:`rclverify.backends.monitors.lifecycle.managed_of`), each trace is read
with its transition events (:func:`rclverify.traces.lifecycle_events.read_run`) and judged by
:func:`judge_recorded`: the live run's gate and judge, the messages at their
recorded times.  ``--transition-deadline NODE:TRANSITION=DURATION`` (repeatable; ``Battery:activate=200ms``,
a duration in ``ms`` or ``s``, seconds when bare) bounds a managed node's transitions, beside the
deadlines its contract states (``ready within 200 ms of activate``), which it replaces for the same
node and transition.

Printed per trace and node: the node's status and explanation, then its lifecycle line (state,
transitions heard, outputs judged, violations, deadlines met and missed) and the inputs held back as
no question; ``--json`` prints the runs' records instead.  Exit 1 when a node failed, 2 for a usage
error (a malformed or refused deadline) or a trace that cannot be read (one located line), else 0
(``--strict``: 1 also when a node is not discharged).
"""
from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from rclverify.lang.types import CheckedNode
from rclverify.backends.monitors.lifecycle import TRANSITION_TYPE, gate_of
from rclverify.backends.monitors.lifecycle_record import LifecycleRun
from rclverify.runtime.live import LiveRun

_DEADLINE = re.compile(r"^([A-Za-z_]\w*):([a-z]+)=([0-9]+(?:\.[0-9]*)?|\.[0-9]+)\s*(ms|s)?$")


def parse_deadlines(texts: Sequence[str]) -> dict[str, dict[str, float]]:
    """``NODE:TRANSITION=DURATION`` options as ``{node: {transition: seconds}}``.  Raises
    :class:`ValueError` naming the option for one not of that form."""
    out: dict[str, dict[str, float]] = {}
    for text in texts:
        m = _DEADLINE.match(text.strip())
        if m is None:
            raise ValueError(f"--transition-deadline {text!r}: write NODE:TRANSITION=DURATION "
                             f"(Battery:activate=200ms)")
        value = float(m.group(3)) / (1000.0 if m.group(4) == "ms" else 1.0)
        out.setdefault(m.group(1), {})[m.group(2)] = value
    return out


def _lines(trace: str, run: LifecycleRun) -> list[str]:
    """The printed lines of one judged trace (module docstring)."""
    out: list[str] = []
    life = {n.node: n for n in run.lifecycle.nodes}
    for n in run.nodes:
        out.append(f"{trace}: {n.node}: {n.status}: {n.explanation}")
        m = life.get(n.node)
        if m is not None:
            timed = m.deadlines
            said = ", ".join(f"{sum(t.status == s for t in timed)} {s}" for s in ("met", "missed", "open")
                             if any(t.status == s for t in timed))
            out.append(f"  lifecycle {m.ros_node}: {m.transitions} transition(s) heard, last {m.state}; "
                       f"{m.outputs_judged} output(s) judged, {len(m.violations)} outside active"
                       + (f"; deadlines: {said}" if said else ""))
            out += [f"    {t.status}: {t.reason}" + (f" (stated at {t.stated})" if t.stated else "")
                    for t in timed if t.status != "met"]
    held = run.lifecycle.not_questions
    if held:
        scopes = sorted({s for n in run.lifecycle.nodes for s in n.scope},
                        key=["unconfigured", "inactive", "active", "finalized"].index)
        out.append(f"{trace}: no question (heard while its readers were outside their lifecycle scope: "
                   f"{' or '.join(scopes)}): "
                   + ", ".join(f"/{t} {k}" for t, k in held.items()))
    return out


def judge_recorded(checked: Any, nodes: Sequence[CheckedNode], rules: Any, horizon: float, events: Iterable[Any],
                   log: Path, *, deadlines: Mapping[str, Mapping[str, float]] | None = None,
                   evidence: Path | None = None) -> dict[str, Any]:
    """A recorded run's ``events`` (:class:`rclverify.traces.events.Event`, in the order read: a
    bag's or a log's, :func:`rclverify.traces.lifecycle_events.read_run`) judged as the live run
    judges them (:mod:`rclverify.backends.monitors.lifecycle`): each pushed to a :class:`rclverify.runtime.live.LiveRun` of
    ``nodes`` (``rules``, ``horizon`` s: the monitor configuration's) at its recorded time, through
    the lifecycle gate of ``nodes`` with ``deadlines``
    (:class:`rclverify.backends.monitors.lifecycle.LifecycleGate`); the run's log written to ``log``.  Returns
    the run's record (``nodes``, ``lifecycle``; written to ``evidence`` when given).  Raises
    :class:`ValueError` when no node of ``nodes`` is managed, or for a deadline the gate refuses."""
    gate = gate_of(nodes, deadlines)
    if gate is None:
        raise ValueError(f"no managed node among {', '.join(n.name for n in nodes)}: no contract names a "
                         f"{TRANSITION_TYPE.replace('/msg/', '/')} <node>/transition_event topic")
    run = LiveRun(checked, list(nodes), rules, horizon, log, reorder_window=0.0)
    run.gate = gate
    last = float("-inf")
    for e in events:
        last = max(last, e.time)
        run.tick(e.time)
        run.push(e.topic, e.fields, e.time)
    if last > float("-inf"):
        run.tick(last + gate.settle + horizon)
    return run.stop(evidence)


def lifecycle_command(args: argparse.Namespace, checked: Any, nodes: Sequence[Any], cfg: Any, root: Path) -> int:
    """Judge ``args.traces`` (module docstring) for ``nodes`` of ``checked`` under the monitor
    configuration ``cfg`` (its message directories relative to ``root``); returns the exit code,
    never raising for user input."""
    from rclverify.traces.events import TraceError  # deferred: start-up (the traces package only when called)
    from rclverify.traces.lifecycle_events import read_run  # deferred: as above
    try:
        deadlines = parse_deadlines(getattr(args, "transition_deadline", None) or [])
    except ValueError as exc:
        print(f"rclverify monitor: error: {exc}", file=sys.stderr)
        return 2
    records: list[dict[str, Any]] = []
    failed = undecided = False
    with tempfile.TemporaryDirectory(prefix="rclverify-lifecycle-") as tmp:
        for k, trace in enumerate(args.traces):
            try:
                events, _ = read_run(Path(trace), [root / d for d in cfg.msg_dirs])
                rec = judge_recorded(checked, nodes, cfg.rules, cfg.horizon, events, Path(tmp) / f"run{k}.jsonl",
                                     deadlines=deadlines)
            except TraceError as exc:
                print(str(exc), file=sys.stderr)
                return 2
            except ValueError as exc:  # a deadline the gate refuses
                print(f"rclverify monitor: error: --transition-deadline: {exc}", file=sys.stderr)
                return 2
            rec["trace"] = trace
            records.append(rec)
            run = LifecycleRun.of(rec)
            failed = failed or any(n.status == "failed" for n in run.nodes)
            undecided = undecided or any(n.status != "discharged" for n in run.nodes)
            if not args.json:
                print("\n".join(_lines(trace, run)))
    if args.json:
        print(json.dumps(records, indent=2, sort_keys=True))
    return 1 if failed or (getattr(args, "strict", False) and undecided) else 0


__all__ = ["judge_recorded", "lifecycle_command", "parse_deadlines"]
