"""Dafny contract stubs: one ``abstract module <Node>Contract`` per node.

Paper lines 1667-1762 re-specify the Agent in Dafny to show that a node's
implementation (and its verification technique) can be swapped as long as
the new one meets the node's first-order contract.  The stub makes that
contract a Dafny method specification, generated from RCL so that it cannot
drift from, or be weakened relative to, the RCL contract:

* context enumerations and constructor sets the node uses become
  ``datatype`` declarations, context constants it uses ``const``
  declarations, and context type names of its inputs/outputs type synonyms
  (:mod:`.types`);
* the node's inputs are the method's parameters and its outputs the
  ``returns`` values.  **Function-typed inputs** (``WayP : REAL x REAL -->
  NATURAL``) **are parameters of Dafny's total arrow type** rather than
  uninterpreted module-level functions: a refining module may give a
  module-level function a body, which would prove the contract for that one
  function only, whereas a parameter obliges the implementation to meet
  the contract for every function, which is what the RCL contract says;
* each top-level conjunct of each ``assume`` clause becomes one
  ``requires``, each top-level conjunct of each ``guarantee`` clause one
  ``ensures``, each preceded by a comment line
  ``// guarantee 2 at <file>:<line>:<col>`` that the runner uses to map
  Dafny's "related location" back to the RCL source;
* the method is a ``ghost method`` by default.  The contract's inputs are
  mathematical functions over ``real``; a model that has to inspect them
  (choose ``x, y :| at(x, y)``, branch on ``exists``) is specification-level
  code, which Dafny only accepts in ghost context.  The plan key
  ``executable: true`` emits a compiled ``method`` instead, for
  implementations that only evaluate their inputs at computed points.

The user writes ``module <Any> refines <Node>Contract { [ghost] method
<Node>(...) returns (...) { body } }``; the runner hands Dafny both files.
"""
from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Mapping

import jinja2

from rclverify.lang import ast

from rclverify.lang import typeexpr
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import CheckedNode, DataT, EnumT, Env, Type
from rclverify.targets.dafny.translate import Translator
from rclverify.targets.dafny.types import dafny_ident, dafny_type, datatype_decl, datatypes_in


@dataclass(frozen=True)
class StubClause:
    """One ``requires``/``ensures`` line of a stub.

    ``kind`` is ``"requires"`` or ``"ensures"``; ``role`` ``"assumption"``
    or ``"guarantee"``; ``index`` the 1-based clause index in the node;
    ``conjunct`` the 1-based top-level conjunct (0 when the clause has one);
    ``source`` its RCL location; ``rcl`` and ``dafny`` its text.
    """

    kind: str
    role: str
    index: int
    conjunct: int
    source: ast.Loc
    rcl: str
    dafny: str

    @property
    def label(self) -> str:
        return f"{self.role} {self.index}" + (f".{self.conjunct}" if self.conjunct else "")


@dataclass(frozen=True)
class Stub:
    """A rendered contract stub: ``text`` plus what the runner needs to know.

    ``module``/``method``: Dafny names; ``ghost``: ghost method or not;
    ``params``/``returns``: ``(Dafny name, Dafny type)`` pairs;
    ``io``: RCL qualified name (``in.at``) -> Dafny parameter name.
    """

    module: str
    method: str
    ghost: bool
    params: tuple[tuple[str, str], ...]
    returns: tuple[tuple[str, str], ...]
    clauses: tuple[StubClause, ...]
    io: dict[str, str] = field(default_factory=dict)
    text: str = ""

    def signature(self) -> str:
        """The method signature a refining module repeats (one line)."""
        kw = "ghost method" if self.ghost else "method"
        sig = f"{kw} {self.method}(" + ", ".join(f"{n}: {t}" for n, t in self.params) + ")"
        if self.returns:
            sig += " returns (" + ", ".join(f"{n}: {t}" for n, t in self.returns) + ")"
        return sig


@lru_cache(maxsize=1)
def _jinja() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.backends.dafny", "templates"),
                              undefined=jinja2.StrictUndefined, keep_trailing_newline=True,
                              trim_blocks=True, lstrip_blocks=True, autoescape=False)


@dataclass(frozen=True)
class Refutation:
    """What a refutation stub states instead of the contract (:mod:`.refute`):
    the method keeps every ``requires``, gains one ``requires`` per pinned
    input, and has the one ``ensures`` ``!(g)`` of guarantee ``guarantee``'s
    conjunct ``conjunct`` (0: the whole guarantee).  ``pins`` are
    ``(parameter, Dafny literal, RCL text of the pin)`` triples."""

    guarantee: int
    conjunct: int
    pins: tuple[tuple[str, str, str], ...] = ()


def conjuncts(e: ast.Expr) -> list[ast.Expr]:
    """The top-level conjuncts of ``e`` (``a and (b and c)`` -> ``[a, b, c]``)."""
    if isinstance(e, ast.Binary) and e.op == "and":
        return conjuncts(e.left) + conjuncts(e.right)
    return [e]


def module_name(node: str) -> str:
    """``<Node>Contract``: the abstract module of ``node``'s stub."""
    return dafny_ident(f"{node}Contract")


def snake(name: str) -> str:
    """``RadiationSensor`` -> ``radiation_sensor`` (file names of stubs and implementations)."""
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name).lower()


def _order(env: Env, t: Type) -> tuple[int, str]:
    names = list(env.types)
    name = getattr(t, "name", "")
    return (names.index(name) if name in names and env.types[name] == t else len(names), name)


def _type_rank(env: Env, dafny_name: str) -> int:
    names = [dafny_ident(t) for t in env.types]
    return names.index(dafny_name) if dafny_name in names else len(names)


def build_stub(env: Env, node: CheckedNode, *, ghost: bool = True, header: str = "",
               commands: tuple[str, ...] = (), implementation: str = "",
               widths: Mapping[str, str] | None = None, refute: Refutation | None = None) -> Stub:
    """Build (and render) the Dafny contract stub of ``node``.

    ``ghost``          emit a ``ghost method`` (default) or a compiled ``method``;
    ``header``         the first line's text (after ``// ``);
    ``commands``       Dafny command lines shown in the stub's comment;
    ``implementation`` the workspace-relative implementation path shown there;
    ``widths``         ``"in.x"`` -> ``float32``/``float64``: the widths the clauses'
                       comparisons are read at (:class:`~rclverify.targets.dafny.translate.Translator`);
    ``refute``         build the refutation stub of one guarantee instead (:class:`Refutation`): the
                       same module name, declarations and signature, so the user's implementation
                       refines it unchanged.

    Raises :class:`~rclverify.model.plan.errors.PlanError` (located at the RCL
    construct) for types or formulas Dafny cannot express, e.g. an input of
    the empty type ``{}``.
    """
    n = node.node
    module = module_name(n.name)
    method, consts, io, reserved = _names(env, node, module)
    needed: list[Type] = []
    synonyms: dict[str, str] = {}
    params = tuple((io[f"in.{v.name}"], _param_type(env, v, node.inputs[v.name], "input", needed, synonyms))
                   for v in n.inputs)
    returns = tuple((io[f"out.{v.name}"], _param_type(env, v, node.outputs[v.name], "output", needed, synonyms))
                    for v in n.outputs)
    tr = Translator(env, node, io, consts, frozenset(reserved | set(synonyms)), dict(widths or {}))
    clauses = _clauses(tr, n)
    if refute is not None:
        negated = [dataclasses.replace(c, rcl=f"not ({c.rcl})", dafny=f"!({c.dafny})") for c in clauses
                   if c.role == "guarantee" and (c.index, c.conjunct) == (refute.guarantee, refute.conjunct)]
        pins = [StubClause("requires", "counterexample input", k, 0, n.loc, rcl, f"{param} == {lit}")
                for k, (param, lit, rcl) in enumerate(refute.pins, start=1)]
        clauses = [c for c in clauses if c.kind == "requires"] + pins + negated
    const_lines = _constant_lines(env, tr, consts, needed)
    dts: list[EnumT | DataT] = []
    for t in needed + tr.used_types:
        for d in datatypes_in(t):
            if d not in dts:
                dts.append(d)
    dts.sort(key=lambda d: _order(env, d))
    stub = Stub(module, method, ghost, params, returns, tuple(clauses), io)
    text = _jinja().get_template("contract.dfy.j2").render(
        header=header or f"Dafny contract of node {n.name} -- generated by rclverify",
        node=n.name, source=str(n.loc), module=module, datatypes=[datatype_decl(d, n.loc) for d in dts],
        synonyms=sorted(synonyms.items(), key=lambda kv: (_type_rank(env, kv[0]), kv[0])),
        consts=[const_lines[c] for c in env.constants if c in const_lines],
        signature=stub.signature(), clauses=clauses, commands=list(commands), implementation=implementation,
        ghost=ghost, refutation=refute,
    )
    return Stub(module, method, ghost, params, returns, tuple(clauses), io, text)


def _names(env: Env, node: CheckedNode, module: str) -> tuple[str, dict[str, str], dict[str, str], set[str]]:
    """The Dafny names of the stub: ``(method, constants, io, reserved)`` with
    ``constants`` RCL constant -> Dafny name, ``io`` ``"in.x"``/``"out.x"`` ->
    parameter name (``in_x``/``out_x`` for a name that is both), and
    ``reserved`` every name taken besides the parameters."""
    n = node.node
    reserved: set[str] = {module}
    reserved |= {dafny_ident(t) for t in env.types}
    reserved |= {dafny_ident(v) for v in env.enum_values} | {dafny_ident(c) for c in env.ctors}
    method = dafny_ident(n.name, reserved)
    reserved.add(method)
    consts = {c: dafny_ident(c, reserved - {dafny_ident(c)}) for c in env.constants}
    reserved |= set(consts.values())
    both = set(node.inputs) & set(node.outputs)
    io: dict[str, str] = {}
    for prefix, ios in (("in", n.inputs), ("out", n.outputs)):
        for v in ios:
            want = f"{prefix}_{v.name}" if v.name in both else v.name
            io[f"{prefix}.{v.name}"] = dafny_ident(want, reserved | set(io.values()))
    return method, consts, io, reserved


def _param_type(env: Env, v: ast.IOVar, t: Type, kind: str, needed: list[Type], synonyms: dict[str, str]) -> str:
    """The Dafny type text of the parameter ``v`` (an ``input``/``output`` of
    RCL type ``t``); records ``t`` in ``needed`` and, for a declared type
    name that is no datatype, the synonym it stands for in ``synonyms``."""
    text = dafny_type(t, v.loc, f"{kind} {v.name} of type {t}")
    needed.append(t)
    if isinstance(v.type, typeexpr.TName) and not isinstance(t, (EnumT, DataT)) and v.type.name in env.types:
        syn = dafny_ident(v.type.name)
        synonyms[syn] = text
        return syn
    return text


def _clauses(tr: Translator, n: ast.Node) -> list[StubClause]:
    """One ``requires`` per conjunct of each assumption and one ``ensures``
    per conjunct of each guarantee, each with its RCL location."""
    clauses: list[StubClause] = []
    for kind, role, group in (("requires", "assumption", n.assumes), ("ensures", "guarantee", n.guarantees)):
        for k, cl in enumerate(group, start=1):
            parts = conjuncts(cl.formula)
            for j, part in enumerate(parts, start=1):
                loc = part.loc if part.loc.line else cl.loc
                clauses.append(StubClause(kind, role, k, j if len(parts) > 1 else 0, loc,
                                          expr_to_rcl(part), tr.formula(part)))
    return clauses


def _constant_lines(env: Env, tr: Translator, consts: Mapping[str, str], needed: list[Type]) -> dict[str, str]:
    """RCL constant -> its ``const`` declaration, for the constants the
    clauses use and, closed over, those their values use; records each
    constant's type in ``needed``."""
    const_lines: dict[str, str] = {}
    pending = set(tr.used_consts)
    while pending:
        c = pending.pop()
        if c in const_lines:
            continue
        t, value = env.constants[c]
        before = set(tr.used_consts)
        text, vt = tr.term(value)
        const_lines[c] = f"const {consts[c]}: {dafny_type(t, value.loc, f'constant {c}')} := {tr.conv(text, vt, t)}"
        needed.append(t)
        pending |= set(tr.used_consts) - before - set(const_lines)
    return const_lines


_MARK = re.compile(r"^\s*// (?P<role>assumption|guarantee) (?P<index>\d+)(?:\.(?P<conj>\d+))? at "
                   r"(?P<src>.+:\d+:\d+)\s*$")
_CLAUSE = re.compile(r"^\s*(?P<kind>requires|ensures)\b")


@dataclass(frozen=True)
class ClauseRef:
    """Which RCL clause a line of a stub holds: ``role`` (``assumption`` /
    ``guarantee``), 1-based ``index`` and ``conjunct`` (0: whole clause),
    ``source`` (``file:line:col`` in RCL) and ``kind`` (``requires`` /
    ``ensures``)."""

    role: str
    index: int
    conjunct: int
    source: str
    kind: str

    @property
    def label(self) -> str:
        return f"{self.role} {self.index}" + (f".{self.conjunct}" if self.conjunct else "")


def clause_lines(text: str) -> dict[int, ClauseRef]:
    """Map each 1-based line number of a stub's ``requires``/``ensures``
    clauses to the RCL clause it came from, read from the location comment
    that precedes it (the format :func:`build_stub` writes)."""
    out: dict[int, ClauseRef] = {}
    mark: re.Match[str] | None = None
    for no, line in enumerate(text.splitlines(), start=1):
        m = _MARK.match(line)
        if m:
            mark = m
            continue
        c = _CLAUSE.match(line)
        if c and mark is not None:
            out[no] = ClauseRef(mark.group("role"), int(mark.group("index")), int(mark.group("conj") or 0),
                                mark.group("src"), c.group("kind"))
            mark = None
    return out
