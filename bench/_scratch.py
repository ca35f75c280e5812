"""The benches' scratch folder, and what its file system charges for creating a file.

A bench that times cold runs writes thousands of files per run.  On ext4
mounted without a journal, creating a file (its inode) skips every free
inode of the block group that was deleted within the last minute (up to
six while the inode table's block is still dirty): the Linux kernel's
``recently_deleted()`` in ``fs/ext4/ialloc.c``, which guards inodes whose
deletion may not have reached the disk.  Each skip reads the inode's
block from the buffer cache, so a creation costs time in proportion to
what was deleted nearby in the last minutes: on the 2-core machine of
docs/scale.md, 32 µs a file in a fresh folder, 160 µs after 1,000
deletions in the same folder, 505 µs after 4,000.  A bench that removed
one run's workspace and then timed the next one in the same folder
charged that run for its own clean-up (docs/scale.md, "Measuring").

:func:`scratch` therefore keeps every workspace of a bench until the bench
ends, and :func:`describe` names the file system in the bench's header, so
its figures say what they were taken on.  Journaled ext4, XFS, Btrfs and
tmpfs do not have this cost.
"""
from __future__ import annotations

import contextlib
import itertools
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator


def describe(path: Path, proc: Path = Path("/proc")) -> str:
    """One line naming the file system that holds ``path``: its type and,
    for ext4, whether it has a journal (read from ``proc``'s ``mounts``,
    ``fs/ext4`` and ``fs/jbd2``, proc(5); Linux only, ``"unknown"``
    elsewhere).  The mount whose point is the longest prefix of ``path``
    wins.  Never raises."""
    try:
        mounts = (proc / "mounts").read_text(encoding="utf-8").splitlines()
    except OSError:
        return "file system: unknown"
    target = os.path.realpath(path)
    best = ("", "", "")
    for line in mounts:
        dev, mnt, fstype = (line.split() + ["", "", ""])[:3]
        mnt = mnt.replace("\\040", " ")
        if (target == mnt or target.startswith(mnt.rstrip("/") + "/")) and len(mnt) >= len(best[1]):
            best = (dev, mnt, fstype)
    dev, mnt, fstype = best
    if not fstype:
        return "file system: unknown"
    if fstype != "ext4":
        return f"file system: {fstype} on {mnt}"
    name = Path(os.path.realpath(dev)).name  # the kernel's name of the device (/dev/mapper/x -> dm-0)
    if not (proc / "fs" / "ext4" / name).is_dir():
        return f"file system: ext4 on {mnt}"
    if any(j.name.startswith(name + "-") for j in (proc / "fs" / "jbd2").glob("*")):
        return f"file system: ext4 with a journal on {mnt}"
    return (f"file system: ext4 without a journal on {mnt} (a file created soon after deletions nearby costs "
            "more: bench/_scratch.py)")


@contextlib.contextmanager
def scratch(prefix: str = "rclverify-bench-") -> Iterator[Iterator[Path]]:
    """A temporary folder for a whole bench, removed when the bench ends.

    Yields an endless iterator of new, empty sub-folders (``run0``,
    ``run1``, ...), one per timed run, so no run is timed right after the
    bench deleted an earlier run's files (see the module's docstring).
    Raises ``OSError`` when the folder cannot be made."""
    base = Path(tempfile.mkdtemp(prefix=prefix))
    try:
        def runs() -> Iterator[Path]:
            for k in itertools.count():
                d = base / f"run{k}"
                d.mkdir()
                yield d
        yield runs()
    finally:
        shutil.rmtree(base, ignore_errors=True)
