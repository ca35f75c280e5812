"""A C++ program's code in the workspace's other packages (docs/ros.md,
"Reading real code").

A node of one package is often built on a helper library of another package
of the same workspace: its base class (``pkg_util::LifecycleNode``), a twist
subscriber or publisher wrapper, an odometry smoother, a service client
wrapper, each creating endpoints with the names its caller passes.  The
linker (:mod:`link`) reads such names across a program's files; this module
adds the files of the other packages that a program includes (C++) or
imports (Python), so the linker follows calls into them as it does within
one package.

Rules (the ament layout of a C++ package, ROS 2 "Developer Guide: Code style
and language versions", and REP 122's ``include/<package>/`` headers):

* an ``#include "P/x.hpp"`` or ``<P/x.hpp>`` whose first path component is
  another scanned package ``P`` (never the program's own), found at
  ``P/include/P/x.hpp`` (or ``P/P/x.hpp``), is a file of the program;
* an include whose first path component is no package (a scoped install
  directory, ``install(DIRECTORY include/vendor ...)``: ``<vendor/p/x.hpp>``)
  is the header at ``include/vendor/p/x.hpp`` of the one other package that
  has it;
* with it, what it includes in ``P`` and, for each header, the source of the
  same name in ``P`` (its implementation: ``src/x.cpp``), as within a package
  (:func:`programs._closure`);
* transitively, through the packages those files include (at most
  :data:`MAX_FILES` files added per program).

A loose program of ``P`` (a library file no executable of ``P`` runs, which
names no node itself) whose files another package's program runs is a library
for other packages: the endpoints it leaves to its callers' names are read at
the callers, so it is not a program of its own (:func:`library_programs`).
"""
from __future__ import annotations

from rclverify.ros.extract.programs import _SOURCE, NO_FILE, PackageCode, Program, _closure

MAX_FILES = 2000  # files of other packages one program may take in


def _other(inc: str, own: str, codes: dict[str, PackageCode]) -> tuple[str, str] | None:
    """``(package, file)`` an include of ``inc`` names in another scanned package:
    the package its first path component names, else the one other package
    with a header at ``include/<inc>`` (a scoped install directory:
    ``#include <vendor/pkg/helper.hpp>`` of ``include/vendor/pkg/``); ``None``
    when none or several have it."""
    if "/" not in inc:
        return None
    pkg = inc.split("/", 1)[0]
    code = codes.get(pkg) if pkg != own else None
    if code is not None:
        for cand in (f"{code.root}/include/{inc}", f"{code.root}/{inc}"):
            if cand in code.records:
                return pkg, cand
    if pkg in codes:
        return None
    hits = [(name, f"{c.root}/include/{inc}") for name, c in codes.items()
            if name != own and f"{c.root}/include/{inc}" in c.records]
    return hits[0] if len(hits) == 1 else None


def _implementations(code: PackageCode, header: str) -> list[str]:
    """The sources of ``code``'s package named as ``header`` is (``x.hpp`` -> ``x.cpp``)."""
    stem = header.rsplit("/", 1)[-1].rsplit(".", 1)[0]
    return sorted(f for name, fs in code.by_name.items() if name.rsplit(".", 1)[0] == stem and
                  "." + name.rsplit(".", 1)[-1] in _SOURCE for f in fs)


def extend(prog: Program, codes: dict[str, PackageCode]) -> dict[str, str]:
    """Add to program ``prog`` (in place, to ``prog.files``) the files of other
    packages it includes (C++) or imports (Python: ``from other_pkg.module import
    Node``, a package's modules importable by its name, ament_python's layout),
    transitively (see the module docstring).

    ``codes``: every scanned package's code by name.  Returns ``{file: package}``
    of the files added (empty for one that takes in no other package).  Never raises."""
    own = codes.get(prog.package)
    if own is None:
        return {}
    python = any(own.facts.get(f, NO_FILE).py for f in prog.entry)
    added: dict[str, str] = {}
    todo = list(prog.files)
    seen = set(todo)
    while todo and len(added) < MAX_FILES:
        f = todo.pop(0)
        pkg_of_f = added.get(f, prog.package)
        for pkg, start in (_imported if python else _included)(codes, pkg_of_f, f, prog.package):
            for g in _closure(codes[pkg], start, set()):
                if g not in seen:
                    seen.add(g)
                    added[g] = pkg
                    todo.append(g)
    prog.files.extend(added)
    return added


def _included(codes: dict[str, PackageCode], pkg_of_f: str, f: str, own: str) -> list[tuple[str, list[str]]]:
    """``[(package, files to start from)]``: the other packages' headers C++ file ``f``
    includes, each with its implementation."""
    out = []
    for inc in codes[pkg_of_f].facts.get(f, NO_FILE).includes:
        hit = _other(inc, pkg_of_f, codes)
        if hit is not None and hit[0] != own:
            out.append((hit[0], [hit[1]] + _implementations(codes[hit[0]], hit[1])))
    return out


def _imported(codes: dict[str, PackageCode], pkg_of_f: str, f: str, own: str) -> list[tuple[str, list[str]]]:
    """``[(package, [module file])]``: the other packages' modules Python file ``f`` imports."""
    out = []
    for origin in codes[pkg_of_f].facts.get(f, NO_FILE).imports:
        pkg = origin.split(".", 1)[0]
        hit = codes[pkg].module(origin) if pkg in codes and pkg != own else None
        if hit is not None:
            out.append((pkg, [hit[0]]))
    return out


def view(prog: Program, codes: dict[str, PackageCode], added: dict[str, str]) -> PackageCode:
    """The code the linker reads for ``prog``: its package's, with the records of
    the other packages' files ``added`` to it (:func:`extend`)."""
    own = codes[prog.package]
    if not added:
        return own
    records, facts = dict(own.records), dict(own.facts)
    for f, pkg in added.items():
        records[f], facts[f] = codes[pkg].records[f], codes[pkg].facts[f]
    return PackageCode(own.name, own.root, records, own.show, facts)


def library_programs(progs: dict[str, list[Program]], used: dict[str, set[str]],
                     codes: dict[str, PackageCode]) -> None:
    """Drop, in place, each package's loose programs (no executable, no class of
    their own to start) whose entry files the programs of other packages run
    (``used[pkg]``: those files) and which name no node with a literal name: a
    library for other packages (see the module docstring)."""
    for pkg, lst in progs.items():
        files = used.get(pkg, set())
        if not files:
            continue
        facts = codes[pkg].facts
        lst[:] = [p for p in lst if not (p.exe is None and p.units is None and p.entry and
                                         all(f in files for f in p.entry) and
                                         not any(facts.get(f, NO_FILE).makes_node for f in p.entry))]
