"""``rclverify monitor [-w WS] TRACE...``: check recorded runs against every node's contract;
``rclverify monitor --live``: monitor the running ROS 1 system, or with
``--ros2`` the ROS 2 system over DDS (:mod:`.dds_live`).

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
from rclverify.backends.monitors.summary import monitoring_details, summary_line, tool_versions, verdict_status
from rclverify.backends.monitors.deadline_text import deadline_status
from rclverify.backends.monitors.config import ConfigError, load_mapping
from rclverify.backends.monitors.judged import explain, strict_line
from rclverify.backends.monitors.declarations import declaration_status
from rclverify.backends.monitors.periods import period_status
from rclverify.backends.monitors.recorded import RecordedRun, check_recorded
from rclverify.backends.monitors.verdict_lines import log_records, verdict_record, write_records
from rclverify.core.extras import MissingExtra



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
    from rclverify.backends.monitors.shared_topics import shared_topic_errors  # two variables on one topic read distinct fields; deferred: start-up (imported where it is used)
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
    from rclverify.runtime.lifecycle import managed_of  # deferred: managed nodes' runs are judged as live (cli/lifecycle_runs.py)
    if managed_of(nodes) or getattr(args, "transition_deadline", None):
        from rclverify.cli.lifecycle_runs import lifecycle_command  # deferred: as above
        return lifecycle_command(args, checked, nodes, cfg, root)
    violated = False
    unjudged: list[dict[str, str]] = []
    report: list[Mapping[str, object]] = []
    records: list[dict[str, Any]] = []  # --verdicts: every verdict, one line each (verdict_lines.py)
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
    return 1 if violated else _strict(args, unjudged, _undecided(report))


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
        _print_not_judged(items, f"{trace}: ")
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


def _print_not_judged(items: list[dict[str, str]], prefix: str) -> None:
    """One line per item the run did not judge (silence is never green: judged.py)."""
    for i in items:
        print(f"{prefix}not judged: {i['kind']} {i['name']} ({i['node']}): {i['reason']}: {i['detail']}")


def _strict(args: argparse.Namespace, unjudged: list[dict[str, str]],
            undecided: Sequence[Mapping[str, object]] = ()) -> int:
    """The exit code of a run with no violation: 1 under ``--strict`` when
    an item went unjudged (``unjudged``, the first named on stderr) or a
    verdict stayed undecided (``undecided``: the ``inconclusive`` entries, as
    ``doit verify --strict`` fails on what is not discharged), else 0."""
    if not getattr(args, "strict", False) or not (unjudged or undecided):
        return 0
    if unjudged:
        print(strict_line(unjudged), file=sys.stderr)
    else:
        first = undecided[0]
        print(f"rclverify monitor: --strict: {len(undecided)} verdict(s) undecided; the first: {first['node']}: "
              f"{first['explanation']}", file=sys.stderr)
    return 1


def _undecided(report: list[Mapping[str, object]]) -> list[Mapping[str, object]]:
    """The entries of ``report`` whose status is ``inconclusive``."""
    return [e for e in report if e.get("status") == "inconclusive"]


def _mapping_refused(cfg: Any, root: Path, checked: Any) -> bool:
    """Whether the plan's mapping (``cfg.mapping``) names a field path the message definitions refuse:
    the check ``doit verify`` makes (``check_field_paths``), with the robot's own types allowed.  Prints
    each refusal (``file:line:col: error: ...``) on stderr; ``False`` when there is no mapping or when no
    standard definition is known (rosbags missing: the run reads what comes)."""
    if not cfg.mapping:
        return False
    from rclverify.backends.monitors.fieldpaths import check_field_paths  # deferred: start-up (only live)
    try:
        wrong = check_field_paths(root, cfg.mapping, cfg.msg_dirs, checked, robot_types=True)
    except MissingExtra:
        return False
    if wrong:
        print("\n".join(map(str, wrong)), file=sys.stderr)
    return bool(wrong)


def live_command(args: argparse.Namespace, checked: Any, cfg: Any, root: Path) -> int:
    """``--live``: monitor the running ROS 1 system (``--ros2``: ROS 2 over DDS) until
    SIGINT/SIGTERM or ``--duration``.

    Writes the log (``--log``) and, on stop, the evidence record
    (``--evidence``); prints a status line per ``--status`` seconds.  Exit
    status 1 when a contract was violated (a topic, a call, a deadline), 0
    otherwise, 2 when ROS 1, the DDS domain or a message type is unavailable
    (one message on stderr)."""
    from functools import partial  # deferred: start-up (imported where it is used)

    import os  # deferred: start-up (imported where it is used)

    from rclverify.runtime.live import LiveRun  # deferred: start-up (loads rclverify.records, rclverify.records.records and more only when called)
    from rclverify.runtime.live_ros1 import run_ros1  # deferred: start-up (loads rclverify.runtime.live and more only when called)
    from rclverify.runtime.ros1 import RosUnavailable  # deferred: start-up (imported where it is used)
    from rclverify.ros.live.dds import DdsUnavailable  # deferred: start-up (imported where it is used)
    from rclverify.runtime.rclpy_source.bus import RclpyUnavailable  # deferred: start-up (imported where it is used)
    if args.traces:
        print("rclverify monitor: error: --live takes no TRACE (it monitors the running system)", file=sys.stderr)
        return 2
    nodes = selected_nodes(checked, args.nodes, "monitor")
    if nodes is None:
        return 2
    if _mapping_refused(cfg, root, checked):
        return 2
    log = Path(args.log)
    ros = args.ros or os.environ.get("ROS_VERSION", "1")  # ROS's setup scripts set ROS_VERSION
    enforce_items, record = getattr(args, "enforce", []), getattr(args, "record", None)
    usage = _live_usage(args, ros, bool(enforce_items or record))
    if usage:
        print(usage, file=sys.stderr)
        return 2
    run_class: Any = LiveRun
    extra: dict[str, Any] = {}
    if enforce_items:
        enforcing = _enforcing(enforce_items, nodes, extra)
        if enforcing is None:
            return 2
        run_class = enforcing
    from rclverify.backends.monitors.widths import judged_at_widths  # deferred: start-up (only live)
    dirs = [root / d for d in cfg.msg_dirs]  # the contract's constants, named ones too, as the fields carry them
    judged = [judged_at_widths(checked, n, cfg.rules, dirs)[0] for n in nodes]  # the offline check's route
    nodes = judged  # every part of the run judges them so: the topics' engine, the calls, the service proxy
    warn_margin = getattr(args, "warn_margin", None)
    factory = partial(run_class, checked, judged, cfg.rules, cfg.horizon, log,
                      reorder_window=args.reorder_window, silence_s=args.silence,
                      margins=bool(getattr(args, "margins", False)), warn_margin=warn_margin,
                      warn=lambda line: print(line, file=sys.stderr, flush=True), **extra)
    from rclverify.runtime.stopping import StopFlag, on_signals  # deferred: start-up (only live)
    stop = StopFlag()  # a handler that takes no lock: a stop is always heard (stopping.py)
    on_signals(stop)  # kept once the run is over: a second Ctrl-C while the process ends is no traceback
    try:
        common: dict[str, Any] = dict(
            verdict_topic=args.verdict_topic, last_prefix=args.verdict_topic.rsplit("/", 1)[0] or "/rclverify",
            node_name="rclverify_monitor", duration=args.duration, tick_s=0.02, status_s=args.status, stop=stop,
            evidence=Path(args.evidence) if args.evidence else None, out=lambda line: print(line, flush=True))
        from rclverify.runtime.service_proxy import ProxyUsage, proxy_factory  # deferred: start-up (loads rclverify.runtime, rclverify.runtime.ros1 and more only when called)
        interfaces = [root / d for d in getattr(args, "interfaces", [])]
        try:
            if ros == "2":
                record_ = _run_ros2(args, factory, checked, nodes, [root / d for d in cfg.msg_dirs], interfaces, common,
                                    extra.get("guarded"), record)
                if record_ is None:
                    return 2
            else:
                proxy = proxy_factory(checked, nodes, getattr(args, "forward", []), interfaces)
                record_ = run_ros1(factory, checked, nodes, [root / d for d in cfg.msg_dirs], **common, proxy=proxy)
        except (RosUnavailable, DdsUnavailable, ProxyUsage, RclpyUnavailable) as exc:
            text = str(exc)
            print(text if ": error: " in text else f"rclverify monitor --live: error: {text}", file=sys.stderr)
            return 1 if isinstance(exc, MissingExtra) else 2  # a missing extra exits 1 (docs/install.md)
        _print_live(log, record_)
        if getattr(args, "verdicts", None):  # the log's verdict lines, as a recorded run's are written
            write_records(Path(args.verdicts), log_records(log))
        return _live_exit(args, record_)
    finally:
        stop.close()  # the stop request's pipe given back (an in-process caller runs many)


def _run_ros2(args: argparse.Namespace, factory: Any, checked: Any, nodes: Any, msg_dirs: list[Path],
              interfaces: list[Path], common: dict[str, Any], guarded: Any, record: str | None) -> Any:
    """Run the live monitor on ROS 2 (``run_dds``) through the source ``--source`` picks, recording to
    ``record`` (``--record``) when given; returns the run's evidence record, ``None`` after printing why
    the source cannot be had (exit 2).  Raises what ``run_dds`` and :func:`_source` raise."""
    from functools import partial  # deferred: start-up (only --ros2)

    from rclverify.runtime.dds.bag import storage_of  # deferred: optional or conditional (only --ros2)
    from rclverify.runtime.dds.live import run_dds  # deferred: optional or conditional (only --ros2)
    rec = (Path(record), storage_of(Path(record), getattr(args, "record_storage", None))) if record else None
    bus_factory = _source(args)
    if bus_factory is False:
        return None
    describe = None
    if bus_factory is not None:  # the rclpy source (partial(RclpyBus, ros2_python)): types its Python knows
        from rclverify.runtime.rclpy_source.describe import installed_declarations  # deferred: optional or conditional (only --ros2)
        describe = partial(installed_declarations, bus_factory.args[0])
    # the bag records each contract type in the definition the monitor decodes it with (``--interfaces`` too)
    return run_dds(factory, checked, nodes, msg_dirs + interfaces, **common, enforce=guarded, record=rec,
                   msg_dirs=msg_dirs + interfaces, reorder_window=args.reorder_window, bus_factory=bus_factory, describe=describe)


def _source(args: argparse.Namespace) -> Any:
    """The bus factory of the ROS 2 source ``--source`` asks for (docs/ros2.md, "Two sources"): the rclpy
    source's, ``None`` for the DDS source, ``False`` after printing why it cannot be had (exit 2). Says
    which source on the first line.  Raises :class:`~rclverify.ros.live.dds.DdsUnavailable` (its subclass
    ``DdsExtraMissing`` without the ``[ros2]`` extra) before that line when the DDS source cannot load."""
    from functools import partial  # deferred: start-up (imported where it is used)

    from rclverify.runtime.rclpy_source.bus import RclpyBus  # deferred: optional or conditional (only --ros2)
    from rclverify.runtime.rclpy_source.python import pick_source  # deferred: optional or conditional (only --ros2)
    try:
        source, py, why = pick_source(getattr(args, "source", "auto"), getattr(args, "ros2_python", None))
    except ValueError as exc:
        print(f"rclverify monitor --live --ros2: error: {exc}", file=sys.stderr)
        return False
    if source == "dds":  # the binding first: without the [ros2] extra the one line is the error
        from rclverify.ros.live.dds import import_cyclonedds  # deferred: optional or conditional (only --ros2)
        import_cyclonedds()
    print(f"source: {source} ({why})", flush=True)
    return partial(RclpyBus, py) if source == "rclpy" and py else None


def _live_usage(args: argparse.Namespace, ros: str, ros2_only: bool) -> str | None:
    """The error line for options the ROS version ``ros`` does not take
    (``ros2_only``: ``--enforce`` or ``--record`` given), or ``None``."""
    if ros != "2" and ros2_only:
        return "rclverify monitor --live: error: --enforce and --record need ROS 2 (--ros2)"
    if ros == "2" and getattr(args, "forward", []):
        return ("rclverify monitor --live --ros2: error: --forward is for ROS 1's service proxy; over DDS the "
                "monitor reads every call on the bus (name the .srv/.action directories with --interfaces)")
    return None


def _enforcing(items: list[str], nodes: list[Any], extra: dict[str, Any]) -> Any:
    """The enforcing run class for ``--enforce`` ``items``, its guarded and
    fail-open topics put in ``extra``; ``None`` after printing one error
    line for an item that does not parse or names a topic no monitored
    contract names."""
    from rclverify.runtime.enforce import EnforceUsage, EnforcingRun, fail_open, parse_enforce  # deferred: optional or conditional (inside a block)
    try:
        extra["guarded"] = parse_enforce(items)
        extra["open_topics"] = fail_open(items)
    except EnforceUsage as exc:
        print(f"rclverify monitor --live: error: {exc}", file=sys.stderr)
        return None
    unknown = sorted(set(extra["guarded"]) - {t.field.strip("/") for n in nodes for t in n.node.topics})
    if unknown:
        print(f"rclverify monitor --live: error: --enforce /{unknown[0]}: no monitored contract names this "
              f"topic", file=sys.stderr)
        return None
    return EnforcingRun


def _print_live(log: Path, record_: dict[str, Any]) -> None:
    """The lines a stopped live run prints: its log, then per node its
    calls, deadlines, periods and declarations, enforcement, the recording
    and what it did not judge (``record_``: the run's evidence record)."""
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


def _live_exit(args: argparse.Namespace, record_: dict[str, Any]) -> int:
    """The exit code of a stopped live run: 1 when a message, call,
    deadline, period or declaration failed, else :func:`_strict`'s."""
    late = bool(record_.get("deadlines", {}).get("false"))
    late = late or any(d["status"] == "failed" for d in record_.get("topic_deadlines", []) + record_.get("periods", [])
                       + record_.get("declarations", []))
    calls_failed = any(n["status"] == "failed" for n in record_.get("calls", {}).get("nodes", []))
    if late or calls_failed or any(n["status"] == "failed" for n in record_["nodes"]):
        return 1
    undecided = [d for d in record_["nodes"] + record_.get("calls", {}).get("nodes", [])
                 + record_.get("topic_deadlines", []) + record_.get("periods", []) + record_.get("declarations", [])
                 if d.get("status") == "inconclusive"]
    return _strict(args, list(record_.get("not_judged", [])), undecided)


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


def _emit(report: list[Mapping[str, object]], as_json: bool) -> None:
    if as_json:
        print(json.dumps(report, indent=2, sort_keys=True))


__all__ = ["monitor_command", "RclError"]
