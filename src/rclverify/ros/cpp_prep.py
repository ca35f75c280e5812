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
* ``#ifdef __cplusplus`` / ``#if defined(__cplusplus)`` blocks that only
  open ``extern "C" {`` or close its ``}`` (a C header made includable from
  C++) are blanked, both of them, so the braces balance;
* ``RCLCPP_COMPONENTS_REGISTER_NODE(ns::C)`` (no semicolon) is blanked, its
  class recorded by the caller.

Source: the C++ standard's preprocessing and ``<cinttypes>`` macros (C99 7.8.1).
"""
from __future__ import annotations

import re

_CLASS_MACRO = re.compile(rb"\b(?:class|struct)\s+((?:[A-Z][A-Z0-9_]*[A-Z0-9]\s+)+)(?=[A-Za-z_]\w*\s*(?:final\s*)?[:{])")
_SUFFIX = rb"(?:PUBLIC|EXPORT|EXPORTS|API|LOCAL|DECL|HIDDEN|VISIBLE|DLL|DLLAPI|PUBLIC_TYPE|IMPORT)"
_MEMBER_MACRO = re.compile(rb"^[ \t]*([A-Z][A-Z0-9]*(?:_[A-Z0-9]+)*_" + _SUFFIX + rb")(?=[ \t]*$|[ \t]+[A-Za-z_~])", re.M)
_FORMAT = re.compile(rb'(?<=")([ \t]*)((?:PRI|SCN)[diouxXcs](?:8|16|32|64|MAX|PTR|FAST\d+|LEAST\d+))\b'
                     rb'|\b((?:PRI|SCN)[diouxXcs](?:8|16|32|64|MAX|PTR|FAST\d+|LEAST\d+))(?=[ \t]*")')
_CPLUSPLUS = re.compile(rb'^[ \t]*#[ \t]*if(?:def[ \t]+__cplusplus|[ \t]+defined[ \t]*\(?[ \t]*__cplusplus[ \t]*\)?)'
                        rb'[ \t]*\r?\n[ \t]*(?:extern[ \t]+"C"[ \t]*\{|\})[ \t]*(?://[^\n]*)?\r?\n[ \t]*#[ \t]*endif\b[^\n]*',
                        re.M)
REGISTER = re.compile(rb"\bRCLCPP_COMPONENTS_REGISTER_NODE\s*\(\s*([A-Za-z_][\w:]*)\s*\)")


def _spaces(b: bytes) -> bytes:
    return bytes(c if c in b"\r\n" else 32 for c in b)


def blank_macros(data: bytes) -> bytes:
    """``class API Name :`` -> ``class     Name :``: upper-case macro words between
    ``class``/``struct`` and the class name become spaces (offsets unchanged)."""
    return _CLASS_MACRO.sub(lambda m: m.group(0)[: m.start(1) - m.start(0)] + b" " * len(m.group(1)), data)


def _format(m: re.Match[bytes]) -> bytes:
    if m.group(2) is not None:
        w = m.group(2)
        return m.group(1) + b'"' + b"d" * (len(w) - 2) + b'"'
    w = m.group(3)
    return b'"' + b"d" * (len(w) - 2) + b'"'


def prepare(data: bytes) -> bytes:
    """``data`` with every rewrite of the module docstring applied (same length)."""
    data = blank_macros(data)
    if b"_" in data:
        data = _MEMBER_MACRO.sub(lambda m: m.group(0)[: m.start(1) - m.start(0)] + b" " * len(m.group(1)), data)
    if b"PRI" in data or b"SCN" in data:
        data = _FORMAT.sub(_format, data)
    if b"__cplusplus" in data:
        data = _CPLUSPLUS.sub(lambda m: _spaces(m.group(0)), data)
    if b"RCLCPP_COMPONENTS_REGISTER_NODE" in data:
        data = REGISTER.sub(lambda m: b" " * len(m.group(0)), data)
    return data
