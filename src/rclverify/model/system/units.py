"""Units of measure on the connections of the system model (docs/rcl-language.md, "Units of measure").

A connection (:class:`~rclverify.model.system.model.Link`: a producer's output
feeds a consumer's input, found by the plan, by name, by a service or action
link, or by topic) carries the producer's number to the consumer unchanged,
so both ends must read it in one unit:

* both ends declare a unit and they differ: a located error at **both**
  declarations, the producer's output and the consumer's input, naming the
  factor (``E-unit-scale``: ``[mm]`` against ``[m]``, a factor of 1000), the
  dimensions (``E-unit-dimension``) or the offset (``E-unit-offset``:
  ``degC`` against ``K``);
* the consumer declares a unit and the producer's output does not, but its
  unit is *inferred* from its guarantee (:mod:`rclverify.lang.unitinfer`:
  ``out.heading == in.cog`` with ``cog : REAL [deg]``) and rules the
  consumer's out: a located error at the **equation** the unit was
  inferred from (the producer is to blame), naming the consumer's
  declaration and the factor; with the warning below, since the output
  still declares no unit;
* one end declares a unit and the other does not: a warning
  (``W-unit-missing``) at the end without one;
* neither end declares one: nothing here (the calculus' probable scale
  mismatch, :mod:`rclverify.calculus.scale`, looks at their ranges).

A unit mismatch does not stop a run: :func:`rclverify.model.system.model.build`
builds the model whatever the units, ``rclverify check`` prints the errors
(both ends of a declared mismatch) and fails, and the check stage records
each mismatch once, at the producer's end (:func:`producer_diagnostics`), as
a lint error row of the report (a problem, SARIF, ``--strict`` fails); the
diagnosis joins it with what follows from it (:mod:`rclverify.diagnosis.units`).
The functions take the links as values with ``from_node``, ``from_var``,
``to_node``, ``to_var`` and ``via`` and import nothing of the model, which
imports them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, error, warning
from rclverify.lang.types import Checked
from rclverify.lang.unitcheck import mismatch
from rclverify.lang.unitinfer import Inferred, certain, infer_units
from rclverify.lang.units import Unit, describe


def _decl(checked: Checked, node: str, prefix: str, var: str) -> ast.IOVar | None:
    n = checked.nodes[node].node
    for v in (n.inputs if prefix == "in" else n.outputs):
        if v.name == var:
            return v
    return None


@dataclass(frozen=True)
class Mismatch:
    """A connection whose two ends read its number in different units:
    ``writer``/``reader`` keys ``(node, "out"|"in", variable)``, ``via``
    (how the connection was found), their units, ``code`` and ``reason``
    (:func:`~rclverify.lang.unitcheck.mismatch`), the two declarations
    (``writer_decl``, ``reader_decl``) and ``inferred`` (the writer's
    :class:`~rclverify.lang.unitinfer.Inferred` when its unit is inferred,
    else ``None``): ``at`` is where the writer's unit comes from, the
    producer's own declaration or the equation it was inferred from."""

    writer: tuple[str, str, str]
    reader: tuple[str, str, str]
    via: str
    writer_unit: Unit
    reader_unit: Unit
    code: str
    reason: str
    writer_decl: ast.Loc
    reader_decl: ast.Loc
    inferred: Inferred | None = None

    @property
    def at(self) -> ast.Loc:
        return self.inferred.loc if self.inferred is not None else self.writer_decl

    @property
    def name(self) -> str:
        """``Gnss.out.heading -> Localiser.in.heading``."""
        return f"{'.'.join(self.writer)} -> {'.'.join(self.reader)}"


def mismatches(checked: Checked, links: Iterable[Any]) -> list[Mismatch]:
    """The connections of ``links`` whose ends disagree on the unit, in link
    order: both ends declare one, or the writer's is inferred
    (:func:`~rclverify.lang.unitinfer.infer_units`) and rules the reader's
    declared one out (:func:`~rclverify.lang.unitinfer.certain`)."""
    links = list(links)
    inf = infer_units(checked, links)
    out: list[Mismatch] = []
    for l in links:
        p, c = checked.nodes.get(l.from_node), checked.nodes.get(l.to_node)
        if p is None or c is None:
            continue
        pd, cd = _decl(checked, l.from_node, "out", l.from_var), _decl(checked, l.to_node, "in", l.to_var)
        uc = c.unit_of("in", l.to_var)
        if pd is None or cd is None or uc is None:
            continue
        up, got = p.unit_of("out", l.from_var), None
        if up is None:
            got = inf.inferred.get((l.from_node, "out", l.from_var))
            if not certain(got, uc):
                continue
            up = got.unit  # type: ignore[union-attr]
        bad = mismatch(up, uc)
        if bad is not None:
            out.append(Mismatch((l.from_node, "out", l.from_var), (l.to_node, "in", l.to_var), l.via, up, uc,
                                bad[0], bad[1], pd.loc, cd.loc, got))
    return out


def _message(m: Mismatch) -> str:
    writer, reader = ".".join(m.writer), ".".join(m.reader)
    if m.code == "E-unit-dimension":
        advice = (f"these are different quantities: check that {writer} should feed {reader} at all "
                  f"(a name, topic or plan connection may match by accident)")
    else:
        advice = (f"a connection carries the number unchanged, so {m.reader[0]} would read {m.writer_unit} as "
                  f"{m.reader_unit}; declare one unit at both ends and convert in {m.writer[0]}")
    whence = ""
    if m.inferred is not None:
        alt = f" (or {m.inferred.alternative}, reading the factor as a gain)" if m.inferred.alternative else ""
        whence = f" as its contract says: inferred from {m.inferred.why()}{alt}"
    return (f"unit mismatch on the connection {writer} -> {reader} (via {m.via}): {writer} is "
            f"{describe(m.writer_unit)}{whence}, {reader} is {describe(m.reader_unit)}: {m.reason}; {advice}")


def connection_diagnostics(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """The unit errors and warnings of ``links`` (see the module docstring),
    in link order, each located at a declaration or at the equation a
    unit was inferred from (``file:line:col``)."""
    links = list(links)
    bad = {(m.writer, m.reader): m for m in mismatches(checked, links)}
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
        m = bad.get(((l.from_node, "out", l.from_var), (l.to_node, "in", l.to_var)))
        if m is not None and m.inferred is None:
            what = _message(m)
            out.append(error(pd.loc, f"{what} (the reader's declaration: {cd.loc})", m.code))
            out.append(error(cd.loc, f"{what} (the writer's declaration: {pd.loc})", m.code))
        elif up is None:
            assert uc is not None  # one of the two declares a unit (tested above)
            out.append(warning(pd.loc, f"{writer} declares no unit but feeds {reader}, which is {describe(uc)} "
                                       f"({conn}): declare the unit {l.from_node} publishes so the connection is "
                                       "checked", "W-unit-missing"))
            if m is not None:  # the writer's unit inferred from its guarantee: the error is there (blame the producer)
                out.append(error(m.at, f"{_message(m)} (the reader's declaration: {cd.loc})", m.code))
        elif uc is None:
            out.append(warning(cd.loc, f"{reader} declares no unit but reads {writer}, which is {describe(up)} "
                                       f"({conn}): declare the unit {l.to_node} expects so the connection is "
                                       "checked", "W-unit-missing"))
    return out


def producer_diagnostics(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """:func:`connection_diagnostics` as the check stage records them: each
    mismatch once, at the producer's end (its declaration, or the equation
    its unit was inferred from), so the report's row, SARIF and the
    terminal blame the producer; the warnings as they are."""
    links = list(links)
    readers = {m.reader_decl for m in mismatches(checked, links) if m.inferred is None}
    return [d for d in connection_diagnostics(checked, links) if not (d.severity == "error" and d.loc in readers)]


def connection_errors(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """The errors of :func:`connection_diagnostics` only."""
    return [d for d in connection_diagnostics(checked, links) if d.severity == "error"]


def connection_warnings(checked: Checked, links: Iterable[Any]) -> list[Diagnostic]:
    """The warnings of :func:`connection_diagnostics` only (``W-unit-missing``)."""
    return [d for d in connection_diagnostics(checked, links) if d.severity == "warning"]
