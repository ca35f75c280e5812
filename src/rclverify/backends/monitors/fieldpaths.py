"""Check-time validation of a mapping file's field paths against the message definitions.

A topic rule's ``fields`` may name nested fields and array elements
(``linear.x``, ``pose.pose.position.x``, ``ranges[0]``, ``ranges[-1]``:
:func:`rclverify.traces.mapping.parse_path`).  Where the contracts give the
topic's ROS type (``topics(geometry_msgs/Twist cmd_vel matches(...))``, a
service's request and response, an action's goal, feedback and result) and
the type is known (the mapping's ``msg_dirs``, or the standard types of
rosbags' store, which the bag reader uses too), every entry is followed
through the definitions (:func:`rclverify.ros.extract.interfaces.field_path`, the
ROS grounding's reader): a field that does not exist, a message where a
number is read, an array read without an index (unless the topic, or the
service's or action's part, sets a ``seq(T)`` variable, which the array
fills: an action's ``int32[] sequence`` feedback for a ``seq(INTEGER)``) or
a path through every item (``poses[*].position.x``, read as the grounding's
``poses[].position.x``) on a topic whose variable is not a sequence is one
located error at the entry in the mapping file (``mapping.yaml:7:22: error:
topic cmd_vel: field 'linar.x' of geometry_msgs/Twist: ...``), before any
run is read.  An unknown type is left to the run (its events are then
``inconclusive`` with the reason when a field is missing).

``doit verify`` (the plan's check) and ``rclverify monitor --live`` call the
one :func:`check_field_paths`; the live monitor leaves a field the
definitions lack to the run (a publisher may declare its own definition of
the type, docs/ros2.md, "The publisher's own definition") and refuses the rest alike.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

from rclverify.model.plan.errors import plan_error
from rclverify.model.plan.yamlguard import load_located, read_yaml_text
from rclverify.lang.errors import Diagnostic
from rclverify.lang.types import Checked, SeqT
from rclverify.ros.extract.interfaces import BASE_TYPES, TypeTable, field_path
from rclverify.ros.extract.model import canon_type, short_type
from rclverify.backends.monitors.verdicts import LINK_TOPICS


def topic_types(checked: Checked) -> dict[str, str]:
    """topic (no leading ``/``) -> the canonical ROS type of what its rule
    maps (``pkg/msg/Type``; for a link's topic the part's type,
    ``std_srvs/srv/SetBool_Request``, ``pkg/action/Move_Goal``); the first
    node naming a topic wins."""
    out: dict[str, str] = {}
    for node in checked.nodes.values():
        for t in node.node.topics:
            typ = canon_type(t.msg_type)
            if typ:
                out.setdefault(t.field.lstrip("/"), typ)
        for lk in node.node.links:
            base = canon_type(lk.ros_type, "srv" if lk.kind == "service" else "action")
            if not base:
                continue
            suffixes = {"request": "_Request", "response": "_Response", "goal": "_Goal", "feedback": "_Feedback",
                        "result": "_Result"}
            for part in LINK_TOPICS.get(lk.kind, ()):
                out.setdefault(f"{lk.name.lstrip('/')}/{part}", base + suffixes[part])
    return out


def _table(root: Path, msg_dirs: Sequence[str]) -> TypeTable:
    """The workspace's interface files under ``msg_dirs`` (``<pkg>/msg/*.msg``,
    also ``srv``/``action``), standard types from rosbags' store on demand."""
    table = TypeTable()
    for d in msg_dirs:
        base = root / d
        if not base.is_dir():
            continue
        for f in sorted(p for ext in ("msg", "srv", "action") for p in base.rglob(f"*.{ext}")):
            if f.is_file() and f.parent.name == f.suffix.lstrip("."):
                table.add_file(f, f.parent.parent.name, f.relative_to(root).as_posix(), "workspace", None)
    return table


def check_field_paths(root: Path, rel: str, msg_dirs: Sequence[str], checked: Checked,
                      robot_types: bool = False) -> list[Diagnostic]:
    """Located errors for the ``fields`` entries of mapping file ``rel`` that
    do not name a number, string or boolean field of their topic's known
    type (module docstring); empty when every known one does.  ``doit verify``
    and ``rclverify monitor --live`` both call it; the live monitor with
    ``robot_types`` true: a field the definitions lack is then left to the
    run, which reads a publisher's own definition of its type (docs/ros2.md,
    "The publisher's own definition"), while a field that is there and cannot fill its
    variable (an array for a single value ...) is refused as ``doit verify``
    refuses it."""
    path = root / rel
    raw, locs = load_located(read_yaml_text(path, rel), rel)
    out: list[Diagnostic] = _unknown_sim_nodes(raw, locs, rel, checked)
    topics = raw.get("topics") if isinstance(raw, Mapping) else None
    if not isinstance(topics, Mapping):
        return out
    types = topic_types(checked)
    seqs = _sequence_topics(checked)
    table: TypeTable | None = None
    for topic, spec in topics.items():
        fields: Any = spec.get("fields") if isinstance(spec, Mapping) else None
        typ = types.get(str(topic).lstrip("/"))
        if typ is None or not isinstance(fields, (list, tuple)) or not fields:
            continue
        if table is None:
            table = _table(root, msg_dirs)
        if table.get(typ) is None:
            continue  # a type this workspace does not define: the run decides
        for k, f in enumerate(fields):
            why = _why(table, typ, str(f), str(topic).lstrip("/") in seqs, robot_types)
            if why is None:
                continue
            at = locs.get(("topics", topic, "fields", k)) or locs.get(("topics", topic, "fields"))
            line, col = (at.line, at.col) if at is not None else (1, 1)
            out.extend(plan_error(rel, line, col, f"topic {topic}: field {str(f)!r} of {short_type(typ)}: {why}",
                                  "E-field").diagnostics)
    return out


def _unknown_sim_nodes(raw: Any, locs: Mapping[Any, Any], rel: str, checked: Checked) -> list[Diagnostic]:
    """Located errors for the names of the mapping's ``use_sim_time`` list that name no contract node
    (a typo would leave that node's deadlines in a clock it does not keep)."""
    names = raw.get("use_sim_time") if isinstance(raw, Mapping) else None
    if not isinstance(names, list):
        return []
    out: list[Diagnostic] = []
    for k, name in enumerate(names):
        if name in checked.nodes:
            continue
        at = locs.get(("use_sim_time", k)) or locs.get(("use_sim_time",))
        line, col = (at.line, at.col) if at is not None else (1, 1)
        out.extend(plan_error(rel, line, col, f"use_sim_time: {name!r} is no contract node (known: "
                              f"{', '.join(sorted(checked.nodes))})", "E-field").diagnostics)
    return out


def _sequence_topics(checked: Checked) -> set[str]:
    """The topics (no leading ``/``) that set a ``seq(T)`` variable: an array fills it whole.  A topic
    of the contracts' ``topics(...)``, and a part of a linked service or action (``move/feedback``, the
    link's variable of that part: :data:`~.verdicts.LINK_TOPICS`), as :func:`topic_types` names them."""
    out: set[str] = set()

    def sets_seq(node: Any, v: Any) -> bool:
        typ = (node.inputs if v.prefix == "in" else node.outputs).get(v.name) if v is not None else None
        return isinstance(typ, SeqT)
    for node in checked.nodes.values():
        for t in node.node.topics:
            if sets_seq(node, t.match):
                out.add(t.field.lstrip("/"))
        for lk in node.node.links:
            for part, v in zip(LINK_TOPICS.get(lk.kind, ()), lk.parts):
                if sets_seq(node, v):
                    out.add(f"{lk.name.lstrip('/')}/{part}")
    return out


def _why(table: TypeTable, typ: str, name: str, sequence: bool = False, robot_types: bool = False) -> str | None:
    """What is wrong with field ``name`` of ``typ`` (``None``: nothing); ``sequence``: the topic sets a
    ``seq(T)`` variable, which an array, or a path through every item of one (``poses[*].position.x``), fills;
    ``robot_types``: a path the definitions cannot follow is not wrong (:func:`check_field_paths`)."""
    every = "[*]" in name
    rt, err, arr = field_path(table, typ, name.replace("[*]", "[]"))  # the grounding's reader writes every item []
    if err is not None:
        return None if robot_types else err
    if (rt or "").endswith("/wstring"):  # rosbags' .msg reader takes wstring, which it lacks, for a message
        rt = "wstring"
    if every and not sequence:
        return "every item ([*]) fills a sequence; the topic's variable is not a seq(T)"
    if every and arr:
        return "an array in every item: a sequence of sequences is not mapped"
    if arr and not sequence:
        return f"an array ({short_type(rt)}[]) cannot fill a single value; index it ({name}[0], {name}[-1])"
    if (rt or "").split("<=")[0] not in BASE_TYPES:
        return f"a message ({short_type(rt)}); name one of its fields ({name}.<field>)"
    return None


__all__ = ["check_field_paths", "topic_types"]
