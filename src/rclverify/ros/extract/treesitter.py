"""The tree-sitter parsers of the scan's two languages, made once per process, and
the text of a syntax node (py-tree-sitter's ``Parser``/``Language`` API; grammars
from the ``tree-sitter-cpp`` and ``tree-sitter-python`` packages)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from tree_sitter import Parser

_PARSERS: dict[str, Parser] = {}


def parser(language: str) -> Any:
    """The ``tree_sitter.Parser`` of ``language`` ("cpp" or "python"), built on
    first use. Raises :class:`~rclverify.core.extras.MissingExtra` (an
    ``ImportError``) when tree-sitter or that grammar package, the ``ros``
    extra, is not installed, ``KeyError`` for another language."""
    p = _PARSERS.get(language)
    if p is None:
        if language not in ("cpp", "python"):
            raise KeyError(language)
        from rclverify.core.extras import require  # deferred: optional or conditional (inside a block)
        purpose = "reading the robot's C++ sources" if language == "cpp" else "reading the robot's Python sources"
        ts = require("tree_sitter", purpose)
        grammar = require(f"tree_sitter_{language}", purpose)
        p = _PARSERS[language] = ts.Parser(ts.Language(grammar.language()))
    return p


def text(n: Any) -> str:
    """The source text of syntax node ``n`` (UTF-8, undecodable bytes replaced);
    ``""`` for ``None``."""
    return n.text.decode("utf-8", errors="replace") if n is not None else ""


def walk(n: Any):  # type: ignore[no-untyped-def]
    """Every syntax node under ``n`` (``n`` included), in source order (iterative:
    no recursion limit on deep trees)."""
    stack = [n]
    while stack:
        x = stack.pop()
        yield x
        stack.extend(reversed(x.children))
