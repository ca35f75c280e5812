"""Classes named the short way in an out-of-line definition (docs/ros.md,
"Reading real code").

C++ lets a source file define a class's members outside the namespace that
declares it, naming the class through a ``using`` declaration, a ``typedef``
or a ``using namespace`` directive::

    using robotis::turtlebot3::TurtleBot3;          // or: typedef ns::C C;
    TurtleBot3::TurtleBot3(const std::string & port) : Node("turtlebot3_node") {...}

The file's own record (:mod:`sources_cpp`) then keys the constructor
``TurtleBot3::TurtleBot3``, of unit ``TurtleBot3``, while the header declares
the class ``robotis::turtlebot3::TurtleBot3``.  Before a program is linked
(:mod:`link`), :func:`canonical` renames such a unit, in every function key,
unit, member binding and symbolic value of the file's record, to the class
it names: the file's alias of it (``using`` declaration or ``typedef``),
else the class under one of the file's ``using namespace`` directives, else
the one class of the program whose qualified name ends with it.  A name
that stays ambiguous is left as written (its code is then linked as a free
function's: what it calls and creates is still read, its members are not).

Source: the C++ standard's name lookup for a qualified declarator
(``[namespace.udecl]``, ``[namespace.udir]``, ``[class.mfct]``).
"""
from __future__ import annotations

import dataclasses
from typing import Any

from rclverify.ros.extract.model import Endpoint

#: the parts of a file's record the linker reads units and function keys from
_LINKED = ("fns", "units", "fields", "calls", "endpoints", "node_names", "member_decls", "member_calls",
           "callbacks", "consts", "aliases", "user_creates", "optional", "returns",
           "call_targs", "fn_tparams")


def canonical(recs: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """``recs`` (``{file: record}`` of one program) with every C++ file's short
    class names replaced by the classes they name (see the module docstring).
    Records needing no change are returned as they are; the others are copies
    (records are shared by the programs of a package and never changed)."""
    classes = {u for r in recs.values() if r.get("lang") != "py" for u in r.get("units", {})}
    if not classes:
        return recs
    out = dict(recs)
    for f, r in recs.items():
        if r.get("lang") == "py":
            continue
        amap = _short_names(r, classes)
        if amap:
            out[f] = {k: _sub(v, amap) if k in _LINKED else v for k, v in r.items()}
    return out


def _short_names(r: dict[str, Any], classes: set[str]) -> dict[str, str]:
    """``{short unit: class}`` for the out-of-line units of one file's record."""
    amap: dict[str, str] = {}
    aliases: dict[str, str] = r.get("aliases", {})
    for key, (unit, *_rest) in r.get("fns", {}).items():
        if unit in classes or unit == key or unit in amap:
            continue
        hit = _named(unit, aliases, r.get("using_ns", []), classes)
        if hit is not None and hit != unit:
            amap[unit] = hit
    return amap


def _named(unit: str, aliases: dict[str, str], using_ns: list[str], classes: set[str]) -> str | None:
    head, _, rest = unit.partition("::")
    full = aliases.get(head)
    if full is not None:
        cand = full.strip().lstrip(":").split("<")[0] + (f"::{rest}" if rest else "")
        if cand in classes:
            return cand
    under = [f"{ns.lstrip(':')}::{unit}" for ns in using_ns if f"{ns.lstrip(':')}::{unit}" in classes]
    if len(under) == 1:
        return under[0]
    ends = [c for c in classes if c.endswith("::" + unit)]
    return ends[0] if len(ends) == 1 else None


def _rename(s: str, amap: dict[str, str]) -> str:
    hit = amap.get(s)
    if hit is not None:
        return hit
    head = s.split("::", 1)[0]
    if head in amap and "::" in s:
        for short, full in amap.items():
            if s.startswith(short + "::"):
                return full + s[len(short):]
    return s


def _sub(x: Any, amap: dict[str, str]) -> Any:
    """``x`` with every unit-like string renamed; string literals (``("str", s)``)
    and locations are left alone."""
    if isinstance(x, str):
        return _rename(x, amap)
    if isinstance(x, tuple):
        if x and x[0] == "str":
            return x
        return tuple(_sub(i, amap) for i in x)
    if isinstance(x, list):
        return [_sub(i, amap) for i in x]
    if isinstance(x, dict):
        return {_sub(k, amap): _sub(v, amap) for k, v in x.items()}
    if isinstance(x, Endpoint):
        return dataclasses.replace(x, unit=_sub(x.unit, amap), func=_sub(x.func, amap),
                                   pending=_sub(x.pending, amap))
    return x
