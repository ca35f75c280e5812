"""ROS 1 service and action classes generated from a workspace's ``.srv`` and
``.action`` files, for the service proxy and example nodes.

Debian ships few interface packages (no ``std_srvs``, no ``actionlib``), so
as :func:`~.ros1.message_class` does for ``.msg`` files, the classes are
generated at run time by ROS 1's own generators (``genmsg``/``genpy``) from
``<dir>/<pkg>/srv/<Name>.srv`` and ``<dir>/<pkg>/action/<Name>.action``.

An action ``Name.action`` (goal ``---`` result ``---`` feedback) expands to
actionlib's seven messages, as actionlib's ``genaction`` does: ``NameGoal``,
``NameResult``, ``NameFeedback``; ``NameActionGoal`` (``Header header``,
``actionlib_msgs/GoalID goal_id``, ``NameGoal goal``); ``NameActionResult``
and ``NameActionFeedback`` (``Header header``, ``actionlib_msgs/GoalStatus
status``, then ``result``/``feedback``); and ``NameAction``.  Their topics
are ``<action>/goal``, ``<action>/feedback`` and ``<action>/result``.
"""
from __future__ import annotations

import types
from pathlib import Path
from typing import Any, Sequence

from rclverify.runtime.ros1 import RosUnavailable, import_rospy
import sys
from rclverify.runtime.ros1 import message_class

_CACHE: dict[str, dict[str, type]] = {}


def _search(dirs: Sequence[Path], extra: dict[str, list[str]] | None = None) -> dict[str, list[str]]:
    search: dict[str, list[str]] = {}
    for d in dirs:
        for p in sorted(Path(d).glob("*/msg")):
            search.setdefault(p.parent.name, []).append(str(p))
    for share in Path("/usr/share").glob("*/msg"):
        search.setdefault(share.parent.name, []).append(str(share))
    for k, v in (extra or {}).items():
        search.setdefault(k, []).extend(v)
    return search


def _run(code: str, name: str, where: str) -> types.ModuleType:
    module = types.ModuleType(f"rclverify_generated_{name.replace('/', '_')}")
    exec(compile(code, where, "exec"), module.__dict__)  # genpy's generated module
    return module


def service_class(srv_type: str, dirs: Sequence[Path]) -> Any:
    """The rospy service class of ``pkg/Name`` from ``<dir>/pkg/srv/Name.srv``
    (first directory that has it).  Raises :class:`RosUnavailable`."""
    if srv_type in _CACHE:
        return _CACHE[srv_type]
    pkg, _, name = srv_type.partition("/")
    path = next((Path(d) / pkg / "srv" / f"{name}.srv" for d in dirs
                 if (Path(d) / pkg / "srv" / f"{name}.srv").is_file()), None)
    if path is None:
        raise RosUnavailable(f"service type {srv_type}: no {pkg}/srv/{name}.srv under "
                             f"{', '.join(map(str, dirs)) or 'the workspace'}")
    import_rospy()
    import genmsg  # deferred: start-up (loads genmsg only when called)
    import genmsg.msg_loader  # deferred: start-up (loads genmsg and more only when called)
    import genpy.generator  # deferred: start-up (loads genpy and more only when called)
    ctx = genmsg.MsgContext.create_default()
    search = _search(dirs)
    try:
        spec = genmsg.msg_loader.load_srv_from_file(ctx, str(path), srv_type)
        genmsg.msg_loader.load_depends(ctx, spec, search)
        code = "\n".join(genpy.generator.srv_generator(ctx, spec, search))
    except Exception as exc:  # genmsg's parse and resolution errors
        raise RosUnavailable(f"{path}:1: error: cannot generate the ROS 1 service {srv_type}: {exc}") from None
    cls = getattr(_run(code, srv_type, str(path)), name)
    _CACHE[srv_type] = cls
    return cls


def action_texts(pkg: str, name: str, text: str) -> dict[str, str]:
    """The seven ``.msg`` texts of action ``pkg/name`` from its ``.action``
    text (module docstring).  Raises ``ValueError`` without two ``---``."""
    parts = [p.strip("\n") for p in text.split("\n---")]
    if len(parts) != 3:
        raise ValueError(f"{pkg}/{name}.action needs goal, result and feedback separated by two '---' lines")
    goal, result, feedback = (p.lstrip("-").strip("\n") for p in parts)
    return {
        f"{name}Goal": goal, f"{name}Result": result, f"{name}Feedback": feedback,
        f"{name}ActionGoal": f"Header header\nactionlib_msgs/GoalID goal_id\n{name}Goal goal",
        f"{name}ActionResult": f"Header header\nactionlib_msgs/GoalStatus status\n{name}Result result",
        f"{name}ActionFeedback": f"Header header\nactionlib_msgs/GoalStatus status\n{name}Feedback feedback",
        f"{name}Action": (f"{name}ActionGoal action_goal\n{name}ActionResult action_result\n"
                          f"{name}ActionFeedback action_feedback"),
    }


def action_classes(action_type: str, dirs: Sequence[Path], out_dir: Path) -> dict[str, type]:
    """``{"goal", "feedback", "result"}`` -> the rospy classes of the
    ``<action>/goal``, ``/feedback`` and ``/result`` topics of ``pkg/Name``,
    from ``<dir>/pkg/action/Name.action``; the expanded ``.msg`` files are
    written under ``out_dir``.  Raises :class:`RosUnavailable`."""
    if action_type in _CACHE:
        return _CACHE[action_type]
    pkg, _, name = action_type.partition("/")
    path = next((Path(d) / pkg / "action" / f"{name}.action" for d in dirs
                 if (Path(d) / pkg / "action" / f"{name}.action").is_file()), None)
    if path is None:
        raise RosUnavailable(f"action type {action_type}: no {pkg}/action/{name}.action under "
                             f"{', '.join(map(str, dirs)) or 'the workspace'}")
    try:
        texts = action_texts(pkg, name, path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise RosUnavailable(f"{path}:1: error: {exc}") from None
    msg_dir = Path(out_dir) / pkg / "msg"
    msg_dir.mkdir(parents=True, exist_ok=True)
    for n, t in texts.items():
        (msg_dir / f"{n}.msg").write_text(t + "\n", encoding="utf-8")
    search = [Path(out_dir), *map(Path, dirs)]
    # genpy's code of MoveActionGoal imports `pkg.msg` for MoveGoal: give it that module, made of the
    # classes generated first (the package is not installed; Debian's packages come first on sys.path)
    module = sys.modules.get(f"{pkg}.msg")
    if module is None:
        top = sys.modules.setdefault(pkg, types.ModuleType(pkg))
        module = types.ModuleType(f"{pkg}.msg")
        setattr(top, "msg", module)
        sys.modules[f"{pkg}.msg"] = module
    for part in ("Goal", "Result", "Feedback"):
        setattr(module, f"{name}{part}", message_class(f"{pkg}/{name}{part}", search))
    classes = {part: message_class(f"{pkg}/{name}Action{part.capitalize()}", search)
               for part in ("goal", "feedback", "result")}
    for part, cls in classes.items():
        setattr(module, f"{name}Action{part.capitalize()}", cls)
    _CACHE[action_type] = classes
    return classes
