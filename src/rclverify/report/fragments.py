"""Rendered pieces of the report, kept between runs and keyed by their data.

After a one-contract edit of a large system, almost every piece of the
report -- a node's section of the HTML and Markdown report, its rows of the
health and obligation tables, an evidence record's block, an element of the
JSON report -- is the same text as last run.  Rendering them all again was
most of such a run (docs/scale.md).  A piece is a pure function of the data
it is rendered from, so its text can be reused when that data is equal.

The pieces are a :class:`~rclverify.core.cache.store.Shelf` of kind
``report-fragments`` (salted with the jinja2 version besides the rclverify
code, which covers every template), one file per part of the report
(``artifacts/cache/report-fragments.<part>.pickle``:
:mod:`rclverify.report.parts`), keyed by the piece's kind and the
:func:`~rclverify.core.cache.keys.fingerprint` of exactly the data it is
rendered from (:func:`rclverify.core.cache.keys.Keyer`).
:meth:`FragmentCache.text` returns the kept text for a key or renders it
(the callable gets nothing else: whatever the piece shows must be in the
data the key is computed from); :meth:`FragmentCache.save` keeps the pieces
used in this run (pieces of an old version of a node are dropped).

A report rendered with a warm cache is byte for byte the one rendered
without (``tests/report/test_report_fragments.py``).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

from rclverify.core.atomic import dumps
from rclverify.core.cache import Shelf, fingerprint

__all__ = ["FragmentCache", "cached_dumps", "fingerprint"]

KIND = "report-fragments"


def _versions() -> tuple[str, ...]:
    import jinja2  # deferred: start-up (loads jinja2 only when called)
    return (f"jinja2 {jinja2.__version__}",)


class FragmentCache(Shelf):
    """Pieces of rendered text by key; see the module docstring.

    ``path`` is the file (``None``: keep pieces in memory only, for this
    object's life -- what a render without a workspace uses).
    """

    def __init__(self, path: Path | None = None) -> None:
        super().__init__(path, KIND, _versions())

    def text(self, kind: str, data: Any, render: Callable[[], str]) -> str:
        """The text of the piece ``kind`` rendered from ``data``: the kept
        one, or ``render()`` (which must depend on ``data`` only)."""
        return self.text_of_fingerprint(kind, fingerprint(data), render)

    def text_of_fingerprint(self, kind: str, fingerprint_of_data: bytes, render: Callable[[], str]) -> str:
        """:meth:`text` for data already fingerprinted
        (:func:`~rclverify.core.cache.keys.fingerprint`), for data that keys
        several kinds of piece."""
        k = self.key(kind, fingerprint_of_data)
        got: str | None = self.get(k)
        if got is None:
            got = render()
            self.put(k, got)
        return got

    def lookup(self, kind: str, fingerprint_of_data: bytes) -> str | None:
        """The kept text of the piece ``kind`` of ``fingerprint_of_data``, or
        ``None`` (then :meth:`store` it: the caller renders many misses at once)."""
        got: str | None = self.get(self.key(kind, fingerprint_of_data))
        return got

    def store(self, kind: str, fingerprint_of_data: bytes, text: str) -> None:
        """Keep ``text`` as the piece ``kind`` of ``fingerprint_of_data``."""
        self.put(self.key(kind, fingerprint_of_data), text)


def cached_dumps(value: Any, cache: FragmentCache, depth: int = 2) -> str:
    """``json.dumps(value, sort_keys=True, indent=2, ensure_ascii=False) + "\\n"``
    -- the text of :func:`rclverify.records.store.dumps` -- with every
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
        return dumps(value)[:-1]  # the reference's text (core/atomic.py), its final newline left out
    if level < depth or not isinstance(value, (dict, list, tuple)) or not value:
        text = render()
    else:
        text = cache.text("json", value, render)
    return text.replace("\n", "\n" + "  " * level) if level else text
