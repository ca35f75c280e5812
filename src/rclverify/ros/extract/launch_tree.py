"""The element tree every launch format becomes, and the ``$(eval ...)``
evaluator (:func:`evaluate`), shared by the readers (:mod:`launch_readers`,
:mod:`launch_ros2`) and the interpreter (:mod:`launch`).

``El(tag, attrs, children, src)``: one action or element, its attributes as
written (substitutions unresolved), located at ``src``.

Source: ROS 2 launch frontend design (design.ros2.org "ROS 2 Launch
XML/YAML format"); launch's ``PythonExpression``; roslaunch ``$(eval ...)``.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rclverify.ros.extract.model import Src


@dataclass
class El:
    tag: str
    attrs: dict[str, str]
    children: list["El"]
    src: Src


#: the attribute a reader sets on an element whose condition it could not read (value: where)
UNREAD = "condition-unread"
#: what joins the tokens of a node's ``ros_args`` attribute when a reader gives them one by one
SEP = "\x1f"
#: elements that start no node and set nothing the graph reads (passed over without a note): environment,
#: logging, machines, ROS 1 tests (roslaunch does not run them), the use_sim_time and global parameters
QUIET_TAGS = frozenset({"env", "set_env", "unset_env", "append_env", "prepend_env", "push_env", "pop_env",
                        "reset_env", "push-env", "pop-env", "log", "shutdown", "machine", "test", "set_ros_log_dir",
                        "set_use_sim_time", "set_parameter", "set_parameters_from_file"})
#: what an element read no further leaves unknown
UNREAD_TAGS = {"rosparam": "the parameters it loads are not read (a name the code takes from one keeps its "
                            "default)"}
#: an include's argument whose value cannot be read statically: using it says so
NOVALUE = "\x00novalue"
#: tags read as another: ROS 2's ``lifecycle_node`` is a node, ``set_remap`` a remap in its scope,
#: ``push_ros_namespace`` (the YAML and later XML spelling) is ``push-ros-namespace``
ALIASES = {"lifecycle_node": "node", "set_remap": "remap", "push_ros_namespace": "push-ros-namespace"}


class Unresolved(Exception):
    """A value that cannot be resolved statically (the message says why)."""


_EVAL_NODES = (ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Not, ast.Compare, ast.Eq, ast.NotEq,
               ast.In, ast.NotIn, ast.Constant, ast.Name, ast.Load, ast.Tuple, ast.List)


def evaluate(expr: str) -> str:
    """The value of ``$(eval expr)`` / ``PythonExpression`` as launch gives it
    (``str()`` of the result: ``True`` / ``False``), for the expressions a
    condition is made of: string, number and boolean literals, ``True`` /
    ``False`` / ``None``, ``not``, ``and``, ``or``, ``==``, ``!=``, ``in``,
    ``not in``.  Raises :class:`Unresolved` for anything else (a name, a call,
    arithmetic): such an expression is not evaluated statically.

    Source: launch's ``PythonExpression`` (``eval`` of the substituted text),
    roslaunch ``$(eval ...)``."""
    try:
        tree = ast.parse(expr, mode="eval")
    except SyntaxError as exc:
        raise Unresolved(f"$(eval {expr}): not a Python expression ({exc.msg})") from None
    for n in ast.walk(tree):
        if not isinstance(n, _EVAL_NODES) or (isinstance(n, ast.Name) and n.id not in ("True", "False", "None")):
            raise Unresolved(f"$(eval {expr}) is not evaluated statically (only literals, not, and, or, ==, !=, in)")

    def ev(n: ast.AST) -> Any:
        if isinstance(n, ast.Expression):
            return ev(n.body)
        if isinstance(n, ast.Constant):
            return n.value
        if isinstance(n, ast.Name):
            return {"True": True, "False": False, "None": None}[n.id]
        if isinstance(n, (ast.Tuple, ast.List)):
            return tuple(ev(x) for x in n.elts)
        if isinstance(n, ast.UnaryOp):
            return not ev(n.operand)
        if isinstance(n, ast.BoolOp):
            vals = [ev(x) for x in n.values]
            return all(vals) if isinstance(n.op, ast.And) else any(vals)
        assert isinstance(n, ast.Compare)
        left = ev(n.left)
        for op, right in zip(n.ops, (ev(x) for x in n.comparators)):
            if isinstance(op, ast.Eq):
                ok = left == right
            elif isinstance(op, ast.NotEq):
                ok = left != right
            else:
                ok = (left in right) == isinstance(op, ast.In)  # In / NotIn (the only others allowed)
            if not ok:
                return False
            left = right
        return True
    try:
        return str(ev(tree))
    except TypeError as exc:  # 'x' in 3
        raise Unresolved(f"$(eval {expr}): {exc}") from None


def ros2_file(path: Path, root: El) -> bool:
    """Whether launch file ``path`` (read as ``root``) is a ROS 2 one: Python or
    YAML, or XML using ROS 2's forms (``exec``, ``$(var)``, ``let``,
    ``push-ros-namespace`` ...) and none of roslaunch's own (``type``,
    ``$(arg)``, ``$(find)``, ``rosparam``).  Source: design.ros2.org "ROS 2
    Launch XML/YAML format"; wiki.ros.org/roslaunch/XML."""
    if path.suffix in (".py", ".yaml", ".yml"):
        return True
    two = one = False
    stack = [root]
    while stack and not (one and two):
        e = stack.pop()
        stack.extend(e.children)
        text = " ".join(e.attrs.values())
        two = two or "exec" in e.attrs or e.tag in ("let", "push-ros-namespace", "push_ros_namespace",
                                                    "lifecycle_node", "set_remap", "node_container") \
            or "$(var " in text or "$(find-pkg-share " in text
        one = one or (e.tag == "node" and "type" in e.attrs) or e.tag == "rosparam" or "$(arg " in text \
            or "$(find " in text
    return two and not one
