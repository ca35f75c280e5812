"""``rclverify monitor [-w WS] TRACE...``: check recorded runs against every node's contract;
``rclverify monitor --live``: monitor the running ROS 1 system, or with
``--ros2`` the ROS 2 system over DDS (:mod:`.monitor_live`).

A live ROS 2 run's log named as a TRACE has its service calls and action
goals judged as the live run judged them (its call lines replayed through
the live call book, :mod:`.log_calls`), and so has its ``--record`` bag
(the calls recorded as ROS 2 records them, :mod:`.bag_calls`).

Exit status: 0 when no contract is violated, 1 when one is (a message, a
call, a deadline), 2 for a trace
or configuration that cannot be read (a located message on stderr; the
verdicts of the traces already checked are printed first) or when ROS 1
or ROS 2's DDS domain cannot be reached in ``--live`` mode.  With
``--strict``, 1 too when the run did not judge an item it was asked to
check (a node, topic, service, action or deadline: :mod:`.judged`), as
``doit verify --strict`` fails on what is not discharged.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any, Mapping, Sequence

from rclverify.lang.errors import RclError
from rclverify.lang.types import Checked
from rclverify.traces import TraceError
from rclverify.backends.monitors.summary import monitoring_details, summary_line, tool_versions
from rclverify.backends.monitors.config import ConfigError, MonitorConfig, load_mapping
from rclverify.backends.monitors.judged import explain
from rclverify.cli.monitor_outcome import print_not_judged, selected_nodes, strict_exit
from rclverify.backends.monitors.declarations import declaration_status
from rclverify.backends.monitors.periods import period_status
from rclverify.backends.monitors.recorded import RecordedRun, check_recorded


def monitor_command(args: argparse.Namespace, checked: Checked) -> int:
    """Run the command on the workspace's checked contracts ``checked`` (the
    caller, rclverify.cli.commands, loads them: a backend does not import the
    pipeline); returns the exit code (never raises for user input)."""
    root = Path(args.workspace)
    cfg = _configuration(args, root, "monitor")
    if cfg is None:
        return 2
    from rclverify.backends.monitors.shared_topics import shared_topic_errors  # two variables on one topic read distinct fields; deferred: start-up (imported where it is used)
    shared = [d for n in checked.nodes for d in shared_topic_errors(checked, n, cfg.rules, cfg.mapping or
                                                                   "backends/monitors/mapping.yaml")]
    if shared:
        print("\n".join(map(str, shared)), file=sys.stderr)
        return 2
    if getattr(args, "live", False):
        from rclverify.cli.monitor_live import live_command  # deferred: start-up (only --live)
        return live_command(args, checked, cfg, root)
    if not args.traces:
        print("rclverify monitor: error: name a TRACE to check, or --live to monitor the running system",
              file=sys.stderr)
        return 2
    nodes = selected_nodes(checked, args.nodes, "monitor")
    if nodes is None:
        return 2
    from rclverify.runtime.lifecycle import managed_of  # deferred: managed nodes' runs are judged as live (cli/lifecycle_runs.py)
    if managed_of(nodes) or getattr(args, "transition_deadline", None):
        from rclverify.cli.lifecycle_runs import lifecycle_command  # deferred: as above
        return lifecycle_command(args, checked, nodes, cfg, root)
    violated = False
    unjudged: list[dict[str, str]] = []
    report: list[Mapping[str, object]] = []
    records: list[dict[str, Any]] = []  # --verdicts: every verdict, one line each (verdict_lines.py)
    if getattr(args, "verdicts", None):
        from rclverify.backends.monitors.verdict_lines import verdict_record, write_records  # deferred: start-up (only with --verdicts)
    for trace in args.traces:
        keep = (lambda kind, v, stamp, t=trace: records.append({**verdict_record(kind, v, stamp), "trace": t})) \
            if getattr(args, "verdicts", None) else None
        try:
            run = check_recorded(checked, nodes, cfg, root, trace, lambda w: print(w, file=sys.stderr),
                                 margins=args.json, on_verdict=keep)  # the margins (docs/semantics.md): JSON only
        except TraceError as exc:
            _emit(report, args.json)
            print(str(exc), file=sys.stderr)
            return 2
        except Exception as exc:  # a recorded run is user input: a located message, never a traceback
            _emit(report, args.json)
            print(f"{trace}: error: the trace could not be checked: {type(exc).__name__}: {exc}", file=sys.stderr)
            return 2
        unjudged += run.not_judged
        violated = _report_run(report, run, trace, cfg, args.json) or violated
    if getattr(args, "verdicts", None):
        write_records(Path(args.verdicts), records)
    _emit(report, args.json)
    return 1 if violated else strict_exit(args, unjudged, _undecided(report))


def _report_run(report: list[Mapping[str, object]], run: RecordedRun, trace: str, cfg: Any, as_json: bool) -> bool:
    """Add the verdicts of the recorded run ``run`` (at path ``trace``) to
    ``report`` and print them unless ``as_json``: per node its messages,
    deadlines, periods and declarations, then a live log's calls and what
    the run did not judge; returns whether a verdict failed."""
    violated = False
    items = run.not_judged
    versions = tool_versions() if as_json else ""  # only the JSON report shows them (the distributions' search costs start-up)
    for res in run.results:
        status, explanation = run.verdict(res, trace)
        violated = violated or status == "failed"
        entry = {"node": res.node, "status": status, "explanation": explanation,
                 **monitoring_details(res, trace, run.events, "", versions, cfg.horizon, cfg.tolerance)}
        entry.pop("sha256")
        entry["evaluation"] = dict(res.evaluation)  # debug: which formulas ran as compiled code
        entry["not_judged"] = [i for i in items if i["node"] == res.node]
        explain(entry, items)
        report.append(entry)
        if not as_json:
            print(f"{trace}: {summary_line(res)}")
            print(f"  {status}: {entry['explanation']}")
    for d in run.deadlines:
        from rclverify.backends.monitors.deadline_text import deadline_status  # deferred: start-up (loaded only by a run with a deadline)
        status, explanation = deadline_status(d, trace)
        violated = violated or status == "failed"
        report.append({"node": d.node, "status": status, "explanation": explanation, "trace": trace,
                       "deadlines": d.to_json()})
        if not as_json:
            print(f"{trace}: {d.node} deadlines: " + (", ".join(f"{n} {v}" for v, n in d.counts.items() if n)
                                                        or "no trigger event")
                  + ("; no verdict: " + ", ".join(f"{n} {v}" for v, n in d.unaccepted.items() if n)
                     if any(d.unaccepted.values()) else ""))
            print(f"  {status}: {explanation}")
    # periods, then the declarations (initially, progress, periods: declarations.py): one row each
    judged: list[tuple[str, Any, Any, Any]] = [("periods", pr, period_status(pr, trace), pr.to_json())
                                               for pr in run.periods]
    judged += [("declarations", dr, declaration_status(dr, trace), dr.rows()) for dr in run.declarations]
    for label, res_, (status, explanation), part in judged:
        violated = violated or status == "failed"
        report.append({"node": res_.node, "status": status, "explanation": explanation, "trace": trace,
                       label: part})
        if not as_json:
            print(f"{trace}: {res_.node} {label}: {status}: {explanation}")
    if run.calls is not None:
        violated = _report_calls(report, run.call_entries + run.deadline_entries, run.calls, run.missed, trace,
                                 as_json) or violated
    if not as_json:
        print_not_judged(items, f"{trace}: ")
    return violated


def _report_calls(report: list[Mapping[str, object]], entries: Sequence[Mapping[str, object]],
                  summary: Mapping[str, object], missed: tuple[int, int], trace: str, as_json: bool) -> bool:
    """Add a live log's call verdicts per node and its call deadlines
    (``entries``, each with the log's ``call_counts`` from ``summary``) to
    ``report`` and print them as the live run does; returns whether one
    failed (a violated call, a missed call deadline)."""
    failed = False
    for e in entries:
        entry = {**e, "call_counts": summary["counts"]}
        failed = failed or entry["status"] == "failed"
        report.append(entry)
        if not as_json and "calls" in entry:
            print(f"{trace}: calls: {entry['node']}: {entry['status']}: {entry['explanation']}")
    if not as_json:
        print(f"{trace}: deadlines: {missed[0]} of {missed[1]} judged call(s) or goal(s) missed their deadline")
    return failed or missed[0] > 0


def _undecided(report: list[Mapping[str, object]]) -> list[Mapping[str, object]]:
    """The entries of ``report`` whose status is ``inconclusive``."""
    return [e for e in report if e.get("status") == "inconclusive"]


def oracle_command(args: argparse.Namespace, checked: Checked) -> int:
    """``rclverify oracle --port N``: serve the workspace's checked contracts
    ``checked`` (loaded by the caller, rclverify.cli.commands: a backend does not import
    the pipeline) as a ROSMonitoring oracle (WebSocket, :mod:`.oracle`) until
    SIGINT/SIGTERM.  Exit 2 for a port that cannot be bound or a configuration
    that cannot be read."""
    import asyncio  # deferred: start-up (loads asyncio only when called)
    import signal  # deferred: start-up (loads signal only when called)

    from rclverify.runtime.oracle import serve  # deferred: start-up (loads rclverify.runtime, rclverify.runtime.oracle and more only when called)
    root = Path(args.workspace)
    cfg = _configuration(args, root, "oracle")
    if cfg is None:
        return 2
    nodes = selected_nodes(checked, args.nodes, "oracle")
    if nodes is None:
        return 2

    async def main() -> None:
        stop, ready = asyncio.Event(), asyncio.Event()
        loop = asyncio.get_running_loop()
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, stop.set)
        task = asyncio.create_task(serve(checked, nodes, cfg.rules, cfg.horizon, args.port, args.host, ready, stop))
        done, _ = await asyncio.wait([task, asyncio.create_task(ready.wait())], return_when=asyncio.FIRST_COMPLETED)
        if task in done:
            task.result()  # raises the bind error
        print(f"oracle for {', '.join(n.name for n in nodes)} on ws://{args.host}:{args.port}", flush=True)
        await task
    try:
        asyncio.run(main())
    except OSError as exc:
        print(f"rclverify oracle: error: cannot listen on {args.host}:{args.port}: {exc.strerror or exc}",
              file=sys.stderr)
        return 2
    return 0


def _configuration(args: argparse.Namespace, root: Path, command: str) -> MonitorConfig | None:
    """The monitor configuration (:func:`~rclverify.backends.monitors.config.load_mapping`) of ``args``
    in workspace ``root``; ``None`` after printing why it cannot be read (``rclverify COMMAND``'s error
    line, or the located one)."""
    try:
        return load_mapping(root, args.mapping, args.horizon)
    except ConfigError as exc:
        print(f"{exc}" if exc.located else f"{args.mapping or f'rclverify {command}'}: error: {exc}", file=sys.stderr)
        return None


def _emit(report: list[Mapping[str, object]], as_json: bool) -> None:
    if as_json:
        print(_indented(report))


def _indented(report: list[Mapping[str, object]]) -> str:
    """``json.dumps(report, indent=2, sort_keys=True)``: the json module's C encoder writes it on one line
    and msgspec's ``format`` lays it out, changing only the whitespace, as the indenting encoder does (on a
    report of 900 violations a third of the indenting encoder's time, which is pure Python); a text
    msgspec does not read (``Infinity``, ``NaN``, a lone surrogate's escape) is written by the indenting
    encoder itself."""
    import msgspec  # deferred: start-up (imported where it is used)
    line = json.dumps(report, sort_keys=True)
    try:
        return msgspec.json.format(line.encode(), indent=2).decode()
    except msgspec.DecodeError:
        return json.dumps(report, indent=2, sort_keys=True)


__all__ = ["monitor_command", "RclError"]
