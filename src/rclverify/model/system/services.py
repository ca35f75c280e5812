"""Rule S1: a service's or action's client and server linked
(docs/decisions.md, "Services, actions and deadlines").

A request (action goal) is the client's output and the server's input; the
response (feedback, result) the other way round.  :func:`peers` answers, for
one input of one node, which output of which node feeds it through a link;
:func:`side_conditions` reports, located, a link whose two ends disagree on
the ROS type, and a second server of one name.

A client's call reaches a server only through the link: a node that
``calls`` a service (or action) that no node ``serves`` sends its requests
to no one and gets no response.  :func:`unserved` warns about it, located
at the ``calls`` (``W-unserved``); :func:`unserved_parts` names the
client's variables that such a link carries, so that a deadline chain
through them is not proved (:mod:`rclverify.calculus.deadlines`).  A server
no node calls is normal (a service is also called from the command line)
and is not reported.
"""
from __future__ import annotations

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, error, warning
from rclverify.lang.types import Checked


def _links(checked: Checked) -> list[tuple[str, ast.Link]]:
    return [(n, lk) for n, cn in checked.nodes.items() for lk in cn.node.links]


def peers(checked: Checked, node: str, var: str) -> list[tuple[str, str]]:
    """The ``(node, output)`` pairs that feed ``node.in.var`` through a
    service or action link of the same kind and name (the other role), with
    the same ROS type and RCL type.  Usually zero or one pair."""
    cn = checked.nodes[node]
    out: list[tuple[str, str]] = []
    for lk in cn.node.links:
        for i, v in enumerate(lk.parts):
            if v.prefix != "in" or v.name != var:
                continue
            for m, other in _links(checked):
                if m == node or other.kind != lk.kind or other.name != lk.name or other.role == lk.role:
                    continue
                if other.ros_type != lk.ros_type:
                    continue
                w = other.parts[i]
                ocn = checked.nodes[m]
                if w.prefix == "out" and w.name in ocn.outputs and ocn.outputs[w.name] == cn.inputs[var]:
                    out.append((m, w.name))
    return out


def side_conditions(checked: Checked) -> list[Diagnostic]:
    """Located errors of S1's side conditions (a) one ROS type per service or
    action name and (b) at most one server per name; empty when they hold."""
    diags: list[Diagnostic] = []
    first: dict[tuple[str, str], tuple[str, ast.Link]] = {}
    server: dict[tuple[str, str], str] = {}
    for n, lk in _links(checked):
        key = (lk.kind, lk.name)
        if key in first:
            m, f = first[key]
            if f.ros_type != lk.ros_type:
                diags.append(error(lk.loc, f"{lk.kind} {lk.name!r} has type {lk.ros_type} here but "
                                   f"{f.ros_type} in node {m} ({f.loc})", "E-link"))
        else:
            first[key] = (n, lk)
        if lk.role == "serves":
            if key in server:
                diags.append(error(lk.loc, f"{lk.kind} {lk.name!r} already has a server, node {server[key]}; "
                                   "ROS allows one", "E-link"))
            else:
                server[key] = n
    return diags


def _unserved_links(checked: Checked) -> list[tuple[str, ast.Link]]:
    served = {(lk.kind, lk.name) for _, lk in _links(checked) if lk.role == "serves"}
    return [(n, lk) for n, lk in _links(checked) if lk.role == "calls" and (lk.kind, lk.name) not in served]


def unserved(checked: Checked) -> list[Diagnostic]:
    """Located warnings (``W-unserved``), one per ``calls`` link whose
    service or action no node of ``checked`` serves, in source order.
    ``checked``: the type-checked contracts of one system."""
    return [warning(lk.loc, f"{n} calls {lk.kind} {lk.name!r}, which no node serves: its "
                    f"{'requests' if lk.kind == 'service' else 'goals'} reach no one and no response comes; "
                    "a deadline through it is not proved", "W-unserved")
            for n, lk in _unserved_links(checked)]


def unserved_parts(checked: Checked) -> dict[tuple[str, str], str]:
    """``(node, variable) -> reason`` for every variable a ``calls`` link to
    an unserved service or action carries (the request or goal output, the
    response, feedback or result inputs): what the client sends reaches no
    one, what it waits for never comes."""
    out: dict[tuple[str, str], str] = {}
    for n, lk in _unserved_links(checked):
        for v in lk.parts:
            out.setdefault((n, v.name), f"{n} calls {lk.kind} {lk.name!r}, which no node serves "
                                        f"({v.prefix}.{v.name} is part of that call)")
    return out
