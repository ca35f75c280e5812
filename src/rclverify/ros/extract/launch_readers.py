"""ROS 1 and ROS 2 XML and ROS 2 YAML launch files read into the element
tree of :mod:`launch_tree` (never executed).

Two frontend actions become the elements the interpreter reads
(:func:`lower`): ``<executable cmd="ros2 run PKG EXE ...">`` (launch's
``ExecuteProcess``) is the node it starts, its ``--ros-args`` read as a
node's; another command is an ``unread`` element naming it; ``<timer>`` /
``<ros_timer>`` start their actions, unscoped, as launch runs a
``TimerAction``.

Source: roslaunch XML format (wiki.ros.org/roslaunch/XML), ROS 2 launch
frontend design (design.ros2.org "ROS 2 Launch XML/YAML format").
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from rclverify.ros.extract import safefs
from rclverify.ros.extract.launch_rosargs import after_ros_args
from rclverify.ros.extract.launch_tree import SEP, El
from rclverify.ros.extract.model import Note, Src
from rclverify.ros.extract.xmlsrc import line_of, parse_xml


def _from_xml(e: Any, shown: str) -> El:
    kids = [_from_xml(c, shown) for c in e if isinstance(c.tag, str)]
    return El(str(e.tag), {str(k): str(v) for k, v in e.attrib.items()}, kids, Src(shown, line_of(e)))


def read_xml(path: Path, shown: str) -> tuple[El | None, list[Note]]:
    """A ROS 1 or ROS 2 XML launch file as an element tree (root ``launch``)."""
    root, note = parse_xml(path, shown)
    if root is None:
        return None, [note] if note else []
    if root.tag != "launch":
        return None, [Note(Src(shown, 1), f"root element is <{root.tag}>, not <launch>", "ROS-PARSE", "error")]
    return lower(_from_xml(root, shown)), []


_TOKEN = re.compile(r"(?:\$\([^)]*\)|[^\s$]+|\$)+")  # a command's words; a $(...) substitution stays whole
_KEEP = ("if", "unless")


def lower(el: El) -> El:
    """``el`` with its ``executable`` and ``timer`` elements (at any depth) as
    the elements they start (module docstring)."""
    kids = [lower(c) for c in el.children]
    kept = {k: v for k, v in el.attrs.items() if k in _KEEP}
    if el.tag in ("timer", "ros_timer"):
        return El("group", {**kept, "scoped": "false"}, kids, el.src)
    if el.tag == "executable":
        toks = _TOKEN.findall(el.attrs.get("cmd", ""))
        if len(toks) >= 4 and toks[0].rsplit("/", 1)[-1] == "ros2" and toks[1] == "run":
            attrs = {**kept, "pkg": toks[2], "exec": toks[3]}
            ros = after_ros_args(toks[4:])
            if ros:
                attrs["ros_args"] = SEP.join(ros)
            return El("node", attrs, kids, el.src)
        return El("unread", {**kept, "what": f"<executable> runs '{el.attrs.get('cmd', '')}', not 'ros2 run PKG "
                                             f"EXE': the nodes it starts, if any, are unknown"}, [], el.src)
    return El(el.tag, el.attrs, kids, el.src)


def _yaml_el(tag: str, body: Any, shown: str, line: int) -> El:
    attrs: dict[str, str] = {}
    kids: list[El] = []
    if isinstance(body, list):  # - group: [ {push_ros_namespace: ...}, {node: ...} ] (the form in ROS 2's examples)
        kids.extend(_yaml_list(body, shown, line))
    elif isinstance(body, dict):
        for k, v in body.items():
            if k in ("remap", "arg", "param", "composable_node") and isinstance(v, list):
                for item in v:
                    kids.append(_yaml_el(str(k), item, shown, line))
            elif k == "children" and isinstance(v, list):
                kids.extend(_yaml_list(v, shown, line))
            elif isinstance(v, (str, int, float, bool)):
                attrs[str(k)] = str(v).lower() if isinstance(v, bool) else str(v)
    return El(tag, attrs, kids, Src(shown, line))


def _yaml_list(items: list[Any], shown: str, line: int) -> list[El]:
    out = []
    for item in items:
        if isinstance(item, dict) and len(item) == 1:
            (tag, body), = item.items()
            ln = getattr(item, "line", line)
            out.append(_yaml_el(str(tag), body, shown, ln))
    return out


def read_yaml(path: Path, shown: str) -> tuple[El | None, list[Note]]:
    """A ROS 2 YAML launch file (``launch: [ {node: {...}}, ...]``) as an element tree.

    Lines: each top-level action is located at its own line."""
    import yaml  # deferred: start-up (loads yaml only when called)

    class _L(yaml.SafeLoader):
        pass

    def _map(loader: Any, node: Any) -> Any:
        d = _LineDict(loader.construct_mapping(node, deep=True))
        d.line = node.start_mark.line + 1
        return d
    _L.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _map)
    try:
        text = safefs.read_text(path)
        if len(text) > 5_000_000:
            return None, [Note(Src(shown), "launch file too large", "ROS-PARSE", "error")]
        from rclverify.model.plan.errors import PlanError  # deferred: optional or conditional (inside a block)
        from rclverify.model.plan.yamlguard import compose_guarded  # deferred: optional or conditional (inside a block)
        try:
            compose_guarded(text, shown)  # alias bombs, cycles and depth refused before expansion
        except PlanError as exc:
            return None, [Note(Src(shown), f"YAML launch file refused: {exc}", "ROS-PARSE", "error")]
        data = yaml.load(text, Loader=_L)  # noqa: S506 (a SafeLoader subclass)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        return None, [Note(Src(shown, mark.line + 1 if mark else 1, mark.column + 1 if mark else 1),
                           f"not valid YAML: {getattr(exc, 'problem', exc)}", "ROS-PARSE", "error")]
    except (OSError, RecursionError, ValueError) as exc:
        return None, [Note(Src(shown), f"cannot read: {exc}", "ROS-PARSE", "error")]
    if not isinstance(data, dict) or not isinstance(data.get("launch"), list):
        return None, [Note(Src(shown), "a YAML launch file is a mapping with a 'launch' list", "ROS-PARSE", "error")]
    return lower(El("launch", {}, _yaml_list(data["launch"], shown, 1), Src(shown, 1))), []


class _LineDict(dict):  # type: ignore[type-arg]
    line = 1
