"""Atomic file writes and deterministic JSON, for every layer above.

Every write goes to a temporary file in the destination directory and is
moved into place with :func:`os.replace`, so a crash or a failing stage never
leaves a half-written file and never loses the file already there.  Nothing
here knows of RCL or evidence: the caches (``core/cache``), the evidence
store (``records/store.py``), every stage's artifacts, the reports and every
``-o FILE`` write through it; a directory built beside its place is moved
there by :func:`move_into_place`.

Where a write may go (docs/integrity.md, "Where outputs go"):

* a path the user named on the command line (``named=True``: ``-o FILE``,
  ``--json FILE``) is written wherever it leads: a symbolic link is followed
  (the link stays a link, its target is replaced atomically), and a FIFO or
  a device is written in place, never renamed over (``-o /dev/null``
  discards, as a shell redirection does; as root a rename over
  ``/dev/null`` would replace the machine's device node).  The special file
  is opened without blocking: a FIFO no process opens for reading within
  :data:`READER_WAIT_S` seconds fails (``ENXIO``), and a write that finds no
  room for :data:`SPECIAL_WRITE_TIMEOUT_S` seconds fails (``ETIMEDOUT``), so
  the write cannot hang;
* every other path (a report, an artifact) is written only as a regular
  file: a FIFO, device or socket there is refused, never opened
  (:class:`~rclverify.core.within.Refused`), and with ``within`` (the
  workspace) the path must resolve inside it, so a symbolic link planted in
  ``reports/`` that leads out is refused as the bundle refuses it
  (:func:`rclverify.core.within.outside`).
"""
from __future__ import annotations

import errno
import itertools
import json
import os
import select
import stat
import time
from pathlib import Path
from typing import Any

from rclverify.core.within import Refused, kind_of, outside

#: Seconds a write into a FIFO or device the user named may find no room before it fails.
SPECIAL_WRITE_TIMEOUT_S = 10.0
#: Seconds a FIFO the user named is given for a reader to open it (``cat FIFO`` started beside the command).
READER_WAIT_S = 2.0


def atomic_write_text(path: Path, text: str, *, durable: bool = False, within: Path | None = None,
                      named: bool = False) -> bool:
    """Write ``text`` to ``path`` atomically; skip the write when the file
    already holds exactly ``text``.

    Atomic (a temporary file renamed into place) always: a crash or a failing
    stage never leaves a half-written file.  ``durable=True`` also flushes the
    data to disk (fsync) before the rename, so the new content survives a
    power loss; evidence records are written so.  Other artifacts are derived
    and re-created by the next run, and an fsync per artifact (eight per node)
    was the largest single cost of a cold run of a large system.  ``within``
    and ``named`` as in :func:`atomic_write_bytes`.

    Returns ``True`` when the file changed.  Parent directories are created.
    Raises ``OSError`` when the directory cannot be written and
    :class:`~rclverify.core.within.Refused` for a target the module
    docstring refuses.
    """
    data = text.encode("utf-8")
    if output_target(path, within=within, named=named) is None and holds(path, data):
        return False
    atomic_write_bytes(path, data, durable=durable, within=within, named=named)
    return True


def atomic_write_bytes(path: Path, data: bytes, *, durable: bool = False, mode: int | None = None,
                       within: Path | None = None, named: bool = False) -> None:
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

    ``named=True``: the user named ``path`` (module docstring): a symbolic
    link is followed wherever it leads, a character or block device or FIFO
    is written in place within :data:`SPECIAL_WRITE_TIMEOUT_S` seconds of no
    progress (``ENXIO`` for a FIFO no process opens for reading within
    :data:`READER_WAIT_S` seconds, ``ETIMEDOUT`` past the limit).  Otherwise a special file raises
    :class:`~rclverify.core.within.Refused` without being opened, and with
    ``within`` (a directory, the workspace) a ``path`` that resolves outside
    it does too.  A socket is always refused; a directory raises
    :class:`IsADirectoryError`.
    """
    special = output_target(path, within=within, named=named)
    if special is not None:
        _write_in_place(special, data, SPECIAL_WRITE_TIMEOUT_S)
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


def output_target(path: Path, *, within: Path | None = None, named: bool = False) -> Path | None:
    """Check ``path`` as a place to write (module docstring): ``None`` when it
    is written as a regular file (it is one, or is missing, or is a dangling
    link), the resolved special file when it is a device or FIFO the user
    named (``named=True``).  Raises :class:`~rclverify.core.within.Refused`
    for a special file not named, a socket, or (``within`` given, not
    ``named``) a path that resolves outside ``within``;
    :class:`IsADirectoryError` for a directory."""
    if not named and within is not None:
        real = outside(within, path)
        if real is not None:
            how = "through a symbolic link" if real != Path(os.path.abspath(path)) else "as written"
            raise Refused(path, f"leads to {real}, outside the workspace ({how}); rclverify writes there only "
                                "inside the workspace or where the command line names")
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(errno.EISDIR, "Is a directory", str(path))
    if stat.S_ISREG(st.st_mode):
        return None
    if stat.S_ISSOCK(st.st_mode) or not named:
        raise Refused(path, f"is {kind_of(st.st_mode)}, not a regular file; rclverify writes into a FIFO or a "
                            "device only when the command line names it (-o)")
    return Path(os.path.realpath(path))


def holds(path: Path, data: bytes) -> bool:
    """Whether the regular file ``path`` holds exactly ``data`` (``False``
    when it is missing, unreadable as a file or anything but a regular
    file: it is opened without blocking and checked on its descriptor, so a
    FIFO put there is never waited on)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return False
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_size != len(data):
            return False
        with os.fdopen(fd, "rb", closefd=False) as fh:
            return fh.read(len(data) + 1) == data
    finally:
        os.close(fd)


def _write_in_place(path: Path, data: bytes, timeout_s: float) -> None:
    """Write ``data`` into the existing device or FIFO ``path`` without
    creating, truncating or renaming anything, never blocking: opened with
    ``O_NONBLOCK`` (a FIFO no process has open for reading gives ``ENXIO``;
    the open is tried again for :data:`READER_WAIT_S` seconds, then refused),
    and each time the file takes no byte, waiting for room at most
    ``timeout_s`` seconds (then ``TimeoutError``, ``ETIMEDOUT``)."""
    waited = time.monotonic()
    while True:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
            break
        except OSError as exc:
            if exc.errno != errno.ENXIO:
                raise
            if time.monotonic() - waited >= READER_WAIT_S:
                raise Refused(path, f"is a FIFO no process reads (none opened it within {READER_WAIT_S:g} s): "
                                    "nothing would take the output", errno.ENXIO) from None
            time.sleep(0.02)
    try:
        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        view = memoryview(data)
        while view:
            try:
                view = view[os.write(fd, view):]
                continue
            except BlockingIOError:
                pass
            waited = time.monotonic()
            while not poller.poll(max(1, int(timeout_s * 1000 - (time.monotonic() - waited) * 1000))):
                if time.monotonic() - waited >= timeout_s:
                    raise TimeoutError(errno.ETIMEDOUT, f"took no output for {timeout_s:g} s (its reader does not "
                                                        "read); the output is incomplete", str(path))
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


def write_json(path: Path, value: Any, *, durable: bool = False, within: Path | None = None,
               named: bool = False) -> bool:
    """Atomically write ``value`` as deterministic JSON (see :func:`dumps`;
    ``durable``, ``within`` and ``named`` as in :func:`atomic_write_text`)."""
    return atomic_write_text(path, dumps(value), durable=durable, within=within, named=named)


def read_json(path: Path) -> Any:
    """Read a JSON file.  Raises ``FileNotFoundError`` / ``json.JSONDecodeError``."""
    return json.loads(path.read_text(encoding="utf-8"))
