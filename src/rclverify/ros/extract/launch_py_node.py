"""A ``Node``'s (``LifecycleNode``'s, ``ComposableNode``'s) own arguments in
a ROS 2 Python launch file, read from its syntax tree: ``remappings``,
``parameters`` (literal dicts), and ``ros_arguments`` / the ``--ros-args``
part of ``arguments`` (kept as tokens for :mod:`launch_rosargs`).  What
cannot be read is left out with a located note; the node is kept.  An
``ExecuteProcess`` running ``ros2 run PKG EXE`` is that node
(:func:`execute_process`).
"""
from __future__ import annotations

import ast

from rclverify.ros.extract.launch_tree import SEP, El
from rclverify.ros.extract.launch_py_values import Unres as _Unres, callee as _callee, expand as _expand
from rclverify.ros.extract.launch_py_values import kw as _kw, value as _value
from rclverify.ros.extract.launch_rosargs import after_ros_args
from rclverify.ros.extract.model import Note, Src


def ros_args(c: ast.Call, attrs: dict[str, str], shown: str, notes: list[Note]) -> None:
    """``ros_arguments=[...]`` and the ``--ros-args`` part of ``arguments=[...]``
    of a node as its ``ros_args`` attribute (tokens joined by :data:`.launch_tree.SEP`, read
    by :mod:`launch_rosargs`); a ROS argument that cannot be read leaves them
    out, said with a located note (the program's own arguments are not read)."""
    toks: list[str] = []
    for key in ("ros_arguments", "arguments"):
        v = _kw(c, key)
        if v is None:
            continue
        v = _expand(v)
        at = Src(shown, v.lineno, v.col_offset + 1)
        if not isinstance(v, (ast.List, ast.Tuple)):
            notes.append(Note(at, f"{_callee(c)}(...): {key} '{ast.unparse(v)}' cannot be read statically; the "
                                  f"names its ROS arguments may remap are left out", "ROS-LAUNCH"))
            continue
        inside = key == "ros_arguments"
        mine: list[str] = []
        for x in v.elts:
            try:
                t = _value(x)
            except _Unres as exc:
                if inside:
                    notes.append(Note(at, f"{_callee(c)}(...): {key} item {exc} cannot be read statically; its "
                                          f"ROS arguments are left out", "ROS-LAUNCH"))
                    mine = []
                    break
                t = "\x00"  # a program argument of its own: no ROS argument
            inside = inside and t != "--" or t == "--ros-args"
            mine.append(t)
        toks += mine if key == "ros_arguments" else after_ros_args(mine)
    if toks:
        attrs["ros_args"] = SEP.join(toks)


def node_kids(c: ast.Call, shown: str, notes: list[Note]) -> list[El]:
    """``remappings=[(a, b)]`` and ``parameters=[{name: value}]`` of a ``Node`` or
    ``ComposableNode`` as ``remap`` and ``param`` elements, through names bound
    once and list concatenation (:func:`.launch_py_values.expand`); a parameter file (a path in
    ``parameters``, ``ParameterFile(path)``, a substitution giving one) as a ``param`` element
    ``from`` that path; an unreadable pair, value or path is left out with a located
    note.  A parameter whose value is a list of literals (a string array) is
    no name and is not kept."""
    kids = []
    rm = _kw(c, "remappings")
    if rm is not None:
        rm = _expand(rm)
        if not isinstance(rm, (ast.List, ast.Tuple)):
            notes.append(Note(Src(shown, rm.lineno, rm.col_offset + 1), f"{_callee(c)}(...): remappings "
                              f"'{ast.unparse(rm)}' cannot be read statically; the node is read without them",
                              "ROS-LAUNCH"))
        else:
            for pair in rm.elts:
                at = Src(shown, pair.lineno, pair.col_offset + 1)
                try:
                    if not isinstance(pair, (ast.Tuple, ast.List)) or len(pair.elts) != 2:
                        raise _Unres(f"'{ast.unparse(pair)}' (not a pair)")
                    kids.append(El("remap", {"from": _value(pair.elts[0]), "to": _value(pair.elts[1])}, [], at))
                except _Unres as exc:
                    notes.append(Note(at, f"{_callee(c)}(...): remapping {exc} cannot be read statically; "
                                          f"remapping left out", "ROS-LAUNCH"))
    ps = _kw(c, "parameters")
    ps = _expand(ps) if ps is not None else None
    if isinstance(ps, (ast.List, ast.Tuple)):
        for item in ps.elts:
            at = Src(shown, item.lineno, item.col_offset + 1)
            if not isinstance(item, ast.Dict):  # a parameter file: its path (param_yaml.launch_file_params)
                try:
                    kids.append(El("param", {"from": _value(item)}, [], at))
                except _Unres as exc:
                    notes.append(Note(at, f"parameter file {exc} cannot be read statically: its parameters are "
                                          f"not read", "ROS-LAUNCH"))
                continue
            for k, v in zip(item.keys, item.values):
                if k is None:
                    continue
                if isinstance(v, (ast.List, ast.Tuple)) and v.elts and all(isinstance(x, ast.Constant)
                                                                             for x in v.elts):
                    continue  # a string (or number) array: a list value, never a name
                try:
                    kids.append(El("param", {"name": _value(k), "value": _value(v)}, [],
                                   Src(shown, v.lineno, v.col_offset + 1)))
                except _Unres as exc:
                    notes.append(Note(at, f"parameter value {exc} is not a literal: not resolved statically",
                                      "ROS-LAUNCH"))
    elif ps is not None:
        notes.append(Note(Src(shown, ps.lineno, ps.col_offset + 1), f"parameters '{ast.unparse(ps)}' are not a "
                                                                    f"literal list: not resolved statically",
                          "ROS-LAUNCH"))
    return kids


def execute_process(c: ast.Call, src: Src, notes: list[Note]) -> El | None:
    """``ExecuteProcess(cmd=['ros2', 'run', pkg, exe, ...])`` as the node it
    starts (its ``--ros-args`` read as a node's); any other command, or one
    that cannot be read, is named in a located note (``None``)."""
    cmd = _kw(c, "cmd") or (c.args[0] if c.args else None)
    toks: list[str] = []
    seq = _expand(cmd) if cmd is not None else None
    if isinstance(seq, (ast.List, ast.Tuple)):
        try:
            toks = [_value(x) for x in seq.elts]
        except _Unres as exc:
            notes.append(Note(src, f"ExecuteProcess(...): command item {exc} cannot be read statically; the node "
                                   f"it starts, if any, is unknown", "ROS-LAUNCH"))
            return None
    if len(toks) >= 4 and toks[0].rsplit("/", 1)[-1] == "ros2" and toks[1] == "run":
        attrs = {"pkg": toks[2], "exec": toks[3]}
        ros = after_ros_args(toks[4:])
        if ros:
            attrs["ros_args"] = SEP.join(ros)
        return El("node", attrs, [], src)
    notes.append(Note(src, f"ExecuteProcess(...) runs '{' '.join(toks) or (ast.unparse(cmd) if cmd else '?')}', not "
                           f"'ros2 run PKG EXE': the nodes it starts, if any, are unknown", "ROS-LAUNCH"))
    return None
