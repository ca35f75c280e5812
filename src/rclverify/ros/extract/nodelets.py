"""ROS 1 nodelets read statically (docs/ros.md, "Nodelets").

A nodelet is a class deriving from ``nodelet::Nodelet``, built into a
library, registered with pluginlib and loaded into a manager process by a
launch file.  What is read, and from where:

* the registration in C++: ``PLUGINLIB_EXPORT_CLASS(ns::Cls, nodelet::Nodelet)``
  and the older ``PLUGINLIB_DECLARE_CLASS(pkg, Name, ns::Cls, nodelet::Nodelet)``
  (:func:`registered`; the C++ reader records them before the macro is blanked);
* the plugin description: ``package.xml``'s ``<export><nodelet
  plugin="${prefix}/nodelet_plugins.xml"/></export>`` names an XML file whose
  ``<library path="lib/libNAME">`` holds ``<class name="pkg/Type"
  type="ns::Cls" base_class_type="nodelet::Nodelet">`` entries: the lookup
  name ``pkg/Type`` is the class ``ns::Cls`` of CMake library ``NAME``
  (:func:`plugin_classes`; a class without ``name`` is looked up by its type);
* the launch: ``<node pkg="nodelet" type="nodelet" name="N" args="load
  pkg/Type manager"/>`` or ``args="standalone pkg/Type"`` loads the nodelet as
  node ``N`` (in the launch namespace, with the element's remaps and
  parameters: the nodelet's private names are ``N``'s); ``args="manager"``
  starts a manager, a container that is not itself a node of the graph, as
  a component container is not (:func:`launch_args`).

In the nodelet's code ``getNodeHandle()``/``getMTNodeHandle()`` are handles
in the node's namespace, ``getPrivateNodeHandle()``/``getMTPrivateNodeHandle()``
private ones (``~``), and ``getName()`` is the node's own name (the value
readers, :mod:`cpp_values`).  Sources: the ROS wiki "nodelet" and
"pluginlib" pages (plugin description file, ``class_list_macros.h``), nodelet's
``nodelet`` command line (``manager``, ``load``, ``standalone``).
"""
from __future__ import annotations

import re
from pathlib import Path

from rclverify.ros.extract import safefs
from rclverify.ros.extract.model import Src
from rclverify.ros.extract.xmlsrc import parse_xml

_EXPORT = re.compile(rb"\bPLUGINLIB_EXPORT_CLASS\s*\(\s*([A-Za-z_][\w:]*)\s*,\s*([A-Za-z_][\w:]*)\s*\)")
_DECLARE = re.compile(rb"\bPLUGINLIB_DECLARE_CLASS\s*\(\s*(\w+)\s*,\s*(\w+)\s*,\s*([A-Za-z_][\w:]*)\s*,"
                      rb"\s*([A-Za-z_][\w:]*)\s*\)")
MAX_PLUGIN_FILES = 16  # plugin description files read per package


def registered(data: bytes, shown: str) -> list[tuple[str, str | None, Src]]:
    """``[(class as written, lookup name or None, where)]`` of the nodelet classes a
    C++ file registers with pluginlib (a base class other than a nodelet's is
    some other plugin and is left out)."""
    out: list[tuple[str, str | None, Src]] = []
    if b"PLUGINLIB_" not in data:
        return out
    for m in _EXPORT.finditer(data):
        if b"odelet" in m.group(2):
            out.append((m.group(1).decode().lstrip(":"), None, Src(shown, data.count(b"\n", 0, m.start()) + 1, 1)))
    for m in _DECLARE.finditer(data):
        if b"odelet" in m.group(4):
            out.append((m.group(3).decode().lstrip(":"), f"{m.group(1).decode()}/{m.group(2).decode()}",
                        Src(shown, data.count(b"\n", 0, m.start()) + 1, 1)))
    return out


def plugin_classes(root: Path) -> dict[str, tuple[str, str | None]]:
    """``{lookup name: (C++ class, CMake library or None)}`` of the nodelets the
    package at ``root`` exports (see the module docstring); unreadable files
    give nothing (the package's own scan reports a bad ``package.xml``)."""
    out: dict[str, tuple[str, str | None]] = {}
    manifest, _note = parse_xml(root / "package.xml", "package.xml")
    if manifest is None:
        return out
    files = [e.get("plugin", "") for ex in manifest.iter("export") for e in ex if e.tag == "nodelet"]
    for rel in files[:MAX_PLUGIN_FILES]:
        rel = rel.replace("${prefix}", "").lstrip("/")
        path = root / rel
        if not rel or ".." in Path(rel).parts or not safefs.inside(path):
            continue
        desc, _note = parse_xml(path, rel)
        if desc is None:
            continue
        libs = [desc] if desc.tag == "library" else [x for x in desc if x.tag == "library"]
        for lib in libs:
            name = Path(lib.get("path", "")).name
            target = name[3:] if name.startswith("lib") else name or None
            for c in lib:
                if c.tag == "class" and c.get("type"):
                    out[c.get("name") or c.get("type")] = (c.get("type").lstrip(":"), target or None)
    return out


def launch_args(args: str | None) -> tuple[str, str | None] | None:
    """What a ``nodelet`` launch node's ``args`` say: ``("manager", None)``,
    ``("load", "pkg/Type")``, ``("standalone", "pkg/Type")``; ``None`` for
    anything else (``unload``, nothing)."""
    words = (args or "").split()
    if not words:
        return None
    if words[0] == "manager":
        return "manager", None
    if words[0] in ("load", "standalone") and len(words) >= 2 and "/" in words[1]:
        return words[0], words[1]
    return None
