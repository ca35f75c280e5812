"""``rclverify ros scan``: one computation graph from ROS 1 and ROS 2
workspaces, launch files, node sources and bags (docs/ros.md).

Nodes come from the launch files given (``launch``); without any, each
node source that names its node (``rospy.init_node('n')``,
``ros::init(.., "n")``, ``Node("n")`` ...) is one node in the root
namespace (programs naming the same node are kept apart, each a node
``/name@package.executable``: :func:`.graph_nodes.apart_name`; a Python file's node
classes are one node each).  A node's topics are its sources' publishers and subscribers,
resolved in the node's namespace (ROS name rules, :mod:`names`) and then
remapped by the launch file's ``remap`` elements (the last matching remap wins).

The graph's nodes and edges are added by :mod:`.graph_nodes`.
"""
from __future__ import annotations

from rclverify.ros.extract import safefs

import dataclasses
import functools
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

from rclverify.ros.graph.absent import absent_interfaces
from rclverify.ros.graph.accounting import NOT_BUILT, Account
from rclverify.ros.graph.assemble import Assembly
from rclverify.ros.graph.link_cache import LinkCache
from rclverify.ros.graph.graph_nodes import GraphNodes
from rclverify.ros.extract.cache import ParseCache
from rclverify.ros.extract.executables import Targets, exported_cmake, targets
from rclverify.ros.extract.interfaces import TypeTable
from rclverify.ros.extract.launch import Interpreter
from rclverify.ros.extract.launch_readers import read_xml, read_yaml
from rclverify.ros.extract.launch_tree import El
from rclverify.ros.extract.launch_ros2 import read_python
from rclverify.ros.extract.link import UNBUILT
from rclverify.ros.extract.model import SERVICE_ROLES, Graph, Note, Src
from rclverify.ros.extract.param_yaml import PackageParams
from rclverify.ros.extract.packages import Package, find_manifests, read_package
from rclverify.ros.extract.sources_cpp import scan_cpp
from rclverify.ros.extract.sources_py import scan_python
from rclverify.ros.extract.interfaces import DEBIAN_SHARE, ament_prefixes

_CPP = {".cpp", ".cc", ".cxx", ".hpp", ".h", ".hh"}
_SKIP_DIRS = {"build", "devel", "install", "log", "test", "tests", "launch", "msg", "srv", "action", "__pycache__"}
_NOT_SCRIPTS = {"CMakeLists", "Makefile", "LICENSE", "COPYING", "AUTHORS", "CHANGELOG", "README", "CONTRIBUTING",
                "Doxyfile", "Dockerfile", "COLCON_IGNORE", "CATKIN_IGNORE", "AMENT_IGNORE", "PKG-INFO"}
_SCRIPT_DIRS = ("scripts", "nodes", "bin")
MAX_SOURCE_BYTES = 2_000_000


@dataclass
class ScanResult:
    """The graph plus what the scan used: packages, the type table, and
    each file's parse results (``sources[shown] = {nodes, endpoints, notes}``)."""

    graph: Graph
    packages: dict[str, Package]
    table: TypeTable
    sources: dict[str, dict[str, Any]] = field(default_factory=dict)
    cache_hits: int = 0  # source files whose parse the cache gave
    cache_misses: int = 0  # source files parsed (the cache had none)
    link_hits: int = 0  # programs whose linking the cache gave
    link_misses: int = 0  # programs linked (the cache had none)


class Shower:
    """Paths as shown in locations: relative to ``base`` when inside it."""

    def __init__(self, base: Path | None) -> None:
        self.base = os.path.realpath(base or Path.cwd())
        self._memo: dict[str, str] = {}

    def __call__(self, p: Path) -> str:
        key = str(p)
        shown = self._memo.get(key)
        if shown is None:
            real = os.path.realpath(key)
            inside = real == self.base or real.startswith(self.base.rstrip(os.sep) + os.sep)
            shown = Path(os.path.relpath(real, self.base)).as_posix() if inside else key
            self._memo[key] = shown
        return shown


def _source_files(root: Path, skipped: list[str] | None = None) -> tuple[list[Path], list[Path], list[Path]]:
    """``(Python files, C++ files, files without an extension)`` of a package; the last
    are Python programs when their first line is a Python ``#!`` (or a build file
    installs them as one)."""
    py, cpp, bare = [], [], []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in safefs.keep_names(dirpath, dirnames, skipped)
                             if d not in _SKIP_DIRS and not d.startswith("."))
        for f in sorted(safefs.keep_names(dirpath, filenames, skipped)):
            p = Path(dirpath) / f
            if f.endswith(".py") and f != "setup.py" and not f.endswith(".launch.py") and (
                    f != "__init__.py" or _reexports(p)):
                py.append(p)  # a package's __init__.py read when it imports names (re-exports them)
            elif p.suffix in _CPP:
                cpp.append(p)
            elif not p.suffix and not f.startswith(".") and f not in _NOT_SCRIPTS:
                bare.append(p)
    return py, cpp, bare


def _reexports(p: Path) -> bool:
    """Whether package ``__init__.py`` ``p`` imports names (``from .x import
    Name``, ``from pkg.x import Name``): read, so ``from pkg import Name`` finds
    ``Name``'s module (:meth:`~rclverify.ros.extract.programs.PackageCode.module`);
    an empty or unreadable one is not."""
    try:
        return b"from " in safefs.read_bytes(p)
    except OSError:
        return False


def _python_shebang(data: bytes) -> bool:
    """Whether a file's first line is a ``#!`` naming a Python interpreter."""
    return data.startswith(b"#!") and b"python" in data.split(b"\n", 1)[0]


def _load_launch(path: Path, shown: str) -> tuple[El | None, list[Note]]:
    n = path.name
    if n.endswith(".py"):
        return read_python(path, shown)
    if n.endswith((".yaml", ".yml")):
        return read_yaml(path, shown)
    return read_xml(path, shown)


def scan(paths: Sequence[Path], launch: Sequence[Path] = (), launch_args: dict[str, str] | None = None,
         bags: Sequence[Path] = (), cache_path: Path | None = None, base: Path | None = None,
         standard: bool = True) -> ScanResult:
    """Scan workspaces ``paths`` (directories holding packages) into a graph.

    ``launch``: entry launch files (with ``launch_args``); ``bags``: recorded
    runs; ``cache_path``: the per-file parse cache (``None``: no cache);
    ``base``: paths in locations are shown relative to it (default: the
    current directory). Never raises on bad input: unreadable files become
    located notes (``ROS-PARSE`` errors) in ``graph.notes``.
    """
    # Reads are confined to the workspace (``base``, else the scanned paths
    # and entry launch files as given): links leaving it are skipped (docs/ros.md).
    tops = [base] if base is not None else [*paths, *(Path(lf).parent for lf in launch)]
    with safefs.confined([*tops, DEBIAN_SHARE, *(p / "share" for p in ament_prefixes())]):
        return _scan(paths, launch, launch_args, bags, cache_path, base, standard)


def _scan(paths: Sequence[Path], launch: Sequence[Path], launch_args: dict[str, str] | None,
          bags: Sequence[Path], cache_path: Path | None, base: Path | None, standard: bool) -> ScanResult:
    sc = _Scan(Shower(base), ParseCache(cache_path) if cache_path is not None else None)
    sc.read_packages(paths)
    sc.read_types(standard)
    sc.read_sources()
    sc.assemble(launch, launch_args)
    sc.finish(bags)
    return sc.res


class _Scan(GraphNodes):
    """One scan's state, step by step (:func:`scan`): the packages and their
    manifests, the type table, each source file's record, then the nodes
    assembled from the launch files (or, without them, from the programs),
    the recorded runs and the types the graph uses."""

    def __init__(self, show: Shower, cache: ParseCache | None) -> None:
        self.show, self.cache = show, cache
        self.g = Graph()
        self.table = TypeTable()
        self.pkgs: dict[str, Package] = {}
        self.skipped: list[str] = []
        self.res = ScanResult(self.g, self.pkgs, self.table)
        self.records: dict[str, dict[str, dict[str, Any]]] = {}
        self.tgts: dict[str, Targets] = {}
        self.launch_params: dict[str, tuple[str, Src]] = {}
        self.unsure: dict[Src, Src] = {}  # a launch node -> the unevaluated condition it was read under
        self.digests: dict[str, str] = {}  # a source file as shown -> the sha256 of its bytes
        self.by_ros_name: dict[str, list[str]] = {}  # a ROS node name -> the graph nodes of the programs taking it
        self.standard = True  # whether the standard (installed) interface packages are read (read_types)

    def read_packages(self, paths: Sequence[Path]) -> None:
        """The packages under ``paths`` (one per name; a second is a note)."""
        g, show, cache, pkgs = self.g, self.show, self.cache, self.pkgs
        tops = []
        for p in paths:
            if safefs.inside(p):
                tops.append(Path(p))
            else:
                g.notes.append(Note(Src(show(Path(p))), "workspace path resolves outside the workspace "
                                                        "(symlink): not scanned", "ROS-PARSE"))
        for m in find_manifests(tops, self.skipped):
            shown = show(m)
            try:
                g.files[shown] = ParseCache.digest(safefs.read_bytes(m))
            except OSError:
                pass
            try:
                sha_m = g.files.get(shown) or ParseCache.digest(safefs.read_bytes(m))
            except OSError:
                sha_m = ""
            pkg, notes = cache.get(f"pkg:{shown}", sha_m, lambda: read_package(m, shown)) if cache and sha_m \
                else read_package(m, shown)
            g.notes.extend(notes)
            if pkg is None:
                continue
            # the cache is keyed by workspace-relative path and content: the
            # directory is this tree's, never the one the entry was made in
            pkg = dataclasses.replace(pkg, root=m.parent, manifest=m)
            if pkg.name in pkgs:
                g.notes.append(Note(Src(shown), f"package '{pkg.name}' also at {show(pkgs[pkg.name].manifest)}; "
                                                f"this one is ignored", "ROS-MANIFEST"))
                continue
            pkgs[pkg.name] = pkg
            g.packages[pkg.name] = pkg.to_json(shown)

    def read_types(self, standard: bool) -> None:
        """The message, service and action types of the packages and, with
        ``standard``, of the standard packages."""
        g, table, pkgs, cache = self.g, self.table, self.pkgs, self.cache
        self.standard = standard
        for name in sorted(pkgs):
            table.add_package_dir(pkgs[name].root, name, self.show, "workspace", cache, g.files)
        # Debian's ros-*-msgs packages are ROS 1 (Noetic) definitions: used unless
        # every scanned package is a ROS 2 one, whose standard types come from
        # rosbags' ROS 2 store instead (docs/ros.md).
        if standard and (not pkgs or any(p.ros == 1 for p in pkgs.values())):
            table.add_debian_standard(cache)
        elif standard:  # rosbags' ROS 2 store has messages only: services of message-less packages (std_srvs)
            table.add_debian_standard(cache, services_only=True)
            table.add_ament_index(cache, ament_prefixes())  # a sourced ROS 2's services and actions (rcl_interfaces)
        g.notes.extend(table.notes)  # a field of an unknown type: noted in finish (absent.py)

    def read_sources(self) -> None:
        """Each package's build targets and the record of each of its source
        files (Python, C++, and extensionless Python programs)."""
        g, show, cache = self.g, self.show, self.cache
        exported = {name: exported_cmake(self.pkgs[name].root) for name in sorted(self.pkgs)}
        for name in sorted(self.pkgs):
            root = self.pkgs[name].root
            # the CMake functions and macros the other packages export (vendor_register_node(...))
            others = {k: v for other, defs in exported.items() if other != name for k, v in defs.items()}
            self.tgts[name] = targets(root, name, others)
            installed = {p for paths in self.tgts[name].programs.values() for p in paths}
            py, cpp, bare = _source_files(root, self.skipped)
            recs = self.records[name] = {}
            for f in py + cpp + bare:
                quiet = f in bare and f not in installed and f.parent.name not in _SCRIPT_DIRS
                try:
                    data = safefs.read_bytes(f)
                except OSError as exc:
                    if not quiet:
                        sev = "warning" if isinstance(exc, safefs.Refused) else "error"
                        g.notes.append(Note(Src(show(f)), f"cannot read: {exc}", "ROS-PARSE", sev))
                    continue
                if f in bare and not _python_shebang(data) and (f not in installed or data.startswith(b"#!")):
                    continue  # not a Python program (a shell script, a data file)
                if len(data) > MAX_SOURCE_BYTES:
                    g.notes.append(Note(Src(show(f)), "source file larger than 2 MB: not scanned", "ROS-PARSE"))
                    continue
                shown = show(f)
                sha = ParseCache.digest(data)
                is_py = f not in cpp
                fn = functools.partial(_parse, data, shown, is_py)
                r = cache.get(f"{'py' if is_py else 'cpp'}:{shown}", sha, fn) if cache else fn()
                recs[shown] = r
                self.digests[shown] = sha
                if r["nodes"] or r["endpoints"] or r["notes"] or r.get("node_names"):
                    g.files[shown] = sha
                    self.res.sources[shown] = r
        for bad in sorted({safefs.escaped(show(Path(b))) for b in self.skipped}):
            g.notes.append(Note(Src(bad), "name is not valid UTF-8: skipped", "ROS-PARSE"))

    def assemble(self, launch: Sequence[Path], launch_args: dict[str, str] | None) -> None:
        """The graph's nodes: those the entry launch files start, else the
        programs of the packages and the ros2_control controllers."""
        g, show, pkgs = self.g, self.show, self.pkgs
        table = self.table
        kept = None
        if self.cache is not None:  # linked programs kept between scans, keyed by what they read
            cache = self.cache
            kept = LinkCache(cache.get, self.digests, sorted(table.types))
        self.asm = Assembly(pkgs, self.records, self.tgts, show, lambda t: table.get(t) is not None, kept)
        self.pfiles = PackageParams({} if launch else {p: pkgs[p].root for p in pkgs}, show)
        g.notes.extend(self.pfiles.notes)
        if launch:
            interp = Interpreter(lambda p: pkgs[p].root.resolve() if p in pkgs else None,
                                 lambda p: _load_launch(p, show(p)), show)
            for lf in launch:
                interp.run(Path(lf), dict(launch_args or {}))
            for f in interp.files:
                try:
                    g.files[show(f)] = ParseCache.digest(safefs.read_bytes(f))
                except OSError:
                    pass
            g.notes.extend(interp.notes)
            self.launch_params.update(interp.params)
            self.unsure = {ln.src: ln.unsure for ln in interp.nodes if ln.unsure is not None}
            for ln in interp.nodes:
                self.asm.launch_node(ln, self.add_node, g)
        else:
            self.asm.source_nodes(self.add_node, g)
            self.asm.controller_nodes(self.add_node, self.pfiles.entries, g)  # ros2_control controllers
        g.notes.extend(self.asm.unloaded_plugins())
        apart = {(u.package, u.name) for u in self.asm.unbuilt}  # accounted for as not built, below
        accounts = self.asm.ledger.accounts({p: [d for d in self.tgts[p].declared if (p, d.name) not in apart]
                                             for p in self.tgts}, bool(launch))
        accounts += [Account(u.package, "not built", u.name, u.at) for u in self.asm.unbuilt]
        g.programs = [a.to_json() for a in accounts]
        g.notes.extend(a.note() for a in accounts if a.why is not None and a.kind != "launch node")
        g.notes.extend(Note(u.at, f"{u.kind} {u.name} of package {u.package} is not built: {u.why}; listed apart, "
                                  f"not a node", NOT_BUILT) for u in self.asm.unbuilt)

    def finish(self, bags: Sequence[Path]) -> None:
        """The notes once each, the absent interface packages (:mod:`absent`),
        the recorded runs' topics, the types the graph uses, and the parse cache saved."""
        g, res = self.g, self.res
        for shown, r in sorted(res.sources.items()):
            g.notes.extend(r["notes"])
        g.notes = list(dict.fromkeys(g.notes))  # a note given by several programs (a shared header) once
        made = {e.src for n in g.nodes.values() for r in ("pub", "sub") + SERVICE_ROLES for e in n.edges_of(r)}
        g.notes = [n for n in g.notes if not (n.message.endswith(UNBUILT) and n.src in made)]  # another program makes it
        # types nothing defines: one note per absent package, its types known by name from here on
        # (without the standard packages read, nothing can be said absent: only the fields are noted)
        g.notes.extend(absent_interfaces(g, self.table, set(self.pkgs), self.standard))
        for b in bags:
            from rclverify.ros.graph.bag import bag_topics  # deferred: optional or conditional (inside a block)
            recorded, notes = bag_topics(Path(b), self.show(Path(b)))
            g.notes.extend(notes)
            if recorded is not None:
                g.bags.append(recorded)
        used = {e.msg_type for n in g.nodes.values() for e in n.publishes + n.subscribes if e.msg_type}
        used |= {t["type"] for b in g.bags for t in b["topics"] if t["type"]}
        used |= {k for k, v in self.table.types.items() if v.origin == "workspace"}
        g.types = {k: v.to_json() for k, v in self.table.closure(sorted(used)).items()}
        if self.cache is not None:
            self.cache.save()
            kept = getattr(getattr(self, "asm", None), "kept", None)
            res.link_hits, res.link_misses = (kept.hits, kept.misses) if kept is not None else (0, 0)
            res.cache_hits, res.cache_misses = self.cache.hits - res.link_hits, self.cache.misses - res.link_misses


def _parse(data: bytes, shown: str, is_py: bool) -> dict[str, Any]:
    """The record of one source file (:func:`scan_python` or :func:`scan_cpp`)."""
    return scan_python(data.decode("utf-8", errors="replace"), shown) if is_py else scan_cpp(data, shown)
