"""Substitution classes of other packages than ``launch`` itself, each read as
what it does when launched: resolved where its inputs are statically known,
otherwise named as known only at run time (:class:`~.launch_py_values.Unres`).

Read from a Python launch file (:func:`call_value`, into ``$(...)`` text the
:class:`~.launch.Interpreter` resolves with :func:`perform`):

* launch's logic substitutions ``NotSubstitution(x)``, ``AndSubstitution(a,
  b)``, ``OrSubstitution(a, b)``, ``AllSubstitution(*x)``,
  ``AnySubstitution(*x)``: ``true``/``false`` of operands that are
  ``true``/``false``/``1``/``0`` (any case), as launch's
  ``perform_typed_substitution(..., bool)`` reads them; ``IfElseSubstitution(
  condition, if_value, else_value)``; ``StringJoinSubstitution(parts,
  delimiter)``; ``AnonName(x)`` (``$(anon x)``);
* launch_ros' ``FindPackagePrefix(pkg)`` / ``FindPackage(pkg)`` (the
  package's directory, as ``FindPackageShare``: a scan reads sources);
  ``ParameterFile(f)`` (the file ``f``) and ``ParameterValue(v)`` (``v``);
* nav2_common's ``HasNodeParams(source_file, node_name)``: ``True`` when the
  YAML file's top-level mapping has the key ``node_name``, else ``False``
  (read through the YAML guard); ``RewrittenYaml(source_file, ...)`` and
  ``ReplaceString(source_file, ...)`` are a parameter file written when
  launched from ``source_file``: their value names it (``rewritten-yaml:``,
  ``replace-string:`` and the source), so a ``HasNodeParams`` of one, whose
  keys the rewrite decides, is said, never guessed.

Named as known only at run time: ``Command`` (a program's output, e.g.
xacro's), ``FindExecutable`` (the launching machine's ``PATH``),
``LaunchLogDir``, ``LocalSubstitution`` (an event's data),
``ExecutableInPackage`` (an install space), launch_ros' ``Parameter(name)``
(a ROS parameter's value in the launch context), ``ParseMultiRobotPose``.

Source: ros2/launch ``launch/substitutions``, ros2/launch_ros
``launch_ros/substitutions`` and ``parameter_descriptions``,
ros-navigation/navigation2 ``nav2_common/launch``.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Callable

from rclverify.ros.extract import safefs
from rclverify.ros.extract.launch_tree import Unresolved

#: the value of a parameter file written when launched (RewrittenYaml, ReplaceString): prefix + source
WRITTEN = ("rewritten-yaml:", "replace-string:")

#: class -> what makes its value known only at run time
RUN_TIME = {
    "Command": "runs a program when launched; its output",
    "FindExecutable": "looks the program up on the launching machine's PATH; the path",
    "LaunchLogDir": "is the log directory of the launch run; it",
    "LocalSubstitution": "reads the data of an event or a launch context's locals; it",
    "ExecutableInPackage": "names a file of an install space; it",
    "ParseMultiRobotPose": "parses the robots' poses from a launch argument at run time; it",
}
_LOGIC = {"NotSubstitution": "not", "AndSubstitution": "and", "OrSubstitution": "or",
          "AllSubstitution": "and", "AnySubstitution": "or"}


def call_value(e: ast.Call, name: str, value: Callable[[ast.AST], str], unres: type[Exception]) -> str | None:
    """The ``$(...)`` text of call ``e`` of substitution class ``name`` (``value``
    reads an argument); ``None`` when ``name`` is none of this module's; raises
    ``unres`` for a run-time one, naming why."""
    def a(pos: int, key: str) -> ast.expr | None:
        return e.args[pos] if len(e.args) > pos else next((k.value for k in e.keywords if k.arg == key), None)

    if name in RUN_TIME:
        raise unres(f"'{ast.unparse(e)}' ({name} {RUN_TIME[name]} is known only at run time)")
    if name == "Parameter" and len(e.args) + len(e.keywords) == 1:  # launch_ros.substitutions.Parameter
        raise unres(f"'{ast.unparse(e)}' (Parameter reads a ROS parameter of the launch context; its value "
                    f"is known only at run time)")
    if name in _LOGIC:
        ops = list(e.args) if name in ("AllSubstitution", "AnySubstitution") else \
            [x for x in (a(0, "value" if name == "NotSubstitution" else "left"), a(1, "right")) if x is not None]
        if ops and all(not isinstance(x, ast.Starred) for x in ops):
            return f"$(logic {_LOGIC[name]} {' '.join(value(x) for x in ops)})"
    if name == "IfElseSubstitution":
        c, y, n = a(0, "condition"), a(1, "if_value"), a(2, "else_value")
        if c is not None:
            yes, no = (value(x) if x is not None else "" for x in (y, n))
            if not any(ch in re.sub(r"\$\([^()]*\)", "", yes + no) for ch in " ()$"):  # one word each
                return f"$(logic if {value(c)} {yes or '-'} {no or '-'})"
    if name == "StringJoinSubstitution":
        parts, sep = a(0, "substitutions"), a(1, "delimiter")
        if isinstance(parts, (ast.List, ast.Tuple)):
            return (value(sep) if sep is not None else "").join(value(x) for x in parts.elts)
    if name == "AnonName" and e.args:
        return f"$(anon {value(e.args[0])})"
    if name in ("FindPackagePrefix", "FindPackage") and e.args:
        return f"$(find-pkg-prefix {value(e.args[0])})"
    if name in ("ParameterFile", "ParameterValue"):
        x = a(0, "param_file" if name == "ParameterFile" else "value")
        if x is not None:
            return value(x)
    if name in ("RewrittenYaml", "ReplaceString"):
        x = a(0, "source_file")
        if x is not None:
            return WRITTEN[name == "ReplaceString"] + value(x)
    if name == "HasNodeParams":
        f, n = a(0, "source_file"), a(1, "node_name")
        if f is not None and n is not None:
            return f"$(has-node-params {value(n)} {value(f)})"
    return None


def _bool(text: str) -> bool:
    t = text.strip().lower()
    if t in ("true", "1"):
        return True
    if t in ("false", "0"):
        return False
    raise Unresolved(f"'{text}' is not true, false, 1 or 0")


def perform(kind: str, rest: list[str], here: Path) -> str | None:
    """The value of ``$(kind rest...)`` for this module's kinds (``None``: not
    one); ``here`` is the launch file read (a relative file is found from its
    directory). Raises :class:`Unresolved` saying why a value is not known."""
    if kind == "logic" and rest:
        op, xs = rest[0], rest[1:]
        if op == "not" and len(xs) == 1:
            return str(not _bool(xs[0])).lower()
        if op in ("and", "or") and xs:
            got = [_bool(x) for x in xs]
            return str(all(got) if op == "and" else any(got)).lower()
        if op == "if" and len(xs) == 3:
            pick = xs[1] if _bool(xs[0]) else xs[2]
            return "" if pick == "-" else pick
    if kind == "has-node-params" and len(rest) == 2:
        node, f = rest
        if f.startswith(WRITTEN):
            raise Unresolved(f"HasNodeParams of '{f}': a parameter file written when launched (its keys are "
                             f"known only at run time)")
        return "True" if node in _top_keys(Path(f) if Path(f).is_absolute() else here.parent / f) else "False"
    return None


def _top_keys(path: Path) -> set[str]:
    """The top-level keys of the YAML file at ``path`` (none when it is no
    mapping); raises :class:`Unresolved` when it cannot be read."""
    import yaml  # deferred: start-up (loads yaml only when called)
    from rclverify.model.plan.errors import PlanError  # deferred: start-up
    from rclverify.model.plan.yamlguard import safe_load_guarded  # deferred: start-up
    try:
        data = safe_load_guarded(safefs.read_text(path), str(path))
    except (OSError, ValueError, yaml.YAMLError, RecursionError, PlanError) as exc:
        raise Unresolved(f"HasNodeParams: {path.name} cannot be read ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})") from None
    return {str(k) for k in data} if isinstance(data, dict) else set()
