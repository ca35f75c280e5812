"""Hover: what the contracts and the last run say of the symbol under the cursor.

* a node: its contract (printed as ``rclverify fmt`` prints it), the status
  of the node and of each guarantee in the last report, the nodes it reads
  from and feeds;
* an input or output: its type, unit, the topics it matches (field and
  message type), the producers or consumers at the other end;
* a guarantee (its keyword): its text, its status, the evidence covering
  it with each obligation's verdict, and the health checks about it;
* a requirement id of the plan: its text, the last run's verdict and
  status, and the premises its proof used;
* a context name: what it is and its declaration.

The text is Markdown from ``templates/hover.md.j2``.  Statuses come from
the last run's ``reports/assurance.json`` decoded into its record
(:class:`~rclverify.records.report_record.AssuranceReport`, :mod:`.lastrun`),
read by attribute; without one the contract parts are shown alone.
"""
from __future__ import annotations

import jinja2
import msgspec
from lsprotocol import types as lsp

from rclverify.lang import ast
from rclverify.records.node_rows import CulpritOf, GuaranteeRow, NodeRow
from rclverify.records.report_record import AssuranceReport
from rclverify.records.requirement_check import RequirementCheckRow
from rclverify.tools.lsp.diagnostics import Analysis
from rclverify.tools.lsp.index import Symbol, all_nodes, declarations
from rclverify.lang.printer import node_to_rcl, type_to_rcl

_ENV = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.tools.lsp", "templates"), autoescape=False,
                          keep_trailing_newline=False, undefined=jinja2.StrictUndefined)


def _report_node(report: AssuranceReport | None, name: str) -> NodeRow | None:
    return next((n for n in report.nodes if n.name == name), None) if report else None


def _culprits(row: NodeRow | GuaranteeRow | None) -> list[CulpritOf]:
    """The problems ``row`` is the culprit of (``[]`` without a row or when none)."""
    return [] if row is None or row.culprit_of is msgspec.UNSET else list(row.culprit_of)


def hover_text(a: Analysis, sym: Symbol, report: AssuranceReport | None) -> str | None:
    """The Markdown hover of ``sym`` in the analysis ``a`` with the last
    ``report`` (``None``: no last run); ``None`` when there is nothing to say."""
    nodes = all_nodes(a)
    t = _ENV.get_template("hover.md.j2")
    if sym.kind == "node" and sym.name in nodes:
        rn = _report_node(report, sym.name)
        model = a.model
        return t.render(kind="node", name=sym.name, status=rn.status if rn else None, culprit_of=_culprits(rn),
                        contract=node_to_rcl(nodes[sym.name]).rstrip(), guarantees=rn.guarantees if rn else [],
                        producers=model.producers(sym.name) if model else [],
                        consumers=model.consumers(sym.name) if model else [])
    if sym.kind == "io" and sym.node in nodes:
        n = nodes[sym.node]
        decl = next((v for v in (n.inputs if sym.prefix == "in" else n.outputs) if v.name == sym.name), None)
        if decl is None:
            return None
        topics = [tp for tp in n.topics if tp.match is not None and tp.match.name == sym.name
                  and tp.match.prefix in (sym.prefix, None)]
        ends = []
        for lk in a.model.links if a.model is not None else ():
            if sym.prefix == "in" and (lk.to_node, lk.to_var) == (sym.node, sym.name):
                ends.append(f"{lk.from_node}.out.{lk.from_var} (via {lk.via})")
            if sym.prefix == "out" and (lk.from_node, lk.from_var) == (sym.node, sym.name):
                ends.append(f"{lk.to_node}.in.{lk.to_var} (via {lk.via})")
        return t.render(kind="io", name=sym.name, node=sym.node, prefix=sym.prefix, type=type_to_rcl(decl.type),
                        unit=decl.unit.text.strip("[]") if decl.unit else "", topics=topics, ends=ends)
    if sym.kind == "guarantee" and sym.node in nodes:
        n = nodes[sym.node]
        if not 1 <= sym.index <= len(n.guarantees):
            return None
        from rclverify.lang.printer import expr_to_rcl  # deferred: optional or conditional (inside a block)
        rn = _report_node(report, sym.node)
        g = next((x for x in (rn.guarantees if rn else ()) if x.index == sym.index), None)
        obligations = [o for o in (report.obligations if report else ())
                       if o.node == sym.node and o.guarantee == sym.index]
        findings = [f for f in (report.findings if report else ())
                    if f.node == sym.node and f.guarantee == sym.index]
        return t.render(kind="guarantee", node=sym.node, index=sym.index, status=g.status if g else None,
                        culprit_of=_culprits(g),
                        text=expr_to_rcl(n.guarantees[sym.index - 1].formula), obligations=obligations, findings=findings)
    if sym.kind == "requirement":
        r = next((x for x in (report.requirements if report else ()) if x.id == sym.name), None)
        req = next((x for x in (a.plan.requirements if a.plan else ()) if x.id == sym.name), None)
        if r is None and req is None:
            return None
        return t.render(kind="requirement", name=sym.name, verdict=r.verdict if r else None,
                        status=r.status if r else None, text=(r.text if r else None) or (req.text if req else ""),
                        used=RequirementCheckRow.of(r.check).used if r else [])
    if sym.kind == "decl":
        found = declarations(a).get(sym.name)
        if found is None:
            return None
        what, d = found
        if isinstance(d, ast.TypeDecl):
            text = f"{d.name} : {type_to_rcl(d.type)} ;"
        else:
            from rclverify.lang.printer import context_to_rcl  # deferred: optional or conditional (inside a block)
            text = context_to_rcl(ast.Context((d,))).split("\n")[1].strip()
        return t.render(kind="decl", what=what, name=sym.name, declaration=text)
    return None


def hover(a: Analysis, sym: Symbol, report: AssuranceReport | None) -> lsp.Hover | None:
    """The LSP hover of ``sym`` (see :func:`hover_text`)."""
    text = hover_text(a, sym, report)
    if text is None:
        return None
    return lsp.Hover(contents=lsp.MarkupContent(kind=lsp.MarkupKind.Markdown, value=text))
