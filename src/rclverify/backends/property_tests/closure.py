"""The import closure of a Python implementation: every workspace file that
runs when the property tests run it, so that what runs is what is hashed
(docs/property-tests.md, "What runs is what is hashed").

A property test's verdict is about the code the implementation runs, and
that code is the implementation's file *and every workspace module it
imports*, transitively: a helper module changed under an unchanged
implementation changes the verdict.  The closure's files are inputs of
every property-test obligation, so a change to any of them makes the
evidence stale and re-runs the tests (docs/integrity.md).

Imports are read from the source with :mod:`ast`, never by running it:
``import a.b``, ``from a.b import c``, ``from . import c``, ``from .m import
c``, ``importlib.import_module("a.b")`` and ``__import__("a")`` with literal
names, at any depth (inside functions, ``try``, ``if``), except under ``if
__name__ == "__main__"`` and ``if TYPE_CHECKING``, which do not run.  Each
name is found as the interpreter of the test process finds it
(:class:`~.importpath.ImportFinder`): the harness's folders first, the
implementation's own and then the workspace root (:func:`~.importpath.harness_path`,
the function the harness puts on ``sys.path``), packages through their
``__init__.py`` and ``__path__``; a relative import from the package of the
module that holds it (the implementation itself, loaded as a top-level
module, has none: its relative imports fail when they run, and nothing of
them runs).  A name found behind the harness's folders, in the standard
library or an installed distribution, is outside the workspace: the
distribution's version is recorded instead (:func:`outside_versions`).

What cannot be followed is named, ``file:line: why``, in
:attr:`Closure.unresolved`, and the harness then gives no verdict
(inconclusive): an import of a computed name, code loaded from a path
(``spec_from_file_location``, ``runpy.run_path``, a loader class), a change
of ``sys.path`` (except ``sys.path.insert(0, <its own folder>)``, the ROS
script idiom, where that folder is on the harness's path already: the
implementation's folder and the workspace root), ``sys.meta_path``, ``sys.path_hooks``, ``sys.modules`` or a
package's ``__path__``, a
name found nowhere or outside the workspace in no installed distribution, a
workspace module with the name of one outside it (which of the two runs
depends on what the process imported before), a compiled module (its
imports cannot be read).
"""
from __future__ import annotations

import ast
import os
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

from rclverify.backends.property_tests.importpath import ImportFinder, distributions


class Ref(NamedTuple):
    """One import of a file: ``module`` (dotted, ``""`` for ``from . import x``),
    ``level`` (> 0 for a relative import), the ``names`` after ``import`` of a
    ``from`` import, its ``line``, and ``problem`` (why it cannot be
    followed; ``""`` when it can)."""

    module: str
    level: int
    names: tuple[str, ...]
    line: int
    problem: str = ""


#: calls that load code from a path, which no module name says
_BY_PATH = frozenset({"spec_from_file_location", "run_path", "SourceFileLoader", "SourcelessFileLoader",
                      "ExtensionFileLoader", "load_source", "load_compiled", "load_dynamic", "zipimporter"})
#: the import system's state: changing it changes what an import finds
_IMPORT_STATE = frozenset({"sys.path", "sys.meta_path", "sys.path_hooks", "sys.modules", "sys.path_importer_cache",
                           "__path__"})
_MUTATORS = frozenset({"insert", "append", "extend", "remove", "pop", "clear", "reverse", "sort", "__setitem__",
                       "__delitem__", "__iadd__", "setdefault", "update"})
#: the calls that put a module into ``sys.modules`` (taking one out only makes the next import find it again)
_ADDS = frozenset({"__setitem__", "setdefault", "update"})
#: :attr:`Ref.problem` of ``sys.path.insert(0, <the module's own folder>)`` (or ``append``): no problem where
#: that folder is on the harness's path already (:func:`~.importpath.harness_path`), which :class:`_Walk` decides
OWN_FOLDER = "adds its own folder to sys.path"


def _own_folder(e: ast.expr) -> bool:
    """Whether ``e`` is the folder of the file that runs it, written as ROS scripts write it:
    ``os.path.dirname(__file__)`` (through ``abspath``/``realpath`` either side), ``Path(__file__).parent``
    (through ``resolve()``/``absolute()``), either in ``str(...)`` or ``os.fspath(...)``."""
    if isinstance(e, ast.Call) and _dotted(e.func) in ("str", "os.fspath") and len(e.args) == 1:
        return _own_folder(e.args[0])
    if isinstance(e, ast.Call) and _dotted(e.func) in ("os.path.abspath", "os.path.realpath", "os.path.normpath") \
            and len(e.args) == 1:
        return _own_folder(e.args[0])
    if isinstance(e, ast.Call) and _dotted(e.func) == "os.path.dirname" and len(e.args) == 1:
        return _this_file(e.args[0])
    if isinstance(e, ast.Attribute) and e.attr == "parent":
        return _this_file(e.value)
    if isinstance(e, ast.Call) and isinstance(e.func, ast.Attribute) and e.func.attr in ("resolve", "absolute") \
            and not e.args:
        return _own_folder(e.func.value)
    return False


def _this_file(e: ast.expr) -> bool:
    """Whether ``e`` is the running file's path: ``__file__``, through ``abspath``/``realpath``, ``Path(...)``,
    ``resolve()``/``absolute()``."""
    if isinstance(e, ast.Name):
        return e.id == "__file__"
    if isinstance(e, ast.Call) and _dotted(e.func) in ("os.path.abspath", "os.path.realpath", "Path",
                                                       "pathlib.Path") and len(e.args) == 1:
        return _this_file(e.args[0])
    if isinstance(e, ast.Call) and isinstance(e.func, ast.Attribute) and e.func.attr in ("resolve", "absolute") \
            and not e.args:
        return _this_file(e.func.value)
    return False


def _dotted(e: ast.expr) -> str:
    if isinstance(e, ast.Name):
        return e.id
    if isinstance(e, ast.Attribute):
        return f"{_dotted(e.value)}.{e.attr}"
    return ""


def _literal(e: ast.expr | None) -> str | None:
    return e.value if isinstance(e, ast.Constant) and isinstance(e.value, str) else None


class _Reader(ast.NodeVisitor):
    """The :class:`Ref` list of one module's tree (module docstring)."""

    def __init__(self) -> None:
        self.refs: list[Ref] = []

    def visit_If(self, n: ast.If) -> None:
        test = _dotted(n.test)
        main = (isinstance(n.test, ast.Compare) and _dotted(n.test.left) == "__name__"
                and any(_literal(c) == "__main__" for c in n.test.comparators))
        if main or test in ("TYPE_CHECKING", "typing.TYPE_CHECKING"):
            for s in n.orelse:  # the body does not run when the module is imported
                self.visit(s)
            return
        self.generic_visit(n)

    def visit_Import(self, n: ast.Import) -> None:
        self.refs.extend(Ref(a.name, 0, (), n.lineno) for a in n.names)

    def visit_ImportFrom(self, n: ast.ImportFrom) -> None:
        self.refs.append(Ref(n.module or "", n.level, tuple(a.name for a in n.names), n.lineno))

    def _state(self, target: ast.expr, line: int) -> None:
        t = target.value if isinstance(target, ast.Subscript) else target
        if _dotted(t) in _IMPORT_STATE:
            self.refs.append(Ref("", 0, (), line, f"changes {_dotted(t)}, so imports are not found where the "
                                                  "harness's path says"))

    def visit_Assign(self, n: ast.Assign) -> None:
        for t in n.targets:
            self._state(t, n.lineno)
        self.generic_visit(n)

    def visit_AugAssign(self, n: ast.AugAssign) -> None:
        self._state(n.target, n.lineno)
        self.generic_visit(n)

    def visit_Call(self, n: ast.Call) -> None:
        name = _dotted(n.func)
        last = name.rpartition(".")[2]
        arg = _literal(n.args[0]) if n.args else None
        if last == "import_module" or name in ("__import__", "builtins.__import__"):
            pkg = n.args[1] if len(n.args) > 1 else next((k.value for k in n.keywords if k.arg == "package"), None)
            full = _absolute(arg, (_literal(pkg) or "") if last == "import_module" else "") if arg else None
            if full:
                self.refs.append(Ref(full, 0, (), n.lineno))
            else:
                self.refs.append(Ref("", 0, (), n.lineno, f"{name}() of a name computed when it runs" if arg is None
                                     else f"{name}({arg!r}) relative to no literal package"))
        elif last == "run_module":
            self.refs.append(Ref(arg, 0, (), n.lineno) if arg else Ref("", 0, (), n.lineno, f"{name}() of a computed name"))
        elif last in _BY_PATH:
            self.refs.append(Ref("", 0, (), n.lineno, f"{name}() loads code from a path, which no import names"))
        elif name in ("sys.path.insert", "sys.path.append") and n.args and _own_folder(n.args[-1]):
            self.refs.append(Ref("", 0, (), n.lineno, OWN_FOLDER))
        elif last in (_MUTATORS if name.rpartition(".")[0] != "sys.modules" else _ADDS) and \
                name.rpartition(".")[0] in _IMPORT_STATE:
            self._state(n.func.value if isinstance(n.func, ast.Attribute) else n.func, n.lineno)
        self.generic_visit(n)


def _absolute(name: str, package: str) -> str | None:
    """The absolute name of ``name`` (relative when it starts with dots) from
    ``package``, as ``importlib.import_module`` resolves it; ``None`` beyond
    the top package."""
    level = len(name) - len(name.lstrip("."))
    if not level:
        return name
    parts = package.split(".") if package else []
    if level > len(parts):
        return None
    base = ".".join(parts[:len(parts) - level + 1])
    rest = name[level:]
    return f"{base}.{rest}" if rest else base


def _imports(path: str) -> tuple[Ref, ...]:
    """The :class:`Ref` of each import of the file ``path``; ``()`` for a
    file that cannot be read or does not parse (the run says why).  The file is read every
    time; its text's imports are parsed once per process
    (:func:`_imports_of_text`: a 1000-node system's property tests parsed one
    200-function file 976 times, docs/scale.md)."""
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError:  # unreadable: importing it fails when it runs, and says why
        return ()
    return _imports_of_text(text, path)


@lru_cache(maxsize=256)
def _imports_of_text(text: str, filename: str) -> tuple[Ref, ...]:
    """:func:`_imports` of a file's ``text`` (a pure function of its arguments)."""
    try:
        tree = ast.parse(text, filename)
    except (SyntaxError, ValueError, RecursionError):
        return ()
    reader = _Reader()
    reader.visit(tree)
    return tuple(reader.refs)


@dataclass(frozen=True)
class Closure:
    """The import closure of one implementation file.

    ``files``: every workspace file that runs, the implementation included,
    workspace-relative with ``/``, sorted; ``outside``: the top-level names
    imported from outside the workspace that are not the standard library's,
    sorted; ``unresolved``: ``"file:line: why"`` for each import that cannot
    be followed (module docstring), sorted; ``modules``: the dotted names
    found in the workspace, sorted (the harness imports them afresh)."""

    files: tuple[str, ...]
    outside: tuple[str, ...]
    unresolved: tuple[str, ...]
    modules: tuple[str, ...]


class _Walk:
    """One closure's walk from the implementation file over what it imports."""

    def __init__(self, root: Path, file: str) -> None:
        self.finder = ImportFinder(root, file)
        self.files: set[str] = set()  # absolute paths
        self.seen: set[tuple[str, str]] = set()  # (absolute path, the module name it runs as)
        self.outside: set[str] = set()
        self.unresolved: set[str] = set()
        self.modules: set[str] = set()
        self.todo = [(os.path.normpath(os.path.join(self.finder.top, file)), "")]

    def run(self) -> Closure:
        while self.todo:
            path, name = self.todo.pop()
            if (path, name) in self.seen or not os.path.isfile(path):
                continue
            self.seen.add((path, name))  # one file imported under two names runs twice, each with its own package
            self.files.add(path)
            rel = self.finder.rel(path)
            if not path.endswith(".py"):
                self.unresolved.add(f"{rel}: a compiled module: the imports it makes cannot be read")
                continue
            package = name if os.path.basename(path) == "__init__.py" else name.rpartition(".")[0]
            for ref in _imports(path):
                if ref.problem == OWN_FOLDER and os.path.dirname(path) in self.finder.first:
                    continue  # the folder is on the harness's path already: what imports find is unchanged
                self.follow(ref, package, f"{rel}:{ref.line}")
        f = self.finder
        outside = (n for n in self.outside if n not in sys.stdlib_module_names and n not in sys.builtin_module_names)
        return Closure(tuple(sorted(f.rel(p) for p in self.files)), tuple(sorted(outside)),
                       tuple(sorted(self.unresolved)), tuple(sorted(self.modules)))

    def follow(self, ref: Ref, package: str, where: str) -> None:
        """Add what ``ref``, an import of a module of ``package``, runs."""
        if ref.problem:
            self.unresolved.add(f"{where}: {ref.problem}")
            return
        target = _absolute("." * ref.level + ref.module, package) if ref.level else ref.module
        if not target:  # a relative import with no parent package: ImportError when it runs, nothing runs
            return
        if not self.need(target, where, False):
            return
        for n in ref.names:  # `from pkg import mod` imports the module pkg/mod.py
            if n != "*":
                self.need(f"{target}.{n}", where, True)

    def need(self, fullname: str, where: str, attribute: bool) -> bool:
        """Queue the files importing ``fullname`` runs (its packages' ``__init__``
        on the way); ``False`` when it is not (all) in the workspace."""
        parts = fullname.split(".")
        for i in range(1, len(parts) + 1):
            found = self.finder.find(".".join(parts[:i]))
            if found.kind == "outside":
                self.outside.add(parts[0])
                return False
            if found.kind == "missing":
                if not (attribute and found.attribute and i == len(parts)):  # else a name its package defines
                    self.unresolved.add(f"{where}: {found.reason}")
                return False
            assert found.spec is not None
            self.modules.add(found.spec.name)
            if found.spec.has_location and found.spec.origin:
                self.todo.append((found.spec.origin, found.spec.name))
        return True


def resolve_closure(root: Path, file: str) -> Closure:
    """The :class:`Closure` of the workspace-relative Python ``file`` of the
    workspace at ``root``.  Never raises for the user's code (an unreadable
    or unparsable file imports nothing: the run says why)."""
    return _Walk(root, file).run()


def import_closure(root: Path, file: str) -> tuple[list[str], list[str]]:
    """``(files, outside)`` of :func:`resolve_closure` as lists."""
    c = resolve_closure(root, file)
    return list(c.files), list(c.outside)


def outside_versions(names: list[str]) -> dict[str, str]:
    """The installed distribution version of each top-level import name of
    ``names`` (``importlib.metadata.packages_distributions``), ``"unknown"``
    where no distribution provides it."""
    from importlib import metadata  # deferred: start-up (importlib.metadata only when versions are asked for)
    dists = distributions()
    out: dict[str, str] = {}
    for n in names:
        versions = []
        for d in sorted(set(dists.get(n) or [])):
            try:
                versions.append(f"{d} {metadata.version(d)}")
            except metadata.PackageNotFoundError:
                continue
        out[n] = ", ".join(versions) or "unknown"
    return out


__all__ = ["Closure", "import_closure", "outside_versions", "resolve_closure"]
