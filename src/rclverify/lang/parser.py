"""RCL parser: Lark LALR(1) over ``rcl.lark``, building the AST as it reduces.

Public entry points
-------------------
``parse_text(text, file)``  -> :class:`~rclverify.lang.ast.Spec`
``parse_file(path)``        -> :class:`~rclverify.lang.ast.Spec`
``parse_files(paths)``      -> list of :class:`~rclverify.lang.ast.Spec`
``parse_formula(text, file, line, col)`` -> :data:`~rclverify.lang.ast.Expr`
  (a single formula, e.g. an environment fact in the plan; ``line``/``col``
  say where ``text`` starts in ``file`` so diagnostics point into it).

All raise :class:`~rclverify.lang.errors.RclError` with a located diagnostic
on malformed input: ``file:line:col: error: unexpected X; expected one of
A, B, ...`` (code ``E-syntax``), where the expected set is what the LALR
automaton would accept at that point, keywords included.  The grammar
follows the paper's EBNF table (shared/reference lines 499-555), its
listings (1131-1171) and appendix A (1890-1983); see ``rcl.lark`` for the
precedence table and the reserved words.

The AST is built by lark's inline transformer (no intermediate parse tree)
with the cyclic garbage collector paused, which keeps parsing linear in the
size of the system (bench/parse_scale.py).
"""
from __future__ import annotations

import os
import sys
import threading
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Iterable, Mapping

import lark
from lark import Lark
from lark.exceptions import UnexpectedInput

from rclverify.core.cache.heap import no_collection
from rclverify.lang import ast
from rclverify.lang.builder import ToAst
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.nesting import check_nesting
from rclverify.lang.syntax_errors import syntax_error
from rclverify.lang.source import decode_text

_FRIENDLY = {
    "NAME": "a name", "IO_NAME": "an in./out. name", "NUMBER": "a number", "ROS_TYPE": "a ROS type",
    "CMP_OP": "a comparison", "EXISTS_BANG": "'exists!'", "$END": "end of file",
    "BASE_TYPE": "REAL/INTEGER/NATURAL/BOOL/STRING",
    "QUALIFIED_BASE": "a qualified built-in such as REAL.REAL", "STRING_LIT": "a string", "LT": "'<'", "GT": "'>'",
    "UNIT": "a unit such as [m]", "GLOBAL_NAME": "a global ROS name such as /safety/stop",
    "PRIVATE_NAME": "a private ROS name such as ~/stop",
}


def grammar_text() -> str:
    """The text of ``rcl.lark`` (for tools that build other lark parsers
    over the same grammar, e.g. the parse benchmark)."""
    return resources.files("rclverify.lang").joinpath("rcl.lark").read_text(encoding="utf-8")


def lark_cache_file(name: str) -> str | bool:
    """Where lark keeps the analysed LALR tables of the grammar ``name``
    (lark's own ``cache`` option): ``$XDG_CACHE_HOME/rclverify`` or
    ``~/.cache/rclverify``; the RCL, Hoare and Gwendolen grammars use it.
    Building the RCL tables costs about 0.25 s, a
    tenth of a doit run that re-parses one edited contract; loading them
    costs 0.02 s (docs/scale.md).  lark stores the sha256 of the grammar and
    options in the file and rebuilds (and rewrites) the tables when they
    differ, and falls back to building them when the file cannot be read or
    written.  Returns ``False`` (no cache) when the directory cannot be made."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    folder = os.path.join(base, "rclverify")
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return False
    return os.path.join(folder, f"{name}-lark{lark.__version__}-py{sys.version_info[0]}{sys.version_info[1]}.cache")


@lru_cache(maxsize=1)
def _lark() -> Lark:
    """The LALR(1) parser with the AST builder applied during parsing
    (no intermediate parse tree).  ``keep_all_tokens`` keeps keywords and
    punctuation in the children so every AST node spans its full text."""
    return Lark(grammar_text(), parser="lalr", start=["start", "expr"], keep_all_tokens=True,
                maybe_placeholders=True, transformer=_BUILDER, cache=lark_cache_file("rcl"))


def describe_terminal(parser: Lark, term: str, friendly: Mapping[str, str]) -> str:
    """How a syntax error names the terminal ``term`` of ``parser``: the
    ``friendly`` wording when there is one, the literal text of a keyword or
    punctuation terminal in quotes, else the terminal's name in lower case.
    Shared by every Lark grammar of the project (RCL, the Hoare language)."""
    if term in friendly:
        return friendly[term]
    try:
        pattern = parser.get_terminal(term).pattern
    except KeyError:
        return term
    return f"'{pattern.value}'" if pattern.type == "str" else term.lower()


def _describe(term: str) -> str:
    return describe_terminal(_lark(), term, _FRIENDLY)


_BUILDER = ToAst()
_LOCK = threading.Lock()


def parse_text(text: str, file: str = "<string>") -> ast.Spec:
    """Parse a whole RCL file's text.  Raises :class:`RclError` on a syntax error.
    A UTF-8 byte-order mark left at the start of ``text`` is ignored
    (:mod:`rclverify.lang.source`)."""
    if text.startswith("\ufeff"):
        text = text[1:]
    return _parse(text, file, "start", 0, 0)  # type: ignore[no-any-return]


def parse_formula(text: str, file: str = "<string>", line: int = 1, col: int = 1) -> ast.Expr:
    """Parse one RCL formula (or term) starting at ``file:line:col``."""
    return _parse(text, file, "expr", line - 1, col - 1)  # type: ignore[no-any-return]


def _parse(text: str, file: str, start: str, dline: int, dcol: int) -> Any:
    parser = _lark()
    # parse trees and AST nodes hold no reference cycles; without the pause the collector
    # scans the growing heap again and again (about 2x slower at a thousand nodes, bench/parse_scale.py)
    with _LOCK, no_collection():
        _BUILDER.reset(file, dline, dcol)
        try:
            result = parser.parse(text, start=start)
        except UnexpectedInput as exc:
            raise syntax_error(exc, file, text, dline, dcol, _describe) from None
        finally:
            _BUILDER.reset("<string>", 0, 0)
    check_nesting(result, text, dline)
    return result


def ast_from_tree(tree: Any, file: str = "<string>") -> Any:
    """The AST of a lark parse tree of ``rcl.lark`` built by another lark
    parser with ``keep_all_tokens=True`` and ``maybe_placeholders=True``
    (e.g. an Earley parser over the same grammar, in the parse benchmark)."""
    with _LOCK:
        _BUILDER.reset(file, 0, 0)
        try:
            return _BUILDER.transform(tree)
        finally:
            _BUILDER.reset("<string>", 0, 0)


def parse_file(path: str | Path) -> ast.Spec:
    """Read and parse an RCL file.  A missing/unreadable file is an RclError."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise RclError([error(ast.Loc(str(path), 1, 1), f"cannot read RCL file: {exc.strerror or exc}", "E-io")]) from None
    return parse_text(decode_text(data, str(path)), str(path))


def parse_files(paths: Iterable[str | Path]) -> list[ast.Spec]:
    """Parse several files; collects the syntax errors of all of them."""
    specs: list[ast.Spec] = []
    diags: list[Diagnostic] = []
    for p in paths:
        try:
            specs.append(parse_file(p))
        except RclError as e:
            diags.extend(e.diagnostics)
    if diags:
        raise RclError(diags)
    return specs
