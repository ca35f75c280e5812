"""Completion: keywords, declared names, message fields and units.

What is offered depends on the text before the cursor on its line:

* after ``in.`` or ``out.`` inside a node: that node's inputs or outputs,
  with their types;
* inside a unit's brackets (``[m/``): the unit symbols RCL accepts
  (:data:`rclverify.lang.units.SYMBOLS`, with what each is);
* after a message type in a ``topics(...)`` entry
  (``geometry_msgs/Twist |``): the fields of that type, from the
  workspace's own ``msg`` files (any ``<pkg>/msg/*.msg`` under the root,
  outside ``artifacts/`` and ``reports/``), else the standard types rosbags
  knows (ROS 2 Humble's definitions; :class:`rclverify.ros.extract.interfaces.TypeTable`);
* anywhere else: RCL's keywords (rcl.lark), the names the context clauses
  declare, the node names, and ``in.x``/``out.y`` of the node the cursor is in.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from lsprotocol import types as lsp

from rclverify.tools.lsp.diagnostics import Analysis
from rclverify.tools.lsp.index import all_nodes, code_point_col, declarations, node_at
from rclverify.tools.lsp.lines import split_lines

#: The words of rcl.lark that are keywords somewhere (reserved or contextual).
KEYWORDS = ("context", "node", "inputs", "outputs", "topics", "matches", "assume", "guarantee", "triggered", "by",
            "within", "services", "actions", "serves", "calls", "initially", "progress", "eventually", "periodic",
            "while", "ready", "of",
            "and", "or", "not", "in", "forall", "exists", "exists_unique", "TRUE", "FALSE", "REAL", "INTEGER",
            "NATURAL", "BOOL", "STRING", "set", "seq", "upto", "first")

_IO = re.compile(r"\b(in|out)\.\w*$")
_UNIT = re.compile(r"\[[^\[\]]*$")
_TOPIC = re.compile(r"([A-Za-z_]\w*(?:/[A-Za-z_]\w*)+)\s+\w*$")
_SKIP = {"artifacts", "reports", ".git", "node_modules", "build", "install", "devel", "log"}


class MessageTypes:
    """The message types of a workspace root, read once (see the module docstring)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self._table: Any = None

    def table(self) -> Any:
        if self._table is None:
            from rclverify.ros.extract.interfaces import TypeTable  # deferred: optional or conditional (inside a block)
            t = TypeTable()
            for msg in sorted(self._msg_files(self.root, 0)):
                pkg = msg.parent.parent.name
                t.add_file(msg, pkg, msg.relative_to(self.root).as_posix(), "workspace", None)
            self._table = t
        return self._table

    def _msg_files(self, d: Path, depth: int) -> list[Path]:
        out: list[Path] = []
        if depth > 6:
            return out
        try:
            entries = sorted(d.iterdir())
        except OSError:
            return out
        for e in entries:
            if e.is_symlink() or e.name in _SKIP:
                continue
            if e.is_dir():
                out += self._msg_files(e, depth + 1)
            elif e.suffix == ".msg" and e.parent.name == "msg":
                out.append(e)
        return out

    def fields(self, msg_type: str) -> list[tuple[str, str]]:
        """``(field, type)`` of ``pkg/Type`` or ``pkg/msg/Type``; ``[]`` when unknown."""
        parts = msg_type.split("/")
        name = f"{parts[0]}/msg/{parts[-1]}" if len(parts) in (2, 3) else msg_type
        try:
            info = self.table().get(name)
        except Exception:  # rosbags' store may be absent or refuse the name; completion then has no fields
            return []
        if info is None:
            return []
        from rclverify.ros.extract.interfaces import describe  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
        return [(n, describe(d)["type"] + (describe(d)["array"] or "")) for n, d in info.fields]


def _item(label: str, kind: lsp.CompletionItemKind, detail: str = "") -> lsp.CompletionItem:
    return lsp.CompletionItem(label=label, kind=kind, detail=detail or None)


def completions(a: Analysis | None, rel: str, text: str, line: int, char16: int,
                messages: MessageTypes | None = None) -> list[lsp.CompletionItem]:
    """The completion items at the LSP position of ``rel`` (whose text is
    ``text``) from the analysis ``a`` (``None``: keywords and units only)."""
    lines = split_lines(text)
    here = lines[line] if 0 <= line < len(lines) else ""
    before = here[:code_point_col(here, char16)]
    K = lsp.CompletionItemKind
    if _UNIT.search(before):
        from rclverify.lang.units import SYMBOLS  # deferred: optional or conditional (inside a block)
        return [_item(name, K.Unit, sym.name) for name, sym in SYMBOLS.items()]  # Symbol.name: what the unit is
    node = node_at(a, rel, line + 1) if a is not None else None
    m = _IO.search(before)
    if m:
        if node is None:
            return []
        vs = node.inputs if m.group(1) == "in" else node.outputs
        from rclverify.lang.printer import type_to_rcl  # deferred: optional or conditional (inside a block)
        return [_item(v.name, K.Variable, type_to_rcl(v.type)) for v in vs]
    m = _TOPIC.search(before)
    if m and messages is not None and "topics" in "\n".join(lines[max(0, line - 20):line + 1]):
        return [_item(f, K.Field, t) for f, t in messages.fields(m.group(1))]
    items = [_item(k, K.Keyword) for k in KEYWORDS]
    if a is not None:
        for name, (what, _d) in sorted(declarations(a).items()):
            kind = {"type": K.Class, "function": K.Function, "constant": K.Constant,
                    "enumeration value": K.EnumMember, "constructor": K.Constructor}.get(what, K.Text)
            items.append(_item(name, kind, what))
        items += [_item(n, K.Module, "node") for n in all_nodes(a)]
        if node is not None:
            from rclverify.lang.printer import type_to_rcl  # deferred: optional or conditional (inside a block)
            items += [_item(f"in.{v.name}", K.Variable, type_to_rcl(v.type)) for v in node.inputs]
            items += [_item(f"out.{v.name}", K.Variable, type_to_rcl(v.type)) for v in node.outputs]
    return items
