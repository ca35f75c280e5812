"""What a launch file's scope holds and the actions that open, share or reset
one, for :class:`~.launch.Interpreter`: groups (launch's ``GroupAction``, ROS
1's ``<group ns>``) and includes (roslaunch's, which give the included file
only the arguments passed; ROS 2 launch's, which read it in the including
scope).

Source: launch's ``IncludeLaunchDescription.execute``,
``DeclareLaunchArgument.execute``, ``GroupAction.get_sub_entities``,
``ResetLaunchConfigurations`` (ros2/launch); roslaunch XML ``<include>``
(wiki.ros.org/roslaunch/XML/include).
"""
from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass, field
from pathlib import Path

from rclverify.ros.extract import names
from rclverify.ros.extract.launch_tree import NOVALUE, El, Unresolved
from rclverify.ros.extract.model import Src


@dataclass
class Scope:
    ns: str
    args: dict[str, str]
    remaps: list[tuple[str, str, Src]] = field(default_factory=list)
    unsure: Src | None = None  # a condition of an enclosing element read as holding without being evaluated
    # what PushLaunchConfigurations saved (configurations, namespace, remaps: all launch configurations)
    saved: list[tuple[dict[str, str], str, list[tuple[str, str, Src]]]] = field(default_factory=list)


class ScopeActions:
    """The scope-opening actions of :class:`~.launch.Interpreter`, which gives
    the methods declared here (reading an attribute, a condition, a body, a file)."""

    ros2: dict[Path, bool]  # whether a file read is a ROS 2 launch file (its includes share the scope)

    @abstractmethod
    def _attr(self, el: El, key: str, scope: Scope, path: Path, default: str | None = None) -> str | None:
        ...

    @abstractmethod
    def _cond(self, el: El, scope: Scope, path: Path) -> bool:
        ...

    @abstractmethod
    def _body(self, els: list[El], scope: Scope, path: Path) -> None:
        ...

    @abstractmethod
    def run(self, path: Path, args: dict[str, str] | None = None, ns: str = "/",
            remaps: list[tuple[str, str, Src]] | None = None, unsure: Src | None = None,
            shared: Scope | None = None) -> None:
        ...

    def _group(self, el: El, scope: Scope, path: Path) -> None:
        """A ``group`` (ROS 1 ``ns``; launch's ``GroupAction``): scoped unless
        ``scoped="false"`` (what it sets stays after it: also OpaqueFunction's,
        an event handler's or a timer's actions); ``forwarding="false"`` starts it
        from its ``keep`` configurations alone, the namespace and remaps (launch
        configurations too) cleared; ``keep`` children (``launch_configurations=``)
        are set in it; ``reset="true"`` (``ResetLaunchConfigurations``) clears the
        scope's configurations, namespace and remaps but its ``keep`` ones.  Source: launch's ``GroupAction.get_sub_entities``,
        ``ResetLaunchConfigurations``."""
        ns = self._attr(el, "ns", scope, path) or self._attr(el, "namespace", scope, path)
        keep = {self._attr(k, "name", scope, path) or "": self._attr(k, "value", scope, path) or ""
                for k in el.children if k.tag == "keep"}
        body = [k for k in el.children if k.tag != "keep"]
        if el.tag == "reset" or el.attrs.get("reset") == "true":  # ResetLaunchConfigurations: the kept ones stay
            scope.args.clear()
            scope.args.update(keep)
            scope.ns, scope.remaps[:] = "/", []
        elif el.attrs.get("scoped") == "false" and not ns:
            scope.args.update(keep)
            self._body(body, scope, path)
        elif el.attrs.get("forwarding") == "false":
            self._body(body, Scope("/", keep, [], scope.unsure), path)
        else:
            self._body(body, Scope(names.join(scope.ns, ns) if ns else scope.ns, {**scope.args, **keep},
                                    list(scope.remaps), scope.unsure), path)

    def _include_element(self, el: El, scope: Scope, path: Path) -> None:
        """An ``<include>`` in ``scope``: the included file read with its arguments (``pass_all_args``
        and its ``<arg>`` children) under the scope's namespace and remaps.  Raises
        :class:`Unresolved` when the file is not named or not found."""
        f = self._attr(el, "file", scope, path)
        if not f:
            raise Unresolved("include needs 'file'")
        target = Path(f)
        if not target.is_absolute():
            target = path.parent / target
        if not target.is_file():
            raise Unresolved(f"included file {f} not found")
        ns = self._attr(el, "ns", scope, path)
        if self.ros2.get(path.resolve() if path.exists() else path) and not ns:
            self._include_ros2(el, target, scope, path)
            return
        args: dict[str, str] = dict(scope.args) if el.attrs.get("pass_all_args") == "true" else {}
        for c in el.children:
            if c.tag == "arg" and self._cond(c, scope, path):
                n = self._attr(c, "name", scope, path)
                if n and c.attrs.get("novalue"):  # a value its reader could not read (said there)
                    args[n] = NOVALUE
                    continue
                v = self._attr(c, "value", scope, path) or self._attr(c, "default", scope, path)
                if n and v is not None:
                    args[n] = v
        self.run(target, args, names.join(scope.ns, ns) if ns else scope.ns, scope.remaps, scope.unsure)

    def _include_ros2(self, el: El, target: Path, scope: Scope, path: Path) -> None:
        """A ROS 2 include: its arguments set, in order, as launch configurations of
        ``scope`` (a later one reads an earlier one), then ``target`` read in ``scope``
        itself: it sees every configuration set before it (a ``DeclareLaunchArgument``
        default gives way to any), and what it sets stays after it (launch's
        ``IncludeLaunchDescription.execute``, ``DeclareLaunchArgument.execute``)."""
        for c in el.children:
            if c.tag == "arg" and self._cond(c, scope, path):
                n = self._attr(c, "name", scope, path)
                if n and c.attrs.get("novalue"):  # a value its reader could not read (said there)
                    scope.args[n] = NOVALUE
                    continue
                v = self._attr(c, "value", scope, path)
                if n and v is not None:
                    scope.args[n] = v
        self.run(target, shared=scope)
