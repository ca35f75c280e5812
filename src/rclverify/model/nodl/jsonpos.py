"""Strict JSON read with the line and column of every value (a NoDL document's JSON form).

``load_json_located(text, file)`` returns ``(data, locations)`` in the form
:func:`rclverify.model.plan.yamlguard.load_located` gives for YAML: a
location per value path (a tuple of keys and list indices) and, at
``path + (key, KEY)``, the location of each mapping key, so one schema
error locator serves both forms.  The grammar is RFC 8259's: ``json.loads``
decides what is JSON (a malformed text is an error at the line and column
it names); this reader walks the accepted text once more to note where each
value starts (strings through :func:`json.decoder.scanstring`, the
standard library's own string scanner).  A key written twice in one object
is refused (RFC 8259 section 4: names "SHOULD be unique"; ``json.loads``
keeps the last silently), located at the second, naming the first's line.
Nesting deeper than :data:`MAX_DEPTH` is refused.  Every refusal is a
:class:`~rclverify.lang.errors.RclError` with code ``E-nodl-json``.
"""
from __future__ import annotations

import json
import re
from json import decoder
from typing import Any, Callable

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.model.plan.yamlguard import KEY

#: The deepest nesting of arrays and objects read (a NoDL document nests five deep).
MAX_DEPTH = 100

_WS = re.compile(r"[ \t\n\r]*")
_NUMBER = re.compile(r"-?(?:0|[1-9][0-9]*)(?:\.[0-9]+)?(?:[eE][-+]?[0-9]+)?")
_WORDS = {"true": True, "false": False, "null": None}

Path_ = tuple[Any, ...]
#: The standard library's JSON string scanner (``json.decoder.scanstring``, which typeshed does not
#: declare): ``scanstring(text, offset after the quote, strict)`` -> (the string, the offset after it).
scanstring: Callable[[str, int, bool], tuple[str, int]] = getattr(decoder, "scanstring")


def _fail(file: str, line: int, col: int, message: str) -> RclError:
    return RclError([error(ast.Loc(file, line, col), message, "E-nodl-json")])


class _Walk:
    """One pass over JSON text ``json.loads`` accepted, noting each value's location."""

    def __init__(self, text: str, file: str) -> None:
        self.text, self.file = text, file
        self.locs: dict[Path_, ast.Loc] = {}
        # offset of the first character of each line, for line/column of an offset
        self.starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def loc(self, offset: int) -> ast.Loc:
        """``file:line:col`` of character ``offset`` (1-based line and column)."""
        lo, hi = 0, len(self.starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self.starts[mid] <= offset:
                lo = mid
            else:
                hi = mid - 1
        return ast.Loc(self.file, lo + 1, offset - self.starts[lo] + 1)

    def skip(self, i: int) -> int:
        m = _WS.match(self.text, i)
        return m.end() if m else i

    def value(self, i: int, path: Path_, depth: int) -> tuple[Any, int]:
        """The value starting at offset ``i`` (after blanks) and the offset after it."""
        i = self.skip(i)
        self.locs[path] = self.loc(i)
        if depth > MAX_DEPTH:
            where = self.loc(i)
            raise _fail(self.file, where.line, where.col, f"JSON nested too deeply (limit {MAX_DEPTH})")
        c = self.text[i]
        if c == "{":
            return self.obj(i + 1, path, depth)
        if c == "[":
            out: list[Any] = []
            i = self.skip(i + 1)
            if self.text[i] == "]":
                return out, i + 1
            while True:
                v, i = self.value(i, path + (len(out),), depth + 1)
                out.append(v)
                i = self.skip(i)
                if self.text[i] == "]":
                    return out, i + 1
                i += 1  # the comma json.loads saw
        if c == '"':
            s, end = scanstring(self.text, i + 1, True)
            return s, end
        for word, val in _WORDS.items():
            if self.text.startswith(word, i):
                return val, i + len(word)
        m = _NUMBER.match(self.text, i)
        if m is None:  # NaN, Infinity, -Infinity: Python's json reads them, RFC 8259 has no such number
            where = self.loc(i)
            raise _fail(self.file, where.line, where.col, "not JSON: NaN and Infinity are no JSON numbers")
        num = m.group()
        return (float(num) if any(ch in num for ch in ".eE") else int(num)), m.end()

    def obj(self, i: int, path: Path_, depth: int) -> tuple[dict[str, Any], int]:
        out: dict[str, Any] = {}
        first: dict[str, int] = {}
        i = self.skip(i)
        if self.text[i] == "}":
            return out, i + 1
        while True:
            i = self.skip(i)
            key_loc = self.loc(i)
            key, i = scanstring(self.text, i + 1, True)
            if key in first:
                raise _fail(self.file, key_loc.line, key_loc.col,
                            f"duplicate key {key!r} in an object (first written at line {first[key]}); "
                            "each key may appear once")
            first[key] = key_loc.line
            self.locs[path + (key, KEY)] = key_loc
            i = self.skip(i) + 1  # the colon
            out[key], i = self.value(i, path + (key,), depth + 1)
            i = self.skip(i)
            if self.text[i] == "}":
                return out, i + 1
            i += 1  # the comma


def load_json_located(text: str, file: str) -> tuple[Any, dict[Path_, ast.Loc]]:
    """``(data, locations)`` of the JSON ``text`` of ``file`` (module docstring).

    Raises :class:`RclError` (``E-nodl-json``) at the line and column of a
    syntax error, of a repeated key, or of nesting deeper than
    :data:`MAX_DEPTH`."""
    try:
        json.loads(text)
    except json.JSONDecodeError as exc:
        raise _fail(file, exc.lineno, exc.colno, f"not JSON: {exc.msg}") from None
    except RecursionError:
        raise _fail(file, 1, 1, f"JSON nested too deeply (limit {MAX_DEPTH})") from None
    walk = _Walk(text, file)
    data, _ = walk.value(0, (), 0)
    return data, walk.locs
