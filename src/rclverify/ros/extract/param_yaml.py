"""A package's ROS 2 parameter files (``config/*.yaml``): the values they give
each node's parameters, used when no launch file is given (docs/ros.md,
"Real ROS 2 code, round three").

The format is rcl's parameter file (ROS 2 docs, "Understanding parameters",
``--params-file``; rcl_yaml_param_parser)::

    range_fusion:                 # a node name, or namespaces nested: ns: {node: ...}
      ros__parameters:
        output_topic: fused_range
        front:
          topic: front/range      # the parameter front.topic
        observation_sources: ["front", "rear"]

A node key may be a full name (``/ns/node``), a relative one (``node``: in the
root namespace), and use rcl's wildcards (``*`` one name part, ``**`` any
number: ``/**`` every node).  Nested mappings below ``ros__parameters`` make
dotted keys.  Only strings and lists of strings are kept (names of topics,
services and sources); numbers and booleans name nothing.  ROS 2 applies no
file by itself: the scan uses a package's files only for that package's nodes
and only when no launch file is given; when two files give one parameter of
one node different values, neither is used (which one runs is the launch's
choice) and a located warning says so.

A list of sources read from a string-array parameter (``for (auto & s :
get_parameter("observation_sources").as_string_array())`` then
``get_parameter(s + ".topic", topic)``) is expanded with the array's value
(:func:`expand_each`): one endpoint per source.
"""
from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any, Callable, Sequence, Union

from rclverify.ros.extract import names, safefs
from rclverify.ros.extract.model import Endpoint, Note, Src

Value = Union[str, tuple[str, ...]]  # a string, or a string array
DIRS = ("config", "params", "param")  # where packages keep their parameter files
MAX_FILES = 64


def read_file(text: str, shown: str) -> tuple[list[tuple[str, str, Value, Src]], list[Note]]:
    """``([(node pattern, "~key", value, where), ...], notes)`` of one parameter file's
    text.  Never raises: malformed YAML, or YAML over the limits of
    :mod:`rclverify.model.plan.yamlguard`, is one ``ROS-PARSE`` warning."""
    import yaml  # deferred: start-up (loads yaml only when called)

    from rclverify.model.plan.errors import PlanError  # deferred: start-up (loads rclverify.lang, rclverify.lang.ast and more only when called)
    from rclverify.model.plan.yamlguard import compose_guarded  # deferred: start-up (loads yaml, rclverify.lang and more only when called)
    try:
        root = compose_guarded(text, shown)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        return [], [Note(Src(shown, mark.line + 1 if mark else 1, mark.column + 1 if mark else 1),
                         f"parameter file is not valid YAML: {getattr(exc, 'problem', exc)}", "ROS-PARSE")]
    except PlanError as exc:
        return [], [Note(Src(shown), f"parameter file refused: {exc}", "ROS-PARSE")]
    out: list[tuple[str, str, Value, Src]] = []
    if isinstance(root, yaml.MappingNode):
        _nodes(root, "", shown, out)
    return out, []


def _nodes(m: Any, prefix: str, shown: str, out: list[tuple[str, str, Value, Src]]) -> None:
    import yaml  # deferred: start-up (loads yaml only when called)
    for k, v in m.value:
        if not isinstance(k, yaml.ScalarNode) or not isinstance(v, yaml.MappingNode):
            continue
        if k.value == "ros__parameters":
            _params(v, "", prefix or "/", shown, out)
        elif len(prefix.split("/")) < 16:
            _nodes(v, f"{prefix}/{k.value.strip('/')}" if not k.value.startswith("/") or not prefix
                   else f"{prefix}{k.value}", shown, out)


def _params(m: Any, key: str, node: str, shown: str, out: list[tuple[str, str, Value, Src]]) -> None:
    import yaml  # deferred: start-up (loads yaml only when called)
    for k, v in m.value:
        if not isinstance(k, yaml.ScalarNode):
            continue
        full = f"{key}.{k.value}" if key else str(k.value)
        at = Src(shown, v.start_mark.line + 1, v.start_mark.column + 1)
        if isinstance(v, yaml.MappingNode) and full.count(".") < 16:
            _params(v, full, node, shown, out)
        elif isinstance(v, yaml.ScalarNode) and v.tag.endswith(":str"):
            out.append((node, "~" + full, v.value, at))
        elif isinstance(v, yaml.SequenceNode) and v.value and all(
                isinstance(x, yaml.ScalarNode) and x.tag.endswith(":str") for x in v.value):
            out.append((node, "~" + full, tuple(x.value for x in v.value), at))


def matches(pattern: str, full: str) -> bool:
    """Whether a parameter file's node key ``pattern`` names node ``full``
    (``/ns/node``): equal names, ``*`` for one part, ``**`` for any number."""
    pat = names.normalise(pattern)
    rx = "".join("(/[^/]+)*" if p == "**" else "/" + ".*".join(re.escape(x) for x in p.split("*"))
                 if "*" in p else "/" + re.escape(p) for p in pat.split("/")[1:])
    return re.fullmatch(rx or "/", names.normalise(full)) is not None


class PackageParams:
    """The parameter files of the scanned packages: :meth:`for_node` gives a node's
    values.  ``roots[pkg]``: each package's directory; ``show``: how paths are shown."""

    def __init__(self, roots: dict[str, Path], show: Callable[[Path], str]) -> None:
        self.entries: dict[str, list[tuple[str, str, Value, Src]]] = {}
        self.notes: list[Note] = []
        for pkg, root in sorted(roots.items()):
            files = sorted(f for d in DIRS if (root / d).is_dir() for f in (root / d).iterdir()
                           if f.suffix in (".yaml", ".yml") and f.is_file())[:MAX_FILES]
            for f in files:
                try:
                    text = safefs.read_text(f)
                except (OSError, UnicodeDecodeError) as exc:
                    self.notes.append(Note(Src(show(f)), f"cannot read parameter file: {exc}", "ROS-PARSE"))
                    continue
                got, notes = read_file(text, show(f))
                self.entries.setdefault(pkg, []).extend(got)
                self.notes.extend(notes)

    def for_node(self, pkg: str | None, full: str) -> tuple[dict[str, tuple[Value, Src]], list[Note]]:
        """``({"/node/key": (value, where)}, notes)``: the values package ``pkg``'s files
        give node ``full``'s parameters (keys resolved as the node's private names); a
        parameter two files give different values is left out, with a located note."""
        got: dict[str, tuple[Value, Src]] = {}
        clash: dict[str, list[Src]] = {}
        for pattern, key, value, at in self.entries.get(pkg or "", []):
            if not matches(pattern, full):
                continue
            k = names.resolve(key, names.split(full)[0], full)
            prev = got.get(k)
            if prev is not None and prev[0] != value and prev[1].file != at.file:
                clash.setdefault(k, [prev[1]]).append(at)
            got[k] = (value, at)
        notes = [Note(ats[-1], f"parameter {k} has different values in {' and '.join(str(a) for a in ats)}; "
                               f"which file runs is a launch file's choice: not used")
                 for k, ats in clash.items()]
        return {k: v for k, v in got.items() if k not in clash}, notes


_EACH = re.compile(r"\[(~[^\[\]]+)\]")


def expand_each(eps: list[Endpoint], array: Callable[[str], Any], notes: list[Note]) -> list[Endpoint]:
    """``eps`` with each endpoint whose parameter key reads an element of a string-array
    parameter (``~[~observation_sources].topic``, :mod:`symbols` ``each``) made one
    endpoint per element (``~front.topic``, ``~rear.topic``), in the array's order.
    ``array(name)``: the array's value (a tuple of strings; anything else is no
    value).  An endpoint whose array has no value is left out with a located note in
    ``notes`` (the list of sources is read at run time)."""
    out: list[Endpoint] = []
    for e in eps:
        param = e.param or ""
        m = _EACH.search(param)
        if m is None:
            out.append(e)
            continue
        got = array(m.group(1))
        if not isinstance(got, tuple):
            notes.append(Note(e.src, f"name of {e.kind} comes from parameter {param.replace(m.group(0), '<source>')} "
                                     f"of each source listed in parameter {m.group(1)}, which has no list value in "
                                     f"the launch files or the package's parameter files: not resolved statically"))
            continue
        for x in got:
            out.append(dataclasses.replace(e, param=param.replace(m.group(0), x),
                                           topic=e.topic.replace(m.group(0), x) if e.topic else e.topic))
    return out


Entry = tuple[str, str, Value, Src]  # (node key pattern, "~key", value, where): one parameter of a file


def launch_file_params(path: Path, shown: str, node: str | None,
                       pending: list[Entry]) -> tuple[dict[str, tuple[Value, Src]], list[Note]]:
    """The private parameters a ROS 2 launch file gives a node from the parameter file at ``path`` (Python
    ``parameters=[path]`` or ``ParameterFile(path)``, XML ``<param from="path"/>``, YAML ``param: [{from:
    path}]``): ``({"~key": (value, where)}, notes)`` of the entries whose node key matches the node's full
    name ``node`` (:func:`matches`: the name, ``/**``, wildcards, as rcl matches them; a relative key is in
    the root namespace); ``node`` ``None`` (its name not given in the launch file: the code's name, known
    to the graph, applies): the keys that match every node (``/**``), the others appended to ``pending``
    (:func:`pending_for` applies them once the name is known).  A file that cannot be read, or is not YAML, is one
    located note and gives nothing.  The format is :func:`read_file`'s."""
    try:
        text = safefs.read_text(path)
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        return {}, [Note(Src(shown), f"cannot read parameter file: {exc}", "ROS-PARSE")]
    entries, notes = read_file(text, shown)
    out: dict[str, tuple[Value, Src]] = {}
    for pattern, key, value, at in entries:
        if node is None and names.normalise(pattern) not in ("/**", "/**/*"):
            pending.append((pattern, key, value, at))
        elif node is None or matches(pattern, node):
            out[key] = (value, at)
    return out, notes


def pending_for(pending: Sequence[Entry], node: str) -> dict[str, tuple[Value, Src]]:
    """The parameters of ``pending`` (:func:`launch_file_params`) whose node key matches node ``node``'s full
    name, in file order (a later one wins)."""
    return {key: (value, at) for pattern, key, value, at in pending if matches(pattern, node)}


def rosparam_file(path: Path) -> dict[str, str] | str:
    """The parameters a ROS 1 ``<rosparam command="load" file="...">`` loads from
    the YAML file at ``path``: ``{name: value}``, nested mappings joined with
    ``/`` (``a: {b: x}`` is ``a/b``; roslaunch's rosparam loads a mapping as
    a parameter namespace), scalars as text, lists left out; or why it cannot
    be read (a sentence).  Source: wiki.ros.org/roslaunch/XML/rosparam."""
    import yaml  # deferred: start-up (loads yaml only when called)
    from rclverify.model.plan.errors import PlanError  # deferred: start-up (loads rclverify.lang only when called)
    from rclverify.model.plan.yamlguard import compose_guarded  # deferred: start-up (as above)
    try:
        text = safefs.read_text(path)
        compose_guarded(text, str(path))  # alias bombs, cycles and depth refused before expansion
        data = yaml.safe_load(text)
    except (OSError, ValueError, yaml.YAMLError, RecursionError, PlanError) as exc:
        return f"cannot be read ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})"
    if data is None:
        return {}
    if not isinstance(data, dict):
        return "is not a mapping of parameters"
    out: dict[str, str] = {}

    def walk(m: dict[Any, Any], prefix: str) -> None:
        for k, v in m.items():
            key = f"{prefix}{k}"
            if isinstance(v, dict):
                walk(v, key + "/")
            elif isinstance(v, bool):
                out[key] = str(v).lower()
            elif isinstance(v, (str, int, float)):
                out[key] = str(v)
    walk(data, "")
    return out
