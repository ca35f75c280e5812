"""A ROS 2 node's command-line ROS arguments as a launch file gives them:
``ros_arguments=[...]`` (XML/YAML ``ros_args``) whole, and the part of
``arguments=[...]`` (XML/YAML ``args``) after ``--ros-args`` up to ``--``.

* ``-r from:=to`` / ``--remap from:=to``: a remap of the node's names
  (``node:from:=to`` is kept whole: the graph applies it to the node of that
  name only, :func:`.namespaces.remap`, as rcl does, which also sorts out the
  several nodes of one process);
* ``-r __node:=n`` / ``__name:=n``: the node's name; ``-r __ns:=/ns``: its
  namespace (``node:__node:=n``: only when the launch file names the node
  ``node`` or gives no name; rcl matches the code's name, which the launch
  reader does not know);
* ``-p name:=value`` / ``--param name:=value``: a private parameter;
* the other flags (``--params-file f``, ``--log-level l``, ``-e enclave``,
  ``--enable-...`` ...) are not names and are passed over with their value.

Source: ROS 2 design "ROS command line arguments" (design.ros2.org,
``ros2/design`` articles/ros_command_line_arguments.md), docs.ros.org
"Passing ROS arguments to nodes via the command-line".
"""
from __future__ import annotations

from dataclasses import dataclass, field

#: flags followed by one value that is no name
_VALUED = {"--params-file", "--log-level", "--log-config-file", "-e", "--enclave", "--log-file-name"}


@dataclass
class RosArgs:
    """What a node's ROS arguments say: ``remaps`` ``[(from, to)]``, ``name``
    and ``ns`` (``None``: not given), ``params`` ``{name: value}`` and
    ``problems`` (tokens not understood, each a sentence)."""

    remaps: list[tuple[str, str]] = field(default_factory=list)
    name: str | None = None
    ns: str | None = None
    params: dict[str, str] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)


def after_ros_args(tokens: list[str]) -> list[str]:
    """The tokens of a program's ``arguments`` that are ROS arguments: each run
    from ``--ros-args`` up to ``--`` (or the end)."""
    out: list[str] = []
    inside = False
    for t in tokens:
        if t == "--ros-args":
            inside = True
        elif t == "--" and inside:
            inside = False
        elif inside:
            out.append(t)
    return out


def parse(tokens: list[str], node: str | None = None) -> RosArgs:
    """``tokens`` (ROS arguments, without ``--ros-args``) read for node ``node``
    (its name as the launch file gives it; ``None``: not known)."""
    got = RosArgs()
    i = 0
    while i < len(tokens):
        t = tokens[i]
        if t in ("-r", "--remap", "-p", "--param") and i + 1 < len(tokens):
            rule = tokens[i + 1]
            i += 2
            if ":=" not in rule:
                got.problems.append(f"'{t} {rule}' is not 'from:=to'")
                continue
            left, right = rule.split(":=", 1)
            if t in ("-p", "--param"):
                got.params[left] = right
                continue
            only, sep, bare = left.partition(":")
            if sep and not left.startswith("/") and bare in ("__node", "__name", "__ns"):
                if node is not None and only != node.rsplit("/", 1)[-1]:
                    continue  # node:__node:=n renames that node only
                left = bare
            if left in ("__node", "__name"):
                got.name = right
            elif left == "__ns":
                got.ns = right
            else:
                got.remaps.append((left, right))  # node:from:=to kept whole: the graph applies it to that node
        elif t in _VALUED:
            i += 2
        else:
            i += 1  # --enable-rosout-logs, --disable-stdout-logs ...: flags alone
    return got
