"""Rendered pieces of the report, kept between runs and keyed by their data.

After a one-contract edit of a large system, almost every piece of the
report -- a node's section of the HTML and Markdown report, its rows of the
health and obligation tables, an evidence record's block, an element of the
JSON report -- is the same text as last run.  Rendering them all again was
most of such a run (docs/scale.md).  A piece is a pure function of the data
it is rendered from, so its text can be reused when that data is equal:

* a **key** is the sha256 of a *salt* (the rclverify, Python and jinja2
  versions and the text of every report template: a changed template
  misses), the kind of piece, and the :func:`fingerprint` of exactly the
  data the piece is rendered from: its ``marshal`` serialisation (format
  version 2, which writes every string the same way), from which the data
  can be read back, so equal bytes mean equal data.  Equal data built in
  another order (dict insertion order) gives other bytes: a miss, never a
  wrong hit.  ``marshal`` is four times faster than canonical JSON, which
  keyed the pieces before (docs/scale.md, seventh round), and much faster
  than the rendering it saves;
* :meth:`FragmentCache.text` returns the cached text for a key or renders it
  (the callable gets nothing else: whatever the piece shows must be in the
  data the key is computed from);
* :meth:`FragmentCache.save` writes the pieces used in this run (and only
  those: pieces of an old version of a node are dropped) to its file
  atomically, when they differ from what was loaded (each part of the report
  has its own file, ``artifacts/cache/report-fragments.<part>.pickle``:
  :mod:`rclverify.report.parts`).

A damaged or missing file, or one from another salt, is an empty cache.
The cache is machine-local and a pure speed-up: deleting ``artifacts/cache``
is always safe, and a report rendered with a warm cache is byte for byte
the one rendered without (``tests/test_report_fragments.py``).  Like the
workspace cache it is trusted code of the workspace (pickle).
"""
from __future__ import annotations

import hashlib
import json
import marshal
import pickle
import sys
from functools import lru_cache
from importlib.resources import files
from pathlib import Path
from typing import Any, Callable

from ..evidence.store import atomic_write_bytes

_FORMAT = 3
_ENCODE = json.JSONEncoder(sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode


@lru_cache(maxsize=1)
def salt() -> str:
    """Hex sha256 of what every piece's text also depends on: the cache
    format, the rclverify and jinja2 versions and the text of every template
    under ``rclverify/report/templates`` and ``rclverify/argument/templates``."""
    import jinja2

    from .. import __version__
    h = hashlib.sha256(f"{_FORMAT} {__version__} {jinja2.__version__} {sys.version} {marshal.version}\n".encode())
    for package in ("rclverify.report", "rclverify.argument"):
        root = files(package) / "templates"
        for entry in sorted(_walk(root), key=lambda e: e[0]):
            h.update(entry[0].encode() + b"\0" + entry[1] + b"\0")
    return h.hexdigest()


def _walk(root: Any, prefix: str = "") -> list[tuple[str, bytes]]:
    out: list[tuple[str, bytes]] = []
    for item in root.iterdir():
        name = f"{prefix}{item.name}"
        if item.is_dir():
            out += _walk(item, name + "/")
        elif item.name.endswith(".j2"):
            out.append((name, item.read_bytes()))
    return out


def fingerprint(data: Any) -> bytes:
    """Bytes that are equal only for equal ``data`` (see the module
    docstring): its ``marshal`` form, or, for a value ``marshal`` cannot
    hold (a ``str`` subclass such as jinja2's ``Markup``), its canonical
    JSON (sorted keys, no whitespace), each with its own prefix.  Raises
    ``TypeError`` for a value neither can hold."""
    try:
        return b"m" + marshal.dumps(data, 2)
    except ValueError:
        return b"j" + _ENCODE(data).encode("utf-8", "surrogatepass")


class FragmentCache:
    """Pieces of rendered text by key; see the module docstring.

    ``path`` is the pickle file (``None``: keep pieces in memory only, for
    this object's life -- what a render without a workspace uses).
    """

    def __init__(self, path: Path | None = None) -> None:
        self.path = path
        self._salt = salt()
        self._prefixes: dict[str, Any] = {}
        self._old: dict[bytes, str] = self._load() if path is not None else {}
        self._used: dict[bytes, str] = {}
        self.hits = 0
        self.misses = 0

    def _load(self) -> dict[bytes, str]:
        assert self.path is not None
        try:
            with open(self.path, "rb") as fh:
                stored = pickle.load(fh)
        except FileNotFoundError:
            return {}
        except Exception:  # a damaged or foreign file is an empty cache  # noqa: BLE001
            return {}
        if not isinstance(stored, dict) or stored.get("salt") != self._salt or not isinstance(stored.get("pieces"), dict):
            return {}
        pieces: dict[bytes, str] = stored["pieces"]
        return pieces

    def key(self, kind: str, data: Any) -> bytes:
        """The sha256 of the salt, ``kind`` and the :func:`fingerprint` of ``data``."""
        return self._key(kind, fingerprint(data))

    def _key(self, kind: str, fingerprint_of_data: bytes) -> bytes:
        prefix = self._prefixes.get(kind)
        if prefix is None:  # the salt and the kind hashed once per kind; each key copies that state
            prefix = self._prefixes[kind] = hashlib.sha256(f"{self._salt}\0{kind}\0".encode())
        h = prefix.copy()
        h.update(fingerprint_of_data)
        return h.digest()

    def text(self, kind: str, data: Any, render: Callable[[], str]) -> str:
        """The text of the piece ``kind`` rendered from ``data``: the cached
        one, or ``render()`` (which must depend on ``data`` only)."""
        return self.text_of_fingerprint(kind, fingerprint(data), render)

    def text_of_fingerprint(self, kind: str, fingerprint_of_data: bytes, render: Callable[[], str]) -> str:
        """:meth:`text` for data already fingerprinted (:func:`fingerprint`),
        for data that keys several kinds of piece."""
        got = self.lookup(kind, fingerprint_of_data)
        if got is None:
            got = render()
            self.store(kind, fingerprint_of_data, got)
        return got

    def lookup(self, kind: str, fingerprint_of_data: bytes) -> str | None:
        """The kept text of the piece ``kind`` of ``fingerprint_of_data``, or
        ``None`` (then :meth:`store` it: the caller renders many misses at once)."""
        k = self._key(kind, fingerprint_of_data)
        got = self._used.get(k)
        if got is None:
            got = self._old.get(k)
            if got is None:
                return None
            self._used[k] = got
        self.hits += 1
        return got

    def store(self, kind: str, fingerprint_of_data: bytes, text: str) -> None:
        """Keep ``text`` as the piece ``kind`` of ``fingerprint_of_data``."""
        self._used[self._key(kind, fingerprint_of_data)] = text
        self.misses += 1

    def save(self) -> bool:
        """Write the pieces used since this cache was made to :attr:`path`
        (atomically; nothing when there is no path or nothing changed).
        Returns whether a file was written; raises ``OSError`` when the
        directory cannot be written."""
        if self.path is None or self._used.keys() == self._old.keys():
            return False
        self.path.parent.mkdir(parents=True, exist_ok=True)
        data = pickle.dumps({"salt": self._salt, "pieces": self._used}, protocol=pickle.HIGHEST_PROTOCOL)
        atomic_write_bytes(self.path, data)
        self._old = dict(self._used)
        return True


def cached_dumps(value: Any, cache: FragmentCache, depth: int = 2) -> str:
    """``json.dumps(value, sort_keys=True, indent=2, ensure_ascii=False) + "\\n"``
    -- the text of :func:`rclverify.evidence.store.dumps` -- with every
    container ``depth`` levels down (the elements of the report's top-level
    lists) taken from ``cache``.

    The standard library indents in pure Python; the fingerprint that keys
    a piece is made in C.  A nested value's indented text at level ``k``
    is its text at level 0 with each newline followed by ``2k`` more spaces
    (the indenting encoder writes newlines only between tokens).  Raises
    ``TypeError`` like :func:`json.dumps` for a value JSON cannot hold.
    """
    return _dumps_at(value, cache, 0, depth) + "\n"


def _dumps_at(value: Any, cache: FragmentCache, level: int, depth: int) -> str:
    if level >= depth:
        return _leaf(value, cache, level, depth)
    if isinstance(value, (list, tuple)) and value:
        items = [_dumps_at(v, cache, level + 1, depth) for v in value]
    elif isinstance(value, dict) and value and all(isinstance(k, str) for k in value):
        items = [f"{json.dumps(k, ensure_ascii=False)}: {_dumps_at(value[k], cache, level + 1, depth)}"
                 for k in sorted(value)]
    else:
        return _leaf(value, cache, level, depth)
    pad = "\n" + "  " * (level + 1)
    close = "\n" + "  " * level
    brackets = "[]" if isinstance(value, (list, tuple)) else "{}"
    return brackets[0] + pad + ("," + pad).join(items) + close + brackets[1]


def _leaf(value: Any, cache: FragmentCache, level: int, depth: int) -> str:
    """``value`` indented as at ``level``: from the cache at ``depth`` and
    below when it is a non-empty container, else encoded directly."""
    def render() -> str:
        return json.dumps(value, sort_keys=True, indent=2, ensure_ascii=False)
    if level < depth or not isinstance(value, (dict, list, tuple)) or not value:
        text = render()
    else:
        text = cache.text("json", value, render)
    return text.replace("\n", "\n" + "  " * level) if level else text
