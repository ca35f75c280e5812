"""Which source files make up a package's executable.

* ``CMakeLists.txt``: ``add_executable(name src...)`` (``${PROJECT_NAME}``
  is the package name, ``set()`` variables substituted, the file's own
  ``function``/``macro`` wrappers traced: :mod:`cmake`; no CMake is run);
* ROS 2 components: ``rclcpp_components_register_node(target PLUGIN "ns::C"
  EXECUTABLE exe)`` makes ``exe`` a node of class ``ns::C`` (also through a
  wrapper); ``rclcpp_components_register_nodes(target "ns::C" ...)`` registers
  plugins only (started by a launch file's composable node);
* ROS 2 ``setup.py``: ``console_scripts`` entries ``exe = module.path:func``,
  read with ``ast``;
* ROS 1 Python nodes: a script is its own executable (``scripts/talker.py``
  is ``talker.py``; its stem is accepted too).
"""
from __future__ import annotations

from . import safefs

import ast
import re
from pathlib import Path

from .cmake import expand

_ENTRY = re.compile(r"^\s*([A-Za-z0-9_.\-]+)\s*=\s*([A-Za-z0-9_.]+)\s*:\s*[A-Za-z0-9_]+\s*$")


def _commands(root: Path, pkg: str) -> list[tuple[str, list[str], int]]:
    try:
        return expand(safefs.read_text(root / "CMakeLists.txt"), pkg)
    except OSError:
        return []


def cmake_executables(root: Path, pkg: str) -> dict[str, list[Path]]:
    """``{executable: [its source files that exist]}`` from ``add_executable``."""
    out: dict[str, list[Path]] = {}
    for name, args, _line in _commands(root, pkg):
        if name != "add_executable" or not args or "IMPORTED" in args or "ALIAS" in args:
            continue
        srcs = [t for t in args[1:] if t not in ("WIN32", "MACOSX_BUNDLE", "EXCLUDE_FROM_ALL")]
        out[args[0]] = [root / s for s in srcs if (root / s).is_file()]
    return out


def cmake_components(root: Path, pkg: str) -> tuple[dict[str, tuple[str, int]], list[str]]:
    """``({executable: (class, CMakeLists line)}, [plugin classes])`` registered by
    ``rclcpp_components_register_node(s)`` (rclcpp_components' CMake API)."""
    exes: dict[str, tuple[str, int]] = {}
    plugins: list[str] = []
    for name, args, line in _commands(root, pkg):
        if name == "rclcpp_components_register_node" and "PLUGIN" in args:
            k = args.index("PLUGIN")
            if k + 1 < len(args):
                cls = args[k + 1].lstrip(":")
                plugins.append(cls)
                if "EXECUTABLE" in args and args.index("EXECUTABLE") + 1 < len(args):
                    exes[args[args.index("EXECUTABLE") + 1]] = (cls, line)
        elif name == "rclcpp_components_register_nodes" and len(args) > 1:
            plugins.extend(a.lstrip(":") for a in args[1:] if a not in ("RESOURCE_INDEX",) and "::" in a)
    return exes, plugins


def setup_py_executables(root: Path) -> dict[str, list[Path]]:
    f = root / "setup.py"
    out: dict[str, list[Path]] = {}
    try:
        tree = ast.parse(safefs.read_text(f))
    except (OSError, SyntaxError, ValueError):
        return out
    for n in ast.walk(tree):
        if isinstance(n, ast.Constant) and isinstance(n.value, str):
            m = _ENTRY.match(n.value)
            if m:
                mod = root / (m.group(2).replace(".", "/") + ".py")
                if mod.is_file():
                    out[m.group(1)] = [mod]
    return out


def executables(root: Path, pkg: str, py_nodes: list[Path]) -> dict[str, list[Path]]:
    """``{executable: [source files]}`` of one package."""
    out = cmake_executables(root, pkg)
    out.update(setup_py_executables(root))
    for p in py_nodes:
        out.setdefault(p.name, [p])
        out.setdefault(p.stem, [p])
    return out
