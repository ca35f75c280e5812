"""Launch files read statically: ROS 1 XML (roslaunch format), ROS 2 XML
and YAML (launch frontend), and ROS 2 Python through ``launch_ros2``
(no launch file is ever executed).

All formats become one element tree ``El(tag, attrs, children, src)``,
interpreted here:

* ``arg`` (``default``/``value``), ``let`` (ROS 2); substitutions ``$(arg x)``
  / ``$(var x)``, ``$(find pkg)`` / ``$(find-pkg-share pkg)``,
  ``$(env X)``, ``$(optenv X d)``, ``$(dirname)``; anything else
  (``$(eval ...)``, ``$(command ...)``) is reported unresolved, located;
* ``group`` with ``ns`` (ROS 1) or a ``push-ros-namespace`` child (ROS 2);
  ``if`` / ``unless`` on any element (``true``/``1`` or ``false``/``0``);
* ``node`` (``pkg``, ``type``/``exec``, ``name``, ``ns``/``namespace``) with
  ``remap`` and ``param`` (``name``/``value``: the node's private parameter)
  children, and ``remap``/``param`` in a scope (applies to the nodes after it);
* ROS 2 ``node_container`` / ``load_composable_node`` with ``composable_node``
  children (``pkg``, ``plugin``, ``name``, ``namespace``, ``remap``, ``param``):
  each is a node of class ``plugin`` (the container process itself is not);
* ``include`` (``file``, ``ns``, ``arg`` children, ``pass_all_args``), found
  relative to the packages of the scanned workspaces; include cycles stop.

Source: roslaunch XML format (wiki.ros.org/roslaunch/XML), ROS 2 launch
frontend design (design.ros2.org "ROS 2 Launch XML/YAML format").
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from rclverify.ros.extract import safefs
from rclverify.ros.extract import names
from rclverify.ros.extract.model import Note, Src
from rclverify.ros.extract.xmlsrc import line_of, parse_xml


@dataclass
class El:
    tag: str
    attrs: dict[str, str]
    children: list["El"]
    src: Src


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
    params: dict[str, tuple[str, Src]] = field(default_factory=dict)
    args: str | None = None  # the node's command-line ``args`` (a nodelet's ``load pkg/Type manager``)


@dataclass
class _Scope:
    ns: str
    args: dict[str, str]
    remaps: list[tuple[str, str, Src]] = field(default_factory=list)


class Unresolved(Exception):
    pass


_SUBST = re.compile(r"\$\(([^()]*)\)")


MAX_LAUNCH_FILES = 256      # launch files read per scan (all includes together)
MAX_INCLUDE_DEPTH = 20      # nested <include>s
MAX_SUBST_CHARS = 65_536    # length of one attribute after substitution


class Interpreter:
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

    def run(self, path: Path, args: dict[str, str] | None = None, ns: str = "/",
            remaps: list[tuple[str, str, Src]] | None = None) -> None:
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
        try:
            self._body(root.children, _Scope(ns, dict(args or {}), list(remaps or [])), path)
        finally:
            self._stack.pop()

    def _node_children(self, el: El, scope: _Scope, path: Path, node_ns: str,
                       name: str | None) -> tuple[list[tuple[str, str, Src]], dict[str, tuple[str, Src]]]:
        """A node's ``remap`` and ``param`` children (a node's ``param`` is private:
        ``~name``, kept as ``~name`` when the node's name is not known here)."""
        remaps = list(scope.remaps)
        params: dict[str, tuple[str, Src]] = {}
        for c in el.children:
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
                else:
                    pn, pv = self._attr(c, "name", scope, path), self._attr(c, "value", scope, path)
                    if not pn or pv is None:
                        raise Unresolved("param needs 'name' and 'value' (a parameter file is not read)")
                    params["~" + pn.lstrip("~/")] = (pv, c.src)
            except Unresolved as exc:
                self.notes.append(Note(c.src, f"<{c.tag}>: {exc}; element skipped", "ROS-LAUNCH"))
        return remaps, params

    def _composable(self, el: El, scope: _Scope, path: Path) -> None:
        """A ``composable_node`` (ROS 2 XML/YAML, or ``ComposableNode`` read by
        :mod:`launch_ros2`): the node of class ``plugin`` from package ``pkg``."""
        pkg, plugin = self._attr(el, "pkg", scope, path), self._attr(el, "plugin", scope, path)
        if not pkg or not plugin:
            raise Unresolved("composable_node needs 'pkg' and 'plugin'")
        name = self._attr(el, "name", scope, path)
        ns = self._attr(el, "namespace", scope, path) or self._attr(el, "ns", scope, path)
        node_ns = names.join(scope.ns, ns) if ns else scope.ns
        remaps, params = self._node_children(el, scope, path, node_ns, name)
        self.nodes.append(LaunchNode(pkg, "", name, node_ns, remaps, el.src, plugin, params))

    # -- substitutions
    def sub(self, text: str, scope: _Scope, path: Path) -> str:
        def one(m: re.Match[str]) -> str:
            parts = m.group(1).split()
            if not parts:
                raise Unresolved("empty substitution $()")
            kind, rest = parts[0], parts[1:]
            if kind == "var-default" and rest:  # a Python launch file's LaunchConfiguration(name, default=d)
                return scope.args[rest[0]] if rest[0] in scope.args else " ".join(rest[1:])
            if kind in ("arg", "var") and len(rest) == 1:
                if rest[0] not in scope.args:
                    raise Unresolved(f"$({kind} {rest[0]}): argument '{rest[0]}' has no value")
                return scope.args[rest[0]]
            if kind in ("find", "find-pkg-share", "find-pkg-prefix") and len(rest) == 1:
                d = self.pkg_dir(rest[0])
                if d is None:
                    raise Unresolved(f"$({kind} {rest[0]}): package '{rest[0]}' is not in the scanned workspaces")
                return str(d)
            if kind == "env" and len(rest) >= 1:
                v = os.environ.get(rest[0])
                if v is None:
                    if len(rest) > 1:
                        return " ".join(rest[1:])
                    raise Unresolved(f"$(env {rest[0]}): not set")
                return v
            if kind == "optenv" and rest:
                return os.environ.get(rest[0], " ".join(rest[1:]))
            if kind == "dirname":
                return str(path.parent)
            if kind == "anon" and rest:
                return rest[0]
            raise Unresolved(f"$({m.group(1)}) cannot be resolved statically")
        out = text
        for _ in range(10):
            new = _SUBST.sub(one, out)
            if len(new) > MAX_SUBST_CHARS:
                raise Unresolved(f"substitution expands beyond {MAX_SUBST_CHARS} characters")
            if new == out:
                break
            out = new
        return out

    def _attr(self, el: El, key: str, scope: _Scope, path: Path, default: str | None = None) -> str | None:
        v = el.attrs.get(key)
        return default if v is None else self.sub(v, scope, path)

    def _cond(self, el: El, scope: _Scope, path: Path) -> bool:
        for key, want in (("if", True), ("unless", False)):
            v = self._attr(el, key, scope, path)
            if v is None:
                continue
            lv = v.strip().lower()
            if lv in ("true", "1"):
                val = True
            elif lv in ("false", "0"):
                val = False
            else:
                raise Unresolved(f"{key}=\"{v}\" is not true/false/1/0")
            if val != want:
                return False
        return True

    def _body(self, els: list[El], scope: _Scope, path: Path) -> None:
        for el in els:
            try:
                if not self._cond(el, scope, path):
                    continue
                self._element(el, scope, path)
            except Unresolved as exc:
                self.notes.append(Note(el.src, f"<{el.tag}>: {exc}; element skipped", "ROS-LAUNCH"))

    def _element(self, el: El, scope: _Scope, path: Path) -> None:
        t = el.tag
        if t in ("arg", "let"):
            name = self._attr(el, "name", scope, path)
            if not name:
                raise Unresolved("no name")
            val = self._attr(el, "value", scope, path)
            if val is None:
                val = scope.args.get(name) if t == "arg" and name in scope.args else self._attr(el, "default", scope, path)
            if val is not None:
                scope.args[name] = val
        elif t == "group":
            ns = self._attr(el, "ns", scope, path) or self._attr(el, "namespace", scope, path)
            inner = _Scope(names.join(scope.ns, ns) if ns else scope.ns, scope.args if el.attrs.get("scoped") == "false"
                           else dict(scope.args), list(scope.remaps))
            self._body(el.children, inner, path)
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
            for c in el.children:
                if c.tag == "composable_node":
                    try:
                        if self._cond(c, scope, path):
                            self._composable(c, scope, path)
                    except Unresolved as exc:
                        self.notes.append(Note(c.src, f"<composable_node>: {exc}; element skipped", "ROS-LAUNCH"))
        elif t == "node":
            pkg = self._attr(el, "pkg", scope, path)
            exe = self._attr(el, "type", scope, path) or self._attr(el, "exec", scope, path)
            if not pkg or not exe:
                raise Unresolved("node needs 'pkg' and 'type'/'exec'")
            name = self._attr(el, "name", scope, path)
            ns = self._attr(el, "ns", scope, path) or self._attr(el, "namespace", scope, path)
            node_ns = names.join(scope.ns, ns) if ns else scope.ns
            remaps, params = self._node_children(el, scope, path, node_ns, name)
            self.nodes.append(LaunchNode(pkg, exe, name, node_ns, remaps, el.src, None, params,
                                         self._attr(el, "args", scope, path) if pkg == "nodelet" else None))
        elif t == "include":
            f = self._attr(el, "file", scope, path)
            if not f:
                raise Unresolved("include needs 'file'")
            target = Path(f)
            if not target.is_absolute():
                target = path.parent / target
            if not target.is_file():
                raise Unresolved(f"included file {f} not found")
            ns = self._attr(el, "ns", scope, path)
            args: dict[str, str] = dict(scope.args) if el.attrs.get("pass_all_args") == "true" else {}
            for c in el.children:
                if c.tag == "arg" and self._cond(c, scope, path):
                    n = self._attr(c, "name", scope, path)
                    v = self._attr(c, "value", scope, path) or self._attr(c, "default", scope, path)
                    if n and v is not None:
                        args[n] = v
            self.run(target, args, names.join(scope.ns, ns) if ns else scope.ns, scope.remaps)
        # rosparam, env, machine, test, executable ...: not part of the topic graph


# -- readers ------------------------------------------------------------

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
    return _from_xml(root, shown), []


def _yaml_el(tag: str, body: Any, shown: str, line: int) -> El:
    attrs: dict[str, str] = {}
    kids: list[El] = []
    if isinstance(body, dict):
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
    return El("launch", {}, _yaml_list(data["launch"], shown, 1), Src(shown, 1)), []


class _LineDict(dict):  # type: ignore[type-arg]
    line = 1
