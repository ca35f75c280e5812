"""``rclverify monitor --live``: monitor the running ROS 1 system, or with
``--ros2`` the ROS 2 system over DDS or through rclpy (docs/ros2.md, "Two
sources"), until SIGINT/SIGTERM or ``--duration``; then print what the run
judged and exit as :mod:`.monitor` says (1 on a violation, 2 when the
system or a message type cannot be reached).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from rclverify.backends.monitors.verdict_lines import log_records, write_records
from rclverify.cli.monitor_outcome import print_not_judged, selected_nodes, strict_exit
from rclverify.core.extras import MissingExtra


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
    nodes = judged  # every part of the run judges them so: the topics' engine, the calls, the deadline checks
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
                proxy = proxy_factory(checked, getattr(args, "forward", []), interfaces)
                record_ = run_ros1(factory, checked, nodes, [root / d for d in cfg.msg_dirs], **common, proxy=proxy)
        except (RosUnavailable, DdsUnavailable, ProxyUsage, RclpyUnavailable) as exc:
            text = str(exc)
            print(text if ": error: " in text else f"rclverify monitor --live: error: {text}", file=sys.stderr)
            return 1 if isinstance(exc, MissingExtra) else 2  # a missing extra exits 1 (docs/install.md)
        _print_live(log, record_)
        if getattr(args, "verdicts", None):  # the log's verdict lines, as a recorded run's are written
            write_records(Path(args.verdicts), log_records(log))
        return _ended(_live_exit(args, record_))  # everything written: the process ends within a bound
    finally:
        stop.close()  # the stop request's pipe given back (an in-process caller runs many)



def _ended(code: int) -> int:
    """``code``, once the command line's own process (:func:`_command_line`) is set to end within
    :data:`~rclverify.runtime.stopping.EXIT_BOUND_S` whatever a library left behind (``end_bounded``;
    docs/monitors.md, "Stopping"); an in-process caller's process is left as it is."""
    if _command_line():
        from rclverify.runtime.stopping import end_bounded  # deferred: start-up (only live)
        end_bounded(code)
    return code


def _command_line() -> bool:
    """Whether this process is the ``rclverify`` command line (its console script, which runs
    :func:`rclverify.cli.main`, or ``python -m rclverify.cli.commands``), not a program running the
    command in its own process (a test's ``main([...])``), whose process goes on after it."""
    from rclverify.cli import main as console  # deferred: start-up (only live)
    top = sys.modules.get("__main__")
    spec = getattr(top, "__spec__", None)
    return str(getattr(spec, "name", "") or "").split(".")[0] == "rclverify" or getattr(top, "main", None) is console



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
    print_not_judged(record_.get("not_judged", []), "")



def _live_exit(args: argparse.Namespace, record_: dict[str, Any]) -> int:
    """The exit code of a stopped live run: 1 when a message, call,
    deadline, period or declaration failed, else :func:`strict_exit`'s."""
    late = bool(record_.get("deadlines", {}).get("false"))
    late = late or any(d["status"] == "failed" for d in record_.get("topic_deadlines", []) + record_.get("periods", [])
                       + record_.get("declarations", []))
    calls_failed = any(n["status"] == "failed" for n in record_.get("calls", {}).get("nodes", []))
    if late or calls_failed or any(n["status"] == "failed" for n in record_["nodes"]):
        return 1
    undecided = [d for d in record_["nodes"] + record_.get("calls", {}).get("nodes", [])
                 + record_.get("topic_deadlines", []) + record_.get("periods", []) + record_.get("declarations", [])
                 if d.get("status") == "inconclusive"]
    return strict_exit(args, list(record_.get("not_judged", [])), undecided)
