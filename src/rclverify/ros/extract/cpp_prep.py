"""C++ text blanked before tree-sitter reads it: valid code the grammar, which
does not run the preprocessor, would take for syntax errors.  Each rewrite
keeps every byte offset (same length, newlines kept), so locations stay.

* export/visibility macros: between ``class``/``struct`` and the class name
  (``class MY_PKG_PUBLIC Talker :``), and before a member declaration, alone
  on its line or before ``explicit``/a type (``DEMO_NODES_CPP_PUBLIC\\n
  explicit Talker(...)``): upper-case words with an ``_PUBLIC``, ``_EXPORT``,
  ``_API``, ``_LOCAL``, ``_DECL``, ``_HIDDEN`` ... suffix;
* ``<cinttypes>`` format macros beside a string literal (``"%" PRId64``)
  become a string literal of the same length;
* string macros pasted together in an argument (``f(PREFIX_S NAME_S, 1)``:
  upper-case words side by side between ``(``/``,`` and ``,``/``)``) become
  string literals of the same length (their values are not kept);
* ``#ifdef __cplusplus`` / ``#if defined(__cplusplus)`` blocks that only
  open ``extern "C" {`` or close its ``}`` (a C header made includable from
  C++) are blanked, both of them, so the braces balance;
* Qt's access specifiers ``private slots:`` / ``public Q_SLOTS:`` lose the
  ``slots`` word, ``signals:`` / ``Q_SIGNALS:`` become ``public:`` (Qt's moc,
  not the compiler, reads them);
* a statement or member that is only an upper-case macro, with no
  semicolon (``PLUGINLIB_EXPORT_CLASS(a::B, nodelet::Nodelet)``,
  ``EIGEN_MAKE_ALIGNED_OPERATOR_NEW``), starting where a statement may start
  (after ``;``, ``{``, ``}``, ``:`` or a directive) and followed by no ``;``,
  is blanked; ``RCLCPP_COMPONENTS_REGISTER_NODE(ns::C)`` too, its class
  recorded by the caller;
* the lines of an ``#if 0`` (also ``#if false``) group up to its ``#else``,
  ``#elif`` or ``#endif`` (nested groups counted) are blanked: the
  preprocessor drops them, so nothing in them is built (C++ standard
  [cpp.cond]); the directives themselves stay;
* explicit template instantiations (``template class Server<pkg::srv::T>;``,
  ``extern template class ...;``; C++ standard [temp.explicit]), which the
  grammar reads with a missing declarator: they make no object, so nothing
  is lost (the template's types are read where its objects are made).

Source: the C++ standard's preprocessing and ``<cinttypes>`` macros (C99 7.8.1).
"""
from __future__ import annotations

import re
from typing import Any

_CLASS_MACRO = re.compile(rb"\b(?:class|struct)\s+((?:[A-Z][A-Z0-9_]*[A-Z0-9]\s+)+)(?=[A-Za-z_]\w*\s*(?:final\s*)?[:{])")
_SUFFIX = rb"(?:PUBLIC|EXPORT|EXPORTS|API|LOCAL|DECL|HIDDEN|VISIBLE|DLL|DLLAPI|PUBLIC_TYPE|IMPORT)"
_MEMBER_MACRO = re.compile(rb"^[ \t]*([A-Z][A-Z0-9]*(?:_[A-Z0-9]+)*_" + _SUFFIX + rb")(?=[ \t]*$|[ \t]+[A-Za-z_~])", re.M)
_FORMAT = re.compile(rb'(?<=")([ \t]*)((?:PRI|SCN)[diouxXcs](?:8|16|32|64|MAX|PTR|FAST\d+|LEAST\d+))\b'
                     rb'|\b((?:PRI|SCN)[diouxXcs](?:8|16|32|64|MAX|PTR|FAST\d+|LEAST\d+))(?=[ \t]*")')
_CPLUSPLUS = re.compile(rb'^[ \t]*#[ \t]*if(?:def[ \t]+__cplusplus|[ \t]+defined[ \t]*\(?[ \t]*__cplusplus[ \t]*\)?)'
                        rb'[ \t]*\r?\n[ \t]*(?:extern[ \t]+"C"[ \t\r\n]*\{|\})[ \t]*(?://[^\n]*)?\r?\n[ \t]*#[ \t]*endif\b[^\n]*',
                        re.M)
_PASTED = re.compile(rb"(?<=[(,])([ \t\r\n]*)([A-Z][A-Z0-9_]*(?:[ \t\r\n]+[A-Z][A-Z0-9_]*)+)(?=[ \t\r\n]*[,)])")
_WORD = re.compile(rb"[A-Z][A-Z0-9_]*")
_BARE = re.compile(rb"^[ \t]*([A-Z][A-Z0-9_]{2,})[ \t]*(\((?:[^()]|\((?:[^()]|\([^()]*\))*\))*\))?[ \t]*(//[^\n]*)?$",
                   re.M)
_QT_ACCESS = re.compile(rb"\b(?:public|protected|private)([ \t]+(?:slots|Q_SLOTS))(?=[ \t]*:)")
_QT_SIGNALS = re.compile(rb"^([ \t]*)(signals|Q_SIGNALS)(?=[ \t]*:)", re.M)
_INSTANTIATION = re.compile(rb"^[ \t]*(?:extern[ \t]+)?template[ \t]+(?:class|struct)[ \t]+[^;{}<>]*<[^;{}]*>[ \t]*;", re.M)
REGISTER = re.compile(rb"\bRCLCPP_COMPONENTS_REGISTER_NODE\s*\(\s*([A-Za-z_][\w:]*)\s*\)")


def _spaces(b: bytes) -> bytes:
    return bytes(c if c in b"\r\n" else 32 for c in b)


def blank_macros(data: bytes) -> bytes:
    """``class API Name :`` -> ``class     Name :``: upper-case macro words between
    ``class``/``struct`` and the class name become spaces (offsets unchanged)."""
    return _CLASS_MACRO.sub(lambda m: m.group(0)[: m.start(1) - m.start(0)] + b" " * len(m.group(1)), data)


def _statement_start(data: bytes, at: int) -> bool:
    """Whether a statement may start at offset ``at``: the previous code character
    (whitespace, ``//`` comments and whole-line ``/* */`` comments skipped) is
    ``;``, ``{``, ``}`` or ``:``, or a preprocessor line, or nothing."""
    end = at
    for _ in range(50):
        start = data.rfind(b"\n", 0, max(end - 1, 0)) + 1 if end > 0 else 0
        line = data[start:end]
        if b"//" in line:
            line = line[:line.index(b"//")]
        code = line.strip()
        if code.startswith(b"#"):
            return True
        if code.endswith(b"*/") and b"/*" in code:
            code = code[:code.rindex(b"/*")].strip()
        if code:
            return code[-1:] in (b";", b"{", b"}", b":")
        if start == 0:
            return True
        end = start - 1
    return False


def _bare(data: bytes) -> bytes:
    def one(m: re.Match[bytes]) -> bytes:
        rest = data[m.end():m.end() + 200].lstrip()
        if rest[:1] in (b";", b"(", b"=", b"{", b"<", b".", b"-", b",", b")") or not _statement_start(data, m.start()):
            return m.group(0)
        return _spaces(m.group(0))
    return _BARE.sub(one, data)


def _format(m: re.Match[bytes]) -> bytes:
    if m.group(2) is not None:
        w = m.group(2)
        return m.group(1) + b'"' + b"d" * (len(w) - 2) + b'"'
    w = m.group(3)
    return b'"' + b"d" * (len(w) - 2) + b'"'


_IF0 = re.compile(rb"^[ \t]*#[ \t]*if[ \t]+(?:0|false)[ \t]*(?://[^\n]*|/\*[^\n]*)?\r?$", re.M)
_DIRECTIVE = re.compile(rb"^[ \t]*#[ \t]*(if|ifdef|ifndef|elif|else|endif)\b", re.M)


def blank_if0(data: bytes) -> bytes:
    """``data`` with the lines inside each ``#if 0`` group blanked, up to its
    ``#else`` / ``#elif`` / ``#endif`` (same length, newlines kept); applied
    before anything else reads the file (registration macros included)."""
    if b"#" not in data or not _IF0.search(data):
        return data
    out = bytearray(data)
    for m in _IF0.finditer(data):
        depth, start, end = 0, m.end(), len(data)
        for d in _DIRECTIVE.finditer(data, m.end()):
            word = d.group(1)
            if word in (b"if", b"ifdef", b"ifndef"):
                depth += 1
            elif word == b"endif" and depth:
                depth -= 1
            elif not depth:
                end = d.start()
                break
        out[start:end] = _spaces(data[start:end])
    return bytes(out)


def branches(data: bytes) -> dict[int, tuple[tuple[int, int], ...]]:
    """Per 1-based line inside a preprocessor conditional, the groups it lies in,
    outermost first: ``((group, branch), ...)``, ``group`` the line of the
    group's ``#if``/``#ifdef``/``#ifndef`` and ``branch`` 0 for its first
    branch, 1, 2 ... for each ``#elif`` / ``#else`` after it.  Two lines in
    different branches of one group are alternatives: one of them is compiled."""
    out: dict[int, tuple[tuple[int, int], ...]] = {}
    if b"#" not in data:
        return out
    stack: list[tuple[int, int]] = []
    marks = [(data.count(b"\n", 0, d.start()) + 1, d.group(1)) for d in _DIRECTIVE.finditer(data)]
    total = data.count(b"\n") + 1
    marks.append((total + 1, b""))
    prev = 1
    for line, word in marks:
        if stack:
            for k in range(prev, line):
                out[k] = tuple(stack)
        if word in (b"if", b"ifdef", b"ifndef"):
            stack.append((line, 0))
        elif word in (b"elif", b"else") and stack:
            stack[-1] = (stack[-1][0], stack[-1][1] + 1)
        elif word == b"endif" and stack:
            stack.pop()
        prev = line + 1
    return out


def alternatives(a: tuple[tuple[int, int], ...], b: tuple[tuple[int, int], ...]) -> bool:
    """Whether branch paths ``a`` and ``b`` (:func:`branches`) part in different
    branches of one group (only one of the two lines is compiled)."""
    for x, y in zip(a, b):
        if x[0] != y[0]:
            return False
        if x[1] != y[1]:
            return True
    return False


def one_per_branch(endpoints: list[Any], branch: dict[int, tuple[tuple[int, int], ...]]) -> list[Any]:
    """``endpoints`` (:class:`~.model.Endpoint`) less those alike an earlier one
    (role, name as written, type, parameter, handle, class, function, what
    the linker reads) created in an alternative branch of one ``#if ... #elif
    ... #else ... #endif`` group (``branch``: :func:`branches`): one of the
    branches is compiled, so it is one edge, the first branch's."""
    def key(e: Any) -> tuple[Any, ...]:
        return (e.kind, e.topic, e.msg_type, e.param, e.handle, e.unit, e.func,
                repr(e.pending[:5]) if e.pending else None)
    if not branch:
        return endpoints
    kept: list[Any] = []
    for e in endpoints:
        here = branch.get(e.src.line, ())
        if here and any(key(k) == key(e) and alternatives(branch.get(k.src.line, ()), here) for k in kept):
            continue
        kept.append(e)
    return kept


def prepare(data: bytes) -> bytes:
    """``data`` with every rewrite of the module docstring applied (same length)."""
    data = blank_macros(data)
    if b"_" in data:
        data = _MEMBER_MACRO.sub(lambda m: m.group(0)[: m.start(1) - m.start(0)] + b" " * len(m.group(1)), data)
    if b"PRI" in data or b"SCN" in data:
        data = _FORMAT.sub(_format, data)
    data = _PASTED.sub(lambda m: m.group(1) + _WORD.sub(lambda w: b'"' + b"d" * (len(w.group(0)) - 2) + b'"'
                                                        if len(w.group(0)) >= 2 else w.group(0), m.group(2)), data)
    if b"__cplusplus" in data:
        data = _CPLUSPLUS.sub(lambda m: _spaces(m.group(0)), data)
    if b"slots" in data or b"signals" in data or b"Q_S" in data:  # Qt's access specifiers
        data = _QT_ACCESS.sub(lambda m: m.group(0)[: m.start(1) - m.start(0)] + _spaces(m.group(1)), data)
        data = _QT_SIGNALS.sub(lambda m: m.group(1) + b"public" + b" " * (len(m.group(2)) - 6), data)
    if b"RCLCPP_COMPONENTS_REGISTER_NODE" in data:
        data = REGISTER.sub(lambda m: b" " * len(m.group(0)), data)
    if b"template" in data:
        data = _INSTANTIATION.sub(lambda m: _spaces(m.group(0)), data)
    return _bare(data)
