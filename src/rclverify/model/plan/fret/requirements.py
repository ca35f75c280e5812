"""A FRET export as requirements and state declarations of the plan (docs/requirements.md, "Requirements from FRET").

Each requirement of the export becomes a :class:`~rclverify.model.plan.model.Requirement`:
``id`` its ``reqid``, ``text`` its ``fulltext``, ``origin`` the export's
workspace-relative name, located where its ``reqid`` is written.  Its
component is the node of the same name, or the one the plan's
``fret: components:`` maps it to.  Its variables are placed by their
``idType``: ``Input`` as ``Node.in.x``, ``Output`` as ``Node.out.x``; an
``Internal`` variable whose Lustre ``assignment`` is a FRETish expression
(a constant, or arithmetic over other variables) and a ``Mode`` defined by
its ``modeRequirement`` stand for that expression; a name the export does not declare is read as a constant of the
contracts' contexts (an enumeration value), when the contracts are known.
With the contracts' nodes at hand (:func:`ports_of`), the node, each input
and output and its type (FRET ``boolean`` a ``BOOL``, a number type a
``REAL``, ``INTEGER`` or ``NATURAL``) are checked here.

Its formal statement and state variables are :func:`.translate.translate`'s.
A requirement that cannot be translated is kept as an *informal*
requirement (its text, nothing decides it) with its :class:`~.fretish.Refusal`,
which ``rclverify import fret`` prints as ``EXPORT.json:reqid: reason; what
would make it importable``: none is dropped.
"""
from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.model.plan.document import Fret, PlanDocument, plan_document
from rclverify.model.plan.formal import Source
from rclverify.model.plan.model import Requirement
from rclverify.model.plan.state import StateVar
from rclverify.model.plan.fret.declared import DeclaredFunction, functions_of, variables_of
from rclverify.model.plan.fret.export import FretExport, FretRequirement, FretVariable, read_export
from rclverify.model.plan.fret.fretish import Expr, Refusal, parse
from rclverify.model.plan.fret.lustre import LUSTRE, fretish, parse_lustre, self_reads
from rclverify.model.plan.fret.translate import Translation, translate

#: FRET data types read as numbers, and the RCL types a number may be.
NUMBERS = ("double", "single", "float", "real", "integer", "int", "int8", "int16", "int32", "int64", "uint8",
           "uint16", "uint32", "uint64", "unsigned integer")
_NUMBER_TYPES = ("REAL", "INTEGER", "NATURAL")
_INTEGERS = ("integer", "int", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64",
             "unsigned integer")
#: Lustre's word operators in an assignment, read as FRETish's.
_LUSTRE_OPS = {"and": "&", "or": "|", "not": "!", "xor": "xor", "<>": "!="}
_LUSTRE_WORDS = re.compile(r"\b(?:and|or|not)\b|<>")


@dataclass(frozen=True)
class Options:
    """The plan's ``fret:`` section: ``components`` maps FRET's component
    names to nodes; ``step`` the seconds of one step (durations in secs);
    ``variables`` the idType (``Input``/``Output``) of a variable the export
    gives none, ``functions`` the model functions defined in RCL
    (:mod:`.declared`)."""

    components: Mapping[str, str] = field(default_factory=dict)
    step: Fraction | None = None
    variables: Mapping[str, str] = field(default_factory=dict)
    functions: Mapping[str, DeclaredFunction] = field(default_factory=dict)


@dataclass(frozen=True)
class Ports:
    """The contracts' nodes as parsed: ``nodes[node][name] = ("in"|"out", type name or None)``;
    ``constants`` the names of context constants and enumeration values; ``units[node][name]`` the unit
    written on a port (``m/s``), absent when it has none; ``fed[node]`` the node's inputs another node
    publishes (a topic matched to one node's input and another's output, as the system model reads
    :attr:`~rclverify.lang.ast.Topic.key`)."""

    nodes: Mapping[str, Mapping[str, tuple[str, str | None]]]
    constants: frozenset[str]
    units: Mapping[str, Mapping[str, str]] = field(default_factory=dict)
    fed: Mapping[str, tuple[str, ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class Imported:
    """One requirement of the export as the plan reads it: ``requirement``
    (informal when ``refusal``), the ``states`` its statement reads."""

    fret: FretRequirement
    requirement: Requirement
    states: tuple[StateVar, ...] = ()
    refusal: Refusal | None = None


def ports_of(specs: list[ast.Spec]) -> Ports:
    """The :class:`Ports` of parsed contract files ``specs``."""
    nodes: dict[str, dict[str, tuple[str, str | None]]] = {}
    units: dict[str, dict[str, str]] = {}
    consts: set[str] = set()
    published: dict[str, set[str]] = {}  # topic key -> the nodes matching an output to it
    for sp in specs:
        for n in sp.nodes:
            for tp in n.topics:
                outs = {o.name for o in n.outputs}
                if tp.match is not None and (tp.match.prefix == "out" or (tp.match.prefix is None
                                                                         and tp.match.name in outs)):
                    published.setdefault(tp.key, set()).add(n.name)
    fed: dict[str, tuple[str, ...]] = {}
    for sp in specs:
        for n in sp.nodes:
            ins = {v.name for v in n.inputs}
            fed[n.name] = tuple(dict.fromkeys(
                tp.match.name for tp in n.topics if tp.match is not None and tp.match.prefix != "out"
                and tp.match.name in ins and published.get(tp.key, set()) - {n.name}))
    for sp in specs:
        for n in sp.nodes:
            io = nodes.setdefault(n.name, {})
            for prefix, vs in (("in", n.inputs), ("out", n.outputs)):
                for v in vs:
                    io[v.name] = (prefix, getattr(v.type, "name", None))
                    if v.unit is not None:
                        units.setdefault(n.name, {})[v.name] = v.unit.text
        for c in sp.contexts:
            for d in c.decls:
                consts.add(d.name)
                vals = getattr(d.type, "values", None)
                consts.update(vals if isinstance(vals, tuple) else ())
    return Ports(nodes, frozenset(consts), units, {n: f for n, f in fed.items() if f})


class _Places:
    """Where each name of one requirement goes (``var`` of :class:`~.fretish.Writer`)."""

    def __init__(self, exp: FretExport, fr: FretRequirement, node: str, ports: Ports | None,
                 declared: Mapping[str, str] | None = None) -> None:
        self.exp, self.fr, self.node, self.ports = exp, fr, node, ports
        self.declared = declared or {}  # the plan's fret: variables (name -> Input/Output)
        self.depth = 0
        self.defining: list[str] = []

    def _declared(self, name: str) -> FretVariable | None:
        return self.exp.variables.get((self.fr.component, name))

    def __call__(self, name: str, local: bool) -> str | Expr:
        v = self._declared(name)
        kind = v.id_type if v is not None else ""
        if not kind and name in self.declared and (self.ports is None or name not in self.ports.constants):
            kind = self.declared[name]
            v = v if v is not None else FretVariable(self.fr.component, name, "", "", "")
            v = dataclasses.replace(v, id_type=kind)
        if kind in ("Input", "Output"):
            assert v is not None
            prefix = "in" if kind == "Input" else "out"
            self._check_port(v, prefix)
            return f"{prefix}.{name}" if local else f"{self.node}.{prefix}.{name}"
        if kind == "Mode" and v is not None and v.mode_requirement.strip():
            return self._defined(name, v.mode_requirement.strip(), local)
        if kind == "Internal":
            assert v is not None
            a = v.assignment.strip()
            if not a:
                raise Refusal(f"{name} is an Internal variable without an assignment",
                              f"make {name} an input or output of {self.node}, or define it in FRET by a "
                              "FRETish or Lustre expression over the component's variables")
            if LUSTRE.search(a):
                return self._defined(name, a, local, lustre=True)
            return self._defined(name, _LUSTRE_WORDS.sub(lambda m: _LUSTRE_OPS[m.group(0)], a), local)
        if kind in ("Mode", "Function"):
            raise Refusal(f"{name} is a FRET {kind} variable" + (" without a mode requirement" if kind == "Mode"
                                                                  else ""),
                          f"declare {name} as a boolean input or output of {self.node}" + (
                              ", or define the mode by a mode requirement in FRET" if kind == "Mode" else ""))
        if self.ports is not None and name in self.ports.constants:
            return name
        why = "not declared in the export" if v is None else "declared without an idType"
        raise Refusal(f"{name} is {why}", f"declare it in FRET as an Input or Output of {self.fr.component}, in "
                                          f"the plan's fret: variables ({{{name}: input}} or output), or as a "
                                          "constant or enumeration value of the contracts' context")

    def _defined(self, name: str, text: str, local: bool, lustre: bool = False) -> Expr:
        """The tree of a variable defined by a FRETish expression (an Internal variable's assignment, a
        Mode's mode requirement) or a Lustre one (:mod:`.lustre`), every name it reads placed (or refused)
        now; it may read its own value only under a ``pre``."""
        self.depth += 1
        if self.depth > 32:
            raise Refusal(f"the variable {name} is defined through itself", "break the cycle in FRET")
        try:
            tree = fretish(name, parse_lustre(name, text), self._type) if lustre else parse(text)
        except Refusal as exc:
            raise Refusal(exc.reason if exc.reason.startswith(name) else f"{name}'s definition: {exc.reason}",
                          exc.fix) from None
        self.defining.append(name)
        now, before = self_reads(tree)
        for n in now:
            if n in self.defining:
                raise Refusal(f"the variable {n} is defined through itself (not under a pre)",
                              "break the cycle in FRET")
            if n != "FTP":
                self(n, local)
        for n in before:
            if n not in self.defining:
                self(n, local)
        self.defining.pop()
        self.depth -= 1
        return tree

    def _type(self, name: str) -> str:
        """``BOOL``, ``REAL`` or ``INTEGER``: the RCL type of FRET variable ``name`` (its ``dataType``)."""
        v = self._declared(name)
        dt = v.data_type.lower() if v is not None else ""
        return "BOOL" if dt == "boolean" else "INTEGER" if dt in _INTEGERS else "REAL"

    def _check_port(self, v: FretVariable, prefix: str) -> None:
        if self.ports is None:
            return
        io = self.ports.nodes.get(self.node, {})
        want = "input" if prefix == "in" else "output"
        got = io.get(v.name)
        if got is None or got[0] != prefix:
            has = ", ".join(sorted(n for n, (p, _) in io.items() if p == prefix)) or "none"
            raise Refusal(f"{self.node} has no {want} named {v.name} (its {want}s: {has})",
                          f"declare {v.name} as an {want} of {self.node}, or correct its idType in FRET")
        self._check_unit(v, prefix)
        dt, rt = v.data_type.lower(), got[1]
        if rt is None:
            return
        ok = (rt == "BOOL") if dt == "boolean" else (rt in _NUMBER_TYPES or rt not in ("BOOL", "STRING")) \
            if dt in NUMBERS else True
        if not ok:
            raise Refusal(f"{v.name} is a FRET {v.data_type} but {self.node}.{prefix}.{v.name} is a {rt}",
                          f"make the types agree (FRET boolean is BOOL; a number is REAL, INTEGER or NATURAL)")

    def _check_unit(self, v: FretVariable, prefix: str) -> None:
        """FRET's unit of ``v`` (:attr:`FretVariable.unit`) against the port's (docs/rcl-language.md, "Units of
        measure"): the same unit, or none said in FRET.  Raises :class:`Refusal`."""
        if not v.unit or self.ports is None:
            return
        from rclverify.lang.units import UnitError, parse_unit  # deferred: start-up (only a FRET variable with a unit)
        port = f"{self.node}.{prefix}.{v.name}"
        try:
            fret = parse_unit(v.unit)
        except UnitError as exc:
            raise Refusal(f"{v.name}'s unit [{v.unit}] in FRET is not a unit rclverify reads ({exc.message})",
                          "write it as RCL writes units (m, m/s, rad/s^2, 1)") from None
        have = self.ports.units.get(self.node, {}).get(v.name)
        if have is None:
            raise Refusal(f"{v.name} is in [{v.unit}] in FRET but {port} declares no unit",
                          f"declare the unit on the port ({v.name} : ... [{v.unit}]) or correct it in FRET")
        try:
            same = parse_unit(have) == fret
        except UnitError:
            return  # the contract's own unit error, reported where the contracts are checked
        if not same:
            raise Refusal(f"{v.name} is in [{v.unit}] in FRET but {port} is in [{have}]",
                          f"make the units agree: write [{have}] in FRET, or declare [{v.unit}] on the port")


def _states(t: Translation, loc: ast.Loc) -> tuple[StateVar, ...]:
    def src(text: str) -> Source:
        return Source(text, loc.line, loc.col, loc.file)
    return tuple(StateVar(t.node, s.name, s.type_name, src(s.init), src(s.next), loc, loc) for s in t.states)


def import_export(exp: FretExport, options: Options, ports: Ports | None = None) -> list[Imported]:
    """Every requirement of ``exp`` as an :class:`Imported`, in file order
    (module docstring).  ``ports`` the contracts' nodes (``None``: names
    are not checked against them)."""
    out: list[Imported] = []
    used: set[str] = set()
    for fr in exp.requirements:
        node = options.components.get(fr.component, fr.component)
        informal = Requirement(fr.reqid, fr.fulltext, (), fr.loc, origin=exp.file)
        try:
            if not fr.semantics.timing:
                raise Refusal("FRET has not formalised it (no semantics in the export)",
                              "let FRET parse the requirement and export it again")
            if not node:
                raise Refusal("it names no component", "name the component in FRET")
            if ports is not None and node not in ports.nodes:
                known = ", ".join(sorted(ports.nodes)) or "none"
                raise Refusal(f"no node named {node} in the contracts (nodes: {known})",
                              f"map the component in the plan (fret: {{components: {{{fr.component}: Node}}}})")
            t = translate(fr.reqid, fr.fulltext, fr.semantics, node, _Places(exp, fr, node, ports, options.variables),
                          options.step, options.functions, fed=ports.fed.get(node, ()) if ports is not None else ())
        except Refusal as exc:
            out.append(Imported(fr, informal, (), exc))
            continue
        names_ = [s.name for s in t.states]
        if used.intersection(names_):  # two reqids with the same letters and digits: a distinct suffix
            k = 2
            while used.intersection(f"{n}_{k}" for n in names_):
                k += 1
            t = _renamed(t, k)
        used.update(s.name for s in t.states)
        req = Requirement(fr.reqid, fr.fulltext, (), fr.loc, Source(t.formal, fr.loc.line, fr.loc.col, exp.file),
                          origin=exp.file)
        out.append(Imported(fr, req, _states(t, fr.loc)))
    return out


def _renamed(t: Translation, k: int) -> Translation:
    from rclverify.model.plan.fret.translate import NewState  # deferred: start-up (only on a clash of names)
    pat = re.compile(r"\b(" + "|".join(re.escape(s.name) for s in t.states) + r")\b")
    def sub(text: str) -> str:
        return pat.sub(lambda m: f"{m.group(1)}_{k}", text)
    return Translation(sub(t.formal), t.node, [NewState(f"{s.name}_{k}", s.type_name, sub(s.init), sub(s.next))
                                               for s in t.states])


def read_fret(root: Path, rel: str, options: Options, contracts: tuple[str, ...] = ()) -> list[Imported]:
    """The export ``root/rel`` imported against the contract files
    ``contracts`` (workspace-relative; those that do not parse are left out:
    they are reported where they are checked).  Raises
    :class:`~rclverify.model.plan.errors.PlanError` for a malformed export."""
    from rclverify.lang.errors import RclError  # deferred: start-up (only a plan that reads FRET)
    from rclverify.lang.parser import parse_file  # deferred: start-up (loads lark only when called)
    specs = []
    for c in contracts:
        try:
            specs.append(parse_file(root / c))
        except RclError:
            continue
    return import_export(read_export(root / rel, rel), options, ports_of(specs) if contracts else None)


def options_of(data: PlanDocument | Mapping[str, Any]) -> Options:
    """The plan's ``fret:`` section as :class:`Options` (``data``: the plan's typed sections, or its
    schema-checked data); ``step`` a duration (``100 ms``)."""
    spec = (data if isinstance(data, PlanDocument) else plan_document(data)).fret or Fret()
    step = None
    if spec.step is not None:
        from rclverify.lang.timing import parse_duration  # deferred: start-up (only with fret: step:)
        step = parse_duration(spec.step)
    return Options(dict(spec.components), step, variables_of(spec), functions_of(spec))


def plan_additions(root: Path, doc: PlanDocument, contracts: tuple[str, ...]
                   ) -> tuple[list[Requirement], tuple[StateVar, ...]]:
    """The requirements and state declarations the plan's ``requirements_from: {fret: EXPORT.json}``
    adds (none without it; ``doc``: the plan's typed sections).  Raises
    :class:`~rclverify.model.plan.errors.PlanError` for a malformed export."""
    rel = doc.fret_export
    if not rel:
        return [], ()
    got = read_fret(root, rel, options_of(doc), contracts)
    return [i.requirement for i in got], tuple(s for i in got for s in i.states)
