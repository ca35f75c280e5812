"""Atomic file writes and deterministic JSON, for every layer above.

Every write goes to a temporary file in the destination directory and is
moved into place with :func:`os.replace`, so a crash or a failing stage never
leaves a half-written file and never loses the file already there.  A target
that is not a regular file is never replaced: a device, FIFO or socket is
written in place (``-o /dev/null`` discards, as a shell redirection does),
and a symbolic link is followed to the file it names, which is then written
atomically, so the link stays a link.  Nothing here knows of RCL or evidence:
the caches (``core/cache``), the evidence store (``records/store.py``), every
stage's artifacts and every ``-o FILE`` write through it; a directory built
beside its place is moved there by :func:`move_into_place`.
"""
from __future__ import annotations

import itertools
import json
import os
import stat
from pathlib import Path
from typing import Any


def atomic_write_text(path: Path, text: str, *, durable: bool = False) -> bool:
    """Write ``text`` to ``path`` atomically; skip the write when the file
    already holds exactly ``text``.

    Atomic (a temporary file renamed into place) always: a crash or a failing
    stage never leaves a half-written file.  ``durable=True`` also flushes the
    data to disk (fsync) before the rename, so the new content survives a
    power loss; evidence records are written so.  Other artifacts are derived
    and re-created by the next run, and an fsync per artifact (eight per node)
    was the largest single cost of a cold run of a large system.

    Returns ``True`` when the file changed.  Parent directories are created.
    Raises ``OSError`` when the directory cannot be written.
    """
    if _special(path) is not None:
        atomic_write_bytes(path, text.encode("utf-8"), durable=durable)
        return True
    try:
        if path.read_text(encoding="utf-8") == text:
            return False
    except (FileNotFoundError, UnicodeDecodeError):
        pass
    atomic_write_bytes(path, text.encode("utf-8"), durable=durable)
    return True


def atomic_write_bytes(path: Path, data: bytes, *, durable: bool = False, mode: int | None = None) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same
    directory renamed into place (:func:`os.replace`): readers see the old
    content or the new, never a part.  ``durable=True`` fsyncs before the
    rename; ``mode`` sets the permission bits (default: what ``open()``
    gives under the process's umask).

    The temporary file is ``.<name>.<pid>.<n>.tmp``, created with
    ``O_EXCL`` (a name left by a killed process of the same pid is passed
    over), with the permission bits given at creation: ``tempfile.mkstemp``
    draws a random name and creates 0600, which then needed a ``chmod``,
    a third of the cost of the ~19,000 writes of a cold 1000-node run.
    Missing parent directories are created (only when the first attempt
    finds the directory missing).  Raises ``OSError`` when the directory
    cannot be written; the temporary file is removed and ``path`` is left as
    it was.

    A ``path`` that is a symbolic link is resolved first and the file it
    names is replaced (the link stays); a character or block device, FIFO or
    socket is opened and written in place, never renamed over (as root, a
    rename over ``/dev/null`` would replace the machine's device node); a
    directory raises :class:`IsADirectoryError`.
    """
    special = _special(path)
    if special is not None:
        _write_in_place(special, data)
        return
    if os.path.islink(path):
        path = Path(os.path.realpath(path))
    fd, tmp = _create_temporary(path)
    try:
        if mode is not None:
            os.chmod(tmp, mode)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            if durable:
                fh.flush()
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def _special(path: Path) -> Path | None:
    """The resolved path when ``path`` (after symbolic links) is a device,
    FIFO or socket; ``None`` for a regular file, a missing one or a dangling
    link.  Raises :class:`IsADirectoryError` for a directory."""
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "Is a directory", str(path))
    if stat.S_ISREG(st.st_mode):
        return None
    return Path(os.path.realpath(path))


def _write_in_place(path: Path, data: bytes) -> None:
    """Write ``data`` into the existing special file ``path`` (device, FIFO,
    socket-free: a socket cannot be opened and raises ``OSError``) without
    creating, truncating a regular file or renaming anything."""
    fd = os.open(path, os.O_WRONLY | getattr(os, "O_CLOEXEC", 0))
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
    finally:
        os.close(fd)


def move_into_place(built: Path, final: Path) -> None:
    """Move the directory ``built`` (made beside ``final``, on its file
    system) to ``final`` with one rename, so readers see all of it or none.
    Raises ``OSError`` when ``final`` exists and is not an empty directory
    (another process placed it first) or is not a directory at all: a file,
    device or link at ``final`` is never replaced."""
    if os.path.lexists(final) and not os.path.isdir(final) or os.path.islink(final):
        raise FileExistsError(17, "exists and is not a directory", str(final))
    os.rename(built, final)


_TEMPORARY_FLAGS = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
_SERIAL = itertools.count()


def _create_temporary(path: Path) -> tuple[int, str]:
    """A new temporary file beside ``path``: ``(file descriptor, its path)``,
    permission bits 0666 less the umask (what ``open()`` gives)."""
    made_dir = False
    while True:
        tmp = os.path.join(path.parent, f".{path.name}.{os.getpid()}.{next(_SERIAL)}.tmp")
        try:
            return os.open(tmp, _TEMPORARY_FLAGS, 0o666), tmp
        except FileExistsError:
            continue
        except FileNotFoundError:
            if made_dir:
                raise
            path.parent.mkdir(parents=True, exist_ok=True)
            made_dir = True


def dumps(value: Any) -> str:
    """Deterministic JSON text: sorted keys, two-space indent, final newline.

    The text of the reference ``json.dumps(value, sort_keys=True, indent=2,
    ensure_ascii=False) + "\\n"`` (:func:`reference_dumps`), made faster: the
    standard library indents in pure Python, so a value is encoded compact
    by its C encoder (the same numbers, strings and key order) and the
    text is indented by ``msgspec.json.format``, which copies every token
    verbatim and only lays out the whitespace (2-7x faster from 100
    characters on).  A text that is not strict JSON (``NaN``,
    ``Infinity``) or not UTF-8 (a lone surrogate) is encoded by the
    reference.  Raises ``TypeError``/``ValueError`` like :func:`json.dumps`
    for a value JSON cannot hold.
    """
    compact = json.dumps(value, sort_keys=True, ensure_ascii=False, separators=(",", ":"))
    import msgspec  # deferred: 10 ms to import, paid by a process that writes JSON, not by a doit no-op
    try:
        return msgspec.json.format(compact, indent=2) + "\n"
    except (msgspec.DecodeError, UnicodeEncodeError):
        return reference_dumps(value)


def reference_dumps(value: Any) -> str:
    """The reference of :func:`dumps` (the same text, the same errors): the
    standard library's indenting encoder, sorted keys, two-space indent,
    non-ASCII kept, final newline; also what :func:`dumps` falls back to."""
    return json.dumps(value, sort_keys=True, indent=2, ensure_ascii=False) + "\n"


def write_json(path: Path, value: Any, *, durable: bool = False) -> bool:
    """Atomically write ``value`` as deterministic JSON (see :func:`dumps`;
    ``durable`` as in :func:`atomic_write_text`)."""
    return atomic_write_text(path, dumps(value), durable=durable)


def read_json(path: Path) -> Any:
    """Read a JSON file.  Raises ``FileNotFoundError`` / ``json.JSONDecodeError``."""
    return json.loads(path.read_text(encoding="utf-8"))
