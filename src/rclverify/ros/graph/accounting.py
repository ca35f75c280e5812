"""Every program accounted for (docs/ros.md, "Every program accounted for").

Each program a package declares — an executable (``add_executable`` and its
wrappers, CMake functions and macros included), a component
(``rclcpp_components_register_node(s)``), a ``console_scripts`` entry point
(``setup.py``, ``setup.cfg``) — and, with launch files, each node a launch
file starts, is either one or more nodes of the graph or *unaccounted*: named
in a located ``ROS-PROGRAM`` note at its declaration saying what could not be
read and why.  ``ros scan``'s JSON lists them (``programs``), ``ros check``
and ``init --from-ros`` print the unaccounted ones and fail under
``--strict``.  Without launch files every declared program is judged; with
launch files only the nodes they start are (a program no launch file starts
is not part of that deployment).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from rclverify.ros.extract.executables import Declared
from rclverify.ros.extract.model import Note, Src

#: the note code of an unaccounted program (``ros check`` lists these)
CODE = "ROS-PROGRAM"
#: the note code of ROS 1 code no target builds (accounted for as ``not built``: ros/extract/built.py)
NOT_BUILT = "ROS-NOT-BUILT"


@dataclass
class Account:
    """One declared program: ``package``, ``kind``, ``name``, where it is
    ``declared``, the graph ``nodes`` it is, and ``why`` it is none (``None``
    when it is accounted for)."""

    package: str
    kind: str
    name: str
    declared: Src
    nodes: list[str] = field(default_factory=list)
    why: str | None = None

    def to_json(self) -> dict[str, Any]:
        return {"package": self.package, "kind": self.kind, "name": self.name, "declared": self.declared.to_json(),
                "nodes": sorted(self.nodes), "unaccounted": self.why}

    def note(self) -> Note:
        """The located note of an unaccounted program."""
        return Note(self.declared, f"{self.kind} {self.name} of package {self.package} is in no node of the graph: "
                                   f"{self.why}", CODE)


class Ledger:
    """What each program of the scan gave, filled while the graph is assembled."""

    def __init__(self, show: Callable[[Path], str]) -> None:
        self.show = show
        self.made: dict[tuple[str, str], list[str]] = {}  # (package, program key) -> node names
        self.why: dict[tuple[str, str], str] = {}  # (package, program key) -> why it made none
        self.launched: list[Account] = []  # launch-started nodes whose program was not found

    def gave(self, pkg: str, keys: list[str], node: str) -> None:
        """Program ``keys`` (its executable, aliases, classes) of ``pkg`` made node ``node``."""
        for k in keys:
            self.made.setdefault((pkg, k), []).append(node)

    def none(self, pkg: str, keys: list[str], why: str) -> None:
        """Program ``keys`` of ``pkg`` made no node, because ``why``."""
        for k in keys:
            self.why.setdefault((pkg, k), why)

    def launch_missing(self, pkg: str, exe: str, at: Src, why: str) -> None:
        """A launch file's node at ``at`` whose program is not read."""
        self.launched.append(Account(pkg, "launch node", exe, at, why=why))

    def accounts(self, declared: dict[str, list[Declared]], launch: bool) -> list[Account]:
        """One :class:`Account` per declared program (without launch files) and per
        launch-started node whose program was not read."""
        out: list[Account] = list(self.launched)
        if launch:
            return out
        for pkg in sorted(declared):
            seen: set[tuple[str, str]] = set()
            for d in declared[pkg]:
                if (d.kind, d.name) in seen:
                    continue
                seen.add((d.kind, d.name))
                at = Src(self.show(d.file), d.line)
                key = (pkg, d.name)
                nodes = self.made.get(key) or self.made.get((pkg, d.name.split("::")[-1]), [])
                acc = Account(pkg, d.kind, d.name, at, sorted(set(nodes)))
                if not nodes and d.kind == "executable" and in_testing_block(d.file, d.line):
                    acc.kind = "test executable"  # built only with BUILD_TESTING: a test driver, not a robot program
                elif not nodes:
                    acc.why = _why(d, self.why.get(key) or self.why.get((pkg, d.name.split("::")[-1])))
                out.append(acc)
        return out


def in_testing_block(cmake: Path, line: int) -> bool:
    """Whether line ``line`` (1-based) of CMake file ``cmake`` lies inside an
    ``if(BUILD_TESTING)`` block (ament's test switch, also
    ``if(CATKIN_ENABLE_TESTING)``): a program declared there is a test
    driver built only for ``colcon test``, never deployed.  ``False`` when
    the file cannot be read."""
    try:
        lines = cmake.read_text(encoding="utf-8", errors="replace").splitlines()[:max(0, line - 1)]
    except OSError:
        return False
    stack: list[bool] = []
    for raw in lines:
        text = raw.split("#", 1)[0].strip().lower().replace(" ", "")
        if text.startswith("if("):
            cond = text[3:]
            stack.append(("build_testing" in cond or "catkin_enable_testing" in cond) and "not" not in cond)
        elif text.startswith("endif(") and stack:
            stack.pop()
        elif text.startswith(("else(", "elseif(")) and stack:
            stack[-1] = False
    return any(stack)


def _why(d: Declared, why: str | None) -> str:
    """Why declared program ``d`` is no node."""
    if not d.found:
        missing = ", ".join(s for s in d.sources)
        return f"its sources ({missing}) are not in the package"
    if why is not None:
        return why
    if d.kind == "entry point":
        return f"no node is read in module {d.sources[0]}"
    return "no source file of it is read (its sources are named through what the scan does not evaluate)"
