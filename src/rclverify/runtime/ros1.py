"""ROS 1 glue for the live monitor: reaching rospy, message classes, flattening.

**Reaching rospy.**  ROS 1 comes from Debian's packages (``ros-core``,
``python3-rospy``, ``python3-rosbag``, the message packages), which install
into Debian's system Python (``/usr/lib/python3/dist-packages``).  rclverify
may run under another interpreter of the same minor version (a virtual
environment, pyenv): :func:`import_rospy` imports ``rospy`` and, on
``ImportError``, retries once with Debian's directory appended to
``sys.path`` (appended, so rclverify's own dependencies still come first).
A different minor version cannot load Debian's compiled modules; the error
then says so.

**Message classes.**  A contract names each topic's type
(``pkg/Type``).  The class comes from the ROS installation
(``roslib.message.get_message_class``) or, when the workspace has
``<msg_dir>/<pkg>/msg/<Type>.msg`` (the case study's
``gazebo_radiation_plugin/Snapshot``, which no Debian package provides), is
generated from it at run time with ``genmsg``/``genpy``, the ROS 1
generators themselves (the same ``.msg`` file the bag reader uses).  The
workspace's definition wins, so the monitor and the nodes publishing with
:func:`message_class` agree on the md5sum.

**A master is an external peer.**  rospy calls the master without a time
limit and retries a registration for ever: against a master that hangs on
``registerPublisher`` the monitor waited for over ten minutes, deaf to
SIGTERM and SIGINT.  So the monitor asks the master itself first
(``getPid``, bounded: :func:`check_master`), gives rospy's master proxy a
socket timeout (:func:`bound_master_calls`), does every registration in a
daemon thread that the main thread waits for in short steps
(:func:`run_bounded`: a signal stops the wait at once, and the whole
registration has :data:`REGISTER_TIMEOUT_S` seconds), and unregisters and
shuts rospy down within :data:`SHUTDOWN_TIMEOUT_S` seconds each
(:func:`finish_within`).

**Flattening.**  A message becomes the fields ROSMonitoring logs beside
``topic`` and ``time``: each slot by name, nested messages as dicts, ROS
times/durations as ``{"secs", "nsecs"}``, arrays as lists (``uint8[]`` as a
list of ints).
"""
from __future__ import annotations

import importlib
import sys
import threading
import time
import types
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence
import os
import xmlrpc.client

DEBIAN_DIST_PACKAGES = "/usr/lib/python3/dist-packages"
#: Seconds the live monitor may take to register with the master (node, publishers, subscribers, services).
REGISTER_TIMEOUT_S = 60.0
#: Seconds unregistering and shutting rospy down may take when a run stops.
SHUTDOWN_TIMEOUT_S = 5.0
#: Seconds shutting rospy down may take when a signal stopped the monitor while it registered: rospy's
#: ``signal_shutdown`` joins each of its threads for up to 5 s, and one of them is the registration the
#: signal interrupted, held by the master; the user asked to stop, so the exit does not wait for it.
STOPPED_SHUTDOWN_S = 0.5


class RosUnavailable(Exception):
    """ROS 1 (rospy) cannot be imported here, or the master cannot be used;
    ``str`` says why and what to do."""


class RosStopped(RosUnavailable):
    """A signal stopped the monitor before it was registered with the master."""


def check_master(uri: str, caller: str, timeout: float) -> None:
    """Ask the master at ``uri`` for its pid within ``timeout`` seconds;
    :class:`RosUnavailable` naming it and why when it does not answer."""
    from rclverify.ros.live.master_rpc import MasterError, call  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
    try:
        call(uri, "getPid", caller, timeout=timeout)
    except MasterError as exc:
        raise RosUnavailable(f"no ROS master answers at {uri}: {exc} (start roscore, or set ROS_MASTER_URI)") from None


def bound_master_calls(rospy: Any, uri: str, timeout: float) -> bool:
    """Give rospy's proxy for the master at ``uri`` a socket timeout of
    ``timeout`` seconds (its cache of proxies, ``rospy.core.xmlrpcapi``),
    so that no call of rospy's to the master waits for ever.  Returns
    whether this rospy has the cache (an older or newer one is left as it
    is; the registration is still bounded by :func:`run_bounded`)."""
    from rclverify.ros.live.master_rpc import TimeoutTransport  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
    core = getattr(rospy, "core", None)
    cache = getattr(core, "_xmlrpc_cache", None)
    locked = getattr(core, "_LockedServerProxy", None)
    if not isinstance(cache, dict) or locked is None:
        return False
    cache[uri] = locked(uri, transport=TimeoutTransport(timeout))
    return True


def run_bounded(stop: threading.Event, limit: float, what: str, fn: Callable[[], Any]) -> Any:
    """``fn()`` in a daemon thread (:func:`~...ros.master_rpc.in_thread`):
    its value (or its exception); :class:`RosStopped` as soon as ``stop`` is
    set (a signal); :class:`RosUnavailable` once ``limit`` seconds passed."""
    from rclverify.ros.live.master_rpc import in_thread  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
    state, got = in_thread(fn, limit, "rclverify-ros1-register", stop)
    if state == "stopped":
        raise RosStopped(f"stopped by a signal while {what}; nothing was monitored")
    if state == "timeout":
        raise RosUnavailable(f"{what} did not finish within its time limit of {limit:g} s; nothing was monitored")
    if state == "error":
        raise got
    return got


def shutdown_limit(exc: RosUnavailable) -> float:
    """Seconds rospy's shutdown may take after ``exc`` ended the registration:
    :data:`STOPPED_SHUTDOWN_S` when a signal stopped it (:class:`RosStopped`),
    else :data:`SHUTDOWN_TIMEOUT_S`."""
    return STOPPED_SHUTDOWN_S if isinstance(exc, RosStopped) else SHUTDOWN_TIMEOUT_S


def finish_within(fn: Callable[[], Any], limit: float = SHUTDOWN_TIMEOUT_S) -> bool:
    """``fn()`` (unregistering, ``rospy.signal_shutdown``: calls to the
    master) in a daemon thread, waited for at most ``limit`` seconds, so a
    master that hangs cannot hold the exit.  Returns whether it finished
    (its exception, if any, is dropped: the run is ending)."""
    from rclverify.ros.live.master_rpc import in_thread  # deferred: start-up (loads rclverify.ros, rclverify.ros.live and more only when called)
    return in_thread(fn, limit, "rclverify-ros1-shutdown")[0] != "timeout"


def import_rospy() -> Any:
    """The ``rospy`` module, from this interpreter or Debian's dist-packages.

    Raises :class:`RosUnavailable` when neither has it (with the reason).
    """
    try:
        return importlib.import_module("rospy")
    except ImportError as first:
        if DEBIAN_DIST_PACKAGES not in sys.path and Path(DEBIAN_DIST_PACKAGES, "rospy").is_dir():
            sys.path.append(DEBIAN_DIST_PACKAGES)
            try:
                return importlib.import_module("rospy")
            except ImportError as exc:
                raise RosUnavailable(f"rospy from {DEBIAN_DIST_PACKAGES} does not load under Python "
                                     f"{sys.version_info.major}.{sys.version_info.minor}: {exc}") from None
        raise RosUnavailable(f"rospy is not installed ({first}); on Debian/Ubuntu: "
                             "apt-get install ros-core python3-rospy python3-rosbag") from None


_GENERATED: dict[str, type] = {}


def _generate(pkg: str, name: str, path: Path, msg_dirs: Sequence[Path]) -> type:
    import genmsg  # deferred: start-up (loads genmsg only when called)
    import genmsg.msg_loader  # deferred: start-up (loads genmsg and more only when called)
    import genpy.generator  # deferred: start-up (loads genpy and more only when called)
    ctx = genmsg.MsgContext.create_default()
    search: dict[str, list[str]] = {}
    for d in msg_dirs:
        for p in sorted(Path(d).glob("*/msg")):
            search.setdefault(p.parent.name, []).append(str(p))
    for share in Path("/usr/share").glob("*/msg"):  # Debian's message packages (std_msgs, geometry_msgs ...)
        search.setdefault(share.parent.name, []).append(str(share))
    full = f"{pkg}/{name}"
    try:
        spec = genmsg.msg_loader.load_msg_from_file(ctx, str(path), full)
        genmsg.msg_loader.load_depends(ctx, spec, search)
        code = "\n".join(genpy.generator.msg_generator(ctx, spec, search))
    except Exception as exc:  # genmsg's own parse/resolution errors
        raise RosUnavailable(f"{path}:1: error: cannot generate the ROS 1 class of {full}: {exc}") from None
    module = types.ModuleType(f"rclverify_generated_{pkg}_{name}")
    exec(compile(code, str(path), "exec"), module.__dict__)  # genpy's generated module
    return getattr(module, name)  # type: ignore[no-any-return]


def message_class(msg_type: str, msg_dirs: Sequence[Path] = ()) -> type:
    """The rospy message class of ``pkg/Type`` (or ``pkg/msg/Type``).

    Looks in the workspace's ``.msg`` files first (generated with genpy,
    cached), then the ROS installation.  Raises :class:`RosUnavailable`
    when neither knows the type.
    """
    pkg, _, name = msg_type.replace("/msg/", "/").partition("/")
    key = f"{pkg}/{name}"
    hit = _GENERATED.get(key)
    if hit is not None:
        return hit
    for d in msg_dirs:
        f = Path(d) / pkg / "msg" / f"{name}.msg"
        if f.is_file():
            import_rospy()  # genpy/genmsg live beside rospy
            _GENERATED[key] = _generate(pkg, name, f, msg_dirs)
            return _GENERATED[key]
    import_rospy()
    import roslib.message  # deferred: start-up (loads roslib and more only when called)
    cls = roslib.message.get_message_class(key)
    if cls is None:
        raise RosUnavailable(f"message type {key} is neither installed nor defined under "
                             f"{', '.join(str(d) for d in msg_dirs) or 'the workspace'}")
    _GENERATED[key] = cls
    return cls  # type: ignore[no-any-return]


def flatten(msg: Any) -> Any:
    """A rospy message (or value) as JSON-ready data (dicts, lists, numbers, strings)."""
    if hasattr(msg, "secs") and hasattr(msg, "nsecs") and hasattr(msg, "to_nsec"):  # genpy or rospy Time / Duration
        return {"secs": int(msg.secs), "nsecs": int(msg.nsecs)}  # (rospy's subclasses' own __slots__ are empty)
    slots = getattr(msg, "__slots__", None)
    if slots is not None and hasattr(msg, "_slot_types"):
        return {s: flatten(getattr(msg, s)) for s in slots}
    if isinstance(msg, (bytes, bytearray)):
        return list(msg)
    if isinstance(msg, (list, tuple)):
        return [flatten(x) for x in msg]
    return msg


def build_message(cls: type, fields: Mapping[str, object]) -> Any:
    """An instance of ``cls`` with the given fields (those it has; others ignored)."""
    slots = set(getattr(cls, "__slots__", ()))
    return cls(**{k: v for k, v in fields.items() if k in slots})


def contract_topics(checked: Any, nodes: Iterable[Any]) -> dict[str, str]:
    """``/topic`` -> ``pkg/Type`` for every topic the nodes' contracts name (first type wins)."""
    out: dict[str, str] = {}
    for node in nodes:
        for t in node.node.topics:
            out.setdefault("/" + t.field.lstrip("/"), t.msg_type)
    return out


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now (for a master started right after)."""
    import socket  # deferred: start-up (loads socket only when called)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class LocalMaster:
    """A ROS 1 master (``rosmaster --core``) on 127.0.0.1 and a free port, for
    tests and benchmarks: ``with LocalMaster(tmp) as env: ...`` gives the
    environment (``ROS_MASTER_URI``, ``ROS_IP``, ``ROS_HOSTNAME`` on loopback,
    ``ROS_HOME``/``ROS_LOG_DIR`` under ``home``) for the processes to start;
    the master is stopped (its process group) on exit.  Raises
    :class:`RosUnavailable` when ``rosmaster`` is missing or does not answer
    within ``timeout`` seconds."""

    def __init__(self, home: Path, timeout: float = 15.0) -> None:
        self.home, self.timeout = Path(home), timeout
        self.proc: Any = None

    def __enter__(self) -> dict[str, str]:
        import shutil  # deferred: start-up (loads shutil only when called)
        import subprocess  # deferred: start-up (loads subprocess only when called)
        exe = shutil.which("rosmaster")
        if exe is None:
            raise RosUnavailable("rosmaster is not installed (Debian: apt-get install ros-core)")
        port = free_port()
        self.home.mkdir(parents=True, exist_ok=True)
        env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_IP="127.0.0.1",
                   ROS_HOSTNAME="127.0.0.1", ROS_HOME=str(self.home), ROS_LOG_DIR=str(self.home / "log"))
        self.env = env
        self.proc = subprocess.Popen([exe, "--core", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL, start_new_session=True)
        deadline = time.monotonic() + self.timeout
        while True:
            try:
                xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"]).getPid("/probe")
                return env
            except OSError:
                if time.monotonic() > deadline or self.proc.poll() is not None:
                    self.__exit__(None, None, None)
                    raise RosUnavailable(f"rosmaster did not answer on port {port} within {self.timeout} s") from None
                time.sleep(0.1)

    def __exit__(self, *exc: Any) -> None:
        import signal  # deferred: start-up (loads signal only when called)
        if self.proc is not None and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(5)
            except Exception:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(5)


__all__ = ["DEBIAN_DIST_PACKAGES", "LocalMaster", "REGISTER_TIMEOUT_S", "RosStopped", "RosUnavailable",
           "STOPPED_SHUTDOWN_S", "shutdown_limit",
           "SHUTDOWN_TIMEOUT_S", "bound_master_calls", "build_message", "check_master", "contract_topics", "flatten",
           "free_port", "import_rospy", "message_class", "run_bounded", "finish_within"]
