"""The tree-sitter parsers of the scan's two languages, made once per process, and
the text of a syntax node (py-tree-sitter's ``Parser``/``Language`` API; grammars
from the ``tree-sitter-cpp`` and ``tree-sitter-python`` packages)."""
from __future__ import annotations

from typing import Any

_PARSERS: dict[str, Any] = {}


def parser(language: str) -> Any:
    """The ``tree_sitter.Parser`` of ``language`` ("cpp" or "python"), built on
    first use. Raises ``ImportError`` when that grammar package is not installed,
    ``KeyError`` for another language."""
    p = _PARSERS.get(language)
    if p is None:
        from tree_sitter import Language, Parser  # deferred: optional or conditional (inside a block)
        if language == "cpp":
            import tree_sitter_cpp as grammar  # deferred: optional or conditional (inside a block)
        elif language == "python":
            import tree_sitter_python as grammar  # type: ignore[no-redef]; deferred: optional or conditional (inside a block)
        else:
            raise KeyError(language)
        p = _PARSERS[language] = Parser(Language(grammar.language()))
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
