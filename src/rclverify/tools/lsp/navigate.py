"""Go to definition and find references, across the files of a scope and the plan.

Definition (:func:`definition`) of the symbol at a position
(:func:`.index.symbol_at`):

* an input ``in.x`` of a consumer: the outputs that feed it, as the system
  model connects them (:func:`rclverify.model.system.model.build`: the plan's
  connections, equal names, service links, equal topics), in the
  producers' files; an environment input (nothing feeds it): its own
  declaration;
* an output ``out.y``: its declaration in the node's ``outputs(...)``;
* a context name (type, constant, function, enumeration value,
  constructor): its declaration;
* a node name (also a plan entry ``Agent:`` or ``node: Agent``): its
  ``node`` clause;
* a requirement id of the plan: the guarantees it rests on (its
  ``supported_by``).

References (:func:`references`): every whole-word occurrence outside
comments, in every file of the scope and the plan, of a node name or a
context name; for an input or output, its declaration, its uses in its
node, and the other ends of its connections (for an output, the
consumers' inputs it feeds; for an input, the producers' outputs).
"""
from __future__ import annotations

from typing import Iterable, Mapping

from lsprotocol import types as lsp

from rclverify.lang import ast
from rclverify.tools.lsp.diagnostics import Analysis, lsp_range, utf16_col
from rclverify.tools.lsp.index import Symbol, all_nodes, declarations, occurrences
from rclverify.tools.lsp.lines import split_lines
from rclverify.tools.lsp.workspace import LspWorkspace


def _loc(ws: LspWorkspace, texts: Mapping[str, str], loc: ast.Loc) -> lsp.Location:
    text = texts.get(loc.file) or ws.disk_text(loc.file) or ""
    return lsp.Location(ws.uri(loc.file), lsp_range(loc, split_lines(text)))


def _io_decl(a: Analysis, node: str, prefix: str, var: str) -> ast.IOVar | None:
    n = all_nodes(a).get(node)
    for v in (n.inputs if prefix == "in" else n.outputs) if n else ():
        if v.name == var:
            return v
    return None


def _links(a: Analysis, sym: Symbol) -> list[tuple[str, str, str]]:
    """The other ends ``(node, prefix, var)`` of ``sym``'s connections."""
    if a.model is None:
        return []
    if sym.prefix == "in":
        return [(lk.from_node, "out", lk.from_var) for lk in a.model.links
                if lk.to_node == sym.node and lk.to_var == sym.name]
    return [(lk.to_node, "in", lk.to_var) for lk in a.model.links
            if lk.from_node == sym.node and lk.from_var == sym.name]


def definition(ws: LspWorkspace, a: Analysis, texts: Mapping[str, str], sym: Symbol) -> list[lsp.Location]:
    """The definitions of ``sym`` (module docstring), ``[]`` when it has none."""
    locs: list[ast.Loc] = []
    if sym.kind == "io":
        ends = _links(a, sym) if sym.prefix == "in" else []
        for node, prefix, var in ends or [(sym.node, sym.prefix, sym.name)]:
            d = _io_decl(a, node, prefix, var)
            if d is not None:
                locs.append(d.loc)
    elif sym.kind == "node":
        n = all_nodes(a).get(sym.name)
        if n is not None:
            locs.append(ast.Loc(n.loc.file, n.loc.line, n.loc.col))
    elif sym.kind == "decl":
        found = declarations(a).get(sym.name)
        if found is not None:
            locs.append(ast.Loc(found[1].loc.file, found[1].loc.line, found[1].loc.col))
    elif sym.kind == "requirement" and a.plan is not None:
        nodes = all_nodes(a)
        for r in a.plan.requirements:
            if r.id == sym.name:
                for s in r.support:
                    n = nodes.get(s.node)
                    if n is None:
                        continue
                    for k in s.guarantees:
                        if 1 <= k <= len(n.guarantees):
                            locs.append(n.guarantees[k - 1].loc)
    elif sym.kind == "guarantee":
        n = all_nodes(a).get(sym.node)
        if n is not None and 1 <= sym.index <= len(n.guarantees):
            locs.append(n.guarantees[sym.index - 1].loc)
    return [_loc(ws, texts, x) for x in locs]


def _texts(ws: LspWorkspace, a: Analysis, texts: Mapping[str, str]) -> dict[str, str]:
    out = {f: t for f, t in a.texts.items()}
    out.update({f: t for f, t in texts.items() if f in out})
    plan = texts.get(ws.plan, ws.disk_text(ws.plan))
    if plan is not None:
        out[ws.plan] = plan
    return out


def _in_node(text: str, n: ast.Node, names: Iterable[str], file: str) -> list[tuple[str, int, int, int]]:
    out = []
    for name in names:
        for line, s, e in occurrences(text, name):
            if n.loc.line <= line + 1 <= (n.loc.end_line or n.loc.line):
                out.append((file, line, s, e))
    return out


def references(ws: LspWorkspace, a: Analysis, texts: Mapping[str, str], sym: Symbol,
               include_declaration: bool = True) -> list[lsp.Location]:
    """The references of ``sym`` (module docstring), in file and position order."""
    files = _texts(ws, a, texts)
    hits: list[tuple[str, int, int, int]] = []
    if sym.kind in ("node", "decl", "requirement"):
        for f, t in files.items():
            hits += [(f, line, s, e) for line, s, e in occurrences(t, sym.name, yaml=f == ws.plan)]
        if sym.kind == "decl" and not include_declaration:
            d = declarations(a).get(sym.name)
            if d is not None:
                hits = [h for h in hits if (h[0], h[1] + 1) != (d[1].loc.file, d[1].loc.line)]
    elif sym.kind == "io":
        nodes = all_nodes(a)
        for node, prefix, var in [(sym.node, sym.prefix, sym.name), *_links(a, sym)]:
            n = nodes.get(node)
            if n is None or n.loc.file not in files:
                continue
            names = [f"{prefix}.{var}"] + ([var] if include_declaration else [])
            found = _in_node(files[n.loc.file], n, names, n.loc.file)
            decl = _io_decl(a, node, prefix, var)
            # the bare name counts only at its declaration (elsewhere it may be another thing)
            hits += [h for h in found if decl is not None and (h[1] + 1, h[2] + 1) == (decl.loc.line, decl.loc.col)
                     or split_lines(files[h[0]])[h[1]][h[2]:h[3]].startswith(prefix + ".")]
            if ws.plan in files:
                hits += [(ws.plan, line, s, e) for line, s, e in occurrences(files[ws.plan], f"{node}.{prefix}.{var}", yaml=True)]
    out = []
    for f, line, s, e in sorted(set(hits)):
        here = split_lines(files[f])[line]
        out.append(lsp.Location(ws.uri(f), lsp.Range(lsp.Position(line, utf16_col(here, s)),
                                                       lsp.Position(line, utf16_col(here, e)))))
    return out
