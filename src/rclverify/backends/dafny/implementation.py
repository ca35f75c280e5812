"""A user's Dafny implementation read without Dafny (paper lines
1667-1762: the implementation refines the generated contract module).

:func:`scan_implementation` tokenises the text (comments and strings
skipped) and finds which module refines the contract, whether the method is
given a body, and the constructs that would make a successful Dafny run
prove nothing: ``assume``, ``expect``, ``{:axiom}``, ``{:verify false}``,
``{:extern}``, ``decreases *``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Token:
    text: str
    line: int


@dataclass
class ImplementationScan:
    """What :func:`scan_implementation` found.

    ``refining``   ``(module name, line)`` of every module refining the contract;
    ``body_line``  line of the method body's ``{`` in the first refining
                   module, or ``None`` when the method is not given a body;
    ``method_line`` line of the method declaration (``None`` when absent);
    ``unsound``    ``(line, construct)`` of every construct that lets Dafny
                   accept a claim it did not prove.
    """

    refining: list[tuple[str, int]] = field(default_factory=list)
    method_line: int | None = None
    body_line: int | None = None
    unsound: list[tuple[int, str]] = field(default_factory=list)


_TOKEN = re.compile(r"\{:|[A-Za-z_][A-Za-z0-9_'?]*|\d[\d._]*|:=|==>|<==>|==|!=|<=|>=|&&|\|\||::|\S")
_DECL_KEYWORDS = {"method", "function", "predicate", "lemma", "datatype", "codatatype", "type", "const", "class",
                  "module", "import", "iterator", "newtype", "trait", "constructor", "twostate", "inductive",
                  "colemma", "copredicate", "greatest", "least"}
_SPEC_KEYWORDS = {"requires", "ensures", "modifies", "reads", "decreases", "free"}


def _tokens(text: str) -> list[Token]:
    """Dafny tokens of ``text`` with comments, strings and char literals removed."""
    out: list[Token] = []
    i, line, n = 0, 1, len(text)
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    line += text[i] == "\n"
                    i += 1
        elif c == '"':
            i += 1
            while i < n and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
            i += 1
        elif c == "'" and re.match(r"'(\\.|[^'\\])'", text[i:i + 4]):
            i += len(re.match(r"'(\\.|[^'\\])'", text[i:i + 4]).group(0))  # type: ignore[union-attr]
        elif c.isspace():
            i += 1
        else:
            m = _TOKEN.match(text, i)
            assert m is not None
            out.append(Token(m.group(0), line))
            i = m.end()
    return out


def _match_close(toks: list[Token], k: int) -> int:
    """Index of the bracket closing the one at ``toks[k]`` (``len(toks)`` when unclosed).

    ``{:`` (an attribute) closes with ``}``; ``<`` (type parameters) with ``>``.
    """
    if toks[k].text == "<":
        opens, closes = {"<"}, {">"}
    else:
        opens, closes = {"(", "[", "{", "{:"}, {")", "]", "}"}
    depth = 0
    for j in range(k, len(toks)):
        t = toks[j].text
        if t in opens:
            depth += 1
        elif t in closes:
            depth -= 1
            if depth == 0:
                return j
    return len(toks)


def _unsound(toks: list[Token]) -> list[tuple[int, str]]:
    found: list[tuple[int, str]] = []
    for k, t in enumerate(toks):
        nxt = toks[k + 1].text if k + 1 < len(toks) else ""
        nxt2 = toks[k + 2].text if k + 2 < len(toks) else ""
        if t.text in ("assume", "expect"):
            found.append((t.line, f"{t.text} statement"))
        elif t.text == "{:" and nxt in ("axiom", "extern"):
            found.append((t.line, f"{{:{nxt}}} attribute"))
        elif t.text == "{:" and nxt == "verify" and nxt2 == "false":
            found.append((t.line, "{:verify false} attribute"))
        elif t.text == "decreases" and nxt == "*":
            found.append((t.line, "decreases * (possibly non-terminating)"))
    return found


def _body_start(toks: list[Token], k: int, end: int) -> int | None:
    """Given ``toks[k]`` just after a method's name, the index of its body's
    ``{`` (``None`` when the declaration ends without a body)."""
    j = k
    if j < end and toks[j].text == "<":
        j = _match_close(toks, j) + 1
    if j < end and toks[j].text == "(":
        j = _match_close(toks, j) + 1
    if j < end and toks[j].text == "returns" and j + 1 < end and toks[j + 1].text == "(":
        j = _match_close(toks, j + 1) + 1
    while j < end:
        t = toks[j].text
        if t in _DECL_KEYWORDS or t in ("ghost", "static", "}"):
            return None
        if t == "{:":
            j = _match_close(toks, j) + 1
            continue
        if t in ("(", "["):
            j = _match_close(toks, j) + 1
            continue
        if t == "{":
            prev = toks[j - 1].text
            if re.fullmatch(r"[A-Za-z0-9_'?]+|\)|\]|\}", prev) and prev not in _SPEC_KEYWORDS and prev not in (
                    "in", "then", "else", "set", "iset", "multiset", "seq", "map", "imap"):
                return j
            j = _match_close(toks, j) + 1
            continue
        j += 1
    return None


def scan_implementation(text: str, contract_module: str, method: str) -> ImplementationScan:
    """Inspect an implementation's Dafny text (see :class:`ImplementationScan`).

    ``contract_module`` is the abstract module it must refine
    (``AgentContract``), ``method`` the method it must give a body.  A
    lexical reading: comments and strings are skipped, set displays in
    specification clauses are told from the body by the token before
    ``{``.
    """
    toks = _tokens(text)
    scan = ImplementationScan(unsound=_unsound(toks))
    first_module: tuple[int, int] | None = None
    for k, t in enumerate(toks):
        if not (t.text == "module" and k + 3 < len(toks) and toks[k + 2].text == "refines"):
            continue
        j = k + 3
        while j + 2 < len(toks) and toks[j + 1].text == ".":
            j += 2
        if toks[j].text == contract_module:
            scan.refining.append((toks[k + 1].text, t.line))
            if first_module is None:
                brace = next((i for i in range(j + 1, len(toks)) if toks[i].text == "{"), None)
                if brace is not None:
                    first_module = (brace, _match_close(toks, brace))
    if first_module is None:
        return scan
    start, end = first_module
    depth = 0
    for k in range(start + 1, end):
        tx = toks[k].text
        if tx in ("{", "{:"):
            depth += 1
        elif tx == "}":
            depth -= 1
        elif tx == "method" and depth == 0:
            j = k + 1
            while j < end and toks[j].text == "{:":
                j = _match_close(toks, j) + 1
            if j < end and toks[j].text == method:
                scan.method_line = toks[k].line
                b = _body_start(toks, j + 1, end)
                scan.body_line = toks[b].line if b is not None else None
                break
    return scan
