"""``rclverify monitor`` and ``oracle``: their parsers, and the contracts loaded for them
(docs/monitors.md); what they do is cli/monitor.py's."""
from __future__ import annotations

import argparse
from pathlib import Path

from rclverify.cli.common import AddCommand, seconds


def cmd_monitor(args: argparse.Namespace) -> int:
    """Judge recorded runs, or the running system (``--live``), against every node's contract (:func:`rclverify.cli.monitor.monitor_command`)."""
    from rclverify.core.cache.heap import freeze_at_exit, loading  # deferred: start-up (imported where it is used)
    from rclverify.core.cache.startup import keeping  # deferred: start-up (loads rclverify.core.cache.store only when called)
    # what the start-up loads (the modules, the log's reader, the contracts, the plan) stays live to the end: no
    # collection while it is made, then frozen for the run, so that no collection walks it (core/cache/heap.py);
    # the parsed contracts, the plan's schema check, the compiled formulas and the YAML files read (the backends'
    # declarations among them, read when their module is imported) are kept by content (core/cache/startup.py)
    with loading() as loaded, keeping():
        from rclverify.cli.monitor import monitor_command  # deferred: start-up (loads numpy and more only when called)
        from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
        from rclverify.model.instances import instantiate  # deferred: start-up (as above)
        _log_reader(args)
        ws = Workspace(Path(args.workspace), args.plan)
        checked = instantiate(ws.checked, ws.plan.node_instances)  # each instance its own node; raises RclError, printed located by main
        freeze_at_exit()
        loaded()
        return monitor_command(args, checked)


def _log_reader(args: argparse.Namespace) -> None:
    """Import the reader of a ROSMonitoring log (:mod:`rclverify.traces.jsonl_blocks`, with numpy and
    msgspec) when ``args`` names one to check and the reader would take it (:func:`rclverify.traces.read_trace`
    imports it when it reads one): loaded with the rest of the start-up."""
    from rclverify.traces.guard import LOG_SUFFIXES  # deferred: start-up (imported where it is used)
    if getattr(args, "live", False) or not any(Path(t).suffix in LOG_SUFFIXES for t in args.traces):
        return
    from rclverify.core.extras import installed  # deferred: start-up (imported where it is used)
    if installed("numpy"):
        import rclverify.traces.jsonl_blocks  # noqa: F401  # deferred: optional or conditional (inside a block)


def cmd_oracle(args: argparse.Namespace) -> int:
    """Serve the contracts as a ROSMonitoring oracle over WebSocket (:func:`rclverify.cli.monitor.oracle_command`)."""
    from rclverify.cli.monitor import oracle_command  # deferred: start-up (loads jinja2, lark and more only when called)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    checked = Workspace(Path(args.workspace), args.plan).checked  # raises RclError, printed located by main
    return oracle_command(args, checked)


def add_monitor(add: AddCommand) -> None:
    """The ``monitor`` parser (recorded runs; live monitoring's options in their own group)."""
    m = add("monitor", cmd_monitor, "check recorded runs (ROSMonitoring logs, ROS bags) against every "
            "node's contract", True)
    m.add_argument("traces", nargs="*", metavar="TRACE", help="a .jsonl log, a .bag, a ROS 2 bag directory or .mcap")
    m.add_argument("--mapping", help="mapping file (default: backends/monitors/mapping.yaml if present)")
    m.add_argument("--horizon", type=seconds, help="seconds an input event may wait for its answer (default 5.0)")
    m.add_argument("--json", action="store_true", help="print the verdicts as JSON")
    m.add_argument("--verdicts", metavar="FILE", help="write every verdict, one JSON line each (node, item, message "
                   "topic and time, verdict, reason), recorded or live (docs/monitors.md, \"Verdicts one by one\")")
    m.add_argument("--strict", action="store_true",
                   help="exit 1 also when a node, topic, service, action or deadline of the contracts was not "
                        "judged (nothing heard, not decoded, ...; docs/monitors.md, \"Silence is never green\")")
    m.add_argument("--transition-deadline", action="append", metavar="NODE:TRANSITION=DURATION",
                   help="a managed node's transition bound (Battery:activate=200ms; repeatable; recorded runs: "
                        "docs/monitors.md, \"Lifecycle nodes in a recorded run\")")
    _live_options(m.add_argument_group("live monitoring (ROS 1, ROS 2 over DDS; docs/monitors.md)"))


def _margin(text: str) -> float:
    """``--warn-margin``'s VALUE: a finite number > 0 (a space margin, in the deciding comparison's unit)."""
    import math  # deferred: start-up (imported where it is used)
    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not math.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"a margin is a finite number > 0, not {text!r}")
    return v


def _live_options(lv: argparse._ArgumentGroup) -> None:
    """``monitor --live``'s options."""
    lv.add_argument("--live", action="store_true", help="monitor the running ROS system instead (ROS 1: "
                    "ROS_MASTER_URI; ROS 2: --ros2)")
    lv.add_argument("--log", default="monitor_live.jsonl", help="JSON-lines log of events and verdicts to write")
    lv.add_argument("--evidence", help="write the monitoring evidence record (JSON) here when stopped")
    lv.add_argument("--forward", action="append", default=[], metavar="SVC=REAL",
                    help="serve SVC (a service a contract serves) and forward each call to REAL, checking its "
                         "deadline (repeatable; docs/monitors.md, \"Services, actions and deadlines\")")
    lv.add_argument("--interfaces", action="append", default=[], metavar="DIR",
                    help="directory of <pkg>/srv and <pkg>/action files (workspace-relative; repeatable)")
    lv.add_argument("--duration", type=seconds, help="stop after this many seconds (default: at SIGINT/SIGTERM)")
    lv.add_argument("--reorder-window", type=seconds, default=0.05, help="seconds to wait for stamp ordering")
    lv.add_argument("--silence", type=seconds, default=10.0,
                    help="report a contract topic not received for this many seconds (default 10; 0: off)")
    lv.add_argument("--status", type=seconds, default=1.0, help="seconds between status lines (0: off)")
    lv.add_argument("--margins", action="store_true",
                    help="compute each answer's space margin: in the verdicts, the status line (each guarantee's "
                         "smallest so far) and the record (docs/semantics.md, \"Margins\")")
    lv.add_argument("--warn-margin", type=_margin, metavar="VALUE",
                    help="warn on stderr (one line: guarantee, margin, time) when a satisfied answer sets a "
                         "guarantee's smallest margin below VALUE (implies --margins)")
    lv.add_argument("--verdict-topic", default="/rclverify/verdict", help="topic of the per-event verdicts")
    lv.add_argument("--node", dest="nodes", action="append", metavar="NODE", help="monitor only NODE (repeatable)")
    lv.add_argument("--ros", choices=("1", "2"), help="ROS version (default: $ROS_VERSION, else 1)")
    lv.add_argument("--ros2", dest="ros", action="store_const", const="2",
                    help="ROS 2 (ROS_DOMAIN_ID; over DDS: CYCLONEDDS_URI): same as --ros 2")
    lv.add_argument("--source", choices=("auto", "rclpy", "dds"), default="auto",
                    help="ROS 2: hear the robot through rclpy (any middleware; calls through introspection "
                         "events) or a DDS participant of the monitor's own (calls also by their order); auto: "
                         "rclpy where rclverify's Python imports it, else dds")
    lv.add_argument("--ros2-python", metavar="PYTHON",
                    help="ROS 2: the Python with rclpy the rclpy source runs in (default: $RCLVERIFY_ROS2_PYTHON, "
                         "else this one)")
    lv.add_argument("--enforce", action="append", default=[], metavar="TOPIC[:=PRIVATE][@open]",
                    help="ROS 2: republish TOPIC only when the guarantee holds; the node publishes on PRIVATE "
                         "(default TOPIC_unchecked); TOPIC@open also releases what cannot be decided, which is "
                         "held back by default (repeatable)")
    lv.add_argument("--record", metavar="BAG", help="ROS 2: record the contract topics to a new ROS 2 bag")
    lv.add_argument("--record-storage", choices=("sqlite3", "mcap"),
                    help="the bag's storage (default: mcap for a BAG ending .mcap, else sqlite3)")


def add_oracle(add: AddCommand) -> None:
    """The ``oracle`` parser."""
    o = add("oracle", cmd_oracle, "serve the contracts as a ROSMonitoring oracle over WebSocket", True)
    o.add_argument("--port", type=int, default=8080, help="TCP port (default 8080)")
    o.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    o.add_argument("--node", dest="nodes", action="append", metavar="NODE", help="serve only NODE (repeatable)")
    o.add_argument("--mapping", help="mapping file (default: backends/monitors/mapping.yaml if present)")
    o.add_argument("--horizon", type=seconds, help="seconds an input event may wait for its answer")
