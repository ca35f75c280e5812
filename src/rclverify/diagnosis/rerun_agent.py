"""Re-run one node's rclpy callback on the questions of a recorded run, once
per text of its source file (docs/diagnosis.md, "Monitor violations: a
node re-run on its recorded run").

Run as a script in a ROS 2 Python (``python rerun_agent.py``, the request as
one JSON object on stdin, the answer as one JSON object on stdout); it
imports rclpy and the standard library only, never rclverify, so any ROS 2
Python runs it.  The request:

* ``file``: the node's source file (its path names the code objects, so a
  callback's line is a line of that file), ``texts``: the texts to run it
  as (the recorded one and each candidate repair), ``factory`` and
  ``args``: the function of the file that makes the robot's nodes
  (``build``) and its arguments (a JSON list);
* ``kind``: ``topic`` (``inputs``, ``outputs``: the contract's topic
  names), ``service`` or ``action`` (``name``: the link's name, ``type``:
  its ``pkg/Type``);
* ``questions``: the recorded questions in their order, each the fields of
  a message (a topic's message as the log flattens it, a request's, a
  goal's).

For each text the file is compiled under its own path and executed as a
fresh module, ``factory(*args)`` makes the nodes (rclpy is initialised with
discovery off: no node hears or is heard), the node serving the link (or
subscribing to an input topic and publishing an output topic) is found
through rclpy's own lists, its callback is called once per question, in
order, on a message built from the recorded fields, and what it publishes
on the outputs (a topic), returns (a service's response) or reports (an
action's feedback, result and final status, through a goal handle standing
for the action's client) is the answer.  The answer of a text: ``error``
(``""``, or why the text did not load, make its nodes, or answer in time:
its exception's type and message), ``answers``, one per question, and the
``seconds`` its answers took.  The
answer also says ``callback``: the callback's ``line`` in the file, its
``name`` and the ``freevars`` it reads from its enclosing function.
Every node made is destroyed before the next text runs.
"""
from __future__ import annotations

import gc
import importlib
import json
import os
import signal
import sys
import time
import types
import uuid
from typing import Any

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "OFF"  # no node of a re-run hears or is heard


def to_fields(msg: Any) -> Any:
    """A ROS message (or value) as the log flattens it: a dict of its fields, lists for arrays."""
    if hasattr(msg, "get_fields_and_field_types"):
        return {k: to_fields(getattr(msg, k)) for k in msg.get_fields_and_field_types()}
    if isinstance(msg, (list, tuple)) or type(msg).__name__ in ("array", "ndarray"):
        return [to_fields(v) for v in msg]
    if isinstance(msg, bytes):
        return list(msg)
    return msg


def _element(typ: str) -> Any:
    """The message class of a nested field's type string (``sequence<std_msgs/Header>``), ``None`` for a
    primitive."""
    inner = typ.split("<", 1)[1].split(",")[0].rstrip(">") if "<" in typ else typ
    inner = inner.split("[")[0]
    if "/" not in inner:
        return None
    pkg, name = inner.split("/", 1)
    return getattr(importlib.import_module(f"{pkg}.msg"), name)


def fill(msg: Any, fields: dict[str, Any]) -> Any:
    """``msg`` with each of ``fields`` (as the log flattens a message) set; unknown keys are skipped."""
    types_ = msg.get_fields_and_field_types()
    for key, value in fields.items():
        if key not in types_:
            continue
        now = getattr(msg, key)
        if isinstance(value, dict) and hasattr(now, "get_fields_and_field_types"):
            fill(now, value)
            continue
        if isinstance(value, list):
            cls = _element(types_[key])
            value = [fill(cls(), v) if cls is not None and isinstance(v, dict) else v for v in value]
            if value and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value) \
                    and ("float" in types_[key] or "double" in types_[key]):
                value = [float(v) for v in value]
        elif isinstance(now, float) and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        setattr(msg, key, value)
    return msg


class Goal:
    """The goal handle an action's execute callback is given: the recorded goal as ``request``, the feedback
    it publishes kept in order, and the terminal status it sets (``succeeded``, ``aborted``, ``canceled``;
    ``""`` until then).  It stands for the action's client and rclpy's goal exchange, not for the server."""

    def __init__(self, request: Any) -> None:
        self.request = request
        self.goal_id = uuid.uuid4()
        self.feedback: list[Any] = []
        self.status = ""

    @property
    def is_active(self) -> bool:
        return self.status == ""

    @property
    def is_cancel_requested(self) -> bool:
        return False

    def publish_feedback(self, feedback: Any) -> None:
        self.feedback.append(to_fields(feedback))

    def succeed(self) -> None:
        self.status = "succeeded"

    def abort(self) -> None:
        self.status = "aborted"

    def canceled(self) -> None:
        self.status = "canceled"


def _norm(name: str) -> str:
    return name.lstrip("/")


def _nodes(before: set[int]) -> list[Any]:
    from rclpy.node import Node  # deferred: rclpy exists only in the ROS 2 Python that runs this script
    return [o for o in gc.get_objects() if isinstance(o, Node) and id(o) not in before]


def _find(req: dict[str, Any], nodes: list[Any]) -> tuple[Any, Any]:
    """``(node, endpoint)``: the subscription, service or action server that answers the questions."""
    from rclpy.action import ActionServer  # deferred: rclpy exists only in the ROS 2 Python that runs this script
    kind = req["kind"]
    found = []
    for n in nodes:
        if kind == "topic":
            outs = {_norm(p.topic_name) for p in n.publishers}
            found += [(n, s) for s in n.subscriptions if _norm(s.topic_name) in req["inputs"]
                      and outs & set(req["outputs"])]
        elif kind == "service":
            found += [(n, s) for s in n.services if _norm(s.srv_name) == _norm(req["name"])]
        else:
            pkg, name = req["type"].split("/")
            found += [(n, w) for w in n.waitables if isinstance(w, ActionServer)
                      and w._action_type.__name__ == name and w._action_type.__module__.startswith(pkg + ".")]
    if len(found) != 1:
        raise LookupError(f"{len(found)} endpoints of the robot answer this {kind} (one was expected)")
    return found[0]


def _callback(endpoint: Any) -> Any:
    from rclpy.action import ActionServer  # deferred: rclpy exists only in the ROS 2 Python that runs this script
    return endpoint._execute_callback if isinstance(endpoint, ActionServer) else endpoint.callback


def _answer(req: dict[str, Any], node: Any, endpoint: Any, fields: dict[str, Any],
            published: list[tuple[str, Any]]) -> Any:
    """What the callback answers to one question (module docstring)."""
    from rclpy.action import ActionServer  # deferred: rclpy exists only in the ROS 2 Python that runs this script
    if req["kind"] == "topic":
        del published[:]
        endpoint.callback(fill(endpoint.msg_type(), fields))
        return [{"topic": t, "fields": to_fields(m)} for t, m in published if t in req["outputs"]]
    if req["kind"] == "service":
        resp = endpoint.callback(fill(endpoint.srv_type.Request(), fields), endpoint.srv_type.Response())
        return to_fields(resp)
    assert isinstance(endpoint, ActionServer)
    goal = Goal(fill(endpoint._action_type.Goal(), fields))
    result = endpoint._execute_callback(goal)
    return {"feedback": goal.feedback, "result": to_fields(result), "status": goal.status or "aborted"}


def run_text(req: dict[str, Any], k: int, text: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(answer of this text, callback)``; ``callback`` is ``{}`` when it was not found."""
    from rclpy.node import Node  # deferred: rclpy exists only in the ROS 2 Python that runs this script
    before = {id(o) for o in gc.get_objects() if isinstance(o, Node)}
    made: list[Any] = []
    callback: dict[str, Any] = {}
    t0 = time.monotonic()
    try:
        module = types.ModuleType(f"rclverify_rerun_{k}")
        module.__file__ = req["file"]
        exec(compile(text, req["file"], "exec"), module.__dict__)  # noqa: S102 - the robot's own code, as it runs
        robot = getattr(module, req["factory"])(*req["args"])  # held: a node only the result holds lives on
        made = _nodes(before)
        node, endpoint = _find(req, made)
        published: list[tuple[str, Any]] = []
        for n in made:
            for p in n.publishers:
                p.publish = (lambda topic: lambda m: published.append((topic, m)))(_norm(p.topic_name))
        code = getattr(_callback(endpoint), "__code__", None)
        if code is not None:
            callback = {"line": code.co_firstlineno, "name": code.co_name, "freevars": list(code.co_freevars),
                        "file": code.co_filename}
        t0 = time.monotonic()
        signal.setitimer(signal.ITIMER_REAL, float(req.get("timeout_s") or 60.0))
        answers = [_answer(req, node, endpoint, q, published) for q in req["questions"]]
        del robot
        return {"error": "", "answers": answers, "seconds": time.monotonic() - t0}, callback
    except Exception as e:  # noqa: BLE001 - a text that does not load or answer: said, never a repair
        return {"error": f"{type(e).__name__}: {e}", "answers": [], "seconds": time.monotonic() - t0}, callback
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for n in made or _nodes(before):
            try:
                n.destroy_node()
            except Exception:  # noqa: BLE001 - a node already gone
                pass


def _late(_sig: int, _frame: Any) -> None:
    raise TimeoutError("the text took longer than its time bound")


def main() -> int:
    import rclpy  # deferred: rclpy exists only in the ROS 2 Python that runs this script
    signal.signal(signal.SIGALRM, _late)
    req = json.loads(sys.stdin.read())
    sys.path.insert(0, os.path.dirname(os.path.abspath(req["file"])))
    rclpy.init(args=["--ros-args", "--disable-rosout-logs"])
    runs: list[dict[str, Any]] = []
    callback: dict[str, Any] = {}
    try:
        for k, text in enumerate(req["texts"]):
            got, cb = run_text(req, k, text)
            runs.append(got)
            callback = callback or cb
    finally:
        rclpy.try_shutdown()
    sys.stdout.write(json.dumps({"runs": runs, "callback": callback or None}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
