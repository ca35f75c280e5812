"""Which source files make up a package's executables (no CMake or setup.py
is run; docs/ros.md, "Reading real code").

* ``CMakeLists.txt`` (:mod:`cmake`: variables, ``foreach``, the file's own
  ``function``/``macro`` wrappers, ``file(GLOB)``): ``add_executable(name src...)``
  (also ament_cmake_auto's ``ament_auto_add_executable`` (its ``DIRECTORY``
  sources globbed as ament_cmake_auto does) and catkin_simple's
  ``cs_add_executable``), ``add_library`` (``ament_auto_add_library``,
  ``cs_add_library``), ``target_sources``, ``target_link_libraries(target
  libs...)`` (an ``ament_auto`` executable links every ``ament_auto`` library
  added before it); ``catkin_install_python(PROGRAMS ...)`` and
  ``install(PROGRAMS ...)`` name Python programs;
* ROS 2 components: ``rclcpp_components_register_node(target PLUGIN "ns::C"
  EXECUTABLE exe)`` makes ``exe`` a node of class ``ns::C`` (also through a
  wrapper); ``rclcpp_components_register_nodes(target "ns::C" ...)`` registers
  plugins only (started by a launch file's composable node);
* ``setup.py`` (read with ``ast``, :mod:`setup_py`): ``console_scripts`` entries
  ``exe = module.path:func`` and ``scripts=[...]``, a module found where
  ``package_dir={'': 'src'}`` (or ``{'pkg': 'dir'}``) puts it, as setuptools does;
* ``set_target_properties(t PROPERTIES OUTPUT_NAME name)`` names executable
  ``t``'s file ``name``, the name a launch file runs;
* a ROS 1 Python script is its own executable (``scripts/talker.py`` is
  ``talker.py``; its stem is accepted too).
"""
from __future__ import annotations

from rclverify.ros.extract import safefs

import fnmatch
import re
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from rclverify.ros.extract.cmake import Definitions, definitions_of, expand
from rclverify.ros.extract.model import Note
from rclverify.ros.extract.nodelets import plugin_classes
from rclverify.ros.extract.plugins import PluginClass, described
from rclverify.ros.extract.setup_py import entry_points, setup_py_executables

_EXE = {"add_executable", "ament_auto_add_executable", "cs_add_executable"}
_LIB = {"add_library", "ament_auto_add_library", "cs_add_library"}
_KEYWORDS = {"WIN32", "MACOSX_BUNDLE", "EXCLUDE_FROM_ALL", "STATIC", "SHARED", "MODULE", "OBJECT", "PRIVATE",
             "PUBLIC", "INTERFACE", "NO_TARGET_LINK_LIBRARIES", "DIRECTORY", "NO_TARGET_LINK"}


@dataclass
class Targets:
    """A package's build targets: ``executables`` and ``libraries`` ``{name: [source
    files that exist]}``, ``links`` ``{target: [linked target names]}``,
    ``components`` ``{executable: (class, CMakeLists line)}``, ``plugins``
    ``{class: target}`` (every registered component class, and every nodelet
    class its plugin description puts in a library of the package),
    ``programs`` ``{executable: [Python file]}`` (installed scripts, entry
    points), ``nodelets`` ``{lookup name: (class, library)}`` (:mod:`nodelets`),
    ``pluginlib`` the ROS 2 plugin classes it exports and ``plugin_notes`` what
    could not be read of their descriptions (:mod:`plugins`), ``declared`` the
    programs its build files declare and ``catkin_only`` the targets declared
    only in a branch a catkin build takes (:func:`catkin_branch`)."""

    executables: dict[str, list[Path]] = field(default_factory=dict)
    libraries: dict[str, list[Path]] = field(default_factory=dict)
    links: dict[str, list[str]] = field(default_factory=dict)
    components: dict[str, tuple[str, int]] = field(default_factory=dict)
    plugins: dict[str, str] = field(default_factory=dict)
    programs: dict[str, list[Path]] = field(default_factory=dict)
    nodelets: dict[str, tuple[str, str | None]] = field(default_factory=dict)
    pluginlib: list[PluginClass] = field(default_factory=list)
    plugin_notes: list[Note] = field(default_factory=list)
    declared: list[Declared] = field(default_factory=list)
    # targets declared only in a branch a catkin (ROS 1) build takes (if(catkin_FOUND), ROS_VERSION 1)
    catkin_only: set[str] = field(default_factory=set)
    # set_target_properties(t PROPERTIES OUTPUT_NAME name): {target: file name}
    output_names: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Declared:
    """One program a package's build files declare (docs/ros.md, "Every program
    accounted for"): ``kind`` (``executable``, ``component``, ``entry point``),
    its ``name`` (an executable's, or a component's class), the build ``file``
    and ``line`` declaring it, the ``sources`` it names as written, and whether
    they all exist (``found``)."""

    kind: str
    name: str
    file: Path
    line: int
    sources: tuple[str, ...] = ()
    found: bool = True


MAX_GLOB_DIRS = 2000  # directories one file(GLOB) pattern may visit


def _glob(root: Path):  # type: ignore[no-untyped-def]
    """``glob(pattern, recurse)`` for :func:`cmake.expand`: the package files a
    ``file(GLOB ...)`` pattern matches, relative to ``root``; a pattern leaving the
    package matches nothing (links are not followed; the walk is bounded)."""
    real_root = os.path.realpath(root)

    def g(pattern: str, recurse: bool) -> list[str]:
        while pattern.startswith("./"):
            pattern = pattern[2:]
        base, _, pat = pattern.rpartition("/")
        top = Path(base or "/") if pattern.startswith("/") else root / base if base else root
        real = os.path.realpath(top)
        if not (real == real_root or real.startswith(real_root + os.sep)):
            return []
        out: list[str] = []
        for k, (dirpath, dirnames, filenames) in enumerate(os.walk(top)):
            if k >= MAX_GLOB_DIRS or len(out) > 10_000:
                break
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".")) if recurse else []
            rel = Path(dirpath).relative_to(root).as_posix()
            out.extend(f"{rel}/{f}" if rel != "." else f for f in sorted(filenames) if fnmatch.fnmatch(f, pat))
        return out
    return g


def _reader(root: Path, here: Path):  # type: ignore[no-untyped-def]
    """``read(path)`` for :func:`cmake.expand`'s ``include()``: the text of a file of
    the package at ``root`` (relative to ``here``), ``None`` outside it or unreadable."""
    real_root = os.path.realpath(root)

    def read(rel: str) -> str | None:
        f = here / rel
        real = os.path.realpath(f)
        if not real.startswith(real_root + os.sep):
            return None
        try:
            return safefs.read_text(f)
        except OSError:
            return None
    return read


MAX_SUBDIRS = 32  # CMakeLists.txt files read per package (add_subdirectory)


def targets(root: Path, pkg: str, extra: Definitions | None = None) -> Targets:
    """The :class:`Targets` of the package at ``root`` named ``pkg`` (its
    ``CMakeLists.txt`` and those its ``add_subdirectory`` calls name, each
    with source paths relative to its own directory); ``extra``: CMake
    functions and macros other packages export (:func:`exported_cmake`)."""
    t = Targets()
    todo, seen = [root], 0
    auto_libs: list[str] = []
    while todo and seen < MAX_SUBDIRS:
        here = todo.pop(0)
        seen += 1
        try:
            cmds = expand(safefs.read_text(here / "CMakeLists.txt"), pkg, _glob(here), _reader(root, here), extra)
        except OSError:
            continue
        _read(cmds, here, t, auto_libs, todo)
    _rename(t)
    for exe, srcs in setup_py_executables(root).items():
        t.programs.setdefault(exe, srcs)
    for name, f, line, mod, found in entry_points(root):
        t.declared.append(Declared("entry point", name, f, line, (mod,), found))
        if found:
            t.programs.setdefault(name, [root / mod])
    t.nodelets = plugin_classes(root)
    t.pluginlib, t.plugin_notes = described(root)
    for cls, lib in t.nodelets.values():
        if lib in t.libraries:
            t.plugins.setdefault(cls, lib)
    return t


def _read(cmds: list[tuple[str, list[str], int]], root: Path, t: Targets, auto_libs: list[str],
          subdirs: list[Path]) -> None:
    """The targets the commands of one ``CMakeLists.txt`` (in ``root``) declare, into ``t``."""
    def files(srcs: list[str]) -> list[Path]:
        return [root / s for s in srcs if s not in _KEYWORDS and (root / s).is_file()]

    def declare(kind: str, name: str, line: int, srcs: list[str]) -> None:
        named = tuple(x for x in srcs if x not in _KEYWORDS and not x.startswith("$<"))
        t.declared.append(Declared(kind, name, root / "CMakeLists.txt", line, named,
                                   all((root / x).is_file() for x in named)))

    branches: list[list[int | str]] = []  # each open if(): [catkin_branch(cond), "then" | "else" | "other"]
    for name, args, line in cmds:
        if name in ("if", "elseif", "else", "endif"):
            _branch(branches, name, args)
            continue
        if not args:
            continue
        if name in _EXE | _LIB and any((k == 1 and part == "then") or (k == -1 and part == "else")
                                       for k, part in branches):
            t.catkin_only.add(args[0])  # declared where only a catkin build goes (built.py)
        if name in ("ament_auto_add_library", "ament_auto_add_executable") and "DIRECTORY" in args:
            args = _auto_directory(args, root)
        if name == "add_subdirectory" and (root / args[0]).is_dir() and not args[0].startswith(("test", "..")) \
                and ".." not in Path(args[0]).parts and not Path(args[0]).is_absolute():
            subdirs.append(root / args[0])
        elif name in _EXE and "IMPORTED" not in args and "ALIAS" not in args:
            t.executables.setdefault(args[0], []).extend(files(args[1:]))
            declare("executable", args[0], line, args[1:])
            if name == "ament_auto_add_executable":
                t.links.setdefault(args[0], []).extend(auto_libs)
        elif name in _LIB and "IMPORTED" not in args and "ALIAS" not in args and "INTERFACE" not in args[1:2]:
            t.libraries.setdefault(args[0], []).extend(files(args[1:]))
            if name == "ament_auto_add_library":
                auto_libs.append(args[0])
        elif name == "target_sources":
            bucket = t.executables if args[0] in t.executables else t.libraries
            bucket.setdefault(args[0], []).extend(files(args[1:]))
        elif name == "set_target_properties" and "PROPERTIES" in args:
            k = args.index("PROPERTIES")
            props = args[k + 1:]
            for j in range(0, len(props) - 1, 2):
                if props[j] == "OUTPUT_NAME" and props[j + 1]:
                    for target in args[:k]:
                        t.output_names[target] = props[j + 1]
        elif name in ("target_link_libraries", "ament_target_dependencies"):
            t.links.setdefault(args[0], []).extend(a for a in args[1:] if a not in _KEYWORDS)
        elif name == "rclcpp_components_register_node" and "PLUGIN" in args:
            k = args.index("PLUGIN")
            if k + 1 < len(args):
                cls = args[k + 1].lstrip(":")
                t.plugins[cls] = args[0]
                if "EXECUTABLE" in args and args.index("EXECUTABLE") + 1 < len(args):
                    t.components[args[args.index("EXECUTABLE") + 1]] = (cls, line)
                declare("component", cls, line, [])
        elif name == "rclcpp_components_register_nodes" and len(args) > 1:
            # (target [RESOURCE_INDEX index] class...): each class, in a namespace or not
            rest = args[1:]
            if rest[0] == "RESOURCE_INDEX":
                rest = rest[2:]
            for a in rest:
                if re.fullmatch(r":*[A-Za-z_]\w*(::[A-Za-z_]\w*)*", a):
                    t.plugins[a.lstrip(":")] = args[0]
                    declare("component", a.lstrip(":"), line, [])
        elif name in ("catkin_install_python", "install") and "PROGRAMS" in args:
            k = args.index("PROGRAMS") + 1
            while k < len(args) and args[k] not in ("DESTINATION", "PERMISSIONS", "CONFIGURATIONS", "COMPONENT",
                                                      "OPTIONAL", "RENAME"):
                f = root / args[k]
                if f.is_file():
                    t.programs.setdefault(f.name, [f])
                    t.programs.setdefault(f.stem, [f])
                k += 1


def _rename(t: Targets) -> None:
    """Executables whose ``OUTPUT_NAME`` differs from the target's name renamed in
    ``t`` (CMake's ``OUTPUT_NAME`` target property: the file built, which
    ``ros2 run`` and a launch file's ``executable`` name); the target's links
    and components follow."""
    for target, out in t.output_names.items():
        if target not in t.executables or out == target:
            continue
        t.executables[out] = t.executables.pop(target)
        if target in t.links:
            t.links[out] = t.links.pop(target)
        if target in t.components:
            t.components[out] = t.components.pop(target)
        t.declared = [replace(d, name=out) if d.kind == "executable" and d.name == target else d
                      for d in t.declared]


def catkin_branch(cond: list[str]) -> int:
    """Which branch of ``if(cond)`` only a catkin (ROS 1) build takes: ``1`` the
    ``if`` branch (``if(catkin_FOUND)``, ``if($ENV{ROS_VERSION} EQUAL 1)``),
    ``-1`` the ``else`` branch (``if(ament_cmake_FOUND)``, ``ROS_VERSION``
    ``2``, or a ``NOT`` of the first kind), ``0`` neither or not known."""
    text = " ".join(cond)
    flip = -1 if cond and cond[0] == "NOT" else 1
    if "catkin_FOUND" in text:
        return flip
    if "ament_cmake_FOUND" in text:
        return -flip
    if "ROS_VERSION" in text and any(a in ("EQUAL", "STREQUAL", "VERSION_EQUAL") for a in cond):
        v = cond[-1].strip("\"'")
        return flip if v == "1" else -flip if v == "2" else 0
    return 0


def _branch(branches: list[list[int | str]], name: str, args: list[str]) -> None:
    """Track the open ``if()`` blocks of a ``CMakeLists.txt`` (:func:`catkin_branch`)."""
    if name == "if":
        branches.append([catkin_branch(args), "then"])
    elif name in ("elseif", "else") and branches:
        branches[-1][1] = "other" if name == "elseif" else ("else" if branches[-1][1] == "then" else "other")
    elif name == "endif" and branches:
        branches.pop()


MAX_EXPORTED = 64  # .cmake files read per package for the functions and macros it exports


def exported_cmake(root: Path) -> Definitions:
    """The CMake functions and macros the package at ``root`` exports for the
    packages that ``find_package`` it: those of its ``cmake/*.cmake`` files
    and its ``*-extras.cmake`` (ament's ``CONFIG_EXTRAS``, also ``.in``);
    a file that cannot be read gives none."""
    files = sorted((root / "cmake").glob("*.cmake")) if (root / "cmake").is_dir() else []
    files += sorted(root.glob("*-extras.cmake")) + sorted(root.glob("*-extras.cmake.in"))
    out: Definitions = {}
    for f in files[:MAX_EXPORTED]:
        try:
            out.update(definitions_of(safefs.read_text(f)))
        except (OSError, RecursionError):
            continue
    return out


_AUTO_SOURCES = ("*.c", "*.cc", "*.cpp", "*.cxx")


def _auto_directory(args: list[str], root: Path) -> list[str]:
    """``ament_auto_add_library(t [SHARED] DIRECTORY d... [sources])``'s arguments
    with each directory ``d`` replaced by the C and C++ sources under it, as
    ament_cmake_auto globs them (``GLOB_RECURSE`` of ``*.c``, ``*.cc``,
    ``*.cpp``, ``*.cxx``); a directory outside the package gives none."""
    k = args.index("DIRECTORY")
    j = k + 1
    while j < len(args) and args[j] not in _KEYWORDS:
        j += 1
    glob = _glob(root)
    found = [f for d in args[k + 1:j] for pat in _AUTO_SOURCES for f in glob(f"{d.rstrip('/')}/{pat}", True)]
    return args[:k] + sorted(dict.fromkeys(found)) + args[j:]


def cmake_components(root: Path, pkg: str) -> tuple[dict[str, tuple[str, int]], list[str]]:
    """``({executable: (class, CMakeLists line)}, [plugin classes])`` registered by
    ``rclcpp_components_register_node(s)`` (rclcpp_components' CMake API)."""
    t = targets(root, pkg)
    return t.components, list(t.plugins)


def executables(root: Path, pkg: str, py_nodes: list[Path]) -> dict[str, list[Path]]:
    """``{executable: [source files]}`` of one package (the executables' own sources,
    without the libraries they link)."""
    t = targets(root, pkg)
    out = dict(t.executables)
    out.update(t.programs)
    for p in py_nodes:
        out.setdefault(p.name, [p])
        out.setdefault(p.stem, [p])
    return out
