"""Where an implementation's imports are found: the one search path that
both the harness (which runs the code) and the import closure (which hashes
it) use (docs/property-tests.md, "What runs is what is hashed").

The harness puts two folders first on ``sys.path`` while the
implementation imports and runs (:func:`harness_path`,
:func:`on_harness_path`): the implementation's own folder, then the
workspace root, the order ``python <implementation>`` run from the root
would give.  :class:`ImportFinder` answers, for a dotted module name, where
the interpreter finds it with that path: it searches the folders as
Python's path-based finder does (``importlib.machinery.PathFinder`` over
``FileFinder``, with the same loaders and suffixes, namespace portions
gathered across folders; Python's import system, "The path based finder"),
after the built-in and frozen modules that are found before any folder.  A
module found there is the workspace's; a name found behind those folders is
the standard library's, an installed distribution's, or neither.
"""
from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from importlib import invalidate_caches, machinery
from importlib.machinery import ModuleSpec
from pathlib import Path
from typing import Iterator, Sequence

_LOADERS = ((machinery.ExtensionFileLoader, machinery.EXTENSION_SUFFIXES),
            (machinery.SourceFileLoader, machinery.SOURCE_SUFFIXES),
            (machinery.SourcelessFileLoader, machinery.BYTECODE_SUFFIXES))


def harness_path(root: Path, file: str) -> list[str]:
    """The folders the harness puts first on ``sys.path``, in order, for the
    workspace-relative implementation ``file`` of the workspace at ``root``:
    ``[the implementation's folder, the workspace root]`` (one entry when they
    are the same), absolute, not following links.  Never raises."""
    top = os.path.abspath(root)
    return list(dict.fromkeys([os.path.dirname(os.path.normpath(os.path.join(top, file))), top]))


@contextmanager
def on_harness_path(root: Path, file: str) -> Iterator[None]:
    """While inside: :func:`harness_path` first on ``sys.path`` and the
    finders' cached folder listings dropped (``importlib.invalidate_caches``:
    a file created within the folder's timestamp tick is seen); ``sys.path``
    as it was afterwards, whatever the code did to it."""
    saved = list(sys.path)
    sys.path[:0] = harness_path(root, file)
    invalidate_caches()
    try:
        yield
    finally:
        sys.path[:] = saved


@dataclass(frozen=True)
class Found:
    """Where a dotted module name is found: ``kind`` ``"workspace"`` (``spec``
    the module, package or namespace package found in the harness's
    folders), ``"outside"`` (the standard library or an installed
    distribution: ``spec`` ``None``) or ``"missing"`` (``reason`` says why it
    cannot be followed; ``attribute`` when the parent is a package whose
    ``__init__`` may define the name instead)."""

    kind: str
    spec: ModuleSpec | None = None
    reason: str = ""
    attribute: bool = False


class ImportFinder:
    """Finds modules as the test process's interpreter does with the harness's
    path first (module docstring).  One finder per closure: each folder is
    listed once, fresh (no listing cached between two closures)."""

    def __init__(self, root: Path, file: str) -> None:
        self.top = os.path.abspath(root)
        self.first = harness_path(root, file)
        mine = {os.path.realpath(d) for d in self.first}  # the root under another spelling (a link) is the root
        self.rest = [d for d in (os.path.abspath(p or os.curdir) for p in sys.path if isinstance(p, str))
                     if os.path.realpath(d) not in mine]
        self._finders: dict[str, machinery.FileFinder] = {}
        self._memo: dict[str, Found] = {}

    def rel(self, path: str) -> str:
        """``path`` relative to the workspace root, with ``/``."""
        return Path(os.path.relpath(path, self.top)).as_posix()

    def search(self, fullname: str, folders: Sequence[str]) -> ModuleSpec | None:
        """The spec Python's path-based finder gives ``fullname`` over ``folders``
        (a regular module or package in the first folder holding one; else a
        namespace package of every portion met; else ``None``)."""
        portions: list[str] = []
        for d in folders:
            finder = self._finders.get(d)
            if finder is None:
                finder = self._finders[d] = machinery.FileFinder(d, *_LOADERS)
            spec = finder.find_spec(fullname)
            if spec is None:
                continue
            if spec.loader is not None:
                return spec
            portions.extend(spec.submodule_search_locations or ())
        if not portions:
            return None
        spec = ModuleSpec(fullname, None, is_package=True)
        spec.submodule_search_locations = portions
        return spec

    def find(self, fullname: str) -> Found:
        """Where ``fullname`` (absolute, dotted) is found (:class:`Found`); memoised per finder."""
        if fullname not in self._memo:
            parent, _, _ = fullname.rpartition(".")
            self._memo[fullname] = self._sub(parent, fullname) if parent else self._top(fullname)
        return self._memo[fullname]

    def _sub(self, parent: str, fullname: str) -> Found:
        up = self.find(parent)
        if up.kind != "workspace":
            return up
        assert up.spec is not None
        where = up.spec.submodule_search_locations
        if where is None:
            return Found("missing", reason=f"{parent} ({self.rel(str(up.spec.origin))}) is a module, not a package",
                         attribute=True)
        spec = self.search(fullname, list(where))
        if spec is None:
            folders = ", ".join(f"{self.rel(d)}/" for d in where)
            return Found("missing", reason=f"no module {fullname} in {folders}", attribute=up.spec.loader is not None)
        return Found("workspace", spec)

    def _top(self, name: str) -> Found:
        if name in sys.builtin_module_names or machinery.FrozenImporter.find_spec(name) is not None:
            return Found("outside")  # found before any folder of the path
        mine = self.search(name, self.first)
        try:
            theirs = machinery.PathFinder.find_spec(name, self.rest)
        except (ImportError, ValueError, OSError):  # a broken entry of the process's path: not a place it is found
            theirs = None
        stdlib = name in sys.stdlib_module_names
        if mine is not None and (mine.loader is not None or (theirs is None and not stdlib)):
            if stdlib or theirs is not None:
                where = mine.origin if mine.loader is not None else (mine.submodule_search_locations or [""])[0]
                other = "a module of the standard library" if stdlib else f"{name} at {theirs.origin if theirs else ''}"
                return Found("missing", reason=(
                    f"{self.rel(str(where))} has the name of {other} outside the workspace: which of the two runs "
                    "depends on what the process imported before"))
            return Found("workspace", mine)
        if mine is not None and theirs is not None and theirs.loader is None:
            return Found("missing", reason=f"{name} is a namespace package with portions inside and outside the workspace")
        if stdlib or _installed(name, theirs):
            return Found("outside")
        if theirs is None:
            places = [f"{self.rel(d)}/" for d in self.first[:-1]] + ["the workspace root"]
            return Found("missing", reason=(f"{name} is found nowhere: not in {', '.join(places)}, the standard "
                                            "library or an installed distribution"))
        return Found("missing", reason=(f"{name} is found at {theirs.origin or theirs.submodule_search_locations}, "
                                        "outside the workspace and in no installed distribution: its code is not hashed"))


@lru_cache(maxsize=1)
def distributions() -> dict[str, list[str]]:
    """``importlib.metadata.packages_distributions()``, read once per process
    (it reads every installed distribution's metadata: about 0.15 s)."""
    from importlib import metadata  # deferred: start-up (importlib.metadata only when a distribution is asked for)
    return dict(metadata.packages_distributions())


def _installed(name: str, spec: ModuleSpec | None) -> bool:
    """Whether the top-level ``name`` belongs to an installed distribution:
    found under a ``site-packages`` / ``dist-packages`` folder, or named by
    a distribution's metadata (a distribution of that name, else
    :func:`distributions`, read only then)."""
    where = None
    if spec is not None:
        where = spec.origin if spec.has_location else next(iter(spec.submodule_search_locations or ()), None)
    if where and {"site-packages", "dist-packages"} & set(Path(where).parts):
        return True
    from importlib import metadata  # deferred: start-up (importlib.metadata only for a name found outside the installed folders)
    try:
        metadata.distribution(name)
        return True
    except (metadata.PackageNotFoundError, ValueError):
        return name in distributions()


__all__ = ["Found", "ImportFinder", "distributions", "harness_path", "on_harness_path"]
