"""Launch files read statically: ROS 1 XML (roslaunch format), ROS 2 XML
and YAML (launch frontend), and ROS 2 Python through ``launch_ros2``
(no launch file is ever executed).

All formats become one element tree ``El(tag, attrs, children, src)``
(:mod:`launch_tree`; XML and YAML read by :mod:`launch_readers`),
interpreted here:

* ``arg`` (``default``/``value``), ``let`` (ROS 2); substitutions ``$(arg x)``
  / ``$(var x)``, ``$(find pkg)`` / ``$(find-pkg-share pkg)``,
  ``$(env X)``, ``$(optenv X d)``, ``$(dirname)``; anything else
  ``$(eval ...)`` of literals, ``not``, ``and``, ``or``, ``==``, ``!=``,
  ``in`` (:func:`evaluate`); anything else (``$(command ...)``, an
  ``$(eval)`` of names or calls) is reported unresolved, located;
* ``group`` with ``ns`` (ROS 1) or a ``push-ros-namespace`` child (ROS 2);
  ``if`` / ``unless`` on any element (``true``/``1`` or ``false``/``0``,
  any case); a condition that cannot be evaluated is read as holding, with
  a note (the element is never dropped for it);
* ``node`` (``pkg``, ``type``/``exec``, ``name``, ``ns``/``namespace``) with
  ``remap`` and ``param`` (``name``/``value``: the node's private parameter)
  children, and ``remap``/``param`` in a scope (applies to the nodes after it);
* ROS 2 ``node_container`` / ``load_composable_node`` with ``composable_node``
  children (``pkg``, ``plugin``, ``name``, ``namespace``, ``remap``, ``param``):
  each is a node of class ``plugin`` (the container process itself is not);
* ``include`` (``file``, ``ns``, ``arg`` children, ``pass_all_args``), found
  relative to the packages of the scanned workspaces; include cycles stop.
  A ROS 1 include gives the included file only its ``arg`` children (all with
  ``pass_all_args``); a ROS 2 one (:func:`.launch_tree.ros2_file`) sets them
  in the including scope and reads the file there, as launch does;
* ``group`` ``scoped="false"`` / ``forwarding="false"`` with ``keep``
  children, as launch's ``GroupAction`` (groups and includes:
  :mod:`launch_scope`).

Source: roslaunch XML format (wiki.ros.org/roslaunch/XML), ROS 2 launch
frontend design (design.ros2.org "ROS 2 Launch XML/YAML format").  An
element's attributes (substitutions, conditions, ROS arguments) are read by
:mod:`launch_attrs`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from rclverify.ros.extract import launch_subst, names, param_yaml
from rclverify.ros.extract.launch_attrs import AttrReading
from rclverify.ros.extract.launch_readers import read_xml as read_xml, read_yaml as read_yaml
from rclverify.ros.extract.launch_scope import Scope as _Scope, ScopeActions
from rclverify.ros.extract.launch_tree import ALIASES, SEP as SEP, UNREAD as UNREAD, El as El
from rclverify.ros.extract.launch_tree import QUIET_TAGS, UNREAD_TAGS as _UNREAD_TAGS, ros2_file
from rclverify.ros.extract.launch_tree import Unresolved as Unresolved, evaluate as evaluate
from rclverify.ros.extract.model import Note, Src


@dataclass
class LaunchNode:
    """A node a launch file starts: resolved name and namespace, remaps
    ``[(from, to, Src)]`` as written (resolved per node by the graph)."""

    pkg: str
    exe: str
    name: str | None
    ns: str
    remaps: list[tuple[str, str, Src]]
    src: Src
    plugin: str | None = None  # a composable node's class (``ns::Class``); ``exe`` is then ""
    # the node's private parameters the launch file sets: ``~name`` -> (value, where set)
    params: dict[str, tuple[param_yaml.Value, Src]] = field(default_factory=dict)
    args: str | None = None  # the node's command-line ``args`` (a nodelet's ``load pkg/Type manager``)
    # where a condition guarding the node could not be evaluated (the node was read as if it held)
    unsure: Src | None = None
    # the parameters of files given to a node this launch file does not name, for the name its code gives
    # (``param_yaml.pending_for``)
    pending: list[param_yaml.Entry] = field(default_factory=list)


MAX_LAUNCH_FILES = 256      # launch files read per scan (all includes together)
MAX_INCLUDE_DEPTH = 20      # nested <include>s


class Interpreter(AttrReading, ScopeActions):
    """Walk launch trees; ``pkg_dir(name)`` finds a package directory,
    ``load(path, shown)`` reads a launch file into ``(El | None, [Note])``,
    ``show(path)`` gives the path shown in locations."""

    def __init__(self, pkg_dir: Callable[[str], Path | None], load: Callable[[Path], tuple[El | None, list[Note]]],
                 show: Callable[[Path], str]) -> None:
        self.pkg_dir = pkg_dir
        self.load = load
        self.show = show
        self.nodes: list[LaunchNode] = []
        self.notes: list[Note] = []
        self.files: list[Path] = []
        # parameters set outside any node (ROS 1 ``<param>`` in a scope): resolved name -> (value, where)
        self.params: dict[str, tuple[str, Src]] = {}
        self._stack: list[Path] = []
        self._cut = False
        self._guess: Src | None = None  # set by _cond when it takes an unevaluated condition as holding
        self.ros2: dict[Path, bool] = {}  # whether a file read is a ROS 2 launch file (its includes share the scope)

    def run(self, path: Path, args: dict[str, str] | None = None, ns: str = "/",
            remaps: list[tuple[str, str, Src]] | None = None, unsure: Src | None = None,
            shared: _Scope | None = None) -> None:
        """Read launch file ``path`` with launch arguments ``args`` under namespace
        ``ns`` and ``remaps``; with ``shared`` (a ROS 2 include), in the including
        scope itself: ROS 2 launch sets an include's arguments as launch
        configurations of the including context and reads the included file in
        that context, so what it declares, pushes or remaps stays after it unless
        a scoped group holds the include (launch's ``IncludeLaunchDescription``,
        ``GroupAction``)."""
        path = path.resolve() if path.exists() else path
        if path in self._stack or len(self._stack) > MAX_INCLUDE_DEPTH:
            self.notes.append(Note(Src(self.show(path)), "include cycle: file already being read", "ROS-LAUNCH"))
            return
        if len(self.files) >= MAX_LAUNCH_FILES:
            if not self._cut:
                self._cut = True
                self.notes.append(Note(Src(self.show(path)), f"more than {MAX_LAUNCH_FILES} launch files "
                                                             f"included: this include and later ones skipped",
                                       "ROS-LAUNCH"))
            return
        root, notes = self.load(path)
        self.notes.extend(notes)
        self.files.append(path)
        if root is None:
            return
        self._stack.append(path)
        self.ros2[path] = ros2_file(path, root)
        try:
            self._body(root.children, shared if shared is not None
                       else _Scope(ns, dict(args or {}), list(remaps or []), unsure), path)
        finally:
            self._stack.pop()

    def _node_children(self, el: El, scope: _Scope, path: Path, node_ns: str,
                       name: str | None) -> tuple[list[tuple[str, str, Src]], dict[str, tuple[param_yaml.Value, Src]],
                                                   list[param_yaml.Entry]]:
        """A node's ``remap`` and ``param`` children (a node's ``param`` is private:
        ``~name``, kept as ``~name`` when the node's name is not known here), and the parameters of the files
        it is given that wait for its name (``pending``)."""
        remaps = list(scope.remaps)
        params: dict[str, tuple[param_yaml.Value, Src]] = {}
        pending: list[param_yaml.Entry] = []
        for c in el.children:
            if c.tag == "rosparam" and self._cond(c, scope, path):
                for k, v in self._rosparam(c, scope, path).items():
                    params["~" + k.lstrip("~/")] = (v, c.src)
            if c.tag not in ("remap", "param"):
                continue
            try:
                if not self._cond(c, scope, path):
                    continue
                if c.tag == "remap":
                    frm, to = self._attr(c, "from", scope, path), self._attr(c, "to", scope, path)
                    if not frm or not to:
                        raise Unresolved("remap needs 'from' and 'to'")
                    remaps.append((frm, to, c.src))
                elif "from" in c.attrs:  # a ROS 2 parameter file (param_yaml.launch_file_params)
                    f = self._attr(c, "from", scope, path) or ""
                    written = next((w for w in launch_subst.WRITTEN if f.startswith(w)), "")
                    f = f[len(written):]
                    if written:  # RewrittenYaml / ReplaceString: the source file, as written
                        self.notes.append(Note(c.src, f"parameter file {self.show(Path(f))} is rewritten when launched: its values "
                                                      f"are read as the source file writes them, the rewrites "
                                                      f"(root_key, param_rewrites) are not applied", "ROS-LAUNCH"))
                    if not Path(f).is_absolute():  # ros2 launch opens it from the directory it runs in
                        raise Unresolved(f"parameter file '{f}' is a relative path, read from the directory "
                                         f"ros2 launch runs in: not known statically; its parameters are not read")
                    got, said = param_yaml.launch_file_params(Path(f), self.show(Path(f)), names.join(node_ns, name)
                                                              if name else None, pending)
                    self.notes.extend(said)
                    params.update(got)
                else:
                    pn, pv = self._attr(c, "name", scope, path), self._attr(c, "value", scope, path)
                    if not pn or pv is None:
                        raise Unresolved("param needs 'name' and 'value', or 'from' (a parameter file)")
                    params["~" + pn.lstrip("~/")] = (pv, c.src)
            except Unresolved as exc:
                self.notes.append(Note(c.src, f"<{c.tag}>: {exc}; element skipped", "ROS-LAUNCH"))
        return remaps, params, pending

    def _rosparam(self, el: El, scope: _Scope, path: Path) -> dict[str, str]:
        """The parameters a ROS 1 ``<rosparam command="load" file="...">`` loads
        (names relative to its ``ns``); any other form, or a file that cannot be
        read, is said with a located note and loads nothing read."""
        cmd = self._attr(el, "command", scope, path) or "load"
        f = self._attr(el, "file", scope, path)
        ns = (self._attr(el, "ns", scope, path) or "").strip("/")
        got = param_yaml.rosparam_file(Path(f) if Path(f).is_absolute() else path.parent / f) \
            if cmd == "load" and f else f"<rosparam command=\"{cmd}\"> without a file"
        if isinstance(got, str):
            self.notes.append(Note(el.src, f"<rosparam>: {f or ''} {got}: {_UNREAD_TAGS['rosparam']}".replace("  ", " "),
                                   "ROS-LAUNCH"))
            return {}
        return {f"{ns}/{k}" if ns else k: v for k, v in got.items()}

    def _composable(self, el: El, scope: _Scope, path: Path) -> None:
        """A ``composable_node`` (ROS 2 XML/YAML, or ``ComposableNode`` read by
        :mod:`launch_ros2`): the node of class ``plugin`` from package ``pkg``."""
        pkg, plugin = self._attr(el, "pkg", scope, path), self._attr(el, "plugin", scope, path)
        if not pkg or not plugin:
            raise Unresolved("composable_node needs 'pkg' and 'plugin'")
        name = self._soft(el, "name", scope, path)
        ns = self._soft(el, "namespace", scope, path) or self._soft(el, "ns", scope, path)
        node_ns = names.join(scope.ns, ns) if ns else scope.ns
        remaps, params, pending = self._node_children(el, scope, path, node_ns, name)
        self.nodes.append(LaunchNode(pkg, "", name, node_ns, remaps, el.src, plugin, params,
                                     unsure=scope.unsure, pending=pending))

    def _body(self, els: list[El], scope: _Scope, path: Path) -> None:
        for el in els:
            outer = scope.unsure
            try:
                self._guess = None
                if not self._cond(el, scope, path):
                    continue
                scope.unsure = outer or self._guess
                self._element(el, scope, path)
            except Unresolved as exc:
                self.notes.append(Note(el.src, f"<{el.tag}>: {exc}; element skipped", "ROS-LAUNCH"))
            finally:
                scope.unsure = outer

    def _element(self, el: El, scope: _Scope, path: Path) -> None:
        t = ALIASES.get(el.tag, el.tag)
        if t in ("arg", "let"):
            name = self._attr(el, "name", scope, path)
            if not name:
                raise Unresolved("no name")
            try:
                val = self._attr(el, "value", scope, path)
                if val is None:
                    val = scope.args.get(name) if t == "arg" and name in scope.args \
                        else self._attr(el, "default", scope, path)
            except Unresolved as exc:  # the argument stays without a value; what uses it says so
                self.notes.append(Note(el.src, f"<{t}> {name}: {exc}; the argument has no value", "ROS-LAUNCH"))
                return
            if val is not None:
                scope.args[name] = val
        elif t in ("group", "reset"):  # XML/YAML <reset> is launch's ResetLaunchConfigurations
            self._group(el, scope, path)
        elif t == "push-configs":  # PushLaunchConfigurations / PopLaunchConfigurations (launch.actions)
            scope.saved.append((dict(scope.args), scope.ns, list(scope.remaps)))
        elif t == "pop-configs":
            if not scope.saved:
                raise Unresolved("PopLaunchConfigurations without a PushLaunchConfigurations before it in its scope")
            args, scope.ns, scope.remaps[:] = scope.saved.pop()
            scope.args.clear()
            scope.args.update(args)
        elif t == "push-ros-namespace":
            ns = self._attr(el, "namespace", scope, path) or self._attr(el, "ns", scope, path) or ""
            scope.ns = names.join(scope.ns, ns)
        elif t == "remap":
            frm, to = self._attr(el, "from", scope, path), self._attr(el, "to", scope, path)
            if not frm or not to:
                raise Unresolved("remap needs 'from' and 'to'")
            scope.remaps.append((frm, to, el.src))
        elif t == "param":
            name, val = self._attr(el, "name", scope, path), self._attr(el, "value", scope, path)
            if name and val is not None:
                self.params[names.join(scope.ns, name)] = (val, el.src)
        elif t in ("node_container", "load_composable_node"):
            if t == "node_container":
                self._container_note(el, scope, path)
            for c in el.children:
                if c.tag == "composable_node":
                    outer = scope.unsure
                    try:
                        self._guess = None
                        if self._cond(c, scope, path):
                            scope.unsure = outer or self._guess
                            self._composable(c, scope, path)
                    except Unresolved as exc:
                        self.notes.append(Note(c.src, f"<composable_node>: {exc}; element skipped", "ROS-LAUNCH"))
                    finally:
                        scope.unsure = outer
        elif t == "node":
            self._node_element(el, scope, path)
        elif t == "include":
            self._include_element(el, scope, path)
        elif t == "rosparam":
            for k, v in self._rosparam(el, scope, path).items():
                self.params[names.join(scope.ns, k)] = (v, el.src)
        elif t == "unread":
            self.notes.append(Note(el.src, el.attrs.get("what", "element not read"), "ROS-LAUNCH"))
        elif t not in QUIET_TAGS:
            self.notes.append(Note(el.src, f"<{el.tag}> is not an element the scan reads: "
                                           f"{_UNREAD_TAGS.get(t, 'the nodes it starts, if any, are unknown')}",
                                   "ROS-LAUNCH"))

    def _container_note(self, el: El, scope: _Scope, path: Path) -> None:
        """The located ``ROS-CONTAINER`` note of a component container ``el`` starts (a
        ``node_container`` element or a ``Node`` running ``rclcpp_components``'
        ``component_container*``): no node of the graph, its components are."""
        def read(key: str) -> str | None:  # the container's names are only shown: one not read is left out
            try:
                return self._attr(el, key, scope, path)
            except Unresolved:
                return None
        name, ns = read("name"), read("ns") or read("namespace")
        shown = names.join(names.join(scope.ns, ns) if ns else scope.ns, name) if name else "(name not read)"
        self.notes.append(Note(el.src, f"component container '{shown}' is started here: a container is no "
                                       f"node of the graph (its endpoints are rclcpp_components'); its "
                                       f"components are", "ROS-CONTAINER"))

    def _node_element(self, el: El, scope: _Scope, path: Path) -> None:
        """A ``<node>`` (ROS 1) or ``<node>``/``<lifecycle_node>`` (ROS 2 XML, YAML) in ``scope``: one
        :class:`LaunchNode` with its name, namespace, remaps and parameters as launch gives them.
        Raises :class:`Unresolved` when its package or executable is not known."""
        pkg = self._attr(el, "pkg", scope, path)
        exe = self._attr(el, "type", scope, path) or self._attr(el, "exec", scope, path)
        if not pkg or not exe:
            raise Unresolved("node needs 'pkg' and 'type'/'exec'")
        if pkg == "rclcpp_components" and exe.startswith("component_container"):
            self._container_note(el, scope, path)
            return
        name = self._soft(el, "name", scope, path)
        ns = self._soft(el, "ns", scope, path) or self._soft(el, "namespace", scope, path)
        given = self._ros_args(el, scope, path, name)
        name, ns = given.name or name, given.ns or ns
        node_ns = names.join(scope.ns, ns) if ns else scope.ns
        remaps, params, pending = self._node_children(el, scope, path, node_ns, name)
        remaps += [(frm, to, el.src) for frm, to in given.remaps]
        params.update({"~" + k.lstrip("~/"): (v, el.src) for k, v in given.params.items()})
        self.nodes.append(LaunchNode(pkg, exe, name, node_ns, remaps, el.src, None, params,
                                     self._attr(el, "args", scope, path) if pkg == "nodelet" else None,
                                     scope.unsure, pending))
