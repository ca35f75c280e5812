"""AJPF property formulas as SPIN LTL, and property files read from disk.

A :mod:`~rclverify.backends.model_checking.ajpf.psl` formula becomes the text of a SPIN 6
``ltl`` block (SPIN manual, "ltl": ``[]`` always, ``<>`` eventually, ``U``
until, ``V`` release, ``!``, ``&&``, ``||``, ``->``, ``true``/``false``).
Each proposition of the property language (``B(ag, f)``, ``G``, ``D``,
``I``, ``ItD``, ``P(f)``; paper lines 1366-1394) becomes a boolean
variable of the Promela model whose value in each state of the explored
graph is :meth:`StateGraph.holds` (:mod:`.promela`); :class:`Propositions`
names them ``q0``, ``q1``, ... in order of first use.

The property language has no next operator, so every translated formula is
invariant under stuttering: steps of the Promela model that leave the
propositions unchanged (the choice of a successor, a final state repeated)
do not change a verdict (docs/model-checking.md, "Fairness and stuttering").

Property files (the plan's ``properties:``) are in AJPF's format: one
property per line, ``<label>: <formula>``; blank lines and lines whose
first non-blank character is ``#`` are ignored.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

from rclverify.model.plan.errors import plan_error
from rclverify.backends.model_checking.ajpf import psl

Atom = psl.Modal | psl.Percept

_LABEL = re.compile(r"^\s*([A-Za-z0-9_]+)\s*:(.*)$")


class Propositions:
    """The propositions of a set of formulas, each named ``q<k>`` (first use first)."""

    def __init__(self, formulas: Iterable[psl.Formula] = ()) -> None:
        self.names: dict[Atom, str] = {}
        for f in formulas:
            self.add(f)

    def add(self, f: psl.Formula) -> None:
        """Name every proposition of ``f`` not named yet."""
        for atom in psl.propositions(f):
            if atom not in self.names:
                self.names[atom] = f"q{len(self.names)}"  # type: ignore[index]

    def atoms(self) -> list[tuple[str, Atom]]:
        """``(name, proposition)`` in naming order."""
        return [(n, a) for a, n in self.names.items()]


def to_spin(f: psl.Formula, props: Propositions) -> str:
    """``f`` as the body of a SPIN ``ltl`` block; every operand is parenthesised.

    ``props`` must name every proposition of ``f`` (``KeyError`` otherwise).
    ``[] (B(jackal, danger_red) -> <> B(jackal, going(0)))`` with ``q0`` for
    the first atom and ``q1`` for the second becomes ``[] ((q0) -> (<> (q1)))``.
    """
    if isinstance(f, psl.Const):
        return "true" if f.value else "false"
    if isinstance(f, (psl.Modal, psl.Percept)):
        return props.names[f]
    if isinstance(f, psl.Not):
        return f"! ({to_spin(f.operand, props)})"
    if isinstance(f, psl.And):
        return " && ".join(f"({to_spin(p, props)})" for p in f.parts)
    if isinstance(f, psl.Or):
        return " || ".join(f"({to_spin(p, props)})" for p in f.parts)
    if isinstance(f, psl.Implies):
        return f"({to_spin(f.left, props)}) -> ({to_spin(f.right, props)})"
    if isinstance(f, psl.Always):
        return f"[] ({to_spin(f.operand, props)})"
    if isinstance(f, psl.Eventually):
        return f"<> ({to_spin(f.operand, props)})"
    if isinstance(f, psl.Until):
        return f"({to_spin(f.left, props)}) U ({to_spin(f.right, props)})"
    if isinstance(f, psl.Release):
        return f"({to_spin(f.left, props)}) V ({to_spin(f.right, props)})"
    raise TypeError(f"not a PSL formula: {f!r}")


def atom_text(atom: Atom) -> str:
    """A proposition in AJPF's syntax, for comments and counterexamples."""
    return psl.to_text(atom)


@dataclass(frozen=True)
class PslProperty:
    """One property of a property file: ``label``, its ``text`` and parsed
    ``formula``, and where it is (``file`` workspace-relative, 1-based
    ``line`` and ``col`` of the formula)."""

    label: str
    text: str
    formula: psl.Formula
    file: str
    line: int
    col: int


def parse_psl_text(text: str, file: str) -> list[PslProperty]:
    """The properties of a property file's ``text`` (see the module docstring).

    Raises :class:`PlanError` located at ``file:line:col`` for a line that is
    neither blank, a comment nor ``<label>: <formula>``, for a formula that
    does not parse (:func:`psl.parse`), and for a label used twice.
    """
    out: list[PslProperty] = []
    seen: dict[str, int] = {}
    for n, raw in enumerate(text.splitlines(), 1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        m = _LABEL.match(raw)
        if m is None:
            col = len(raw) - len(raw.lstrip()) + 1
            raise plan_error(file, n, col, "expected '<label>: <formula>' (a property of the property "
                                           "specification language), a comment '# ...' or a blank line")
        label, body = m.group(1), m.group(2)
        body_col = m.start(2) + 1
        lead = len(body) - len(body.lstrip())
        if label in seen:
            raise plan_error(file, n, m.start(1) + 1, f"property label {label!r} already used on line {seen[label]}")
        try:
            formula = psl.parse(body)
        except psl.PslSyntaxError as exc:
            raise plan_error(file, n, body_col + exc.col - 1, f"property {label}: {exc.message}") from None
        seen[label] = n
        out.append(PslProperty(label, body.strip(), formula, file, n, body_col + lead))
    return out


def read_psl_file(root: Path, rel: str) -> list[PslProperty]:
    """The properties of the workspace file ``rel`` (see :func:`parse_psl_text`).

    Raises :class:`PlanError` (located at the file's first line) when the
    file cannot be read or is not UTF-8, else as :func:`parse_psl_text`.
    """
    try:
        text = (root / rel).read_bytes().decode("utf-8-sig")
    except OSError as exc:
        raise plan_error(rel, 1, 1, f"cannot read the property file: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise plan_error(rel, 1, 1, f"the property file is not UTF-8 text (byte {exc.start})") from None
    return parse_psl_text(text, rel)

