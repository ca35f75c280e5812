"""ROS 2 pluginlib plugins read statically: which node loads a plugin class, and
the endpoints the plugin makes on that node's handle (docs/ros.md, "Real ROS 2
code, round three").

A plugin is a C++ class a node loads by name at run time through
``pluginlib::ClassLoader<base::Iface>`` (a costmap layer, a controller, a
planner).  What is read, and from where:

* the export: ``package.xml``'s ``<export><base_pkg
  plugin="${prefix}/plugins.xml"/></export>`` (REP 149, "Export": a tag named
  after the package that defines the base class, whose ``plugin`` attribute
  names the plugin description file; ``${prefix}`` is the package's
  directory), any tag but ``nodelet`` (ROS 1 nodelets: :mod:`nodelets`);
* the plugin description (pluginlib's plugin description file, "Writing and
  using a simple plugin" of the ROS 2 pluginlib tutorials): a ``<library
  path="NAME">`` root, or ``<class_libraries>`` of them, whose ``<class
  type="pkg::Plugin" base_class_type="base::Iface" [name="lookup"]>``
  entries are the plugins; the lookup name is ``name`` when given, else
  ``type``; ``path`` (``lib/libNAME`` or ``NAME``) is the CMake library
  holding the class (:func:`described`);
* the loading node: a node of the graph whose parameter file (its package's
  ``config/*.yaml``, :mod:`param_yaml`) gives ``<instance>.plugin:
  "pkg::Plugin"`` under its ``ros__parameters`` loads an instance of the
  plugin named ``<instance>``, when a string-array parameter of the node lists
  ``<instance>`` (``plugins: ["front", "bumper"]``) or when none of its
  string arrays lists any of its plugin instances (the list is then the
  code's default) (:func:`instances`).

The plugin's code runs from its class (the entry unit); the first
string-typed parameter of each of its methods that nothing in the plugin's
code calls (``configure(parent, name, ...)``, ``initialize(..., name, ...)``:
called by the loader) is the instance's name (:func:`entry_sites`), so a
topic read from parameter ``name + ".topic"`` is the loading node's parameter
``<instance>.topic`` with its value from the same file, else the default the
plugin declares.  Endpoints made on the handle the plugin is given (a weak
pointer's ``lock()``, ``initialize(rclcpp::Node::SharedPtr node)``) belong to
the loading node.  A plugin class no node is found to load gives no edge: each
of its endpoints is a located note naming the class (:func:`unloaded_note`);
a ``plugin:`` value naming a class no scanned package exports, or one no
scanned C++ source defines, is a located note at the parameter file's line.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable

from rclverify.ros.extract import safefs
from rclverify.ros.extract.model import Endpoint, Note, Src
from rclverify.ros.extract.xmlsrc import line_of, parse_xml
from rclverify.ros.extract.cmake import expand

MAX_PLUGIN_FILES = 16  # plugin description files read per package
_CLASSY = re.compile(r"^(?:[A-Za-z_]\w*::)+[A-Za-z_]\w*$|^[A-Za-z_]\w*/[A-Za-z_]\w*$")
_KINDS = {"pub": "publisher", "sub": "subscriber", "service_servers": "service server",
          "service_clients": "service client", "action_servers": "action server",
          "action_clients": "action client"}


@dataclass(frozen=True)
class PluginClass:
    """One exported plugin: ``type`` (the C++ class, ``pkg::Plugin``), ``base``
    (``base_class_type``), ``lookup`` (``name``, else ``type``), ``library`` (the
    CMake library of ``<library path>``, or ``None``), ``xml`` (the description
    file) and ``line`` (its ``<class>`` element's line)."""

    type: str
    base: str
    lookup: str
    library: str | None
    xml: Path
    line: int


def described(root: Path) -> tuple[list[PluginClass], list[Note]]:
    """``(plugins, notes)`` of the package at ``root``: every class of the plugin
    descriptions its ``package.xml`` exports (see the module docstring), at most
    :data:`MAX_PLUGIN_FILES` files, none outside the package.  A description that
    is missing or not well-formed XML is a located ``ROS-PARSE`` note (its path
    relative to ``root``; the caller shows it).  Never raises: an unreadable
    ``package.xml`` gives nothing (the package's own scan reports it)."""
    out: list[PluginClass] = []
    notes: list[Note] = []
    manifest, _note = parse_xml(root / "package.xml", "package.xml")
    if manifest is None:
        return out, notes
    refs = [(e.get("plugin", ""), "package.xml", line_of(e)) for ex in manifest.iter("export") for e in ex
            if isinstance(e.tag, str) and e.tag != "nodelet" and e.get("plugin")]
    refs += [r for r in cmake_described(root) if r[0] not in {x[0] for x in refs}]
    for ref, where, line in refs[:MAX_PLUGIN_FILES]:
        rel = ref.replace("${prefix}", "").lstrip("/")
        path = root / rel
        if not rel or ".." in Path(rel).parts or not safefs.inside(path) or not path.is_file():
            notes.append(Note(Src(where, line, 1), f"plugin description '{ref}' is not a file of the "
                                                   f"package: its plugins are not read", "ROS-PARSE"))
            continue
        desc, bad = parse_xml(path, rel)
        if desc is None:
            notes.extend([bad] if bad is not None else [])
            continue
        libs = [desc] if desc.tag == "library" else [x for x in desc if x.tag == "library"]
        for lib in libs:
            name = Path(lib.get("path", "")).name
            target = (name[3:] if name.startswith("lib") else name) or None
            for c in lib:
                if c.tag == "class" and c.get("type"):
                    t = c.get("type").strip().lstrip(":")
                    out.append(PluginClass(t, (c.get("base_class_type") or "").strip().lstrip(":"),
                                           (c.get("name") or t).strip(), target, path, line_of(c)))
    return out, notes


def cmake_described(root: Path) -> list[tuple[str, str, int]]:
    """``[(description file, "CMakeLists.txt", line)]``: the plugin descriptions the
    package's ``CMakeLists.txt`` exports with
    ``pluginlib_export_plugin_description_file(base_pkg file.xml)`` (pluginlib's
    ament CMake macro, the ROS 2 way that ros2_control controllers use instead
    of a ``package.xml`` export); ``[]`` when the file cannot be read."""
    try:
        cmds = expand(safefs.read_text(root / "CMakeLists.txt"), root.name)
    except (OSError, UnicodeDecodeError):
        return []
    return [(args[1], "CMakeLists.txt", line) for name, args, line in cmds
            if name.lower() == "pluginlib_export_plugin_description_file" and len(args) >= 2]


def is_string_type(t: str) -> bool:
    """Whether a C++ parameter type (as :mod:`sources_cpp` records it: ``const
    std::string &``, ``std::string``) is a string."""
    return re.sub(r"\b(const|volatile)\b|[&\s]", "", t or "") in ("std::string", "string")


def entry_sites(fns: dict[str, tuple[str, list[str], list[str], list[Any]]], entry: set[str],
                called: set[str], instance: str) -> dict[str, list[tuple[list[Any], dict[str, Any], None]]]:
    """The call sites the plugin loader gives: ``{function key: [(args, {}, None)]}``
    for each method of an ``entry`` class that nothing in the program calls
    (``called``: keys with call sites) and that takes a string: its first string
    parameter is ``("str", instance)``, the others unknown.  ``fns``: the linker's
    ``{key: (unit, parameter names, parameter types, defaults)}``."""
    out: dict[str, list[tuple[list[Any], dict[str, Any], None]]] = {}
    for k, (unit, _params, ptypes, _defaults) in fns.items():
        if unit not in entry or k in called:
            continue
        i = next((j for j, t in enumerate(ptypes) if is_string_type(t)), None)
        if i is not None:
            out[k] = [([None] * i + [("str", instance)], {}, None)]
    return out


def instances(values: dict[str, tuple[Any, Src]], full: str, classes: dict[str, PluginClass]
              ) -> tuple[list[tuple[str, PluginClass, Src]], list[Note]]:
    """``([(instance name, plugin, where the file names it)], notes)``: the plugins node ``full`` loads, read
    from its parameter values ``values`` (``{"/node/key": (value, where)}``, strings
    and string tuples; :meth:`param_yaml.PackageParams.for_node`).  ``classes``: the
    exported plugins by type and by lookup name.  A ``plugin`` value that looks
    like a class (``a::B``, ``pkg/B``) and names no exported plugin is a located
    note at its line; any other value is not a plugin's and is left alone."""
    pre = full.rstrip("/") + "/"
    named: dict[str, tuple[str, Src]] = {}
    for k, (v, at) in sorted(values.items()):
        if k.startswith(pre) and k.endswith(".plugin") and isinstance(v, str) and len(k) > len(pre) + 7:
            named[k[len(pre):-len(".plugin")]] = (v.strip().lstrip(":"), at)
    listed = {x for k, (v, _at) in values.items() if k.startswith(pre) and isinstance(v, tuple) for x in v}
    out: list[tuple[str, PluginClass, Src]] = []
    notes: list[Note] = []
    for inst, (v, at) in named.items():
        if listed & set(named) and inst not in listed:
            continue  # the node's list names other plugins: this one is not loaded
        pc = classes.get(v)
        if pc is not None:
            out.append((inst, pc, at))
        elif _CLASSY.match(v):
            notes.append(Note(at, f"parameter {pre}{inst}.plugin names plugin '{v}', which no scanned package "
                                  f"exports (package.xml <export> naming a plugin description): its endpoints "
                                  f"are unknown"))
    return out, notes


#: base classes of ros2_control's controllers: each instance runs on a node of its own
CONTROLLER_BASES = ("controller_interface::ControllerInterface", "controller_interface::ChainableControllerInterface")


def is_controller(pc: PluginClass) -> bool:
    """Whether plugin ``pc`` is a ros2_control controller (its base class is one of
    :data:`CONTROLLER_BASES`, or another ``controller_interface::`` base)."""
    return pc.base in CONTROLLER_BASES or pc.base.startswith("controller_interface::")


def controller_instances(entries: Iterable[tuple[str, str, Any, Src]], classes: dict[str, PluginClass],
                         notes: list[Note] | None = None) -> list[tuple[str, str, PluginClass, Src]]:
    """``[(node name, instance, controller, where)]``: the controllers a controller
    manager's parameter file names (ros2_control's controller manager, "Controller
    manager" docs: ``controller_manager: ros__parameters: <name>: type: pkg/Class``),
    each a node ``<name>`` in the manager's namespace (the manager makes one node per
    controller, named after it).  ``entries``: :class:`param_yaml.PackageParams`
    entries (``(node pattern, "~key", value, where)``); ``classes``: the exported
    plugins by type and by lookup name.  A ``type`` naming no exported plugin under
    a ``controller_manager`` key is a located note in ``notes`` (its endpoints are
    unknown); a ``type`` naming a plugin that is no controller is left alone."""
    out: list[tuple[str, str, PluginClass, Src]] = []
    for pattern, key, value, at in entries:
        inst = key[1:-len(".type")] if key.startswith("~") and key.endswith(".type") else ""
        pc = classes.get(value.strip()) if isinstance(value, str) else None
        if inst and "." not in inst and pc is None and isinstance(value, str) and _CLASSY.match(value.strip()) \
                and pattern.rstrip("/").endswith("controller_manager") and notes is not None:
            notes.append(Note(at, f"controller {inst} is a {value.strip()}, which no scanned package exports "
                                  f"(pluginlib_export_plugin_description_file or a package.xml export): its "
                                  f"endpoints are unknown"))
        if not inst or "." in inst or pc is None or not is_controller(pc):
            continue
        ns = pattern.rsplit("/", 1)[0] if "*" not in pattern else ""
        full = (ns.rstrip("/") + "/" + inst) if ns.startswith("/") else "/" + inst
        if not any(x[0] == full and x[2] == pc for x in out):
            out.append((full, inst, pc, at))
    return out


def unloaded_note(e: Endpoint, pc: PluginClass, xml_shown: str) -> Note:
    """The located note for endpoint ``e`` of plugin ``pc`` that no node is found to
    load (``xml_shown``: its description file as shown)."""
    named = (f"no controller manager's parameter file names it ('<name>: type: {pc.lookup}'), so its node "
             f"name is known only at run time") if is_controller(pc) else \
        f"no node's parameter file names it ('<name>.plugin: {pc.type}')"
    return Note(e.src, f"{_KINDS.get(e.kind, e.kind)} of plugin {pc.type} (a {pc.base or 'plugin'} exported in "
                       f"{xml_shown}:{pc.line}): the plugin is loaded at run time and {named}: not in the graph")
