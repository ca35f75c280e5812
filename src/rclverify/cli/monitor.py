"""``rclverify monitor [-w WS] TRACE...``: check recorded runs against every node's contract;
``rclverify monitor --live``: monitor the running ROS 1 system, or with
``--ros2`` the ROS 2 system over DDS (:mod:`.dds_live`).

A live ROS 2 run's log named as a TRACE has its service calls and action
goals judged as the live run judged them (its call lines replayed through
the live call book, :mod:`.log_calls`).

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
from typing import Any, Iterable, Iterator

from rclverify.lang.errors import RclError
from rclverify.lang.types import Checked
from rclverify.traces import TraceError, read_trace
from rclverify.backends.monitors.summary import monitoring_details, summary_line, tool_versions, verdict_status
from rclverify.backends.monitors.check import check_trace
from rclverify.backends.monitors.deadlines import DeadlineMonitor, deadline_status, has_deadlines
from rclverify.backends.monitors.config import ConfigError, load_mapping
from rclverify.backends.monitors.judged import Counted, Heard, explain, not_judged, strict_line
from rclverify.backends.monitors.log_calls import LogCalls
from rclverify.backends.monitors.declarations import DeclarationMonitor, add_periods, declaration_status, has_declarations
from rclverify.backends.monitors.periods import PeriodMonitor, has_periods, period_status



def selected_nodes(checked: Any, names: Any, command: str) -> list[Any] | None:
    """The checked nodes ``names`` (``--node``) selects, every node when it
    is empty; ``None`` after printing one error line when a name is not a
    node of the contracts."""
    unknown = [n for n in names or () if n not in checked.nodes]
    if unknown:
        print(f"rclverify {command}: error: no node named {unknown[0]!r}; nodes: {', '.join(checked.nodes)}",
              file=sys.stderr)
        return None
    return [checked.nodes[n] for n in names] if names else list(checked.nodes.values())

def monitor_command(args: argparse.Namespace, checked: Checked) -> int:
    """Run the command on the workspace's checked contracts ``checked`` (the
    caller, rclverify.cli.commands, loads them: a backend does not import the
    pipeline); returns the exit code (never raises for user input)."""
    root = Path(args.workspace)
    try:
        cfg = load_mapping(root, args.mapping, args.horizon)
    except ConfigError as exc:
        print(f"{exc}" if exc.located else f"{args.mapping or 'rclverify monitor'}: error: {exc}", file=sys.stderr)
        return 2
    from rclverify.backends.monitors.shared_topics import shared_topic_errors  # two variables on one topic read distinct fields (issue 64); deferred: start-up (every command module loads when rclverify starts: cli/common.py)
    shared = [d for n in checked.nodes for d in shared_topic_errors(checked, n, cfg.rules, cfg.mapping or
                                                                   "backends/monitors/mapping.yaml")]
    if shared:
        print("\n".join(map(str, shared)), file=sys.stderr)
        return 2
    if getattr(args, "live", False):
        return live_command(args, checked, cfg, root)
    if not args.traces:
        print("rclverify monitor: error: name a TRACE to check, or --live to monitor the running system",
              file=sys.stderr)
        return 2
    nodes = selected_nodes(checked, args.nodes, "monitor")
    if nodes is None:
        return 2
    violated = False
    unjudged: list[dict[str, str]] = []
    report: list[dict[str, Any]] = []
    timed = [n for n in nodes if has_deadlines(n)]
    for trace in args.traces:
        path = Path(trace)
        # one pass over the run feeds both checks (a log named here may be a stream, read once)
        dmons = [DeadlineMonitor(checked, n, cfg.rules, horizon=cfg.horizon, tolerance=cfg.tolerance) for n in timed]
        pmons = [PeriodMonitor(n) for n in nodes if has_periods(n)]
        decl = [DeclarationMonitor(checked, n, cfg.rules, tolerance=cfg.tolerance) for n in nodes
                if has_declarations(n)]
        calls = LogCalls(checked, nodes, cfg.rules, cfg.horizon, trace)  # a live log's calls (log_calls.py)
        heard: dict[str, int] = {}

        def tap(events: Iterable[Any]) -> Iterator[Any]:
            for ev in events:
                for m in dmons:
                    m.feed(ev)
                for p in pmons:
                    p.feed(ev)
                for dm in decl:
                    dm.feed(ev)
                yield ev
        try:
            run = read_trace(path, [root / d for d in cfg.msg_dirs], streams=True,
                             on_warning=lambda w: print(w, file=sys.stderr))
            source = tap(run) if dmons or pmons or decl else run  # untapped, a log keeps its columnar reading (batch path)
            source = calls.tap(source) if calls.active else source  # only nodes with links: never the batch path
            events, results = check_trace(checked, nodes, Counted(source, heard), cfg.rules, cfg.horizon,
                                          tolerance=cfg.tolerance)
            dres = [m.finish() for m in dmons]
            pres = [p.finish() for p in pmons]
            decl_res = [add_periods(dm.finish(), dm.node, next((p for p in pres if p.node == dm.node.name), None))
                        for dm in decl]
            summary = calls.finish()
        except TraceError as exc:
            _emit(report, args.json)
            print(str(exc), file=sys.stderr)
            return 2
        except Exception as exc:  # a recorded run is user input: a located message, never a traceback
            _emit(report, args.json)
            print(f"{trace}: error: the trace could not be checked: {type(exc).__name__}: {exc}", file=sys.stderr)
            return 2
        statuses = {res.node: [verdict_status(res, trace)] for res in results}
        centries, dentries = calls.entries(), calls.deadline_entries()
        for c in centries:
            statuses.setdefault(c["node"], []).append((c["status"], c["explanation"]))
        dcounts = {d.node: dict(d.counts) for d in dres}
        for r in calls.deadlines():  # the topic and the call deadlines summed, as the live run does
            total = dcounts.setdefault(r.node, {})
            for v, k in r.counts.items():
                total[v] = total.get(v, 0) + k
        items = not_judged(nodes, Heard({**heard, **calls.messages}, dict(calls.orphans)), statuses, dcounts,
                           f"in {trace}")
        unjudged += items
        for res in results:
            status, explanation = verdict_status(res, trace)
            violated = violated or status == "failed"
            entry = {"node": res.node, "status": status, "explanation": explanation,
                     **monitoring_details(res, trace, events, "", tool_versions(), cfg.horizon, cfg.tolerance)}
            entry.pop("sha256")
            entry["evaluation"] = dict(res.evaluation)  # debug: which formulas ran as compiled code
            entry["not_judged"] = [i for i in items if i["node"] == res.node]
            explain(entry, items)
            report.append(entry)
            if not args.json:
                print(f"{trace}: {summary_line(res)}")
                print(f"  {status}: {entry['explanation']}")
        for d in dres:
            status, explanation = deadline_status(d, trace)
            violated = violated or status == "failed"
            report.append({"node": d.node, "status": status, "explanation": explanation, "trace": trace,
                           "deadlines": d.to_json()})
            if not args.json:
                print(f"{trace}: {d.node} deadlines: " + (", ".join(f"{n} {v}" for v, n in d.counts.items() if n)
                                                            or "no trigger event")
                      + ("; no verdict: " + ", ".join(f"{n} {v}" for v, n in d.unaccepted.items() if n)
                         if any(d.unaccepted.values()) else ""))
                print(f"  {status}: {explanation}")
        # periods, then the declarations (initially, progress, periods: declarations.py, issue 64): one row each
        judged: list[tuple[str, Any, Any, Any]] = [("periods", pr, period_status(pr, trace), pr.to_json())
                                                   for pr in pres]
        judged += [("declarations", dr, declaration_status(dr, trace), dr.rows()) for dr in decl_res]
        for label, res_, (status, explanation), part in judged:
            violated = violated or status == "failed"
            report.append({"node": res_.node, "status": status, "explanation": explanation, "trace": trace,
                           label: part})
            if not args.json:
                print(f"{trace}: {res_.node} {label}: {status}: {explanation}")
        if summary is not None:
            violated = _report_calls(report, centries + dentries, summary, calls.missed(), trace,
                                     args.json) or violated
        if not args.json:
            _print_not_judged(items, f"{trace}: ")
    _emit(report, args.json)
    return 1 if violated else _strict(args, unjudged)


def _report_calls(report: list[dict[str, Any]], entries: list[dict[str, Any]], summary: dict[str, Any],
                  missed: tuple[int, int], trace: str, as_json: bool) -> bool:
    """Add a live log's call verdicts per node and its call deadlines to
    ``report`` and print them as the live run does; returns whether one
    failed (a violated call, a missed call deadline)."""
    failed = False
    for e in entries:
        e["call_counts"] = summary["counts"]
        failed = failed or e["status"] == "failed"
        report.append(e)
        if not as_json and "calls" in e:
            print(f"{trace}: calls: {e['node']}: {e['status']}: {e['explanation']}")
    if not as_json:
        print(f"{trace}: deadlines: {missed[0]} of {missed[1]} judged call(s) or goal(s) missed their deadline")
    return failed or missed[0] > 0


def _print_not_judged(items: list[dict[str, str]], prefix: str) -> None:
    """One line per item the run did not judge (silence is never green: judged.py)."""
    for i in items:
        print(f"{prefix}not judged: {i['kind']} {i['name']} ({i['node']}): {i['reason']}: {i['detail']}")


def _strict(args: argparse.Namespace, unjudged: list[dict[str, str]]) -> int:
    """The exit code of a run with no violation: 1 under ``--strict`` when
    an item went unjudged (``unjudged``, the first named on stderr), else 0."""
    if not unjudged or not getattr(args, "strict", False):
        return 0
    print(strict_line(unjudged), file=sys.stderr)
    return 1


def live_command(args: argparse.Namespace, checked: Any, cfg: Any, root: Path) -> int:
    """``--live``: monitor the running ROS 1 system (``--ros2``: ROS 2 over DDS) until
    SIGINT/SIGTERM or ``--duration``.

    Writes the log (``--log``) and, on stop, the evidence record
    (``--evidence``); prints a status line per ``--status`` seconds.  Exit
    status 1 when a contract was violated (a topic, a call, a deadline), 0
    otherwise, 2 when ROS 1, the DDS domain or a message type is unavailable
    (one message on stderr)."""
    import signal  # deferred: start-up (loads signal only when called)
    import threading  # deferred: start-up (every command module loads when rclverify starts: cli/common.py)
    from functools import partial  # deferred: start-up (every command module loads when rclverify starts: cli/common.py)

    import os  # deferred: start-up (every command module loads when rclverify starts: cli/common.py)

    from rclverify.runtime.live import LiveRun, run_ros1  # deferred: start-up (loads rclverify.records, rclverify.records.records and more only when called)
    from rclverify.runtime.ros1 import RosUnavailable  # deferred: start-up (every command module loads when rclverify starts: cli/common.py)
    from rclverify.ros.live.dds import DdsUnavailable  # deferred: start-up (every command module loads when rclverify starts: cli/common.py)
    if args.traces:
        print("rclverify monitor: error: --live takes no TRACE (it monitors the running system)", file=sys.stderr)
        return 2
    nodes = selected_nodes(checked, args.nodes, "monitor")
    if nodes is None:
        return 2
    log = Path(args.log)
    ros = args.ros or os.environ.get("ROS_VERSION", "1")  # ROS's setup scripts set ROS_VERSION
    enforce_items, record = getattr(args, "enforce", []), getattr(args, "record", None)
    if ros != "2" and (enforce_items or record):
        print("rclverify monitor --live: error: --enforce and --record need ROS 2 (--ros2)", file=sys.stderr)
        return 2
    if ros == "2" and getattr(args, "forward", []):
        print("rclverify monitor --live --ros2: error: --forward is for ROS 1's service proxy; over DDS the "
              "monitor reads every call on the bus (name the .srv/.action directories with --interfaces)",
              file=sys.stderr)
        return 2
    run_class: Any = LiveRun
    extra: dict[str, Any] = {}
    if enforce_items:
        from rclverify.runtime.enforce import EnforceUsage, EnforcingRun, fail_open, parse_enforce  # deferred: optional or conditional (inside a block)
        try:
            extra["guarded"] = parse_enforce(enforce_items)
            extra["open_topics"] = fail_open(enforce_items)
        except EnforceUsage as exc:
            print(f"rclverify monitor --live: error: {exc}", file=sys.stderr)
            return 2
        unknown = sorted(set(extra["guarded"]) - {t.field.strip("/") for n in nodes for t in n.node.topics})
        if unknown:
            print(f"rclverify monitor --live: error: --enforce /{unknown[0]}: no monitored contract names this "
                  f"topic", file=sys.stderr)
            return 2
        run_class = EnforcingRun
    factory = partial(run_class, checked, nodes, cfg.rules, cfg.horizon, log,
                      reorder_window=args.reorder_window, silence_s=args.silence, **extra)
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    common: dict[str, Any] = dict(
        verdict_topic=args.verdict_topic, last_prefix=args.verdict_topic.rsplit("/", 1)[0] or "/rclverify",
        node_name="rclverify_monitor", duration=args.duration, tick_s=0.02, status_s=args.status, stop=stop,
        evidence=Path(args.evidence) if args.evidence else None, out=lambda line: print(line, flush=True))
    from rclverify.runtime.service_proxy import ProxyUsage, proxy_factory  # deferred: start-up (loads rclverify.runtime, rclverify.runtime.ros1 and more only when called)
    interfaces = [root / d for d in getattr(args, "interfaces", [])]
    try:
        if ros == "2":
            from rclverify.runtime.dds.bag import storage_of  # deferred: optional or conditional (inside a block)
            from rclverify.runtime.dds.live import run_dds  # deferred: optional or conditional (inside a block)
            msg_dirs = [root / d for d in cfg.msg_dirs]
            rec = (Path(record), storage_of(Path(record), getattr(args, "record_storage", None))) if record else None
            record_ = run_dds(factory, checked, nodes, msg_dirs + interfaces, **common,
                              enforce=extra.get("guarded"), record=rec, msg_dirs=msg_dirs,
                              reorder_window=args.reorder_window)
        else:
            proxy = proxy_factory(checked, nodes, getattr(args, "forward", []), interfaces)
            record_ = run_ros1(factory, checked, nodes, [root / d for d in cfg.msg_dirs], **common, proxy=proxy)
    except (RosUnavailable, DdsUnavailable, ProxyUsage) as exc:
        text = str(exc)
        print(text if ": error: " in text else f"rclverify monitor --live: error: {text}", file=sys.stderr)
        return 2
    print(f"{log}: {record_['events']} event(s), {record_['verdicts']} verdict(s); sha256 {record_['sha256']}")
    for n in record_.get("calls", {}).get("nodes", []):
        print(f"calls: {n['node']}: {n['status']}: {n['explanation']}")
    if "deadlines" in record_:
        judged = sum(r["counts"]["true"] + r["counts"]["false"] for r in record_["deadlines"]["results"])
        print(f"deadlines: {record_['deadlines']['false']} of {judged} judged call(s) or goal(s) missed their "
              f"deadline")
    for d in record_.get("topic_deadlines", []):
        print(f"deadlines: {d['node']}: {d['status']}: {d['explanation']}")
    for d in record_.get("periods", []):
        print(f"periods: {d['node']}: {d['status']}: {d['explanation']}")
    for d in record_.get("declarations", []):
        print(f"declarations: {d['node']}: {d['status']}: {d['explanation']}")
    for topic, c in record_.get("enforce", {}).items():
        print(f"enforce /{topic}: {c['released']} released, {c['blocked']} blocked (read from {c['private']})")
    if "bag" in record_:
        print(f"recorded {record_['bag']['messages']} message(s) to {record_['bag']['path']}")
    _print_not_judged(record_.get("not_judged", []), "")
    late = bool(record_.get("deadlines", {}).get("false"))
    late = late or any(d["status"] == "failed" for d in record_.get("topic_deadlines", []) + record_.get("periods", [])
                       + record_.get("declarations", []))
    calls_failed = any(n["status"] == "failed" for n in record_.get("calls", {}).get("nodes", []))
    if late or calls_failed or any(n["status"] == "failed" for n in record_["nodes"]):
        return 1
    return _strict(args, list(record_.get("not_judged", [])))


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
    try:
        cfg = load_mapping(root, args.mapping, args.horizon)
    except ConfigError as exc:
        print(f"{exc}" if exc.located else f"{args.mapping or 'rclverify oracle'}: error: {exc}", file=sys.stderr)
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


def _emit(report: list[dict[str, Any]], as_json: bool) -> None:
    if as_json:
        print(json.dumps(report, indent=2, sort_keys=True))


__all__ = ["monitor_command", "RclError"]
