"""An element's attributes as the launch interpreter (:mod:`launch`) reads
them: substitutions (``$(arg x)``, ``$(find pkg)``, ``$(env X)``, ``$(eval
...)``, :meth:`AttrReading.sub`), an attribute a node can do without, a
ROS 2 node's ROS arguments, and ``if``/``unless`` conditions (one that
cannot be evaluated statically is taken to hold, with a located note).
Mixed into :class:`~.launch.Interpreter`, which provides the attributes
annotated on the class.
"""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Callable

from rclverify.ros.extract import launch_subst
from rclverify.ros.extract.launch_rosargs import RosArgs, after_ros_args, parse as parse_ros_args
from rclverify.ros.extract.launch_scope import Scope as _Scope
from rclverify.ros.extract.launch_tree import NOVALUE, SEP, UNREAD, El, Unresolved, evaluate
from rclverify.ros.extract.model import Note, Src

_SUBST = re.compile(r"\$\(([^()]*)\)")
MAX_SUBST_CHARS = 65_536    # length of one attribute after substitution


class AttrReading:
    """Reading an element's attributes (module docstring)."""

    pkg_dir: Callable[[str], Path | None]
    notes: list[Note]
    _guess: Src | None  # set by _cond when it takes an unevaluated condition as holding

    def sub(self, text: str, scope: _Scope, path: Path) -> str:
        def one(m: re.Match[str]) -> str:
            parts = m.group(1).split()
            if not parts:
                raise Unresolved("empty substitution $()")
            kind, rest = parts[0], parts[1:]
            if kind in ("var-default", "arg", "var") and rest and scope.args.get(rest[0]) == NOVALUE:
                raise Unresolved(f"$({kind} {rest[0]}): argument '{rest[0]}' has no value read statically "
                                 f"(the include giving it says why)")
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
            if kind == "as-bool":  # Nav2's LaunchConfigAsBool (nav2_common/launch/launch_config_as_bool.py)
                return "True" if " ".join(rest).strip().lower() in ("true", "1", "yes", "on") else "False"
            if kind == "dirname":
                return str(path.parent)
            if kind == "anon" and rest:
                return rest[0]
            if kind == "eval" and rest:
                return evaluate(m.group(1)[len("eval"):].strip())
            got = launch_subst.perform(kind, rest, path)
            if got is not None:
                return got
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

    def _soft(self, el: El, key: str, scope: _Scope, path: Path) -> str | None:
        """Attribute ``key`` of a node the node can do without (its name,
        namespace): one that cannot be resolved is dropped, said with a located
        note; the node is kept."""
        try:
            return self._attr(el, key, scope, path)
        except Unresolved as exc:
            self.notes.append(Note(el.src, f"<{el.tag}>: {key}: {exc}; the node is kept without it", "ROS-LAUNCH"))
            return None

    def _ros_args(self, el: El, scope: _Scope, path: Path, name: str | None) -> RosArgs:
        """A ROS 2 node's ROS arguments (``ros_args``, and ``args`` after
        ``--ros-args``; :mod:`launch_rosargs`); what cannot be resolved or read
        leaves them out, said with a located note."""
        toks: list[str] = []
        for key in ("ros_args", "args"):
            raw = el.attrs.get(key)
            if raw is None or (key == "args" and "--ros-args" not in raw):
                continue
            try:
                got = [self.sub(t, scope, path) for t in (raw.split(SEP) if SEP in raw else raw.split())]
            except Unresolved as exc:
                self.notes.append(Note(el.src, f"<{el.tag}>: {key}: {exc}; its ROS arguments (remaps) are left "
                                               f"out", "ROS-LAUNCH"))
                continue
            toks += got if key == "ros_args" else after_ros_args(got)
        out = parse_ros_args(toks, name)
        for p in out.problems:
            self.notes.append(Note(el.src, f"<{el.tag}>: ROS argument {p}; left out", "ROS-LAUNCH"))
        return out

    def _cond(self, el: El, scope: _Scope, path: Path) -> bool:
        """Whether ``el``'s ``if`` / ``unless`` hold; a condition that cannot be
        evaluated statically is taken to hold (the element is read), said with a
        located note: an unknown condition never drops what it guards."""
        if UNREAD in el.attrs:  # a Python launch file's condition its reader could not read (noted there)
            self._guess = el.src
        for key, want in (("if", True), ("unless", False)):
            try:
                v = self._attr(el, key, scope, path)
            except Unresolved as exc:
                self.notes.append(Note(el.src, f"<{el.tag}>: {key}: {exc}; read as if the condition held",
                                       "ROS-LAUNCH"))
                self._guess = el.src
                continue
            if v is None:
                continue
            lv = v.strip().lower()
            if lv in ("true", "1"):
                val = True
            elif lv in ("false", "0"):
                val = False
            else:
                self.notes.append(Note(el.src, f"<{el.tag}>: {key}=\"{v}\" is not true/false/1/0; read as if "
                                               f"the condition held", "ROS-LAUNCH"))
                self._guess = el.src
                continue
            if val != want:
                return False
        return True
