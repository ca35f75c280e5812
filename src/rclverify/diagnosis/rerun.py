"""A node of a recorded run re-run on that run's questions, and the run
written again with its answers (docs/diagnosis.md, "Monitor violations: a
node re-run on its recorded run").

The run is a live monitor's JSON-lines log (``rclverify monitor --live
--log``): each topic message a line, each call's request and response and
each goal's goal, feedback, status and result an ``rclverify/call`` line
(traces/jsonl.py), read as :class:`RunLine` (a call's line decoded into
:class:`CallLine`).  For the contract node ``node`` it reads the
*questions* (:func:`questions`): the messages of its input topics, the
requests of the service it serves, or the goals of the action it serves.
:func:`rerun` runs the node's callback on them, once per text of its
source file, in a ROS 2 Python (:mod:`.rerun_agent`); :func:`rewritten`
writes the run with the node's recorded answers replaced by a re-run's:
the i-th message it publishes replaces its i-th recorded output, keeping
that line's time and header stamp (the re-run has no time of its own), a
call's response and a goal's feedback, result and final status replace
the recorded ones of the same call or goal.  The live verdict lines
(``rclverify/verdict``) are left out: the run is judged again.
"""
from __future__ import annotations

import json
import os
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import msgspec

#: The live monitor's own topics: a re-written run leaves out its verdicts.
VERDICT_TOPIC = "rclverify/verdict"
#: The topic of a call's lines (backends/monitors/dds_calls.py ``CALL_LOG_TOPIC``).
CALL_TOPIC = "rclverify/call"
#: Seconds the agent may take beyond its texts' own bounds (rclpy's start).
AGENT_TIMEOUT_S = 120.0


class RerunError(Exception):
    """The node cannot be re-run on this run (one sentence: why)."""


class Callback(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The callback that answers the node's questions, as the agent found it (:mod:`.rerun_agent`): its
    function's first ``line`` (1-based) in ``file``, its ``name`` and the names it closes over."""

    line: int
    name: str
    freevars: list[str] = []
    file: str = ""


class AgentRun(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """One text of the node's source re-run: ``error`` (``""``: it answered), the ``answers`` in question
    order (a topic's: the messages it published, each ``{"topic", "fields"}``; a call's: its response; a
    goal's: ``{"feedback", "result", "status"}``) and the ``seconds`` it took."""

    error: str = ""
    answers: list[Any] = []
    seconds: float = 0.0


class AgentAnswer(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """The agent's answer: one :class:`AgentRun` per text, in order, and the ``callback`` (``None`` when
    none was found)."""

    runs: list[AgentRun] = []
    callback: Callback | None = None

    def first(self) -> AgentRun:
        """The first text's run; an empty one when the agent ran none."""
        return self.runs[0] if self.runs else AgentRun()


@dataclass(frozen=True)
class Endpoint:
    """What answers the node's questions: ``kind`` ``topic`` (``inputs``, ``outputs``: topic names without a
    leading ``/``), ``service`` or ``action`` (``name``, ``ros_type`` ``pkg/Type``)."""

    kind: str
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    name: str = ""
    ros_type: str = ""


def endpoint(checked_node: Any, calls: bool) -> Endpoint:
    """The endpoint of the checked contract node ``checked_node`` (:class:`rclverify.lang.types.CheckedNode`)
    whose answers are judged: its served service or action when ``calls`` (the violation is a call's), else
    its topics.  Raises :class:`RerunError` when the contract names none."""
    node = checked_node.node
    if calls:
        served = [link for link in node.links if link.role == "serves"]
        if len(served) != 1:
            raise RerunError(f"{node.name} serves {len(served)} services or actions (one can be re-run)")
        return Endpoint(served[0].kind, name=served[0].name.lstrip("/"), ros_type=served[0].ros_type)
    ins = tuple(t.field.lstrip("/") for t in node.topics if t.match is not None and t.match.prefix == "in")
    outs = tuple(t.field.lstrip("/") for t in node.topics if t.match is not None and t.match.prefix == "out")
    if not ins or not outs:
        raise RerunError(f"{node.name} has no input and output topic to re-run it on")
    return Endpoint("topic", ins, outs)


class CallLine(msgspec.Struct, frozen=True):
    """What is read of a call's line (topic :data:`CALL_TOPIC`): the ``link`` (its service or action),
    the ``part`` (``request``, ``response``, ``goal``, ``feedback``, ``status``, ``result``...), the call's
    ``key``, the message's ``fields`` and a goal's ``status``; its other keys are kept, not read."""

    link: str = ""
    part: str = ""
    key: Any = None
    fields: dict[str, Any] | None = None
    status: str = ""


@dataclass(frozen=True)
class RunLine:
    """One line of the run: its ``topic``, its JSON object as written (``obj``: written back as it is
    unless the node's answer replaces it) and, for a call's line, what is read of it (``call``)."""

    topic: str
    obj: dict[str, Any] = field(repr=False)
    call: CallLine | None = None

    @classmethod
    def of(cls, obj: dict[str, Any]) -> RunLine:
        """The line whose JSON object is ``obj``.  Raises :class:`msgspec.ValidationError` for a call's
        line whose keys hold values of another type."""
        topic = str(obj.get("topic", ""))
        return cls(topic, obj, msgspec.convert(obj, CallLine) if topic == CALL_TOPIC else None)

    def message(self) -> dict[str, Any]:
        """A topic's line as its message: every key but ``topic`` and ``time``."""
        return {k: v for k, v in self.obj.items() if k not in ("topic", "time")}


def read_run(path: Path) -> list[RunLine]:
    """The lines of the log at ``path`` (blank lines skipped).  Raises :class:`RerunError` for a log that
    is not one JSON object a line (a bag is not read here), or a call's line of another shape."""
    out: list[RunLine] = []
    try:
        with path.open(encoding="utf-8") as fh:
            for k, line in enumerate(fh, 1):
                if line.strip():
                    obj = json.loads(line)
                    if not isinstance(obj, dict):
                        raise ValueError("not a JSON object")
                    out.append(RunLine.of(obj))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise RerunError(f"{path}:{locals().get('k', 0)}: the run cannot be read as a JSON-lines log: {e}") from e
    return out


def _call(line: RunLine, ep: Endpoint, part: str) -> CallLine | None:
    """``line`` read as ``ep``'s call line of ``part``; ``None`` when it is another line."""
    c = line.call
    return c if c is not None and c.link.lstrip("/") == ep.name and c.part == part else None


def _topic(line: RunLine) -> str:
    return line.topic.lstrip("/")


def questions(lines: Sequence[RunLine], ep: Endpoint) -> list[dict[str, Any]]:
    """The questions of ``ep`` in the run, in order: the fields of each input message, request or goal."""
    if ep.kind == "topic":
        return [x.message() for x in lines if _topic(x) in ep.inputs]
    part = "request" if ep.kind == "service" else "goal"
    return [dict(c.fields or {}) for x in lines if (c := _call(x, ep, part)) is not None]


def rerun(python: Path, source: Path, texts: Sequence[str], factory: str, args: Sequence[Any], ep: Endpoint,
          asked: Sequence[dict[str, Any]], timeout_s: float = 60.0) -> AgentAnswer:
    """The agent's answer (:mod:`.rerun_agent`, decoded: :class:`AgentAnswer`) for the node at
    ``ep`` of the robot that ``factory(*args)`` of ``source`` (each of ``texts``) makes, asked ``asked``, in
    the ROS 2 Python ``python``, each text within ``timeout_s`` seconds.  Raises :class:`RerunError` when
    the agent does not answer, or answers in another shape."""
    req = {"file": str(source), "texts": list(texts), "factory": factory, "args": list(args), "kind": ep.kind,
           "inputs": list(ep.inputs), "outputs": list(ep.outputs), "name": ep.name, "type": ep.ros_type,
           "questions": list(asked), "timeout_s": timeout_s}
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    try:
        p = subprocess.run([str(python), str(Path(__file__).with_name("rerun_agent.py"))], input=json.dumps(req),
                           capture_output=True, text=True, timeout=AGENT_TIMEOUT_S + timeout_s * len(texts), env=env)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise RerunError(f"the ROS 2 Python {python} did not re-run the node: {e}") from e
    try:
        return msgspec.json.decode(p.stdout, type=AgentAnswer)
    except (msgspec.DecodeError, ValueError):
        tail = (p.stderr or p.stdout).strip().splitlines()[-1:] or ["no output"]
        raise RerunError(f"the ROS 2 Python {python} did not re-run the node (exit {p.returncode}): "
                         f"{tail[0]}") from None


#: The final statuses of a goal.
_ENDS = ("succeeded", "aborted", "canceled")


def _without_stamp(fields: Any) -> Any:
    if isinstance(fields, dict):
        return {k: _without_stamp(v) for k, v in fields.items() if k != "header"}
    return fields


def recorded_answers(lines: Sequence[RunLine], ep: Endpoint) -> list[Any]:
    """The node's recorded answers in the shape a re-run gives them, for :func:`reproduces`: a topic's
    output messages (without headers) in order, each call's response, each goal's feedback, result, status."""
    if ep.kind == "topic":
        return [_without_stamp(x.message()) for x in lines if _topic(x) in ep.outputs]
    if ep.kind == "service":
        return [dict(c.fields or {}) for x in lines if (c := _call(x, ep, "response")) is not None]
    calls = [x.call for x in lines if x.call is not None]
    out = []
    for g in (c for x in lines if (c := _call(x, ep, "goal")) is not None):
        mine = [c for c in calls if c.key == g.key]
        ends = [c.status for c in mine if c.part == "status" and c.status in _ENDS]
        out.append({"feedback": [c.fields for c in mine if c.part == "feedback"],
                    "result": next((c.fields for c in mine if c.part == "result"), None),
                    "status": ends[-1] if ends else ""})
    return out


def _flat(ep: Endpoint, answers: Sequence[Any]) -> list[Any]:
    if ep.kind == "topic":
        return [_without_stamp(m["fields"]) for a in answers for m in a]
    return list(answers)


def _sub(recorded: Any, rerun_fields: Any) -> Any:
    """The re-run's fields, each field the recorded message has and the re-run gives replaced (a header
    and any field the re-run lacks kept as recorded)."""
    if isinstance(recorded, dict) and isinstance(rerun_fields, dict):
        return {k: (v if k == "header" or k not in rerun_fields else _sub(v, rerun_fields[k]))
                for k, v in recorded.items()}
    return rerun_fields


def reproduces(lines: Sequence[RunLine], ep: Endpoint, answers: Sequence[Any]) -> bool:
    """Whether ``answers`` (a re-run of the recorded source) are the recorded ones, field by field."""
    want = recorded_answers(lines, ep)
    got = _flat(ep, answers)
    return len(want) == len(got) and all(_sub(w, g) == w for w, g in zip(want, got))


def rewritten(lines: Sequence[RunLine], ep: Endpoint, answers: Sequence[Any]) -> list[dict[str, Any]]:
    """The run with the node's answers replaced by ``answers`` (module docstring), as the lines' JSON
    objects.  Raises :class:`RerunError` when the re-run answers another number of messages than were
    recorded (they cannot be placed in time)."""
    kept = [x for x in lines if x.topic != VERDICT_TOPIC]
    if ep.kind == "topic":
        got = [m["fields"] for a in answers for m in a]
        at = [k for k, x in enumerate(kept) if _topic(x) in ep.outputs]
        if len(got) != len(at):
            raise RerunError(f"the edited node answers {len(got)} messages where {len(at)} were recorded")
        placed = [x.obj for x in kept]
        for k, fields in zip(at, got):
            placed[k] = {"topic": kept[k].topic, "time": kept[k].obj["time"], **_sub(kept[k].message(), fields)}
        return placed
    goals = [c for x in kept if (c := _call(x, ep, "request" if ep.kind == "service" else "goal")) is not None]
    if len(goals) != len(answers):
        raise RerunError(f"the edited node answered {len(answers)} of {len(goals)} recorded questions")
    by_key = {json.dumps(g.key): a for g, a in zip(goals, answers)}
    out: list[dict[str, Any]] = []
    seen: dict[str, int] = {}  # key -> the feedback lines replaced so far
    for x in kept:
        c = x.call
        key = json.dumps(c.key if c is not None else x.obj.get("key"))
        a = by_key.get(key) if c is not None else None
        if a is None or c is None:
            out.append(x.obj)
        elif ep.kind == "service" and c.part == "response":
            out.append({**x.obj, "fields": _sub(c.fields, a)})
        elif ep.kind == "action" and c.part == "feedback":
            k = seen[key] = seen.get(key, -1) + 1
            if k >= len(a["feedback"]):
                raise RerunError("the edited node sends less feedback than was recorded")
            out.append({**x.obj, "fields": _sub(c.fields, a["feedback"][k])})
        elif ep.kind == "action" and c.part == "result":
            out.append({**x.obj, "fields": _sub(c.fields, a["result"])})
        elif ep.kind == "action" and c.part == "status" and c.status in _ENDS:
            out.append({**x.obj, "status": a["status"]})
        else:
            out.append(x.obj)
    if ep.kind == "action" and any(seen.get(json.dumps(g.key), -1) + 1 != len(a["feedback"])
                                   for g, a in zip(goals, answers)):
        raise RerunError("the edited node sends another number of feedback messages than were recorded")
    return out


def write_run(lines: Sequence[dict[str, Any]], path: Path) -> Path:
    """``lines`` written to ``path`` as a JSON-lines log (a scratch file of the check)."""
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path


__all__ = ["AGENT_TIMEOUT_S", "CALL_TOPIC", "AgentAnswer", "AgentRun", "CallLine", "Callback", "Endpoint", "RunLine", "RerunError", "endpoint", "questions", "read_run", "recorded_answers",
           "reproduces", "rerun", "rewritten", "write_run"]
