"""A FRET export read: its requirements and variables, each with its place in the file.

FRET (NASA's Formal Requirements Elicitation Tool) exports a project as
JSON: either an object ``{"requirements": [...], "variables": [...]}``
(requirements and variables) or a list of requirements.  Each requirement
has ``reqid``, ``fulltext``, and, once FRET has formalised it,
``semantics`` (``scope``, ``condition``, ``timing``, ``response``, the
conditions ``pre_condition``/``regular_condition``/``post_condition``/
``stop_condition``, ``duration``, ``scope_mode``, ``component_name``, and
FRET's formalisations ``ptExpanded``/``ftInfAUExpanded``).  A variable
has ``component_name``, ``variable_name``, ``idType`` (``Input``,
``Output``, ``Internal``, ``Mode``, ``Function``), ``dataType``
(``boolean``, ``integer``, ``double`` ...) and, for an Internal one, its
Lustre ``assignment``.  Entries of the variables list without ``idType``
(the ports of an imported model) are not FRET variables and are left out.

Each requirement's fields and each variable's are decoded once into
:class:`FretSemantics` and :class:`FretVariableEntry` (msgspec Structs: the
fields rclverify reads, typed; FRET's other fields ignored) and read by
attribute after.  A file that is not JSON, or whose shape is not the above
(a requirement without a ``reqid`` string, a ``reqid`` used twice, a field of
another type than FRET writes), is a malformed export:
:class:`~rclverify.model.plan.errors.PlanError` at its line and column.
"""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, TypeVar

import msgspec

from rclverify.lang import ast
from rclverify.model.plan.errors import PlanError, plan_error


#: A unit in brackets at the end of a variable's description.
_DESCRIBED_UNIT = re.compile(r"\[([^\[\]]+)\]\s*$")


class FretScope(msgspec.Struct, frozen=True, kw_only=True):
    """A requirement's ``semantics.scope``: its ``type`` (``null``, ``in``, ``before``, ``after`` ...)."""

    type: str = "null"


class FretSemantics(msgspec.Struct, frozen=True, kw_only=True):
    """What FRET formalised of a requirement (its export's ``semantics``; every field ``None`` when FRET did
    not formalise it): the ``scope``, ``condition`` (``null``, ``regular``, ``noTrigger`` ...), ``timing``
    (``always``, ``within`` ...), ``response`` (``satisfaction``), the FRETish conditions (``pre_condition``,
    ``regular_condition``, ``post_condition``, ``stop_condition``), the ``duration`` (a number, or a list
    whose first item is one), the mode of an ``in`` scope (``scope_mode``), the component
    (``component_name``, older exports ``component``) and FRET's past-time formula ``ptExpanded``."""

    scope: FretScope | None = None
    condition: str | None = None
    timing: str | None = None
    response: str | None = None
    pre_condition: str | None = None
    regular_condition: str | None = None
    post_condition: str | None = None
    stop_condition: str | None = None
    duration: str | int | float | list[str | int | float] | None = None
    scope_mode: str | None = None
    component_name: str | None = None
    component: str | None = None
    ptExpanded: str | None = None


class _RequirementEntry(msgspec.Struct, frozen=True, kw_only=True):
    """The fields of a requirement of the export rclverify reads besides ``reqid`` (checked first)."""

    fulltext: str | None = None
    component_name: str | None = None
    semantics: FretSemantics | None = None

    def component(self) -> str:
        """FRET's component of the requirement: its semantics' ``component_name``, else the requirement's
        own, else the semantics' ``component`` (older exports); ``""`` when none is named."""
        sem = self.semantics or FretSemantics()
        return sem.component_name or self.component_name or sem.component or ""


def component_of(raw: Mapping[str, Any]) -> str:
    """The component a requirement's JSON object ``raw`` names (:meth:`_RequirementEntry.component`);
    ``""`` when a field of it is of another type than FRET writes (:func:`read_export` refuses such an
    export)."""
    try:
        return msgspec.convert(raw, _RequirementEntry).component()
    except msgspec.ValidationError:
        return ""


class FretVariableEntry(msgspec.Struct, frozen=True, kw_only=True):
    """A FRET variable as exported (the fields rclverify reads): ``variable_name``, ``component_name``,
    ``idType``, ``dataType`` (a name, or a list whose first item is one), ``assignment``,
    ``modeRequirement``, ``unit`` and ``description``."""

    variable_name: str
    component_name: str | None = None
    idType: str | None = None
    dataType: str | list[str] | None = None
    assignment: str | None = None
    modeRequirement: str | None = None
    unit: str | None = None
    description: str | None = None


@dataclass(frozen=True)
class FretRequirement:
    """One requirement of an export: ``reqid``, ``fulltext``, FRET's
    ``component`` name, its ``semantics`` as exported (empty: FRET did not
    formalise it), ``loc`` where its ``reqid`` is written and ``digest``
    the sha256 of its JSON (keys sorted): what a re-import compares."""

    reqid: str
    fulltext: str
    component: str
    semantics: FretSemantics
    loc: ast.Loc
    digest: str
    raw: Mapping[str, Any]


@dataclass(frozen=True)
class FretVariable:
    """A FRET variable of ``component``: ``name``, ``id_type``, ``data_type``, ``assignment`` (an
    Internal one's Lustre definition), ``mode_requirement`` (a Mode's FRETish definition) and ``unit``
    (its unit of measure, ``m/s``; ``""`` when none is said): the variable's ``unit`` field, else a unit
    written in brackets at the end of its ``description`` (``distance to the obstacle [m]``), FRET's
    variables having no field of their own for it."""

    component: str
    name: str
    id_type: str
    data_type: str
    assignment: str
    mode_requirement: str = ""
    unit: str = ""


@dataclass(frozen=True)
class FretExport:
    """An export's ``requirements`` in file order and ``variables`` by ``(component, name)``."""

    file: str
    requirements: tuple[FretRequirement, ...]
    variables: Mapping[tuple[str, str], FretVariable]


def _line_col(text: str, pos: int) -> tuple[int, int]:
    line = text.count("\n", 0, pos) + 1
    return line, pos - (text.rfind("\n", 0, pos) + 1) + 1


def _data_type(v: str | list[str] | None) -> str:
    if isinstance(v, list):
        v = v[0] if v else ""
    return str(v or "")


def _unit(v: FretVariableEntry) -> str:
    """A variable's unit (:class:`FretVariable`), blanks removed."""
    u = v.unit
    if u is None or not u.strip():
        m = _DESCRIBED_UNIT.search(v.description or "")
        u = m.group(1) if m else ""
    return "".join(u.split())


_S = TypeVar("_S", bound=msgspec.Struct)


def _decoded(rel: str, text: str, at: int, what: str, raw: Any, type_: type[_S]) -> _S:
    """``raw`` (a requirement's or variable's JSON object) as ``type_``; raises :class:`PlanError`
    (``E-fret``) at offset ``at`` of ``text`` naming ``what`` and the field of another type."""
    try:
        return msgspec.convert(raw, type_)
    except msgspec.ValidationError as exc:
        raise plan_error(rel, *_line_col(text, at), f"{what} of the FRET export: {exc}", "E-fret") from None


def digest(raw: Mapping[str, Any]) -> str:
    """sha256 of a requirement's JSON with its keys sorted (the identity of its content)."""
    return hashlib.sha256(json.dumps(raw, sort_keys=True, ensure_ascii=False).encode("utf-8")).hexdigest()


def read_export(path: Path, rel: str) -> FretExport:
    """The export at ``path`` (``rel`` its name in messages).  Raises
    :class:`PlanError` (``E-fret``, located) for a malformed export,
    ``E-io`` when it cannot be read."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise plan_error(rel, 1, 1, f"cannot read the FRET export: {getattr(exc, 'strerror', None) or exc}",
                         "E-io") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise plan_error(rel, exc.lineno, exc.colno, f"the FRET export is not JSON: {exc.msg}", "E-fret") from None
    vars_raw: Any
    if isinstance(data, list):
        reqs_raw, vars_raw = data, []
    elif isinstance(data, dict) and isinstance(data.get("requirements"), list):
        reqs_raw, vars_raw = data["requirements"], data.get("variables") or []
    else:
        raise plan_error(rel, 1, 1, "a FRET export is a list of requirements or an object with a 'requirements' "
                                    "list (FRET: Export, requirements and variables)", "E-fret")
    if not isinstance(vars_raw, list):
        raise plan_error(rel, 1, 1, "the FRET export's 'variables' must be a list", "E-fret")
    out: list[FretRequirement] = []
    seen: dict[str, ast.Loc] = {}
    pos = 0
    for k, r in enumerate(reqs_raw):
        if not isinstance(r, dict) or not isinstance(r.get("reqid"), str) or not r["reqid"].strip():
            raise plan_error(rel, *_line_col(text, pos), f"requirement {k + 1} of the FRET export has no 'reqid' "
                                                         "string", "E-fret")
        rid = r["reqid"]
        at = text.find(f'"reqid"', pos)
        at = text.find(json.dumps(rid, ensure_ascii=False), at + len('"reqid"')) if at >= 0 else -1
        if at >= 0:
            pos = at
        loc = ast.Loc(rel, *_line_col(text, max(at, 0)))
        if rid in seen:
            o = seen[rid]
            raise plan_error(rel, loc.line, loc.col, f"reqid {rid!r} is used twice in the FRET export (first at "
                                                     f"{o.line}:{o.col})", "E-fret")
        seen[rid] = loc
        if r.get("semantics") is not None and not isinstance(r["semantics"], dict):
            raise plan_error(rel, loc.line, loc.col, f"{rid}: 'semantics' must be an object", "E-fret")
        e = _decoded(rel, text, max(at, 0), f"requirement {rid}", r, _RequirementEntry)
        sem = e.semantics or FretSemantics()
        out.append(FretRequirement(rid, " ".join((e.fulltext or "").split()), e.component(), sem, loc, digest(r), r))
    variables: dict[tuple[str, str], FretVariable] = {}
    for v in vars_raw:
        if isinstance(v, dict) and "idType" in v and isinstance(v.get("variable_name"), str):
            name = json.dumps(v["variable_name"], ensure_ascii=False)
            ve = _decoded(rel, text, max(text.find(name), 0), f"variable {name}", v, FretVariableEntry)
            fv = FretVariable(ve.component_name or "", ve.variable_name, ve.idType or "", _data_type(ve.dataType),
                              ve.assignment or "", ve.modeRequirement or "", _unit(ve))
            variables[(fv.component, fv.name)] = fv
    return FretExport(rel, tuple(out), variables)


def malformed(exc: PlanError) -> str:
    """The first message of a :class:`PlanError` as ``file:line:col: error: message``."""
    d = exc.diagnostics[0]
    return f"{d.loc.file}:{d.loc.line}:{d.loc.col}: error: {d.message}"
