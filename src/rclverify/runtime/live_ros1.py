"""A live monitoring run on a ROS 1 master: :func:`run_ros1`, what
``rclverify monitor --live`` runs on ROS 1 around a :class:`~.live.LiveRun`.

It registers the monitor's node and its verdict publishers with the master,
subscribes to every topic the contracts name (``rospy.AnyMsg``, decoded on
the engine thread with the class of each connection's type) and to
``/clock``, the run's simulated clock (``rosgraph_msgs/Clock``,
:mod:`rclverify.traces.sim_clock`), whatever the contracts name (each message
pushed at its receipt time as a contract topic's is: the deadline checks of a
node under ``use_sim_time`` read it), starts the service proxy when asked, watches the run until it is stopped and writes the
evidence record (:func:`~.live.stop_and_record`).  Every call to the master
is bounded (:mod:`.ros1`, "A master is an external peer").

**The run's clock** (each message's receipt, the engine's timer, the log's
``time``) is the wall clock, also when ``/use_sim_time`` is true and rospy's
own clock is ``/clock``: the ``/clock`` samples the log holds relate the two
clocks, so the deadline checks judge a node the mapping says keeps
``/clock`` in simulated time and one said to keep the wall clock on the wall
clock, live as on the log offline (docs/semantics.md, "Deadlines in simulated
time").  With the run's clock ``/clock`` a node said to keep the wall clock
would be judged on ``/clock`` silently.  The service proxy keeps its own
ROS clock for its stamps (:mod:`.service_proxy`, "Simulated time").

docs/monitors.md ("Live monitoring") gives the decisions.
"""
from __future__ import annotations

import json
import threading
import time as _time
import warnings
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

from rclverify.records.store import atomic_write_text
from rclverify.lang.types import Checked, CheckedNode
from rclverify.runtime.live import LiveRun, stop_and_record
from rclverify.runtime.live_status import warm_bounds
from rclverify.runtime.worker import EngineWorker
from rclverify.traces.sim_clock import CLOCK_TOPIC
from rclverify.traces.mapping import TopicRule, sim_time_of
from rclverify.backends.monitors.deadline_topics import has_deadlines
from rclverify.runtime.ros1 import REGISTER_TIMEOUT_S, SHUTDOWN_TIMEOUT_S, STOPPED_SHUTDOWN_S, bound_master_calls, shutdown_limit, contract_topics, finish_within, import_rospy, message_class, RosUnavailable, check_master, run_bounded, flatten


def _no_delay(pub: Any) -> None:
    """Turn Nagle's algorithm off on the verdict publisher's subscriber
    connections (TCP_NODELAY), whether or not the subscriber asked for it:
    with it on, a verdict written while the previous one is not yet
    acknowledged waits for the subscriber's delayed ACK, up to 40 ms on
    Linux (docs/monitors.md, "Live monitoring", "Threads").  Reaches rospy's publisher
    connections (``impl.connections``, each with its ``socket``); a rospy
    without them is left as it is."""
    import socket  # deferred: start-up (loads socket only when called)
    for c in list(getattr(getattr(pub, "impl", None), "connections", None) or ()):
        sock = getattr(c, "socket", None)
        if sock is not None:  # idempotent, one system call per connection every 0.1 s
            try:
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            except (OSError, AttributeError):
                pass


def run_ros1(run_factory: Callable[..., LiveRun], checked: Checked, nodes: list[CheckedNode],
             msg_dirs: list[Path], *, verdict_topic: str, last_prefix: str, node_name: str,
             duration: float | None, tick_s: float, status_s: float, evidence: Path | None,
             stop: threading.Event, out: Callable[[str], None],
             proxy: Callable[[Any, LiveRun], Any] | None = None) -> dict[str, Any]:
    """Run live monitoring on a ROS 1 master (``ROS_MASTER_URI``) until ``stop``
    is set or ``duration`` seconds passed; returns the evidence record.

    Subscribes with ``rospy.AnyMsg`` to every topic the contracts name and
    decodes each message with the class of its connection's type
    (:func:`~.ros1.message_class`); publishes every verdict as
    ``std_msgs/String`` JSON on ``verdict_topic`` and each node's latest on
    ``<last_prefix>/<node>/last_verdict`` (latched).  Raises
    :class:`~.ros1.RosUnavailable` when rospy or a message class is missing.

    ``proxy(rospy, live)``, when given, starts the service proxy
    and action subscriptions in this process (:mod:`.service_proxy`,
    ``--forward``/``--interfaces``) and returns its run (``close()``): its
    events go to the same log and engine, whose checks judge their
    deadlines (module docstring, "One judge of the calls").  The record's
    ``warnings`` holds the warning lines of :func:`clock_warnings`, when any.
    """
    from rclverify.ros.live.master_rpc import MASTER_TIMEOUT_S  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
    rospy = import_rospy()
    from std_msgs.msg import String  # deferred: start-up (loads std_msgs and more only when called)
    topics = contract_topics(checked, nodes)
    classes = {t: message_class(typ, msg_dirs) for t, typ in topics.items()}  # fail early, located
    heard = _clock(topics, msg_dirs, out)  # /clock beside the contract topics (module docstring)
    import rosgraph  # deferred: start-up (loads rosgraph only when called)
    uri = rosgraph.get_master_uri()
    # every call to the master is bounded and the registration waits in short
    # steps, so a master that hangs neither holds the monitor nor makes it deaf
    # to SIGTERM/SIGINT (ros1.py, "A master is an external peer")
    bound_master_calls(rospy, uri, MASTER_TIMEOUT_S)
    until = _time.monotonic() + REGISTER_TIMEOUT_S
    pub, lasts, ros_sim = _register(rospy, String, stop, uri, node_name, verdict_topic, last_prefix, nodes)
    live = run_factory(publish=lambda text: pub.publish(String(text)),
                       publish_last=lambda n, text: lasts[n].publish(String(text)))
    said = clock_warnings(getattr(live.engine, "rules", {}), nodes, ros_sim)
    for line in said:
        out(line)
    decode_errors: dict[str, int] = {}
    # the callbacks only stamp and queue; one worker thread decodes, checks,
    # publishes and runs the timer (worker.py: why)
    worker = EngineWorker(live, _decoder({**classes, **heard}, decode_errors), _time.time, tick_s=tick_s).start()
    subs: list[Any] = []

    def unsubscribe() -> None:
        for s in list(subs):
            s.unregister()
    calls = _subscribe(rospy, stop, until, uri, [*topics, *heard], live, worker, subs, unsubscribe, proxy)
    out(f"monitoring {len(topics)} topic(s) for {len(nodes)} node(s); verdicts on {verdict_topic}")
    warm_bounds()  # the status line a stop prints need not wait for scipy (live_status.py)
    try:
        _watch(rospy, stop, duration, tick_s, status_s, worker, pub, live, out)
    finally:
        # unregistering asks the master: bounded, so a master that hangs now cannot hold the exit
        if not finish_within(unsubscribe, SHUTDOWN_TIMEOUT_S):
            out(f"rclverify monitor --live: warning: the master at {uri} did not confirm the unsubscriptions "
                f"within {SHUTDOWN_TIMEOUT_S:g} s")
        if calls is not None:
            calls.close()  # before the log closes
        record = stop_and_record(worker, live, evidence, out)
        if said:
            record["warnings"] = said
        record["decode_errors"] = decode_errors
        record["not_judged"] = live.not_judged(record)  # silence is never green (judged.py)
        if evidence is not None:
            atomic_write_text(evidence, json.dumps(record, indent=2, sort_keys=True) + "\n")
        out(live.status_line(wait=False))
        # everything is written: leaving the graph (rospy's shutdown hooks unregister the node; then it joins its
        # threads and sleeps 0.1 s, 0.6 s in all beside a CPU burner) is waited for at most STOPPED_SHUTDOWN_S,
        # so a stop ends within a second; what it has not done then ends with the process
        finish_within(lambda: rospy.signal_shutdown("monitor stopped"), STOPPED_SHUTDOWN_S)
    return record


def _register(rospy: Any, string: Any, stop: threading.Event, uri: str, node_name: str, verdict_topic: str,
              last_prefix: str, nodes: list[CheckedNode]) -> tuple[Any, dict[str, Any], bool | None]:
    """The monitor's node registered with the master at ``uri``, its
    publishers and the system's ``/use_sim_time`` (:func:`_use_sim_time`):
    ``(verdict, {node: last verdict, latched}, use_sim_time)``; within
    ``REGISTER_TIMEOUT_S`` and ``stop``, else rospy is shut down and
    :class:`~.ros1.RosUnavailable` raised."""
    from rclverify.ros.live.master_rpc import MASTER_TIMEOUT_S  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)

    def register_node() -> tuple[Any, dict[str, Any], bool | None]:
        check_master(uri, "/" + node_name, MASTER_TIMEOUT_S)
        rospy.init_node(node_name, anonymous=False, disable_signals=True)
        # synchronous: the engine thread writes each verdict to the subscribers'
        # sockets itself; rospy's queued publisher hands every message to a writer
        # thread and then yields the GIL (time.sleep(0)), which cost the engine
        # thread a GIL hand-over per verdict (docs/monitors.md, "Live monitoring", "Threads")
        with warnings.catch_warnings():  # rospy warns about queue_size=None; here it is the choice made above
            warnings.simplefilter("ignore", SyntaxWarning)
            pub = rospy.Publisher(verdict_topic, string, queue_size=None)
        return pub, {n.name: rospy.Publisher(f"{last_prefix}/{n.name}/last_verdict", string, queue_size=1,
                                             latch=True) for n in nodes}, _use_sim_time(rospy)

    try:
        return run_bounded(stop, REGISTER_TIMEOUT_S, f"registering with the master at {uri}",  # type: ignore[no-any-return]
                           register_node)
    except RosUnavailable as exc:
        finish_within(lambda: rospy.signal_shutdown("monitor not started"), shutdown_limit(exc))
        raise


def _use_sim_time(rospy: Any) -> bool | None:
    """The ROS 1 system's ``/use_sim_time`` parameter (false when unset: rospy's own default, the wall clock),
    ``None`` when the master cannot say; ``rospy.init_node`` must have run."""
    try:
        return bool(rospy.get_param("/use_sim_time", False))
    except Exception:  # noqa: BLE001 - a master that cannot say: no warning is made up
        return None


def clock_warnings(rules: Mapping[str, TopicRule], nodes: Iterable[CheckedNode], ros_sim: bool | None) -> list[str]:
    """One warning line per node of ``nodes`` with a triggered guarantee that the mapping's ``use_sim_time``
    (:func:`~rclverify.traces.mapping.sim_time_of`) says keeps the other clock than ROS 1's global
    ``/use_sim_time`` (``ros_sim``; ``None``: not known, no line) gives its nodes: said on the wall clock with
    it true, or on ``/clock`` with it false.  A node not said gets none."""
    lines: list[str] = []
    if ros_sim is None:
        return lines
    for n in nodes:
        said = sim_time_of(rules, n.name)
        if said is None or said == ros_sim or not has_deadlines(n):
            continue
        mine = "simulated time (/clock)" if said else "the wall clock"
        lines.append(f"rclverify monitor --live: warning: node {n.name} keeps {mine} by the mapping's use_sim_time "
                     f"but /use_sim_time is {'true' if ros_sim else 'false'}: its deadlines are judged in {mine}, "
                     f"as the log's replay judges them")
    return lines


#: the ROS 1 type of the run's simulated clock, ``/clock`` (its one field ``clock`` a ROS 1 ``time``)
CLOCK_TYPE = "rosgraph_msgs/Clock"


def _clock(topics: Mapping[str, str], msg_dirs: list[Path], out: Callable[[str], None]) -> dict[str, type]:
    """``{"/clock": its message class}`` when no contract names ``/clock`` (a contract that does makes it a
    contract topic), else ``{}``; ``{}`` too, said in one line to ``out``, where no ``rosgraph_msgs/Clock`` is
    installed or defined (the run then hears no simulated clock)."""
    topic = "/" + CLOCK_TOPIC
    if topic in topics:
        return {}
    try:
        return {topic: message_class(CLOCK_TYPE, msg_dirs)}
    except RosUnavailable as exc:
        out(f"rclverify monitor --live: warning: /clock is not heard: {exc}; a node under use_sim_time keeps its "
            "deadlines in a simulated time this run cannot read")
        return {}


def _decoder(classes: Mapping[str, type], decode_errors: dict[str, int]) -> Callable[[str, Any], Mapping[str, object] | None]:
    """The engine thread's decoding of a ``rospy.AnyMsg``: with the class of
    its connection's type, else the contract's; undecodable bytes are counted
    per topic in ``decode_errors``.  A message rospy decoded itself is
    flattened as it is: rospy keeps one subscription per topic in a process,
    made with the class of its first subscriber, and under ``/use_sim_time``
    that is rospy's own ``/clock`` subscriber (``rosgraph_msgs/Clock``), so
    the monitor's ``/clock`` callback receives ``Clock`` messages, never raw
    bytes."""
    by_type: dict[str, type] = {getattr(c, "_type"): c for c in classes.values()}

    def decode(topic: str, raw: Any) -> Mapping[str, object] | None:
        if not hasattr(raw, "_buff") and hasattr(raw, "_type"):  # decoded by rospy (a shared subscription)
            return flatten(raw)  # type: ignore[no-any-return]
        typ = raw._connection_header.get("type", "") if getattr(raw, "_connection_header", None) else ""
        cls: Any = by_type.get(typ, classes[topic])
        try:
            msg = cls().deserialize(raw._buff)
        except Exception:  # a publisher of another type on a contract topic: counted, never a crash
            decode_errors[topic] = decode_errors.get(topic, 0) + 1
            return None
        return flatten(msg)  # type: ignore[no-any-return]
    return decode


def _subscribe(rospy: Any, stop: threading.Event, until: float, uri: str, topics: Iterable[str], live: LiveRun,
               worker: EngineWorker, subs: list[Any], unsubscribe: Callable[[], None],
               proxy: Callable[[Any, LiveRun], Any] | None) -> Any:
    """Subscribe to every topic of ``topics`` (the contract topics and ``/clock``; into ``subs``) and start the
    ``proxy``; returns the proxy's run or ``None``.  By the registration's
    deadline ``until`` (monotonic s), else everything started is stopped and
    :class:`~.ros1.RosUnavailable` raised."""

    def register_topics() -> Any:
        calls = proxy(rospy, live) if proxy is not None else None
        for t in topics:
            subs.append(rospy.Subscriber(t, rospy.AnyMsg, lambda raw, t=t: worker.offer(t, raw, _time.time()),
                                         queue_size=10000, tcp_nodelay=True))
        return calls

    try:
        return run_bounded(stop, max(until - _time.monotonic(), 0.1), f"subscribing at the master at {uri}",
                           register_topics)
    except RosUnavailable as exc:
        finish_within(unsubscribe, shutdown_limit(exc))
        stop_and_record(worker, live, None, lambda _line: None)
        finish_within(lambda: rospy.signal_shutdown("monitor not started"), shutdown_limit(exc))
        raise


def _watch(rospy: Any, stop: threading.Event, duration: float | None, tick_s: float, status_s: float,
           worker: EngineWorker, pub: Any, live: LiveRun, out: Callable[[str], None]) -> None:
    """Until ``stop``, rospy's shutdown, ``duration`` s or the engine
    thread's death: the verdict publisher's sockets (:func:`_no_delay`)
    and a status line every ``status_s`` s."""
    t0 = _time.monotonic()
    next_status = t0 + status_s
    while not stop.is_set() and not rospy.is_shutdown():
        if duration is not None and _time.monotonic() - t0 >= duration:
            break
        stop.wait(min(0.1, tick_s * 5))
        if worker.error is not None:
            break  # the engine thread died: stop and say so, never monitor on silently
        _no_delay(pub)
        if status_s > 0 and _time.monotonic() >= next_status:
            out(live.status_line(wait=False))
            next_status += status_s


__all__ = ["clock_warnings", "run_ros1"]
