"""Units of measure on the connections of the system model (docs/rcl-language.md, "Units of measure").

A connection (:class:`~rclverify.system.model.Link`: a producer's output
feeds a consumer's input, found by the plan, by name, by a service or action
link, or by topic) carries the producer's number to the consumer unchanged,
so both ends must read it in one unit:

* both ends declare a unit and they differ: a located error at **both**
  declarations, the producer's output and the consumer's input, naming the
  factor (``E-unit-scale``: ``[mm]`` against ``[m]``, a factor of 1000), the
  dimensions (``E-unit-dimension``) or the offset (``E-unit-offset``:
  ``degC`` against ``K``);
* one end declares a unit and the other does not: a warning
  (``W-unit-missing``) at the end without one, since nothing can be checked;
* neither end declares one: nothing here (the calculus' probable scale
  mismatch, :mod:`rclverify.calculus.scale`, looks at their ranges).

:func:`connection_diagnostics` is called by
:func:`rclverify.system.model.build` (its errors stop the build, as the
other connection errors do) and, for the warnings, by the check stage.  It
takes the links as values with ``from_node``, ``from_var``, ``to_node``,
``to_var`` and ``via`` and imports nothing of the model, which imports it.
"""
from __future__ import annotations

from typing import Any, Iterable

from ..rcl import ast
from ..rcl.errors import Diagnostic, error, warning
from ..rcl.types import Checked
from ..rcl.unitcheck import mismatch
from ..rcl.units import describe


def _decl(checked: Checked, node: str, prefix: str, var: str) -> ast.IOVar | None:
    n = checked.nodes[node].node
    for v in (n.inputs if prefix == "in" else n.outputs):
        if v.name == var:
            return v
    return None


def connection_diagnostics(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """The unit errors and warnings of ``links`` (see the module docstring),
    in link order, each located at a declaration (``file:line:col``)."""
    out: list[Diagnostic] = []
    for l in links:
        p, c = checked.nodes.get(l.from_node), checked.nodes.get(l.to_node)
        if p is None or c is None:
            continue
        up, uc = p.unit_of("out", l.from_var), c.unit_of("in", l.to_var)
        pd, cd = _decl(checked, l.from_node, "out", l.from_var), _decl(checked, l.to_node, "in", l.to_var)
        if pd is None or cd is None or (up is None and uc is None):
            continue
        writer, reader = f"{l.from_node}.out.{l.from_var}", f"{l.to_node}.in.{l.to_var}"
        conn = f"{writer} -> {reader} (via {l.via})"
        if up is not None and uc is not None:
            bad = mismatch(up, uc)
            if bad is None:
                continue
            code, reason = bad
            if code == "E-unit-dimension":
                advice = (f"these are different quantities: check that {writer} should feed {reader} at all "
                          f"(a name, topic or plan connection may match by accident)")
            else:
                advice = (f"a connection carries the number unchanged, so {l.to_node} would read {up} as {uc}; "
                          f"declare one unit at both ends and convert in {l.from_node}")
            what = (f"unit mismatch on the connection {conn}: {writer} is {describe(up)}, {reader} is "
                    f"{describe(uc)}: {reason}; {advice}")
            out.append(error(pd.loc, f"{what} (the reader's declaration: {cd.loc})", code))
            out.append(error(cd.loc, f"{what} (the writer's declaration: {pd.loc})", code))
        elif up is None:
            out.append(warning(pd.loc, f"{writer} declares no unit but feeds {reader}, which is {describe(uc)} "
                                       f"({conn}): declare the unit {l.from_node} publishes so the connection is "
                                       "checked", "W-unit-missing"))
        else:
            out.append(warning(cd.loc, f"{reader} declares no unit but reads {writer}, which is {describe(up)} "
                                       f"({conn}): declare the unit {l.to_node} expects so the connection is "
                                       "checked", "W-unit-missing"))
    return out


def connection_errors(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """The errors of :func:`connection_diagnostics` only."""
    return [d for d in connection_diagnostics(checked, links) if d.severity == "error"]


def connection_warnings(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """The warnings of :func:`connection_diagnostics` only (``W-unit-missing``)."""
    return [d for d in connection_diagnostics(checked, links) if d.severity == "warning"]
