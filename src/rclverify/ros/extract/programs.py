"""The programs of a package: for each executable (or component class), the
files whose code it runs (docs/ros.md, "Reading real code").

* C++: the executable's own sources, the sources of the libraries it links
  (``target_link_libraries``, transitively, within the package), and the
  package headers they include (quoted or ``<pkg/...>``, transitively) with,
  for a header no target lists, the source of the same name beside it or
  under ``src/`` (its implementation);
* Python: the program's file and the package modules it imports
  (``from pkg.sensors import Sensor``, ``import helpers`` beside a script),
  transitively;
* a component class: the sources of the target that registers it;
* a source file that no program holds and that names a node or creates an
  endpoint is a program of its own (the scan's rule without build files).

The units whose code starts the program (its *entry*) are those of its own
files (or the component's class); the linker (:mod:`link`) follows what they
construct and call from there.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from rclverify.ros.extract.executables import Targets

_HEADER = {".h", ".hh", ".hpp", ".hxx"}
_SOURCE = {".cpp", ".cc", ".cxx", ".c"}


@dataclass
class Program:
    """One program: ``package``, ``exe`` (the executable's name; ``None`` for a
    component class registered without one, or a loose file), ``entry`` (the
    files whose units start it), ``files`` (every file it runs, shown paths),
    ``units`` (explicit entry units: a component's or nodelet's class),
    ``aliases`` (other names of the executable: a script's stem),
    ``nodelet`` (for a nodelet class: its lookup name, :mod:`nodelets`),
    ``plugin`` (for a ROS 2 pluginlib class: its type, :mod:`plugins`; such a
    program is no node, its endpoints are the loading node's) and
    ``instance`` (the name a loader gives one instance of that plugin)."""

    package: str
    exe: str | None
    entry: list[str]
    files: list[str]
    units: set[str] | None = None
    aliases: list[str] = field(default_factory=list)
    nodelet: str | None = None  # a nodelet class's lookup name (``pkg/Type``), or its class when none is known
    plugin: str | None = None  # a ROS 2 pluginlib class (``pkg::Plugin``)
    instance: str | None = None  # the instance name a plugin's loader gives it


def module_names(shown: str, pkg_shown: str) -> list[str]:
    """The dotted module names a package file may be imported as: its path below
    the package, below ``src/``, and its bare name (a script's sibling)."""
    rel = shown[len(pkg_shown) + 1:] if shown.startswith(pkg_shown + "/") else shown
    if not rel.endswith(".py"):
        return []
    parts = rel[:-3].split("/")
    if parts[-1] == "__init__":
        parts = parts[:-1]
    out = [".".join(parts[k:]) for k in range(len(parts)) if parts[k:]]
    return out


@dataclass(frozen=True)
class FileFacts:
    """What finding a package's programs reads of one file's source record (sources_cpp.py,
    sources_py.py): whether it is Python, the classes (``units``), functions and constants it defines,
    the modules it imports and the files it includes (in the order written), the nodelets it registers
    (``(class, lookup name, at)``), whether it names a node, makes one, or makes endpoints."""

    py: bool = False
    units: frozenset[str] = frozenset()
    fns: frozenset[str] = frozenset()
    consts: frozenset[str] = frozenset()
    imports: tuple[str, ...] = ()
    includes: tuple[str, ...] = ()
    nodelets: tuple[tuple[str, str | None, Any], ...] = ()
    names_node: bool = False
    makes_node: bool = False
    endpoints: bool = False

    @staticmethod
    def of(r: dict[str, Any]) -> FileFacts:
        """The facts of the source record ``r``."""
        return FileFacts(py=r.get("lang") == "py", units=frozenset(r.get("units", {})), fns=frozenset(r.get("fns", {})),
                         consts=frozenset(r.get("consts", {})), imports=tuple(r.get("imports", [])),
                         includes=tuple(r.get("includes", [])),
                         nodelets=tuple((cls, lookup, at) for cls, lookup, at in r.get("nodelets", [])),
                         names_node=bool(r.get("node_names")), makes_node=bool(r.get("nodes")),
                         endpoints=bool(r.get("endpoints")))


#: the facts of a file the package has no record of
NO_FILE = FileFacts()


class PackageCode:
    """What :func:`programs` needs of one package: its directory as shown, its
    source records (``records[shown]``) and what programs are found by of each
    (``facts[shown]``, :class:`FileFacts`), and how a ``Path`` is shown."""

    def __init__(self, name: str, root_shown: str, records: dict[str, dict[str, Any]],
                 show: Callable[[Path], str], facts: dict[str, FileFacts] | None = None) -> None:
        """``facts``: those of some of ``records`` already read (another view of the same records)."""
        self.name, self.root, self.records, self.show = name, root_shown, records, show
        self.facts = {shown: (facts or {}).get(shown) or FileFacts.of(r) for shown, r in records.items()}
        self.modules: dict[str, str] = {}
        for shown in sorted(records):
            for m in module_names(shown, root_shown):
                self.modules.setdefault(m, shown)
        self.by_name: dict[str, list[str]] = {}
        for shown in records:
            self.by_name.setdefault(shown.rsplit("/", 1)[-1], []).append(shown)

    def module(self, dotted: str, depth: int = 0) -> tuple[str, str] | None:
        """``(file, attribute path)`` a dotted import origin names in this package:
        ``pkg.sensors.Sensor`` -> (``.../pkg/sensors.py``, ``Sensor``).  A name the
        module found does not define but imports itself (a package's
        ``__init__.py`` re-exporting ``from .sensors import Sensor``) is followed
        to the module defining it (Python's import system binds the name in the
        importing module's namespace: ``pkg.Sensor`` is ``pkg.sensors.Sensor``),
        at most four modules deep."""
        parts = dotted.split(".")
        for k in range(len(parts), 0, -1):
            f = self.modules.get(".".join(parts[:k]))
            if f is not None:
                attr = ".".join(parts[k:])
                again = self._reexported(f, attr, dotted) if attr and depth < 4 else None
                hit = self.module(again, depth + 1) if again is not None else None
                return hit if hit is not None and hit[0] != f else (f, attr)
        return None

    def _reexported(self, f: str, attr: str, dotted: str) -> str | None:
        """The origin module file ``f`` imports ``attr``'s first name from, when ``f``
        does not define it (no class, function or constant of that name)."""
        r = self.facts.get(f, NO_FILE)
        head, _, rest = attr.partition(".")
        if not r.py or f"{f}::{head}" in r.units or f"{f}::{head}" in r.fns or head in r.consts:
            return None
        origins = [o for o in r.imports if o.rsplit(".", 1)[-1] == head and o != dotted]
        if len(origins) != 1:
            return None
        return str(origins[0]) + ("." + rest if rest else "")

    def include(self, name: str, at: str) -> str | None:
        """The package file an ``#include`` of ``name`` from file ``at`` reads."""
        here = at.rsplit("/", 1)[0]
        for cand in (f"{here}/{name}", f"{self.root}/include/{name}", f"{self.root}/{name}",
                     f"{self.root}/src/{name}"):
            if cand in self.records:
                return cand
        hits = [f for f in self.by_name.get(name.rsplit("/", 1)[-1], []) if f.endswith("/" + name)]
        return hits[0] if len(hits) == 1 else None


def _closure(code: PackageCode, start: list[str], listed: set[str]) -> list[str]:
    seen: list[str] = []
    todo = list(start)
    while todo:
        f = todo.pop(0)
        if f in seen or f not in code.records:
            continue
        seen.append(f)
        r = code.facts[f]
        if r.py:
            for origin in r.imports:
                hit = code.module(origin)
                if hit is not None and hit[0] not in seen:
                    todo.append(hit[0])
            continue
        for inc in r.includes:
            h = code.include(inc, f)
            if h is None or h in seen:
                continue
            todo.append(h)
            stem = h.rsplit("/", 1)[-1].rsplit(".", 1)[0]
            if "." + h.rsplit(".", 1)[-1] in _HEADER:
                for cand in code.by_name:
                    if cand.rsplit(".", 1)[0] == stem and "." + cand.rsplit(".", 1)[-1] in _SOURCE:
                        for src in code.by_name[cand]:
                            if src not in listed and src not in seen:
                                todo.append(src)
    return seen


def _class_named(code: PackageCode, cls: str) -> str:
    """The class of the package's C++ records that ``cls`` (as a build file or
    plugin description writes it) names: itself, else the one class whose
    qualified name ends with it."""
    cls = cls.strip().lstrip(":")
    units = {u for r in code.facts.values() if not r.py for u in r.units}
    if cls in units:
        return cls
    ends = sorted(u for u in units if u.endswith("::" + cls.split("::")[-1]) and
                  (u.endswith("::" + cls) or "::" not in cls))
    return ends[0] if len(ends) == 1 else cls


def programs(code: PackageCode, t: Targets) -> list[Program]:
    """Every program of the package (see the module docstring)."""
    f = _Finder(code, t)
    f.executables()
    f.plugins()
    f.pluginlib()
    f.scripts()
    f.loose()
    return f.out


class _Finder:
    """The package's programs found kind by kind (:func:`programs`): ``out``
    the programs so far, ``held`` the files one of them takes in."""

    def __init__(self, code: PackageCode, t: Targets) -> None:
        self.code, self.t, self.show = code, t, code.show
        show = code.show
        self.listed = {show(p) for srcs in list(t.executables.values()) + list(t.libraries.values()) for p in srcs}
        self.out: list[Program] = []
        self.held: set[str] = set()

    def linked(self, target: str, seen: set[str]) -> list[str]:
        """The sources of the libraries ``target`` links, transitively."""
        t, show = self.t, self.show
        out = []
        for lib in t.links.get(target, []):
            if lib in t.libraries and lib not in seen:
                seen.add(lib)
                out += [show(p) for p in t.libraries[lib]] + self.linked(lib, seen)
        return out

    def executables(self) -> None:
        """One program per built executable (a component's executable runs its class)."""
        code, t, show = self.code, self.t, self.show
        for exe, srcs in sorted(t.executables.items()):
            own = [show(p) for p in srcs]
            files = _closure(code, own + self.linked(exe, {exe}), self.listed)
            comp = t.components.get(exe)
            self.out.append(Program(code.name, exe, own, files, {comp[0]} if comp else None))
            self.held.update(files)

    def plugins(self) -> None:
        """Nodelets and components: one program per class (and per executable
        of a component that has no executable target of its own); nodelets
        registered in code with no plugin description read count too."""
        code, t, show = self.code, self.t, self.show
        lookups = {c: k for k, (c, _lib) in t.nodelets.items()}
        plugins = dict(t.plugins)
        for f, r in sorted(code.facts.items()):  # nodelets registered in code, with no plugin description read
            for cls, lookup, _at in r.nodelets:
                if _class_named(code, cls) not in {_class_named(code, c) for c in plugins}:
                    lib = next((n for n, ps in sorted(t.libraries.items()) if f in {show(p) for p in ps}), None)
                    plugins[cls] = lib or f"file:{f}"
                    lookups.setdefault(cls, lookup or cls)
        for cls, target in sorted(plugins.items()):
            lib_srcs = [show(p) for p in t.libraries.get(target, []) + t.executables.get(target, [])] or \
                ([target[5:]] if target.startswith("file:") else [])
            files = _closure(code, lib_srcs + self.linked(target, {target}),
                             self.listed if not target.startswith("file:") else set())
            exes: list[str | None] = [e for e, (c, _l) in t.components.items() if c == cls]
            for comp_exe in exes or [None]:
                if comp_exe is not None and comp_exe in t.executables:
                    continue
                self.out.append(Program(code.name, comp_exe, lib_srcs, files, {_class_named(code, cls)},
                                        nodelet=lookups.get(cls)))
            self.held.update(files)

    def pluginlib(self) -> None:
        """ROS 2 pluginlib classes: run from their class, loaded by a node (plugins)."""
        code, t, show = self.code, self.t, self.show
        for pc in t.pluginlib:
            cls = _class_named(code, pc.type)
            srcs = [show(p) for p in t.libraries.get(pc.library or "", [])] or sorted(
                f for f, r in code.facts.items() if not r.py and cls in r.units)
            if srcs and any(cls in r.units for r in code.facts.values() if not r.py):
                target = pc.library if pc.library in t.libraries else None
                files = _closure(code, srcs + (self.linked(target, {target}) if target else []),
                                 self.listed if target else set())
                self.out.append(Program(code.name, None, srcs, files, {cls}, plugin=pc.type))
                self.held.update(f for f in files if not code.facts.get(f, NO_FILE).names_node)

    def scripts(self) -> None:
        """One program per installed script (its other installed names as aliases)."""
        code = self.code
        scripts: dict[str, list[str]] = {}
        for exe, paths in self.t.programs.items():
            scripts.setdefault(self.show(paths[0]), []).append(exe)
        for f, names in sorted(scripts.items()):
            files = _closure(code, [f], self.listed)
            self.out.append(Program(code.name, names[0], [f], files, None, names[1:]))
            self.held.update(files[1:])

    def loose(self) -> None:
        """Files no build target names that name a node or make endpoints:
        a program each, unless another program takes them in."""
        code, held = self.code, self.held
        entries = {p.entry[0] for p in self.out if p.entry and p.exe is not None
                   and code.facts.get(p.entry[0], NO_FILE).py}

        def content(f: str) -> bool:
            r = code.facts[f]
            return r.makes_node or r.names_node or r.endpoints

        loose = [f for f in sorted(code.records) if f not in entries and content(f)]
        py = [f for f in loose if code.facts[f].py]
        cpp = [f for f in loose if not code.facts[f].py]
        # files naming a node first, so the modules and headers they take in are theirs
        for f in sorted(py + cpp, key=lambda f: (not code.facts[f].names_node,
                                                  "." + f.rsplit(".", 1)[-1] in _HEADER, f)):
            if f in held and not (f in py and code.facts[f].makes_node):
                continue  # a module or header a program takes in (a script naming a node also runs alone;
                # a base class naming its node by its constructor's parameter does not)
            files = _closure(code, [f], self.listed)
            name = f.rsplit("/", 1)[-1]
            if f in py:
                stem = name.rsplit(".", 1)[0]
                self.out.append(Program(code.name, name, [f], files, None, [stem] if stem != name else []))
            else:
                self.out.append(Program(code.name, None, [f], files))
            held.update(files)
