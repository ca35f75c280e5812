"""The record of a Python source both Python readers give (``ast`` in
:mod:`sources_py`, tree-sitter-python in :mod:`sources_py_tolerant`): imports,
calls with their arguments, and assignments; :func:`sources_py.extract` reads it."""
from __future__ import annotations

from dataclasses import dataclass, field

from .model import Src


@dataclass
class PyVal:
    """An argument or assigned value: ``kind`` "str" (``text`` its value), "name"
    (a dotted name), "call" (``call``) or "other" (``text`` the source); ``calls``
    are the calls written inside it."""

    kind: str
    text: str
    src: Src
    call: "PyCall | None" = None
    calls: list["PyCall"] = field(default_factory=list)


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
    """What the readers give: ``imports`` (local name -> dotted origin), every call,
    the assignments ``(target as written, value)``, and each class statement's
    ``(name, first line, last line)``."""

    imports: dict[str, str] = field(default_factory=dict)
    calls: list[PyCall] = field(default_factory=list)
    assigns: list[tuple[str, PyVal]] = field(default_factory=list)
    classes: list[tuple[str, int, int]] = field(default_factory=list)
