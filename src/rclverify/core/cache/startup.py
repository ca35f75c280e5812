"""What ``rclverify monitor`` computes at every start from its inputs' content alone, kept between
runs in the user's cache (the command's start-up, docs/scale.md).

Before it reads a trace the command parsed the contracts (lark), checked
the plan against its JSON schema (jsonschema), rendered each monitored
formula's straight-line code (jinja2), asked Z3 which guarantees only an
answer decides and loaded rosbags' message definitions (the widths its
topics carry): most of its start-up, the same result on every
run with the same files.  A process that keeps its start-up
(:func:`keeping`, entered by the command) finds each of these under the key
of exactly what it was computed from and computes it only on a miss:

=========================  ====================================================  ===========
part                       keyed by                                              library
=========================  ====================================================  ===========
``contract``               the file's workspace-relative name and text           lark
``plan-schema``            the plan's data (:func:`.keys.fingerprint`); only a   jsonschema
                           pass is kept: a failing plan is validated again and
                           its errors come from jsonschema
``straightline``           what the template was given (name, comment, loads,    jinja2
                           body; the template is rclverify's code)
``needs-answer``           the pickled environment, node and formulas            Z3
``message-definitions``    the message types a node's topics name and the name   rosbags
                           and text of each workspace ``.msg``
``yaml``                   what was read (the reader and the file's name) and    PyYAML
                           the file's text: the plan's data and locations, the
                           mapping's data, a backend's declaration
                           (:func:`read_kept`)
=========================  ====================================================  ===========

Every key also holds the part's salt (:func:`.keys.salt`: the cache
format, :func:`.keys.code_stamp` -- every file of rclverify, the schema and
the template included -- and the :func:`.keys.library_stamp` of the library
that computed it), so a changed input, rclverify or library is a miss,
never a stale hit: what runs after a hit (the type check, the plan's
resolution, the monitoring) is what runs after a miss.

An entry is one file, ``$XDG_CACHE_HOME/rclverify/start-up/<key>.pickle``
(:func:`.keys.user_cache_dir`: not in the workspace, because the sources
are code and the command only reads a workspace), written atomically in the
kept-file format (:func:`.store.write_stream`) and read through
:mod:`.safeload`; a missing, damaged or unwritable file only costs the
recomputation.  Entries are never pruned (each is a few kilobytes, one
per distinct contract text, plan, formula and node); deleting the folder
is always safe.
"""
from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any, Callable, Iterator, TypeVar

from rclverify.core.cache.keys import Keyer, library_stamp, salt, user_cache_dir
from rclverify.core.cache.store import read_stream, write_stream

KIND = "start-up"
#: Each part and the library whose result it keeps (its version is in the part's salt).
PARTS = {"contract": "lark", "plan-schema": "jsonschema", "straightline": "jinja2", "needs-answer": "z3",
         "message-definitions": "rosbags", "yaml": "yaml"}
_T = TypeVar("_T")


class Kept:
    """The entries of :data:`PARTS` under ``folder`` (``None``: nothing is
    read or written, every lookup misses)."""

    def __init__(self, folder: Path | None) -> None:
        self.folder = folder
        self._keyers: dict[str, Keyer] = {}
        self.hits = 0
        self.misses = 0

    def _path(self, part: str, contents: tuple[bytes | str, ...]) -> tuple[Path, str] | None:
        """The entry's file and its part's salt; ``None`` without a folder or
        when the salt cannot be taken (an unreadable package file)."""
        if self.folder is None:
            return None
        try:
            keyer = self._keyers.get(part)
            if keyer is None:  # salted when first used: a run that never asks Z3 never stamps Z3's files
                keyer = self._keyers[part] = Keyer(salt(f"{KIND}/{part}", (library_stamp(PARTS[part]),)))
            return self.folder / f"{keyer(part, *contents).hex()}.pickle", keyer.salt
        except OSError:
            return None

    def get(self, part: str, *contents: bytes | str) -> Any | None:
        """The value kept for ``part`` (a key of :data:`PARTS`) computed from
        ``contents``, or ``None``.  Never raises."""
        where = self._path(part, contents)
        got = read_stream(where[0], f"{KIND}/{part}", where[1]) if where is not None else None
        if got is None:
            self.misses += 1
            return None
        self.hits += 1
        return got[0]

    def put(self, part: str, value: Any, *contents: bytes | str) -> None:
        """Keep ``value`` (not ``None``) for ``part`` computed from
        ``contents``.  Never raises: a value that cannot be written is not kept."""
        where = self._path(part, contents)
        if where is None:
            return
        try:
            write_stream(where[0], f"{KIND}/{part}", where[1], [value])
        except Exception:  # noqa: BLE001 - a read-only cache, a full disk, a value pickle refuses: not kept
            pass


_ACTIVE: list[Kept] = []


def active() -> Kept | None:
    """The store of the process's innermost :func:`keeping`, or ``None``
    (then every caller computes as before and keeps nothing)."""
    return _ACTIVE[-1] if _ACTIVE else None


@contextlib.contextmanager
def keeping(folder: Path | None = None) -> Iterator[Kept]:
    """Keep the start-up's results while the block runs (``folder``:
    default :func:`.keys.user_cache_dir` ``("start-up")``; no store when it
    cannot be made).  Yields the :class:`Kept` in use."""
    kept = Kept(folder if folder is not None else user_cache_dir(KIND))
    _ACTIVE.append(kept)
    try:
        yield kept
    finally:
        _ACTIVE.remove(kept)


def read_kept(what: str, text: str, read: Callable[[str], _T]) -> _T:
    """``read(text)``: what rclverify reads from a YAML file's ``text`` (``what``: the reader and the file's
    name, e.g. ``"plan contracts/plan.yaml"``), kept by the store of the innermost :func:`keeping` under the
    part ``yaml`` and keyed by ``what`` and ``text``, so that a warm start neither imports PyYAML nor parses
    the file.  Computed (and kept) on a miss or with no store.  What ``read`` raises is raised and nothing is
    kept: an error is computed again, its message the reader's."""
    kept = active()
    if kept is None:
        return read(text)
    got = kept.get("yaml", what, text)
    if got is not None:
        value: _T = got[0]
        return value
    value = read(text)
    kept.put("yaml", (value,), what, text)
    return value


__all__ = ["KIND", "PARTS", "Kept", "active", "keeping", "read_kept"]
