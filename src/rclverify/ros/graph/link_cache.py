"""Linked programs kept in the scan's parse cache between scans
(:class:`LinkCache`): a program is linked again only when what the linker
reads changed (docs/ros.md, "Reading real code").  Used by
:mod:`rclverify.ros.graph.assemble` and :mod:`rclverify.ros.graph.scan`.
"""
from __future__ import annotations

import hashlib
from typing import Any, Callable

from rclverify.ros.extract.programs import PackageCode, Program


class LinkCache:
    """Linked programs kept in the scan's parse cache between scans: a program is
    linked again only when what the linker reads changed.  The key is the
    sha256 of the program (its package, executable, entry files, files, units,
    aliases, nodelet, plugin and instance), of every record its code holds
    (each file's own sha256: the linker reads the package's records, and the
    other packages' files a program takes in) and of the type names the scan
    knows; the cache's own key holds the rclverify code, so a changed linker
    links again.  ``get(kind, sha, make)`` is :meth:`ParseCache.get`."""

    def __init__(self, get: Callable[[str, str, Callable[[], Any]], Any], digests: dict[str, str],
                 types: list[str]) -> None:
        self.get, self.digests = get, digests
        self.types = hashlib.sha256("\n".join(types).encode()).hexdigest()
        self.hits = self.misses = 0  # results the cache gave, results made

    def kept(self, kind: str, prog: Program, code: PackageCode, make: Callable[[], Any]) -> Any:
        """``make()``'s result of ``kind`` for ``prog`` read from ``code``, kept or made now."""
        h = hashlib.sha256()
        ident = (prog.package, prog.exe, tuple(prog.entry), tuple(prog.files), tuple(sorted(prog.units or ())),
                 prog.units is None, tuple(prog.aliases), prog.nodelet, prog.plugin, prog.instance, code.root)
        h.update(repr(ident).encode())
        for f in sorted(code.records):
            h.update(f"\0{f}\0{self.digests.get(f, '')}".encode())
        h.update(self.types.encode())
        made: list[bool] = []

        def counted() -> Any:
            made.append(True)
            return make()
        got = self.get(kind, h.hexdigest(), counted)
        if made:
            self.misses += 1
        else:
            self.hits += 1
        return got
