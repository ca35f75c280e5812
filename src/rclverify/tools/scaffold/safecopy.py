"""Copying a scanned package into a new workspace (``rclverify init
--from-ros``, docs/ros.md "Hostile workspaces") without following links.

Directories are walked with ``os.walk(followlinks=False)``; a directory link
is never entered (so ``a -> .`` cannot loop); a file link is copied (as the
file it names) only when its real path lies inside the package and is a
regular file; FIFOs, devices and sockets are skipped; the copy stops at
:data:`MAX_FILES` files or :data:`MAX_BYTES` bytes.
"""
from __future__ import annotations

import os
import shutil
import stat
from pathlib import Path

MAX_FILES = 20_000
MAX_BYTES = 256 * 1024 * 1024
SKIP_DIRS = frozenset({"build", "devel", "install", "log", ".git", "__pycache__"})


def _shown(p: str, base: str) -> str:
    return repr(os.path.relpath(p, base))[1:-1] if not p.isprintable() else os.path.relpath(p, base)


def copy_package(src: Path, dst: Path) -> list[str]:
    """Copy package directory ``src`` to ``dst`` (regular files only, links
    not followed, bounded); returns one warning line per skipped entry, each
    naming it relative to ``src`` (non-printable characters escaped).
    Raises ``OSError`` when ``dst`` cannot be written."""
    base = os.path.realpath(src)
    warnings: list[str] = []
    files = total = 0
    for dirpath, dirnames, filenames in os.walk(base, followlinks=False):
        keep = []
        for d in sorted(dirnames):
            full = os.path.join(dirpath, d)
            if d in SKIP_DIRS:
                continue
            if os.path.islink(full):
                warnings.append(f"{_shown(full, base)}: warning: directory link not followed: skipped")
            elif not _encodable(full):
                warnings.append(f"{_shown(full, base)!r}: warning: name not valid UTF-8: skipped")
            else:
                keep.append(d)
        dirnames[:] = keep
        for f in sorted(filenames):
            full = os.path.join(dirpath, f)
            shown = _shown(full, base)
            if not _encodable(full):
                warnings.append(f"{shown!r}: warning: name not valid UTF-8: skipped")
                continue
            real = os.path.realpath(full)
            if not (real == base or real.startswith(base + os.sep)):
                warnings.append(f"{shown}: warning: link leaving the package: skipped")
                continue
            try:
                st = os.stat(real)
            except OSError as exc:
                warnings.append(f"{shown}: warning: cannot read: {exc.strerror}: skipped")
                continue
            if not stat.S_ISREG(st.st_mode):
                warnings.append(f"{shown}: warning: not a regular file: skipped")
                continue
            if files + 1 > MAX_FILES or total + st.st_size > MAX_BYTES:
                warnings.append(f"{shown}: warning: copy limit reached ({MAX_FILES} files, "
                                f"{MAX_BYTES // (1024 * 1024)} MiB): the rest of the package is not copied")
                return warnings
            out = dst / os.path.relpath(full, base)
            out.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(real, out)
            files += 1
            total += st.st_size
    dst.mkdir(parents=True, exist_ok=True)
    return warnings


def _encodable(p: str) -> bool:
    try:
        p.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True
