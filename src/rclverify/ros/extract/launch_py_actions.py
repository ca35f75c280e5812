"""The launch actions a ROS 2 Python launch file's evaluator (:mod:`launch_ros2`)
knows by name, and the keyword arguments every action reads alike: the actions
that start no node (passed over), the event handlers and where their actions
are, the scope-setting actions of two arguments; a node's required and
optional keywords, an action's ``condition``; the actions of an
``OnShutdown`` handler, which launch never starts as processes.

Source: ``launch.actions``, ``launch.event_handlers``, ``launch_ros.actions``,
``launch_ros.event_handlers`` (ros2/launch, ros2/launch_ros); launch's
``ExecuteLocal.execute`` starts nothing once the launch context is shutting
down.
"""
from __future__ import annotations

import ast

from rclverify.ros.extract.launch_tree import NOVALUE, UNREAD, El
from rclverify.ros.extract.launch_py_values import Unres as _Unres, callee as _callee, expand as _expand
from rclverify.ros.extract.launch_py_values import arg as _arg, kw as _kw, value as _value
from rclverify.ros.extract.model import Note, Src

#: actions that start no node and set nothing the graph reads (passed over without a note)
QUIET = frozenset({"LogInfo", "SetEnvironmentVariable", "UnsetEnvironmentVariable", "AppendEnvironmentVariable",
                   "PrependEnvironmentVariable", "ResetEnvironment", "SetParameter", "SetParametersFromFile",
                   "SetUseSimTime", "SetROSLogDir", "Shutdown", "EmitEvent", "PopEnvironment", "PushEnvironment",
                   "SetLaunchConfigurationIfUnset", "LifecycleTransition", "UnregisterEventHandler"})
#: event handlers and the keywords holding the actions each starts (launch.event_handlers,
#: launch_ros.event_handlers; OnProcessIO's are functions of the output, always run at the event)
HANDLERS = {"OnProcessExit": ("on_exit",), "OnProcessStart": ("on_start",),
            "OnExecutionComplete": ("on_completion",), "OnStateTransition": ("entities",),
            "EventHandler": ("entities",), "OnShutdown": ("on_shutdown",),
            "OnProcessIO": ("on_stdout", "on_stderr", "on_stdin")}
#: launch's actions on the stack of launch configurations -> the element each is
CONFIG_STACK = {"PushLaunchConfigurations": "push-configs", "PopLaunchConfigurations": "pop-configs",
                "ResetLaunchConfigurations": "group"}
#: the tags of the elements that start a node
STARTS = ("node", "node_container", "load_composable_node", "composable_node", "include")

#: action -> (element tag, (keyword, attribute) of its first and second argument, why one without them
#: is not read): the scope-setting actions of two arguments
PAIRS: dict[str, tuple[str, tuple[str, str], tuple[str, str], str]] = {
    "SetRemap": ("remap", ("src", "from"), ("dst", "to"), "a remap without src and dst"),
    "SetLaunchConfiguration": ("let", ("name", "name"), ("value", "value"), "a configuration without name and value"),
}


def required(c: ast.Call, attrs: dict[str, str], keys: tuple[tuple[str, str], ...]) -> None:
    """The keyword arguments ``keys`` (``(python name, attribute)``) of action
    ``c`` without which it starts nothing known (its package, executable or
    plugin): one that cannot be read raises :class:`_Unres` naming it."""
    for py, key in keys:
        v = _kw(c, py)
        if v is not None:
            try:
                attrs[key] = _value(v)
            except _Unres as exc:
                raise _Unres(f"{py} {exc}") from None


def optional(c: ast.Call, attrs: dict[str, str], keys: tuple[tuple[str, str], ...], shown: str,
              notes: list[Note]) -> None:
    """The keyword arguments ``keys`` (``(python name, attribute)``) of action
    ``c`` that the node can do without: one that cannot be read is left out of
    ``attrs``, said with a located note."""
    what = _callee(c)
    for py, key in keys:
        v = _kw(c, py)
        if v is None:
            continue
        try:
            attrs[key] = _value(v)
        except _Unres as exc:
            notes.append(Note(Src(shown, v.lineno, v.col_offset + 1), f"{what}(...): {py} {exc} cannot be read "
                              f"statically; the {py} the code gives is kept", "ROS-LAUNCH"))


def condition(c: ast.Call, attrs: dict[str, str], shown: str, notes: list[Note]) -> None:
    """``condition=IfCondition(x)`` / ``UnlessCondition(x)`` of action ``c`` as
    an ``if`` / ``unless`` attribute, ``LaunchConfigurationEquals(name, value)``
    / ``LaunchConfigurationNotEquals`` as an ``if`` comparing the configuration's
    value with ``value`` (launch.conditions); one that cannot be read leaves
    the action unconditional, said with a located note."""
    cond = _kw(c, "condition")
    if cond is None:
        return
    cond = _expand(cond)
    at = Src(shown, cond.lineno, cond.col_offset + 1)
    kind = _callee(cond) if isinstance(cond, ast.Call) else ""
    try:
        if kind in ("LaunchConfigurationEquals", "LaunchConfigurationNotEquals") and isinstance(cond, ast.Call):
            n, v = _arg(cond, 0, "launch_configuration_name"), _arg(cond, 1, "expected_value")
            if n is None or v is None:
                raise _Unres(f"'{ast.unparse(cond)}' (a comparison without a name and a value)")
            name, want = _value(n), _value(v)
            if "'" in name + want or "\\" in name + want or " " in name:
                raise _Unres(f"'{ast.unparse(cond)}' (a quote or a space in a compared value)")
            attrs["if"] = f"$(eval '$(var {name})' {'==' if kind.endswith('Equals') and 'Not' not in kind else '!='} '{want}')"
            return
        if kind not in ("IfCondition", "UnlessCondition") or not isinstance(cond, ast.Call) or len(cond.args) != 1:
            raise _Unres(f"'{ast.unparse(cond)}' (not IfCondition(x) or UnlessCondition(x))")
        attrs["if" if kind == "IfCondition" else "unless"] = _value(cond.args[0])
    except _Unres as exc:
        notes.append(Note(at, f"{_callee(c)}(...): condition {exc} cannot be read statically; the action is read "
                              f"as if it held", "ROS-LAUNCH"))
        attrs[UNREAD] = str(at)


def at_shutdown(els: list[El], handler: Src, notes: list[Note]) -> None:
    """The actions of an ``OnShutdown`` handler (``handler``): launch starts no
    process once it is shutting down (``ExecuteLocal.execute`` returns when
    ``context.is_shutdown``), so each node they would start is said at its
    line, never a node of the graph; what else they hold that the scan cannot
    read (an ``OpaqueFunction`` removing a file) starts nothing either and is
    not said."""
    for el in els:
        if el.tag in STARTS:
            what = el.attrs.get("exec") or el.attrs.get("plugin") or el.attrs.get("file") or el.tag
            notes.append(Note(el.src, f"{el.tag} '{what}' is started by OnShutdown ({handler}): launch starts no "
                                      f"process once it is shutting down; not a node of the graph", "ROS-LAUNCH"))
        at_shutdown(el.children, handler, notes)


def group_flags(c: ast.Call, attrs: dict[str, str], shown: str, notes: list[Note]) -> dict[str, str]:
    """``GroupAction``'s ``scoped=`` and ``forwarding=`` as the group's attributes
    (a value not a literal bool is said; launch's default, ``True``, is kept)."""
    for key in ("scoped", "forwarding"):
        v = _kw(c, key)
        if v is None:
            continue
        v = _expand(v)
        if isinstance(v, ast.Constant) and isinstance(v.value, bool):
            if not v.value:
                attrs[key] = "false"
        else:
            notes.append(Note(Src(shown, v.lineno, v.col_offset + 1), f"GroupAction(...): {key}="
                              f"'{ast.unparse(v)}' is not a literal bool; read as True", "ROS-LAUNCH"))
    return attrs


def group_keep(c: ast.Call, shown: str, notes: list[Note]) -> list[El]:
    """``GroupAction(launch_configurations={k: v})`` (and ``ResetLaunchConfigurations``'s
    argument) as ``keep`` elements: set in the group, and with ``forwarding=False``
    or a reset the only configurations kept.  A value that cannot be read is set
    without a value, said at its line; raises :class:`_Unres` for a mapping that
    is not a literal dict."""
    lc = _kw(c, "launch_configurations")
    if lc is None and _callee(c) == "ResetLaunchConfigurations" and c.args:
        lc = c.args[0]
    if lc is None or isinstance(lc, ast.Constant) and lc.value is None:
        return []
    lc = _expand(lc)
    if not isinstance(lc, ast.Dict):
        raise _Unres(f"launch_configurations '{ast.unparse(lc)}'")
    out = []
    for k, v in zip(lc.keys, lc.values):
        if k is None:
            continue
        n = _value(k)
        try:
            out.append(El("keep", {"name": n, "value": _value(v)}, [], Src(shown, v.lineno, v.col_offset + 1)))
        except _Unres as exc:
            notes.append(Note(Src(shown, v.lineno, v.col_offset + 1), f"{_callee(c)}(...): launch configuration "
                              f"'{n}' {exc} cannot be read statically; the group reads it without a value",
                              "ROS-LAUNCH"))
            out.append(El("keep", {"name": n, "value": NOVALUE}, [], Src(shown, v.lineno, v.col_offset + 1)))
    return out
