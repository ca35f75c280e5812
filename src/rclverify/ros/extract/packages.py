"""Packages of a ROS 1 (catkin) or ROS 2 (ament) workspace: every
``package.xml`` (REP 140 / REP 149 formats 1-3) read through ``catkin_pkg``.

A directory holding ``CATKIN_IGNORE``, ``COLCON_IGNORE`` or
``AMENT_IGNORE`` is skipped, as are ``build``, ``devel``, ``install`` and
``log`` trees (catkin's and colcon's own rules).
"""
from __future__ import annotations

from rclverify.ros.extract import safefs

import os
from dataclasses import dataclass
from pathlib import Path

from rclverify.ros.extract.model import Note, Src
from rclverify.ros.extract.shapes import PackageJson
from rclverify.ros.extract.xmlsrc import parse_xml

_SKIP_DIRS = {"build", "devel", "install", "log", ".git", "__pycache__"}
_IGNORE_FILES = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")


@dataclass(frozen=True)
class Package:
    """One package: ``name``, ``version``, ``build_type`` (``catkin``,
    ``ament_cmake``, ``ament_python`` ...), ``ros`` (1 or 2), its directory and manifest path."""

    name: str
    version: str
    build_type: str
    ros: int
    root: Path
    manifest: Path

    def to_json(self, shown: str) -> PackageJson:
        return {"name": self.name, "version": self.version, "build_type": self.build_type,
                "ros": self.ros, "manifest": shown}


MAX_DEPENDS = 1000  # <*depend> elements in one package.xml (catkin_pkg is quadratic in them)


def find_manifests(paths: list[Path], skipped: list[str] | None = None) -> list[Path]:
    """Every ``package.xml`` under ``paths`` (a path may be a package itself), sorted;
    directories whose name is not valid UTF-8 are not entered (appended, escaped, to ``skipped``)."""
    out: list[Path] = []
    for top in paths:
        if top.is_file() and top.name == "package.xml":
            out.append(top)
            continue
        for dirpath, dirnames, filenames in os.walk(top):
            if any(f in filenames for f in _IGNORE_FILES):
                dirnames[:] = []
                continue
            dirnames[:] = sorted(d for d in safefs.keep_names(dirpath, dirnames, skipped)
                                 if d not in _SKIP_DIRS and not d.startswith("."))
            if "package.xml" in filenames:
                out.append(Path(dirpath) / "package.xml")
                # a package does not nest packages (REP 140)
                dirnames[:] = [d for d in dirnames if d not in ("msg", "srv", "action")]
    return sorted(set(out))


def read_package(manifest: Path, shown: str) -> tuple[Package | None, list[Note]]:
    """The package ``manifest`` describes, or ``None`` and a located error."""
    from rclverify.core.extras import require  # deferred: start-up (loads catkin_pkg and more only when called)
    catkin = require("catkin_pkg.package", "reading package.xml")
    InvalidPackage, parse_package_string = catkin.InvalidPackage, catkin.parse_package_string
    root, note = parse_xml(manifest, shown)
    if note is not None:
        return None, [note]
    assert root is not None  # parse_xml gives the root when it gives no note
    deps = sum(1 for el in root.iter() if isinstance(el.tag, str) and el.tag.endswith("depend"))
    if deps > MAX_DEPENDS:
        return None, [Note(Src(shown), f"package.xml has {deps} dependency elements, more than {MAX_DEPENDS}: "
                                       f"not parsed", "ROS-PARSE", "error")]
    warnings: list[str] = []
    try:
        pkg = parse_package_string(safefs.read_text(manifest), str(manifest), warnings)
    except InvalidPackage as exc:
        msg = " ".join(str(exc).replace(str(manifest), shown).split())
        return None, [Note(Src(shown), f"invalid package.xml: {msg}", "ROS-PARSE", "error")]
    except Exception as exc:  # catkin_pkg raises plain errors on odd input (e.g. bad version strings)
        return None, [Note(Src(shown), f"invalid package.xml: {type(exc).__name__}: {exc}", "ROS-PARSE", "error")]
    build_type = "catkin"
    try:
        build_type = str(pkg.get_build_type())
    except Exception:  # several build_type exports: keep the default, say so
        pass
    ros = 2 if build_type.startswith("ament") or any(d.name.startswith("ament") for d in pkg.buildtool_depends) else 1
    notes = [Note(Src(shown), f"package.xml: {w}", "ROS-MANIFEST") for w in warnings]
    return Package(str(pkg.name), str(pkg.version), build_type, ros, manifest.parent, manifest), notes
