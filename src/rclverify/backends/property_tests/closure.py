"""The import closure of a Python implementation inside its workspace.

A property test's verdict is about the code the implementation runs, and
that code is the implementation's file *and every workspace module it
imports*, transitively: a helper module changed under an unchanged
implementation changes the verdict (issue 63, row 2).  The closure's files
are inputs of every property-test obligation, so a change to any of them
makes the evidence stale and re-runs the tests (docs/integrity.md).

Imports are read from the source with :mod:`ast` (``import a.b``,
``from a.b import c``, ``from . import c``, ``from .m import c``; any
nesting: inside functions, ``try``, ``if``), never by running it.  A
module ``a.b`` is looked up as ``a/b.py`` or ``a/b/__init__.py`` (with
``a/__init__.py`` when present) under the importing file's own folder,
then each of its ancestors up to the workspace root, the order in which a
run with that folder or the root on ``sys.path`` would find it
(Python's import system, "The module search path").  A name found nowhere
in the workspace is outside it (the standard library, an installed
package): its distribution's version is reported instead
(:func:`outside_versions`).  Dynamic imports (``importlib.import_module``
of a computed name, ``__import__``) cannot be followed and are not.
"""
from __future__ import annotations

import ast
import sys
from functools import lru_cache
from importlib import metadata
from pathlib import Path


def _imports(path: Path) -> list[tuple[str, int, tuple[str, ...]]]:
    """``(module, level, names)`` of each import statement of ``path``
    (``level`` > 0 for a relative import); ``[]`` for a file that does not
    parse (the run says why).  The file is read every time; its text's
    imports are parsed once per process (:func:`_imports_of_text`: a
    1000-node system's property tests parsed one 200-function file 976
    times, docs/scale.md)."""
    return list(_imports_of_text(path.read_text(encoding="utf-8", errors="replace"), str(path)))


@lru_cache(maxsize=256)
def _imports_of_text(text: str, filename: str) -> tuple[tuple[str, int, tuple[str, ...]], ...]:
    """:func:`_imports` of a file's ``text`` (a pure function of its arguments)."""
    try:
        tree = ast.parse(text, filename)
    except (SyntaxError, ValueError, RecursionError):
        return ()
    out: list[tuple[str, int, tuple[str, ...]]] = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Import):
            out.extend((a.name, 0, ()) for a in n.names)
        elif isinstance(n, ast.ImportFrom):
            out.append((n.module or "", n.level, tuple(a.name for a in n.names)))
    return tuple(out)


def _module_files(base: Path, dotted: str) -> list[Path] | None:
    """The files importing ``dotted`` from ``base`` runs (packages'
    ``__init__.py`` on the way, then the module; ``[]`` for a namespace
    package, a folder without one), or ``None`` when ``base`` does not hold
    it."""
    parts = [p for p in dotted.split(".") if p]
    files: list[Path] = []
    here = base
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        pkg, mod = here / part, here / f"{part}.py"
        if (pkg / "__init__.py").is_file():
            files.append(pkg / "__init__.py")
            here = pkg
        elif mod.is_file() and last:
            files.append(mod)
        elif pkg.is_dir():
            here = pkg  # a namespace package (no __init__.py)
        else:
            return None
    return files if parts else None


def _inside(root: Path, p: Path) -> bool:
    try:
        p.resolve().relative_to(root)
        return True
    except ValueError:
        return False


def import_closure(root: Path, file: str) -> tuple[list[str], list[str]]:
    """``(files, outside)`` for the workspace-relative Python ``file``:
    ``files`` every workspace file the import closure holds, ``file``
    included, workspace-relative with ``/``, sorted; ``outside`` the
    top-level names imported that the workspace does not hold, sorted.
    Never raises for the user's code (an unreadable file imports nothing)."""
    root = root.resolve()
    start = (root / file).resolve()
    seen: set[Path] = set()
    outside: set[str] = set()
    todo = [start]
    while todo:
        path = todo.pop()
        if path in seen or not path.is_file() or not _inside(root, path):
            continue
        seen.add(path)
        folder = path.parent
        ancestors = [folder, *[a for a in folder.parents if _inside(root, a)]]
        for module, level, names in _imports(path):
            if level:
                base = folder
                for _ in range(level - 1):
                    base = base.parent
                if not _inside(root, base):
                    continue
                todo.extend((_module_files(base, module) if module else None) or [])
                for name in names:  # `from . import helper` and `from .pkg import mod`
                    todo.extend(_module_files(base, f"{module}.{name}" if module else name) or [])
                continue
            where = next((b for b in ancestors if _module_files(b, module) is not None), None)
            if where is None:
                outside.add(module.split(".")[0])
                continue
            todo.extend(_module_files(where, module) or [])
            for name in names:  # `from pkg import mod` imports the module pkg/mod.py
                todo.extend(_module_files(where, f"{module}.{name}") or [])
    files = sorted(p.relative_to(root).as_posix() for p in seen)
    return files, sorted(n for n in outside if n and n not in sys.stdlib_module_names)


@lru_cache(maxsize=1)
def _distributions() -> dict[str, list[str]]:
    return dict(metadata.packages_distributions())


def outside_versions(names: list[str]) -> dict[str, str]:
    """The installed distribution version of each top-level import name of
    ``names`` (``importlib.metadata.packages_distributions``), ``"unknown"``
    where no distribution provides it."""
    dists = _distributions()
    out: dict[str, str] = {}
    for n in names:
        found = dists.get(n) or []
        versions = []
        for d in sorted(set(found)):
            try:
                versions.append(f"{d} {metadata.version(d)}")
            except metadata.PackageNotFoundError:
                continue
        out[n] = ", ".join(versions) or "unknown"
    return out


__all__ = ["import_closure", "outside_versions"]
