"""The graph's nodes from the packages' programs (docs/ros.md, "Reading real
code", "Programs without launch files").

Each package's programs (:mod:`programs`) are linked (:mod:`link`) once.

* Without launch files every program is its nodes: each node it names (a
  program naming several gets each the endpoints of its own classes), with
  the endpoints its code creates wherever they are written; a program
  naming no node is reported, not drawn.
* A launch file's node is the program of its package and executable (or its
  component class): all the program's endpoints, under the launch name (or
  the name the code gives).

The caller's ``add_node`` resolves the names (namespaces, remaps, parameters).
"""
from __future__ import annotations

from pathlib import Path
import dataclasses
import functools
from typing import Any, Callable, Sequence

from rclverify.ros.extract import cross_package, emit, names, nodelets, plugins
from rclverify.ros.extract.built import Unbuilt, not_built
from rclverify.ros.extract.executables import Targets
from rclverify.ros.extract.launch import LaunchNode
from rclverify.ros.extract.link import Linked, Linker
from rclverify.ros.extract.model import Endpoint, Graph, Note, Src
from rclverify.ros.extract.packages import Package
from rclverify.ros.extract.param_yaml import pending_for
from rclverify.ros.extract.programs import PackageCode, Program, programs
from rclverify.ros.graph.accounting import Ledger
from rclverify.ros.graph.link_cache import LinkCache


class Assembly:
    """The programs of every scanned package and their linked endpoints.

    ``records[pkg][shown]``: every parsed source record of the package;
    ``targets[pkg]``: its build targets; ``known(t)``: whether the scan's type
    table defines type ``t``."""

    def __init__(self, pkgs: dict[str, Package], records: dict[str, dict[str, dict[str, Any]]],
                 targets: dict[str, Targets], show: Callable[[Path], str], known: Callable[[str], bool],
                 kept: "LinkCache | None" = None) -> None:
        self.pkgs, self.known, self.kept = pkgs, known, kept
        self.codes = {p: PackageCode(p, show(pkgs[p].root), records.get(p, {}), show) for p in sorted(pkgs)}
        self.progs = {p: programs(self.codes[p], targets[p]) for p in sorted(pkgs)}
        self.unbuilt: list[Unbuilt] = []  # ROS 1 code no target builds: listed apart, never nodes (built.py)
        for p in sorted(pkgs):
            self.progs[p], gone = not_built(pkgs[p], self.progs[p], self.codes[p], targets[p])
            self.unbuilt += gone
        self.targets = targets
        self._linked: dict[int, Linked] = {}
        # a program's code in the workspace's other packages (helper libraries)
        self._views: dict[int, PackageCode] = {}
        used: dict[str, set[str]] = {}
        for pk in sorted(self.progs):
            for prog in self.progs[pk]:
                added = cross_package.extend(prog, self.codes)
                if added:
                    self._views[id(prog)] = cross_package.view(prog, self.codes, added)
                    for f, other in added.items():
                        used.setdefault(other, set()).add(f)
        cross_package.library_programs(self.progs, used, self.codes)
        # ROS 2 pluginlib classes by type and lookup name, their programs, the instances loaded
        self.plugin_classes = {k: pc for pk in sorted(targets) for pc in targets[pk].pluginlib
                               for k in (pc.type, pc.lookup)}
        self.plugin_progs = {p.plugin: p for pk in sorted(self.progs) for p in self.progs[pk] if p.plugin}
        self.plugins_loaded: set[str] = set()
        self._instances: dict[tuple[str, str], Program] = {}
        self.ledger = Ledger(show)  # what each program gave (accounting.py)

    def linked(self, prog: Program) -> Linked:
        """``prog`` linked (once)."""
        got = self._linked.get(id(prog))
        if got is None:
            code = self._views.get(id(prog), self.codes[prog.package])
            make = functools.partial(_link, prog, code, self.known)
            got = self._linked[id(prog)] = self.kept.kept("link", prog, code, make) if self.kept is not None \
                else make()
        return got

    def program(self, pkg: str, exe: str) -> Program | None:
        """The program of executable ``exe`` of package ``pkg`` (or one of its aliases)."""
        progs = self.progs.get(pkg, [])
        return next((p for p in progs if p.exe == exe), None) or next((p for p in progs if exe in p.aliases), None)

    def class_program(self, plugin: str, pkg: str | None) -> tuple[Program | None, str | None]:
        """The program of a component class (``ns::C``, or its last part when unique in
        ``pkg``): the target that registers it, else the files that define it."""
        p = plugin.strip().lstrip(":")
        hits: list[tuple[str, str, str]] = []  # (package, class, file)
        for pk, code in self.codes.items():
            for f, r in code.records.items():
                for cls in r.get("units", {}) if r.get("lang") != "py" else ():
                    if cls == p or (cls.split("::")[-1] == p.split("::")[-1] and (pkg is None or pk == pkg)):
                        hits.append((pk, cls, f))
        exact = [h for h in hits if h[1] == p]
        classes = {(h[0], h[1]) for h in (exact or hits)}
        if len(classes) != 1:
            return None, None
        pk, cls = next(iter(classes))
        prog = next((x for x in self.progs.get(pk, []) if x.units == {cls}), None)
        if prog is None:
            files = sorted({h[2] for h in hits if h[1] == cls})
            from rclverify.ros.extract.programs import _closure  # deferred: optional or conditional (inside a block)
            prog = Program(pk, None, files, _closure(self.codes[pk], files, set()), {cls})
            added = cross_package.extend(prog, self.codes)
            if added:
                self._views[id(prog)] = cross_package.view(prog, self.codes, added)
            self.progs[pk].append(prog)
        return prog, cls

    def registered_at(self, prog: Program) -> Src | None:
        """Where a nodelet program's class is registered (``PLUGINLIB_EXPORT_CLASS``)."""
        cls = next(iter(prog.units or ()), "")
        for f in prog.files:
            for written, _lookup, at in self.codes[prog.package].records.get(f, {}).get("nodelets", []):
                if cls == written or cls.endswith("::" + written.split("::")[-1]):
                    return at  # type: ignore[no-any-return]
        return None

    def nodelet_program(self, lookup: str) -> Program | None:
        """The program of the nodelet a launch file loads as ``pkg/Type`` (its plugin
        description's lookup name, else a registered class named ``Type``)."""
        pkg, _, last = lookup.partition("/")
        progs = [p for p in self.progs.get(pkg, []) if p.nodelet is not None]
        exact = [p for p in progs if p.nodelet == lookup]
        near = [p for p in progs if (p.nodelet or "").split("/")[-1].split("::")[-1] == last.split("::")[-1]]
        hit = exact or near
        return hit[0] if len(hit) == 1 else None

    def plugin_endpoints(self, full: str, values: dict[str, tuple[Any, Src]]
                         ) -> tuple[list[Endpoint], list[str], list[Note]]:
        """``(endpoints, files, notes)`` of the plugins node ``full`` loads, found in its
        parameter values ``values`` (:func:`plugins.instances`): each instance's program
        linked with the instance's name (:mod:`plugins`)."""
        found, notes = plugins.instances(values, full, self.plugin_classes)
        eps: list[Endpoint] = []
        files: list[str] = []
        for inst, pc, at in found:
            base = self.plugin_progs.get(pc.type)
            if base is None:
                notes.append(Note(at, f"plugin {pc.type} (instance {inst} of {full}) is exported, but no scanned C++ "
                                      f"source defines the class: its endpoints are unknown"))
                continue
            prog = self._instance(base, pc.type, inst)
            got = self.linked(prog)
            notes.extend(got.notes)
            eps += [e for e, _o in got.endpoints]
            files += [f for f in got.files if f not in files]
        return eps, files, notes

    def _instance(self, base: Any, plugin_type: str, inst: str) -> Any:
        """The program of one named instance of a plugin class (``base`` with the
        instance's name), made once per (class, instance) and sharing the class's
        views; the class is marked loaded."""
        prog = self._instances.get((plugin_type, inst))
        if prog is None:
            prog = self._instances[(plugin_type, inst)] = dataclasses.replace(base, files=list(base.files),
                                                                              instance=inst)
            if id(base) in self._views:
                self._views[id(prog)] = self._views[id(base)]
        self.plugins_loaded.add(plugin_type)
        return prog

    def controller_nodes(self, add_node: Callable[..., None], entries: dict[str, list[Any]], g: Graph) -> None:
        """ros2_control controllers as nodes of their own: each instance a
        controller manager's parameter file names (:func:`plugins.controller_instances`)
        is a lifecycle node of that name whose code is the controller class, linked
        with the instance's name; a controller whose class no scanned source
        defines is a located note at the file's line."""
        found = plugins.controller_instances([x for pk in sorted(entries) for x in entries[pk]],
                                             self.plugin_classes, g.notes)
        for full, inst, pc, at in found:
            base = self.plugin_progs.get(pc.type)
            if base is None:
                g.notes.append(Note(at, f"controller {inst} is a {pc.type}, exported, but no scanned C++ source "
                                        f"defines the class: its endpoints are unknown"))
                continue
            prog = self._instance(base, pc.type, inst)
            got = self.linked(prog)
            g.notes.extend(got.notes)
            eps = [e for e, _o in got.endpoints]
            add_node(full, names.split(full)[0], base.package, pc.lookup, _files(prog, got, eps, None), at, eps,
                     [], "source", lifecycle=True)

    def unloaded_plugins(self) -> list[Note]:
        """A located note for each endpoint of each plugin class no node was found to load
        (:func:`plugins.unloaded_note`), and what the plugin descriptions could not say."""
        out: list[Note] = []
        for pk in sorted(self.targets):
            root = self.pkgs[pk].root if pk in self.pkgs else None
            for n in self.targets[pk].plugin_notes:
                shown = self.codes[pk].show(root / n.src.file) if root is not None else n.src.file
                out.append(dataclasses.replace(n, src=Src(shown, n.src.line, n.src.col)))
        for t, prog in sorted(self.plugin_progs.items()):
            if t in self.plugins_loaded:
                continue
            pc = self.plugin_classes[t]
            code = self._views.get(id(prog), self.codes[prog.package])
            make = functools.partial(_running_endpoints, prog, code, self.known)
            eps: list[Endpoint] = self.kept.kept("plugin-endpoints", prog, code, make) if self.kept is not None \
                else make()
            out += [plugins.unloaded_note(e, pc, self.codes[prog.package].show(pc.xml)) for e in eps]
        return out

    def source_nodes(self, add_node: Callable[..., None], g: Graph) -> None:
        """Without launch files: every program's nodes (see the module docstring)."""
        for pkg in sorted(self.progs):
            named = {e.src for prog in self.progs[pkg] if self.linked(prog).nodes
                     for e, _o in self.linked(prog).endpoints}
            for prog in self.progs[pkg]:
                if prog.plugin is not None:
                    continue  # a pluginlib class: its endpoints are its loading node's (plugin_endpoints)
                got = self.linked(prog)
                if not got.nodes and prog.nodelet is not None and got.endpoints:
                    if all(e.src in named for e, _o in got.endpoints):
                        continue  # the nodelet's code is a node executable's too (its node wrapper)
                    name = prog.nodelet.split("/")[-1].split("::")[-1]
                    at = self.registered_at(prog) or min((e.src for e, _o in got.endpoints),
                                                         key=lambda x: (x.file, x.line, x.col))
                    g.notes.append(Note(at, f"nodelet {prog.nodelet} is loaded by no launch file: shown as node "
                                            f"/{name} (a launch file gives its name)", "ROS-LAUNCH"))
                    g.notes.extend(got.notes)
                    eps = [e for e, _o in got.endpoints]
                    add_node("/" + name, "/", pkg, prog.nodelet, _files(prog, got, eps, None), at, eps, [], "source")
                    self.ledger.gave(pkg, _keys(prog, self.progs.get(pkg, [])), "/" + name)
                    continue
                if not got.nodes:
                    self._nameless(pkg, prog, got, g)
                    continue
                g.notes.extend(got.notes)
                for i, (name, src, ns) in enumerate(got.nodes):
                    eps = [e for e, o in got.endpoints if o == i]
                    full = names.join(names.join("/", ns or ""), name)
                    self.ledger.gave(pkg, _keys(prog, self.progs.get(pkg, [])), full)
                    files = _files(prog, got, eps, src.file)
                    add_node(full, names.split(full)[0], pkg, prog.exe, files, src, eps, [], "source",
                             lifecycle=got.kinds[i] == "lifecycle" if i < len(got.kinds) else False)

    def _nameless(self, pkg: str, prog: Program, got: Linked, g: Graph) -> None:
        """A program that names no node the scan reads: a located note at each of its
        endpoints (never a silent miss) and why, for its account (accounting.py)."""
        said = {n.src for n in g.notes}
        what = f"program {prog.exe}" if prog.exe else "a file that"
        for e, _o in sorted(got.endpoints, key=lambda x: (x[0].src.file, x[0].src.line, x[0].src.col)):
            if e.src not in said:
                said.add(e.src)
                g.notes.append(Note(e.src, f"{emit.WHAT[e.kind]} '{e.topic or e.param or '?'}' of {what} names no "
                                           f"node and is started by no launch file: not in the graph",
                                    "ROS-UNRESOLVED"))
        g.notes.extend(got.notes)
        unread = next((n for n in got.notes if n.message.startswith("node name")), None)
        if unread is not None:
            why = f"its node name is not read statically (at {unread.src})"
        elif got.endpoints:
            why = "its code names no node the scan reads (no Node construction, node class or init call is " \
                  f"followed from its entry); its {len(got.endpoints)} endpoint(s) are not in the graph, each noted"
        elif prog.files:
            why = f"no node is constructed in the code it runs ({', '.join(prog.files[:3])}" + \
                  (", ..." if len(prog.files) > 3 else "") + ")"
        else:
            why = "no source file of it is read"
        self.ledger.none(pkg, _keys(prog, self.progs.get(pkg, [])), why)

    def launch_node(self, ln: LaunchNode, add_node: Callable[..., None], g: Graph) -> None:
        """The node launch element ``ln`` starts (see the module docstring)."""
        comp = self.targets.get(ln.pkg, Targets()).components.get(ln.exe) if ln.exe else None
        plugin = ln.plugin or (comp[0] if comp else None)
        prog: Program | None = None
        if ln.pkg == "nodelet" and ln.exe == "nodelet":
            what = nodelets.launch_args(ln.args)
            if what is None or what[1] is None:  # a manager: a container, not a node (docs/ros.md)
                if what is None:
                    g.notes.append(Note(ln.src, f"nodelet args '{ln.args or ''}' are not 'manager', 'load "
                                                f"pkg/Type manager' or 'standalone pkg/Type': not read", "ROS-LAUNCH"))
                return
            lookup = what[1]
            pkg = lookup.split("/")[0]
            prog = self.nodelet_program(lookup)
            if prog is None:
                where = "is not in the scanned workspaces" if pkg not in self.pkgs else \
                    "has it, not built (no target of its CMakeLists.txt builds its sources)" \
                    if any(u.package == pkg and u.name == lookup for u in self.unbuilt) else \
                    "has no nodelet of that name (plugin description, PLUGINLIB_EXPORT_CLASS)"
                g.notes.append(Note(ln.src, f"nodelet '{lookup}': package '{pkg}' {where}; its topics are unknown",
                                    "ROS-LAUNCH"))
            ln = dataclasses.replace(ln, pkg=pkg, exe=lookup, name=ln.name or lookup.split("/")[-1])
        elif plugin:
            prog, _cls = self.class_program(plugin, ln.pkg)
            if prog is None:
                g.notes.append(Note(ln.src, f"component class '{plugin}' of package '{ln.pkg}' is not found in the "
                                            f"scanned C++ sources; its topics are unknown", "ROS-LAUNCH"))
        elif ln.pkg not in self.pkgs:
            g.notes.append(Note(ln.src, f"node package '{ln.pkg}' is not in the scanned workspaces; "
                                        f"its topics are unknown", "ROS-LAUNCH"))
        else:
            prog = self.program(ln.pkg, ln.exe)
            if prog is None:
                g.notes.append(Note(ln.src, f"executable '{ln.exe}' of package '{ln.pkg}' has no source found "
                                            f"(CMakeLists.txt add_executable, setup.py console_scripts, scripts/); "
                                            f"its topics are unknown", "ROS-LAUNCH"))
        if prog is None:
            said = next((n for n in reversed(g.notes) if n.src == ln.src), None)
            self.ledger.launch_missing(ln.pkg or "?", ln.exe or plugin or "?", ln.src,
                                       said.message if said is not None else "its program is not read")
        got = self.linked(prog) if prog is not None else Linked()
        g.notes.extend(got.notes)
        if ln.name is None and len({n for n, _s, _ns in got.nodes}) > 1 and prog is not None:
            # a ROS 2 process of several nodes, none renamed by the launch file: each node
            # is itself, in the launch namespace, with its own endpoints (docs/ros.md)
            for i, (name, _src, code_ns) in enumerate(got.nodes):
                ns = ln.ns if ln.ns != "/" else names.join("/", code_ns or "")
                mine = [e for e, o in got.endpoints if o == i]
                full = names.normalise(name) if name.startswith("/") else names.join(ns, name)
                add_node(full, names.split(full)[0], ln.pkg, ln.exe or None, _files(prog, got, mine, None),
                         ln.src, mine, ln.remaps, "launch", {**pending_for(ln.pending, full), **ln.params},
                         lifecycle=i < len(got.kinds) and got.kinds[i] == "lifecycle")
            return
        eps = [e for e, _o in got.endpoints]
        name = ln.name or (got.nodes[0][0] if got.nodes else (plugin.split("::")[-1] if plugin else ln.exe))
        # the code's namespace (Node(name, namespace=...), rclcpp::Node(name, ns)) holds unless the launch
        # file gives one: launch_ros then remaps __ns, which replaces it (ROS 2 design "Topic and Service Names")
        code_ns = got.nodes[0][2] if got.nodes else None
        base = ln.ns if ln.ns != "/" or not code_ns else names.join("/", code_ns)
        if name.startswith("/"):
            full = names.normalise(name)
            ns = names.split(full)[0]
        else:
            full, ns = names.join(base, name), base
        files = _files(prog, got, eps, None) if prog is not None else []
        add_node(full, ns, ln.pkg, ln.exe or None, files, ln.src, eps, ln.remaps, "launch",
                 {**pending_for(ln.pending, full), **ln.params}, lifecycle="lifecycle" in got.kinds)


def _link(prog: Program, code: PackageCode, known: Callable[[str], bool]) -> Linked:
    """Program ``prog`` linked over ``code``."""
    return Linker(prog, code, known).run()


def _running_endpoints(prog: Program, code: PackageCode, known: Callable[[str], bool]) -> list[Endpoint]:
    """The endpoints the code of plugin program ``prog`` makes in what it runs,
    in source order (each place once)."""
    lk = Linker(prog, code, known)
    eps = {e.src: e for r in lk.recs.values() for e in list(r.get("endpoints", [])) + lk.members(r)
           if (e.unit is not None or e.func is not None) and lk.runs(e.unit, e.func)}
    return [e for _s, e in sorted(eps.items(), key=lambda x: (x[0].file, x[0].line, x[0].col))]


def _keys(prog: Program, others: Sequence[Program] = ()) -> list[str]:
    """The names a declaration may give program ``prog``: its executable, aliases, classes;
    an alias another program of ``others`` (its package's) has as its executable is that
    program's (a script ``beeper.py`` beside a C++ executable ``beeper``: two programs)."""
    taken = {p.exe for p in others if p is not prog and p.exe}
    return [k for k in [prog.exe, *(a for a in prog.aliases if a not in taken), *sorted(prog.units or ())] if k]


def _files(prog: Program, got: Linked, eps: list[Endpoint], named_in: str | None) -> list[str]:
    """The sources shown for a node: where it is named, its program's entry files,
    and every file holding one of its endpoints."""
    out: list[str] = []
    entry = list(prog.entry) if prog.units is None else []
    for f in ([named_in] if named_in else []) + entry + [e.src.file for e in eps]:
        if f and f not in out:
            out.append(f)
    return out
