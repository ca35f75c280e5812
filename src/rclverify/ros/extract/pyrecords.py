"""The record of a Python source both Python readers give (``ast`` in
:mod:`sources_py`, tree-sitter-python in :mod:`sources_py_tolerant`): imports,
calls with their arguments, and assignments; :func:`sources_py.extract` reads it."""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from rclverify.ros.extract.model import Src

_SPEC = re.compile(r"%(?:\([^)]*\))?[-#0 +]*(?:\d+|\*)?(?:\.\d+)?[a-zA-Z%]")


@dataclass
class PyVal:
    """An argument or assigned value: ``kind`` "str" (``text`` its value), "name"
    (a dotted name), "call" (``call``), "cat" (a concatenation ``a + b`` or an
    f-string: ``parts``) or "other" (``text`` the source); ``calls`` are the
    calls written inside it."""

    kind: str
    text: str
    src: Src
    call: "PyCall | None" = None
    calls: list["PyCall"] = field(default_factory=list)
    parts: list["PyVal"] = field(default_factory=list)


@dataclass
class PyCall:
    """A call: ``func`` its dotted callee as written (``super().__init__`` for the
    super constructor, ``""`` when not a name), positional and keyword arguments."""

    func: str
    args: list[PyVal]
    kwargs: dict[str, PyVal]
    src: Src


@dataclass
class PyModule:
    """What the readers give: ``imports`` (local name -> dotted origin, the first
    in source order), ``import_lines`` (local name -> every ``(origin, line)``
    that binds it: two origins are an import chosen at run time), ``star``
    (modules imported with ``*``), every call, the assignments ``(target as
    written, value)``, each class statement's ``(name, first line, last line)``
    and each function's ``(qualified name, first line, last line, parameters,
    defaults)`` (a method's ``self``/``cls`` left out; ``Cls.f`` for a method),
    and each ``return`` statement's ``(line, value)``."""

    imports: dict[str, str] = field(default_factory=dict)
    calls: list[PyCall] = field(default_factory=list)
    assigns: list[tuple[str, PyVal]] = field(default_factory=list)
    classes: list[tuple[str, int, int]] = field(default_factory=list)
    functions: list[tuple[str, int, int, list[str], list["PyVal | None"]]] = field(default_factory=list)
    star: list[str] = field(default_factory=list)
    import_lines: dict[str, list[tuple[str, int]]] = field(default_factory=dict)
    bases: dict[str, list[str]] = field(default_factory=dict)  # class name -> base classes as written
    returns: list[tuple[int, "PyVal"]] = field(default_factory=list)  # (line, value) of each ``return x``

    def bind_import(self, local: str, origin: str, line: int) -> None:
        """Record that ``local`` is bound to ``origin`` by an import at ``line``."""
        self.import_lines.setdefault(local, []).append((origin, line))
        first = min(self.import_lines[local], key=lambda x: x[1])
        self.imports[local] = first[0]


def percent(fmt: str, args: list[PyVal], text: str, src: Src) -> PyVal:
    """``'fmt' % args`` (``text`` the source) as a concatenation when every
    specifier is ``%s`` (``%%`` a percent sign) and there is one argument per
    specifier; anything else is ``"other"`` (not read)."""
    parts: list[PyVal] = []
    at, k = 0, 0
    for m in _SPEC.finditer(fmt):
        if m.group(0) not in ("%s", "%%") or (m.group(0) == "%s" and k >= len(args)):
            return PyVal("other", text, src)
        parts.append(PyVal("str", fmt[at:m.start()] + ("%" if m.group(0) == "%%" else ""), src))
        if m.group(0) == "%s":
            parts.append(args[k])
            k += 1
        at = m.end()
    if k != len(args):
        return PyVal("other", text, src)
    parts.append(PyVal("str", fmt[at:], src))
    return PyVal("cat", text, src, parts=parts)
