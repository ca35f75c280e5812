"""Only what is built: the ROS 1 code an ament package still holds but no
target of its ``CMakeLists.txt`` builds (docs/ros.md, "Only what is built").

A package ported from ROS 1 to ROS 2 often keeps its ROS 1 sources: nodelet
classes its plugin description still exports, programs calling
``ros::init``.  When no ``add_executable`` / ``add_library`` of the package
(after its functions, macros and loops are expanded: :mod:`cmake`) lists
their sources, they are never compiled, so they run nowhere.  In an
``ament_cmake`` package with a ``CMakeLists.txt``:

* an executable declared only in a branch a catkin build takes
  (``if(catkin_FOUND)``, ``if($ENV{ROS_VERSION} EQUAL 1)``, the ``else`` of
  ``if(ament_cmake_FOUND)`` or of ``ROS_VERSION`` ``2``:
  :func:`executables.catkin_branch`) is *not built* (catkin-only code), and
  the targets of such branches build nothing below;
* a nodelet program (:mod:`nodelets`) none of whose sources a target lists
  (its library is no longer built, or the file registering it is in no
  target) is *not built*;
* a C++ file no target lists, that includes ROS 1 headers (``ros/...``,
  ``nodelet/...``) and none of ``rclcpp``, and that is a program of its own
  (it names a node or makes endpoints: :func:`programs.programs`' loose
  files) is *not built*.

Each is listed apart (:class:`Unbuilt`): never a node, so ``init --from-ros``
writes no contract for it.  A catkin package is built by catkin; its code is
read as before.

Source: CMake's build model (a source file is compiled only as part of a
target, cmake-buildsystem(7)); ament_cmake's package build type (REP 149
``<build_type>``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rclverify.ros.extract.executables import Targets
from rclverify.ros.extract.model import Src
from rclverify.ros.extract.packages import Package
from rclverify.ros.extract.programs import PackageCode, Program

_CPP = (".cpp", ".cc", ".cxx", ".c")


@dataclass(frozen=True)
class Unbuilt:
    """One program of ROS 1 code no target builds: its ``package``, ``kind``
    (``catkin-only executable``, ``ROS 1 nodelet``, ``ROS 1 program``), ``name`` (a nodelet's lookup name,
    a program's file name), where it is (``at``) and ``why`` it is not built."""

    package: str
    kind: str
    name: str
    at: Src
    why: str


def _ros1(record: dict[str, Any]) -> bool:
    """Whether a C++ source record includes ROS 1 headers and no ``rclcpp`` one."""
    inc = [str(i) for i in record.get("includes", [])]
    return any(i.startswith(("ros/", "nodelet/")) for i in inc) and not any(i.startswith("rclcpp") for i in inc)


def not_built(pkg: Package, progs: list[Program], code: PackageCode,
              t: Targets) -> tuple[list[Program], list[Unbuilt]]:
    """``(programs built, programs not built)`` of package ``pkg`` (see the
    module docstring); a package not built by ament_cmake keeps them all."""
    if not pkg.build_type.startswith("ament_cmake") or not (pkg.root / "CMakeLists.txt").is_file():
        return progs, []
    built = {code.show(p) for name, srcs in list(t.executables.items()) + list(t.libraries.items())
             if name not in t.catkin_only for p in srcs}
    kept: list[Program] = []
    gone: list[Unbuilt] = []
    for prog in progs:
        if prog.exe is not None and prog.exe in t.catkin_only:
            d = next((d for d in t.declared if d.kind == "executable" and d.name == prog.exe), None)
            gone.append(Unbuilt(pkg.name, "catkin-only executable", prog.exe,
                                Src(code.show(d.file), d.line) if d is not None else Src(code.show(pkg.manifest)),
                                "CMakeLists.txt declares it only in a branch a catkin build takes "
                                "(if(catkin_FOUND), ROS_VERSION 1)"))
        elif prog.nodelet is not None and not set(prog.entry) & built:
            gone.append(Unbuilt(pkg.name, "ROS 1 nodelet", prog.nodelet, _registered(prog, code, pkg),
                                "its plugin description (or PLUGINLIB_EXPORT_CLASS) names a ROS 1 nodelet whose "
                                "sources no target of CMakeLists.txt builds"))
        elif prog.exe is None and prog.units is None and prog.plugin is None and len(prog.entry) == 1 \
                and prog.entry[0].endswith(_CPP) and prog.entry[0] not in built \
                and _ros1(code.records.get(prog.entry[0], {})):
            f = prog.entry[0]
            named = code.records[f].get("nodes") or []
            at = named[0][1] if named else Src(f)
            gone.append(Unbuilt(pkg.name, "ROS 1 program", f.rsplit("/", 1)[-1], at,
                                "a ROS 1 program (ros/ros.h, ros::init) that no target of CMakeLists.txt builds"))
        else:
            kept.append(prog)
    return kept, gone


def _registered(prog: Program, code: PackageCode, pkg: Package) -> Src:
    """Where nodelet program ``prog``'s class is registered, else its first file,
    else the package's manifest."""
    cls = next(iter(prog.units or ()), "")
    for f, r in sorted(code.records.items()):
        for written, _lookup, at in r.get("nodelets", []):
            if cls == written or cls.endswith("::" + str(written).split("::")[-1]):
                return at  # type: ignore[no-any-return]
    return Src(prog.files[0]) if prog.files else Src(code.show(pkg.manifest))
