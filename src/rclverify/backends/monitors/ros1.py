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

**Flattening.**  A message becomes the fields ROSMonitoring logs beside
``topic`` and ``time``: each slot by name, nested messages as dicts, ROS
times/durations as ``{"secs", "nsecs"}``, arrays as lists (``uint8[]`` as a
list of ints).
"""
from __future__ import annotations

import importlib
import sys
import types
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

DEBIAN_DIST_PACKAGES = "/usr/lib/python3/dist-packages"


class RosUnavailable(Exception):
    """ROS 1 (rospy) cannot be imported here; ``str`` says why and what to install."""


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
    import genmsg
    import genmsg.msg_loader
    import genpy.generator
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
    import roslib.message
    cls = roslib.message.get_message_class(key)
    if cls is None:
        raise RosUnavailable(f"message type {key} is neither installed nor defined under "
                             f"{', '.join(str(d) for d in msg_dirs) or 'the workspace'}")
    _GENERATED[key] = cls
    return cls  # type: ignore[no-any-return]


def flatten(msg: Any) -> Any:
    """A rospy message (or value) as JSON-ready data (dicts, lists, numbers, strings)."""
    slots = getattr(msg, "__slots__", None)
    if slots is not None and hasattr(msg, "_slot_types"):
        return {s: flatten(getattr(msg, s)) for s in slots}
    if hasattr(msg, "secs") and hasattr(msg, "nsecs"):  # genpy Time / Duration
        return {"secs": int(msg.secs), "nsecs": int(msg.nsecs)}
    if isinstance(msg, (bytes, bytearray)):
        return list(msg)
    if isinstance(msg, (list, tuple)):
        return [flatten(x) for x in msg]
    return msg


def build_message(cls: type, fields: Mapping[str, Any]) -> Any:
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


__all__ = ["DEBIAN_DIST_PACKAGES", "RosUnavailable", "build_message", "contract_topics", "flatten",
           "import_rospy", "message_class"]
