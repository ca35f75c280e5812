"""The explored state graph as a Promela model with one LTL claim per property.

The model (template ``templates/graph.pml.j2``) has one process and three
kinds of global variables: ``s`` the graph state, ``n`` its number of
successors, and one ``bool`` per proposition the claims use (``q0``,
``q1``, ... from :class:`~.ltl.Propositions`), true exactly in the graph
states where :meth:`StateGraph.holds` says so -- computed here, in Python,
for every state, and assigned in the ``d_step`` of every transition into a
state where it changes.

One step of the model is one transition of the graph: the process loops
over ``d_step { n > r; <the r-th transition out of s> }`` for every rank
``r`` below the greatest out-degree, so the choice of successor is SPIN's
nondeterministic choice among the executable options, and a ``d_step``
makes the change of ``s`` and of the propositions one atomic step (the
claim never sees a state half-updated).  Inside a ``d_step`` the transition
out of ``s`` is found by a binary tree of ``if`` on ``s`` (leaves of at most
:data:`LEAF` states), so a step costs O(log states), not O(states).

A final state (no successors) stutters: ``d_step { n == 0; ... }`` leaves
every variable as it is, so each finite path of the graph is extended by
repeating its last state for ever, the usual reading of LTL over finite
runs and AJPF's (docs/model-checking.md, "Fairness and stuttering").  The
model therefore never terminates and has no invalid end states.

Text that comes from the workspace (the program's path, property texts and
the files they come from) appears only inside comments, through
:func:`comment_text`, which keeps it on one line, in printable ASCII, and
unable to close the comment: SPIN passes the model through the C
preprocessor, so a path holding ``*/`` and a newline followed by
``#define`` or ``#include`` would otherwise rewrite the model or copy a file
into it.  :func:`build_model` also refuses a rendered model with a line that
starts with ``#``.

Every transition prints ``@T <index>`` and every stutter ``@S <state>``;
printing is off while ``pan`` verifies and on when SPIN replays a trail,
which is how a counterexample is mapped back to the graph (:mod:`.trail`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Mapping, Sequence

from jinja2 import Environment, PackageLoader, StrictUndefined

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.graph import StateGraph
from rclverify.backends.model_checking.ltl import Propositions, atom_text, to_spin
from rclverify.backends.shapes import PromelaBranch, PromelaLeaf, PromelaSplit

#: Most states of one ``if`` inside a transition's ``d_step``.
LEAF = 16


@dataclass(frozen=True)
class Claim:
    """One property to check: SPIN ``name`` (an identifier: ``p3``,
    ``x_authors_phi3a``), its ``formula``, and a one-line ``comment``
    (where it comes from) written above its ``ltl`` block."""

    name: str
    formula: psl.Formula
    comment: str = ""


@dataclass(frozen=True)
class PromelaModel:
    """The rendered model: its ``text``, the propositions as ``(name, AJPF
    text)``, the ``claims`` in it, the graph's size, and for each
    proposition the states where it holds (``truth``)."""

    text: str
    props: tuple[tuple[str, str], ...]
    claims: tuple[Claim, ...]
    states: int
    transitions: int
    truth: Mapping[psl.Formula, frozenset[int]] = field(default_factory=dict, compare=False)


def comment_text(text: object) -> str:
    """``text`` made safe inside a C/Promela block comment on one line.

    Printable ASCII is kept except ``\\``, written ``\\\\``; every other
    character (newlines, control characters, non-ASCII) becomes ``\\n``,
    ``\\t``, ``\\xNN``, ``\\uNNNN`` or ``\\UNNNNNNNN``; then ``*/``, ``/*`` and
    ``??`` (a trigraph's start) are broken by a backslash.  The result has no
    line break, so no preprocessor directive and no line splice can come
    from it, and it cannot end the comment it is written in.
    """
    out = []
    for ch in str(text):
        if ch == "\\":
            out.append("\\\\")
        elif " " <= ch <= "~":
            out.append(ch)
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ord(ch) < 0x100:
            out.append(f"\\x{ord(ch):02x}")
        elif ord(ch) < 0x10000:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(f"\\U{ord(ch):08x}")
    safe = "".join(out)
    while "*/" in safe or "/*" in safe or "??" in safe:
        safe = safe.replace("*/", "*\\/").replace("/*", "/\\*").replace("??", "?\\?")
    return safe


@lru_cache(maxsize=1)
def _templates() -> Environment:
    env = Environment(loader=PackageLoader("rclverify.backends.model_checking", "templates"),
                      undefined=StrictUndefined, keep_trailing_newline=True, trim_blocks=True,
                      lstrip_blocks=True, autoescape=False)
    env.filters["comment"] = comment_text
    return env


def truth_table(graph: StateGraph, props: Propositions) -> list[tuple[bool, ...]]:
    """For each state of ``graph``, the value of each proposition (naming order)."""
    atoms = [a for _, a in props.atoms()]
    return [tuple(graph.holds(k, a) for a in atoms) for k in range(len(graph.states))]


def build_model(graph: StateGraph, claims: Sequence[Claim]) -> PromelaModel:
    """Render ``graph`` with ``claims`` as one Promela model (see the module docstring).

    Claim names must be distinct Promela identifiers (``ValueError``
    otherwise).  The text is deterministic: same graph and claims, same bytes.
    """
    names = [c.name for c in claims]
    if len(set(names)) != len(names) or not all(n.isidentifier() and n.isascii() for n in names):
        raise ValueError(f"claim names must be distinct identifiers: {names}")
    if not graph.states:
        raise ValueError("the graph has no state")
    props = Propositions(c.formula for c in claims)
    pnames = [n for n, _ in props.atoms()]
    table = truth_table(graph, props)
    out: dict[int, list[int]] = {k: [] for k in range(len(graph.states))}
    for t, tr in enumerate(graph.transitions):
        out[tr.src].append(t)
    degree = {k: len(v) for k, v in out.items()}
    ranks = []
    for r in range(max(degree.values(), default=0)):
        branches: list[PromelaBranch] = []
        for src in sorted(k for k, d in degree.items() if d > r):
            t = out[src][r]
            dst = graph.transitions[t].dst
            sets = [] if degree[dst] == degree[src] else [f"n = {degree[dst]}"]
            sets += [f"{pnames[i]} = {int(v)}" for i, v in enumerate(table[dst]) if v != table[src][i]]
            branches.append({"src": src, "dst": dst, "t": t, "sets": sets})
        ranks.append({"rank": r, "tree": _tree(branches)})
    rendered = _templates().get_template("graph.pml.j2").render(
        source=graph.source, agent=graph.agent, states=len(graph.states), transitions=len(graph.transitions),
        complete=graph.complete, cut=graph.cut,
        props=[(n, atom_text(a)) for n, a in props.atoms()],
        initial_n=degree[0], initial_props=[(n, int(v)) for n, v in zip(pnames, table[0])],
        claims=[{"name": c.name, "ltl": to_spin(c.formula, props), "comment": _comment(c)} for c in claims],
        ranks=ranks)
    for k, line in enumerate(rendered.splitlines(), 1):
        if line.lstrip().startswith("#"):  # never: every workspace text goes through comment_text
            raise ValueError(f"the Promela model's line {k} would be a preprocessor directive: {line[:80]!r}")
    truth: dict[psl.Formula, frozenset[int]] = {
        a: frozenset(k for k, row in enumerate(table) if row[i]) for i, (_, a) in enumerate(props.atoms())}
    return PromelaModel(rendered, tuple((n, atom_text(a)) for n, a in props.atoms()), tuple(claims),
                        len(graph.states), len(graph.transitions), truth)


def _comment(c: Claim) -> str:
    return (c.comment + ": " if c.comment else "") + psl.to_text(c.formula)


def _tree(branches: list[PromelaBranch]) -> PromelaLeaf | PromelaSplit:
    """A binary search tree over ``branches`` (sorted by ``src``)."""
    if len(branches) <= LEAF:
        return {"leaf": branches}
    mid = len(branches) // 2
    return {"split": branches[mid]["src"], "low": _tree(branches[:mid]), "high": _tree(branches[mid:])}
