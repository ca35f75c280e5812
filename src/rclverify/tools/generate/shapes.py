"""The template contexts of a generated C++ node, as types.

:class:`TermContext` is one constructor set of ``contract_checks.hpp``
(``Checks.terms``), :class:`CppTolerance` the monitors' tolerance as C++
literals (``Checks.tolerance``), :class:`NodeContext` what
:func:`rclverify.tools.generate.cpp.node_context` gives ``src/<pkg>_node.cpp``.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import TypedDict

from rclverify.targets.shapes import TermFields


class TermContext(TermFields):
    """:class:`~rclverify.targets.shapes.TermFields` with the set's parse
    function name ``fn`` and ``parse``: per constructor (name, number of
    arguments, function name, the C++ expressions parsing each argument)."""
    fn: str
    parse: list[tuple[str, int, str, list[str]]]


class CppTolerance(TypedDict):
    """The bounds of a tolerance as C++ literals (``repr`` of the double) and ``ulps``."""
    abs: str
    rel: str
    ulps: int


class EndRead(TypedDict):
    """A struct field an end reads from its message: field, path, message part, variable."""
    field: str
    path: str
    part: str
    var: str


class EndWrite(TypedDict):
    """A struct field an end writes into its message: field, path, message part."""
    field: str
    path: str
    part: str


class EndContext(TypedDict):
    """One end of the node: role, topic or service name, variables, attribute, C++ type, fields."""
    role: str
    name: str
    var: str
    attr: str
    cpp: str
    reads: list[EndRead]
    writes: list[EndWrite]


class NodeContext(TypedDict):
    """``src/<pkg>_node.cpp``'s context: the ends, the headers, the package dependencies, the class name."""
    ends: list[EndContext]
    headers: list[str]
    deps: list[str]
    cls: str


__all__ = ["CppTolerance", "EndContext", "EndRead", "EndWrite", "NodeContext", "TermContext"]
