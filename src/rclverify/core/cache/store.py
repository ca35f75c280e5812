"""Where rclverify keeps results between runs: one file format, one rule.

Every kept file lives under ``artifacts/cache/`` (:data:`~rclverify.core.cache.keys.CACHE_DIR`)
and is a pickle stream whose first object is its header::

    {"format": FORMAT, "kind": str, "code": code_stamp(), "salt": salt(kind, versions)}

followed by the kind's own objects.  :func:`read_stream` gives the stream
after the header only when the salt is the current one; a missing,
damaged, truncated or foreign file, or one from other code, reads as
empty.  :func:`write_stream` writes a file atomically (a temporary file
renamed into place: a reader sees the old file or the new one).

Two shapes of store are built on it, both keyed by
:mod:`rclverify.core.cache.keys`:

* :class:`Shelf` -- many small entries of one kind in one file
  (``<name>.pickle``): report pieces, contract texts, diagnosis repairs,
  parsed ROS files;
* :class:`Blobs` -- one file per entry (``<dir>/<key>.<suffix>``), for
  entries that several processes may write at once: Graphviz layouts,
  cone summaries.

**The one rule of what is kept**: an entry is found only under the key of
its inputs and the current code; a run keeps the entries it used (a
:class:`Shelf` drops the others at :meth:`Shelf.save`, up to ``keep``
recent ones where recomputing costs minutes); :class:`Blobs` keeps every
layout until ``artifacts/cache`` is deleted, which is always safe.  What
stays in memory is decided here too: a :class:`Shelf` holds its file's
entries for its own life; :class:`Blobs` holds the layouts read or made in
this process; nothing else is kept across calls (:mod:`rclverify.core.cache.memo`
keeps one result per function; :mod:`rclverify.core.cache.heap` decides when the
collector looks at what is kept).

The files are pickles, but reading one never runs code from it: every
read goes through :func:`rclverify.core.cache.safeload.load`, which constructs
only rclverify's own value classes (dataclasses, enumerations, named
tuples) and a few plain ones; a file naming anything else (a poisoned
cache in a cloned workspace) reads as damaged, a cache miss.
"""
from __future__ import annotations

import os
import pickle
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO, Callable, Iterable

from rclverify.core.cache.heap import no_collection
from rclverify.core.cache.keys import CACHE_DIR, FORMAT, Keyer, code_stamp, salt
from rclverify.core.cache.safeload import load

if TYPE_CHECKING:
    from rclverify.core.cache.shapes import KeptFile, KeptHeader

_PROTOCOL = pickle.HIGHEST_PROTOCOL


def header(kind: str, salt_hex: str) -> KeptHeader:
    """The header of a kept file of ``kind`` under ``salt_hex``."""
    return {"format": FORMAT, "kind": kind, "code": code_stamp(), "salt": salt_hex}


def read_header(fh: BinaryIO) -> dict[str, object] | None:
    """The header of an open kept file, or ``None`` when it has none.  Never raises."""
    try:
        got = load(fh)
    except Exception:  # damaged, truncated, not a pickle, or naming a class rclverify does not keep  # noqa: BLE001
        return None
    return got if isinstance(got, dict) and "salt" in got else None


def open_stream(path: Path, kind: str, salt_hex: str) -> BinaryIO | None:
    """``path`` opened and positioned after its header when the header is
    that of ``kind`` under ``salt_hex``; else ``None`` (the caller closes
    the file).  Never raises."""
    try:
        fh = open(path, "rb")
    except OSError:
        return None
    got = read_header(fh)
    if got is None or got.get("kind") != kind or got.get("salt") != salt_hex:
        fh.close()
        return None
    return fh


def read_stream(path: Path, kind: str, salt_hex: str, count: int = 1) -> list[Any] | None:
    """The ``count`` objects after the header of ``path`` when it is a
    current file of ``kind`` (:func:`open_stream`), unpickled without
    cyclic garbage collection (everything read is live); else ``None``.
    Never raises."""
    fh = open_stream(path, kind, salt_hex)
    if fh is None:
        return None
    try:
        with fh, no_collection():
            return [load(fh) for _ in range(count)]
    except Exception:  # truncated, damaged or poisoned after the header  # noqa: BLE001
        return None


def write_stream(path: Path, kind: str, salt_hex: str, objects: Iterable[Any]) -> None:
    """Write the header of ``kind`` under ``salt_hex``, then ``objects``,
    to ``path`` atomically.  Raises ``OSError`` when the directory cannot
    be written and ``pickle.PicklingError`` for an object pickle cannot
    hold; ``path`` is then left as it was."""
    parts = [pickle.dumps(header(kind, salt_hex), protocol=_PROTOCOL)]
    parts += [pickle.dumps(o, protocol=_PROTOCOL) for o in objects]
    from rclverify.core.atomic import atomic_write_bytes  # deferred: start-up (a run that only reads kept files loads no writer)
    atomic_write_bytes(path, b"".join(parts))


class Shelf:
    """Entries of one kind in one file, by key; see the module docstring.

    ``path`` is the file (``None``: this object's memory only); ``kind``
    names the kind (its salt, :func:`~rclverify.core.cache.keys.salt`, with
    ``versions``); ``keep`` is how many entries :meth:`save` keeps in all
    when the run used fewer (0: exactly those used).

    :attr:`key` is the kind's :class:`~rclverify.core.cache.keys.Keyer`.
    """

    def __init__(self, path: Path | None, kind: str, versions: tuple[str, ...] = (), keep: int = 0) -> None:
        self.path = path
        self.kind = kind
        self.salt = salt(kind, versions)
        self.key = Keyer(self.salt)
        self.keep = keep
        self.hits = 0
        self.misses = 0
        self._changed = False
        got = read_stream(path, kind, self.salt) if path is not None else None
        self._old: dict[bytes, Any] = got[0] if got and isinstance(got[0], dict) else {}
        self._used: dict[bytes, Any] = {}

    def get(self, k: bytes) -> Any | None:
        """The entry kept under ``k`` (marked used), or ``None`` (so an entry
        is never ``None``: wrap a result that may be, e.g. in a 1-tuple)."""
        got = self._used.get(k)
        if got is None:
            got = self._old.get(k)
            if got is None:
                return None
            self._used[k] = got
        self.hits += 1
        return got

    def put(self, k: bytes, value: Any) -> None:
        """Keep ``value`` under ``k`` (not ``None``)."""
        self._used[k] = value
        self.misses += 1
        self._changed = True

    def changed(self) -> None:
        """Say that an entry got from :meth:`get` was filled in further (so :meth:`save` writes)."""
        self._changed = True

    def get_or_make(self, k: bytes, make: Callable[[], Any]) -> Any:
        """The entry under ``k``, else ``make()`` kept under it."""
        got = self.get(k)
        if got is None:
            got = make()
            self.put(k, got)
        return got

    def save(self) -> bool:
        """Write the entries used since this shelf was opened (and, with
        ``keep``, earlier ones up to ``keep`` in all) atomically, when they
        differ from what was read.  Returns whether the file was written.
        Raises ``OSError`` when the directory cannot be written."""
        if self.path is None or (not self._changed and self._used.keys() == self._old.keys()):
            return False
        kept = dict(self._used)
        for k, v in self._old.items():
            if len(kept) >= self.keep:
                break
            kept.setdefault(k, v)
        if not self._changed and kept.keys() == self._old.keys():
            return False  # with keep: the same entries as the file holds
        write_stream(self.path, self.kind, self.salt, [kept])
        self._old = kept
        self._changed = False
        return True

    def __len__(self) -> int:
        return len(self._used.keys() | self._old.keys())


class Blobs:
    """One file per entry under ``directory`` (``None``: memory only), for
    large entries written by several processes: each file is written
    atomically and holds its own text, named by its key
    (``<key hex>.<suffix>``).  Entries read or made stay in this object's
    memory.  Only successful results are kept."""

    def __init__(self, directory: Path | None, kind: str, suffix: str, versions: tuple[str, ...] = ()) -> None:
        self.directory = directory
        self.kind = kind
        self.suffix = suffix
        self.key = Keyer(salt(kind, versions))
        self._memory: dict[bytes, str] = {}

    def text(self, k: bytes, make: Callable[[], str | None], wait_s: float = 0.0) -> str | None:
        """The text kept under ``k``, else ``make()`` (the text, or ``None``
        on failure: nothing kept) kept under it.  A file that cannot be
        read or written only costs time.

        ``wait_s`` > 0: the entry is made by one process at a time.  Before
        making it, this process claims it (``<key hex>.claim``, created
        exclusively, removed when the entry is written or ``make`` failed);
        a process that finds it claimed waits up to ``wait_s`` seconds for
        the other's file instead of making the same entry beside it, and
        makes it itself when none comes (the other failed, or was killed
        and left its claim: a claim names its process, and one whose
        process is gone is not waited on)."""
        hit = self._memory.get(k)
        if hit is None:
            hit = self._read(k)
        claim: Path | None = None
        if hit is None and wait_s > 0 and self.directory is not None:
            mine, claim = self._claim(k)
            if not mine:
                hit = self._await(k, wait_s)
        if hit is not None:
            self._memory[k] = hit
            return hit
        try:
            made = make()
            if made is not None:
                self.put(k, made)
        finally:
            if claim is not None:
                try:
                    os.unlink(claim)
                except OSError:
                    pass
        return made

    def put(self, k: bytes, text: str) -> None:
        """Keep ``text`` under ``k``, in memory and (atomically) in its file,
        replacing what was there: an entry its reader found damaged and made
        again.  A file that cannot be written only costs time."""
        self._memory[k] = text
        if self.directory is not None:
            from rclverify.core.atomic import atomic_write_bytes  # deferred: start-up (a run that only reads kept files loads no writer)
            try:
                atomic_write_bytes(self._file(k, self.suffix), text.encode("utf-8"))
            except OSError:
                pass

    def _file(self, k: bytes, suffix: str) -> Path:
        return self.directory / f"{k.hex()}.{suffix}"  # type: ignore[operator]

    def _read(self, k: bytes) -> str | None:
        if self.directory is None:
            return None
        try:
            return self._file(k, self.suffix).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return None

    def _claim(self, k: bytes) -> tuple[bool, Path | None]:
        """``(True, its path)``: this process now holds the claim on ``k``;
        ``(False, None)``: another process holds it; ``(True, None)``: no
        claim could be made for another reason (a read-only directory), so
        this process goes on without one."""
        path = self._file(k, "claim")
        for attempt in (0, 1):
            try:
                fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
                try:
                    os.write(fd, str(os.getpid()).encode())  # who holds it: a waiter stops when it is gone
                finally:
                    os.close(fd)
                return True, path
            except FileExistsError:
                return False, None
            except FileNotFoundError:
                if attempt:
                    break
                try:
                    path.parent.mkdir(parents=True, exist_ok=True)
                except OSError:
                    break
            except OSError:
                break
        return True, None

    def _await(self, k: bytes, wait_s: float) -> str | None:
        """The entry another process is making, once written; ``None`` when its
        claim goes without a file or ``wait_s`` seconds pass."""
        claim = self._file(k, "claim")
        deadline = time.monotonic() + wait_s
        pause = 0.0002
        while True:
            hit = self._read(k)
            if hit is not None or not claim.exists():
                return hit if hit is not None else self._read(k)
            if time.monotonic() >= deadline or not _alive(claim):
                return None
            time.sleep(pause)
            pause = min(pause * 2, 0.005)

    def forget(self) -> None:
        """Drop what this object holds in memory (the files stay)."""
        self._memory.clear()


def _alive(claim: Path) -> bool:
    """Whether the process named in ``claim`` (its pid, written by
    :meth:`Blobs._claim`) still runs on this machine; ``True`` when that
    cannot be told (a claim being written, another user's process), so the
    waiter waits its time.  A claim left by a killed process is then not
    waited on."""
    try:
        pid = int(claim.read_text(encoding="ascii") or "0")
    except (OSError, ValueError):
        return True
    if pid <= 0:
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def kept_files(root: Path) -> list[KeptFile]:
    """What ``root``'s ``artifacts/cache`` holds, for ``rclverify cache``:
    ``[{"file": path relative to root, "kind": str or None, "bytes": int,
    "current": whether it was written by this rclverify code}, ...]``,
    sorted by file.  A directory of :class:`Blobs` is one row (its files'
    bytes summed).  Never raises."""
    base = root / CACHE_DIR
    out: list[KeptFile] = []
    try:
        entries = sorted(base.iterdir())
    except OSError:
        return out
    stamp = code_stamp()
    for p in entries:
        rel = p.relative_to(root).as_posix()
        if p.is_dir():
            files = [f for f in p.iterdir() if f.is_file()]
            out.append({"file": rel + "/", "kind": p.name, "bytes": sum(f.stat().st_size for f in files),
                        "entries": len(files), "current": None})
            continue
        try:
            with open(p, "rb") as fh:
                h = read_header(fh)
            size = os.stat(p).st_size
        except OSError:
            continue
        out.append({"file": rel, "kind": h.get("kind") if h else None, "bytes": size, "entries": None,
                    "current": bool(h and h.get("code") == stamp)})
    return out
