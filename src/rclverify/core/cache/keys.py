"""The one keying function of everything rclverify keeps between runs.

A kept result is found only under the key of what it was computed from
(docs/scale.md, "What is kept between runs"):

* the **salt** of its kind (:func:`salt`): the cache format, the kind's
  name, the rclverify code (:func:`code_stamp`: a changed module, template
  or grammar misses), the Python version and the versions of the other
  programs whose output is kept (jinja2 for report pieces, Z3 for repairs,
  Graphviz's ``dot`` for layouts);
* the **content** of its inputs: sha256 of files (:func:`file_digest`) or
  the :func:`fingerprint` of the data it is rendered from, and, for the
  paths a plan names, what each leads to (:func:`resolved_paths`).

:class:`Keyer` hashes the two together.  Equal keys therefore mean equal
inputs under equal code, and there is no other invalidation to get wrong:
an entry whose inputs changed is simply never looked up again, and the
store drops it at its next save (:mod:`rclverify.core.cache.store`).
"""
from __future__ import annotations

import hashlib
import json
import marshal
import os
import sys
from functools import lru_cache
from pathlib import Path
from typing import Any

#: Where every kept file lives, relative to the workspace root.  Deleting it
#: is always safe: each entry is a pure speed-up.
CACHE_DIR = "artifacts/cache"
#: The cache format; a change misses every entry once.
FORMAT = 4

def user_cache_dir(name: str) -> Path | None:
    """``$XDG_CACHE_HOME/rclverify/<name>`` (else ``~/.cache/rclverify/<name>``),
    made if missing (readable by the user only), or ``None`` when it cannot
    be made.  For what is compiled from rclverify's own files and may hold
    code: jinja2's compiled templates (:func:`rclverify.report.render.use_bytecode_cache`),
    like lark's parser tables (:func:`rclverify.lang.parser.lark_cache_file`).
    Never under a workspace, whose files may come from anyone's repository."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = Path(base) / "rclverify" / name
    try:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
    except OSError:
        return None
    return folder


_ENCODE = json.JSONEncoder(sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode


#: The files of the package whose change changes :func:`code_stamp`.
_CODE_SUFFIXES = (".py", ".lark", ".json", ".j2", ".yaml")  # .yaml: the standard profiles (docs/standards.md)


@lru_cache(maxsize=1)
def code_stamp() -> str:
    """Hex sha256 that changes whenever a file of the installed rclverify
    package changes (the name, size and modification time of every ``.py``,
    ``.lark``, ``.json``, ``.j2`` and ``.yaml`` file) or the Python version does.
    Taken once per process: a run's code does not change under it."""
    pkg = Path(__file__).resolve().parents[2]  # the rclverify package (this file is core/cache/keys.py)
    h = hashlib.sha256(f"{FORMAT} {sys.version}".encode())
    for rel, st in _stats(str(pkg), _CODE_SUFFIXES):
        h.update(f"{rel} {st.st_size} {st.st_mtime_ns}\n".encode())
    return h.hexdigest()


def _stats(top: str, suffixes: tuple[str, ...]) -> list[tuple[str, os.stat_result]]:
    """``(path relative to top, stat)`` of every entry under ``top`` whose
    suffix is one of ``suffixes``, in the order of ``sorted(Path(top).rglob("*"))``
    (by path components; symbolic links to folders are not entered, nor
    ``__pycache__`` folders, where Python writes only ``.pyc`` files), read
    with :func:`os.scandir`: a third of the time ``pathlib`` took for the
    package's 700 files, which every start of a command that keeps results
    pays (docs/scale.md)."""
    out: list[tuple[tuple[str, ...], str, os.stat_result]] = []
    stack: list[tuple[str, tuple[str, ...]]] = [(top, ())]
    while stack:
        folder, parts = stack.pop()
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for e in entries:
            here = parts + (e.name,)
            i = e.name.rfind(".")
            if 0 < i < len(e.name) - 1 and e.name[i:] in suffixes:
                try:
                    out.append((here, "/".join(here), e.stat()))
                except OSError:  # a dangling symbolic link: nothing there to load or to stamp
                    pass
            if e.name != "__pycache__" and e.is_dir() and not e.is_symlink():  # (compiled bytecode only: no suffix read)
                stack.append((e.path, here))
    out.sort(key=lambda x: x[0])
    return [(rel, st) for _, rel, st in out]


#: The files of a library that :func:`library_stamp` reads: its code, compiled extensions and data.
_LIBRARY_SUFFIXES = (".py", ".so", ".pyd", ".dylib", ".dll", ".lark", ".json", ".j2", ".txt", ".typed")


@lru_cache(maxsize=None)
def library_stamp(name: str) -> str:
    """``"<name> <hex sha256>"`` of the installed top-level package ``name``
    (the name, size and modification time of each of its files but the
    compiled bytecode), found without importing it; ``"<name> -"`` when it
    is not installed.  Salts a kind whose entries another library computed
    (lark's syntax trees, Z3's answers): another version, or the same one
    installed again, misses.  Taken once per process."""
    import importlib.util  # deferred: start-up (only where a kind depends on a library)
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        spec = None
    where = list(spec.submodule_search_locations or ()) if spec is not None else []
    if not where:
        return f"{name} -"
    h = hashlib.sha256()
    for folder in where:
        for rel, st in _stats(folder, _LIBRARY_SUFFIXES):
            h.update(f"{rel} {st.st_size} {st.st_mtime_ns}\n".encode())
    return f"{name} {h.hexdigest()}"


@lru_cache(maxsize=None)
def salt(kind: str, versions: tuple[str, ...] = ()) -> str:
    """Hex sha256 of what every entry of ``kind`` also depends on besides
    its own inputs: :data:`FORMAT`, ``kind``, :func:`code_stamp` and
    ``versions`` (the versions of other programs whose output the kind
    keeps, e.g. ``("jinja2 3.1.4",)``)."""
    text = "\0".join((str(FORMAT), kind, code_stamp(), str(marshal.version), *versions))
    return hashlib.sha256(text.encode()).hexdigest()


def fingerprint(data: Any) -> bytes:
    """Bytes that are equal only for equal ``data``: its ``marshal`` form
    (format version 2, which writes every string the same way; the data can
    be read back from it, so equal bytes mean equal data), or, for a value
    ``marshal`` cannot hold (a ``str`` subclass such as jinja2's
    ``Markup``), its canonical JSON (sorted keys, no whitespace), each with
    its own prefix.  Equal data built in another order (dict insertion
    order) gives other bytes: a miss, never a wrong hit.  ``marshal`` is
    four times faster than canonical JSON (docs/scale.md).  Raises
    ``TypeError`` for a value neither can hold."""
    try:
        return b"m" + marshal.dumps(data, 2)
    except ValueError:
        return b"j" + _ENCODE(data).encode("utf-8", "surrogatepass")


def file_digest(path: Path | str) -> str:
    """Hex sha256 of the file's bytes, or ``"-"`` when it cannot be read."""
    try:
        with open(path, "rb") as fh:
            return hashlib.sha256(fh.read()).hexdigest()
    except OSError:
        return "-"


def resolved_paths(root: Path | str, values: Any) -> dict[str, str]:
    """``{value: absolute path}``: what each workspace-relative path of
    ``values`` (strings) leads to from ``root`` now, every symbolic link
    followed; the same as ``os.path.realpath(os.path.join(root, value))``
    (a missing file is resolved as far as it exists).  Each distinct folder
    is resolved once and each path's last part looked at with one ``lstat``
    (2000 paths of a large plan in milliseconds, on every run that reuses
    the plan: :mod:`rclverify.core.cache.workspace`)."""
    folders: dict[str, str] = {}
    out: dict[str, str] = {}
    for value in values:
        head, tail = os.path.split(os.path.join(str(root), value))
        if tail in ("", ".", ".."):
            out[value] = os.path.realpath(os.path.join(str(root), value))
            continue
        real_head = folders.get(head)
        if real_head is None:
            real_head = folders[head] = os.path.realpath(head)
        path = os.path.join(real_head, tail)
        out[value] = os.path.realpath(path) if os.path.islink(path) else path
    return out


class Keyer:
    """The keying function for one salt (:func:`salt`): the sha256 of the
    salt, a sub-kind and the entry's input contents, with the salt and each
    sub-kind hashed once (a report keys tens of thousands of pieces: hashing
    the salt again for each cost more than the lookups)."""

    def __init__(self, salt_hex: str) -> None:
        self.salt = salt_hex
        self._prefixes: dict[str, hashlib._Hash] = {}

    def __call__(self, part: str, *contents: bytes | str) -> bytes:
        """The 32-byte key of an entry of sub-kind ``part`` computed from
        ``contents`` (bytes, or text taken as UTF-8; each length-prefixed,
        so no two sequences of contents share a key)."""
        prefix = self._prefixes.get(part)
        if prefix is None:
            prefix = self._prefixes[part] = hashlib.sha256(f"{self.salt}\0{part}\0".encode())
        h = prefix.copy()
        for c in contents:
            b = c.encode("utf-8", "surrogatepass") if isinstance(c, str) else c
            h.update(len(b).to_bytes(8, "little"))
            h.update(b)
        return h.digest()
