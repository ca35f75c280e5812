"""The one registry of backends, and each backend's declaration read from its own folder.

A backend declares itself once, as data, in ``declaration.yaml`` beside its code
(``rclverify/backends/<folder>/declaration.yaml``; docs/backends.md, "Declaring a
backend", gives the format): its name, the class that implements it, the kind of
evidence it produces and how strong that evidence is, whether it owes one obligation
per node or per guarantee, its plan entry's schema, and the tools it runs.  Every
place that needs one of these reads it here: the plan's entry schema
(:mod:`.entries`) and the ``expected`` check (:mod:`.expected`), the registry of
implementations (:mod:`rclverify.backends`), the evidence tasks' tool fingerprint,
the report's columns and problems, the GSN argument's strength and the bundle's tool
versions.  Adding a backend touches its own folder and :data:`REGISTRY`.

The declarations are read as files, not imported: the plan sits below the
backends (docs/architecture.md) and validates an entry without loading any
backend's code.  A malformed declaration is a fault of rclverify, not of a user's
input: :class:`DeclarationError` names the file and what is wrong, at load; an
evidence kind the report's schema does not declare, or a strength not among
:data:`STRENGTHS`, is one.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from rclverify.records.statuses import EVIDENCE_KINDS

#: The backends, in the order the report's columns and the plan's messages list them:
#: name -> its folder under ``rclverify/backends`` (which holds ``declaration.yaml``).
REGISTRY: Mapping[str, str] = {
    "hoare": "hoare",
    "dafny": "dafny",
    "ajpf": "model_checking/ajpf",
    "property_tests": "property_tests",
    "monitors": "monitors",
    "experiment": "experiment",
    "review": "review",
}

#: The strengths of evidence, strongest first (report/argument/strength.py ranks and weighs them).
STRENGTHS = ("proof", "bounded", "statistical", "tested", "observed", "reviewed", "assumed")


class DeclarationError(ValueError):
    """A backend's ``declaration.yaml`` that does not follow the format (the message names the file)."""


@dataclass(frozen=True)
class Tool:
    """An outside tool a backend runs: ``name`` as recorded; found by ``which`` (a command on
    ``PATH``) or ``env`` (the first of these environment variables that is set); ``version``,
    when given, ``"module:function"`` returning the installed version's text."""

    name: str
    which: str | None = None
    env: tuple[str, ...] = ()
    version: str | None = None


@dataclass(frozen=True)
class PlanEntry:
    """A backend's plan-entry schema (model/plan/entries.py gives each field's meaning)."""

    keys: tuple[str, ...]
    path_keys: frozenset[str] = frozenset()
    tool_keys: frozenset[str] = frozenset()
    qualified_keys: frozenset[str] = frozenset()
    #: tool key -> ``executable`` or ``directory``: what a value written as a path must name
    tool_paths: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Declaration:
    """One backend's declaration (module docstring)."""

    name: str
    folder: str
    #: ``"module:Class"`` of the :class:`rclverify.backends.base.Backend` implementation
    implementation: str
    #: :attr:`rclverify.records.records.Obligation.kind` of its obligations
    evidence_kind: str
    #: one of :data:`STRENGTHS`: how strong its discharged evidence is
    strength: str
    #: one obligation per node for the whole contract (guarantee ``0``), not one per guarantee
    whole_contract: bool
    plan: PlanEntry
    tools: tuple[Tool, ...] = ()
    #: the fixed sentence the GSN argument gives for its strength, when the strength alone does not say
    strength_detail: str | None = None


_TOP = {"name", "implementation", "evidence_kind", "strength", "strength_detail", "whole_contract", "plan", "tools"}
_PLAN = {"keys", "path_keys", "tool_keys", "qualified_keys", "tool_paths"}
_TOOL = {"name", "which", "env", "version"}


def _strings(raw: Any, where: str) -> tuple[str, ...]:
    if not isinstance(raw, list) or not all(isinstance(x, str) for x in raw):
        raise DeclarationError(f"{where} must be a list of strings")
    return tuple(raw)


def _only(raw: Any, allowed: set[str], where: str) -> Mapping[str, Any]:
    if not isinstance(raw, dict):
        raise DeclarationError(f"{where} must be a mapping")
    extra = sorted(set(raw) - allowed)
    if extra:
        raise DeclarationError(f"{where}: unknown key(s) {', '.join(extra)}; allowed: {', '.join(sorted(allowed))}")
    return raw


def _plan(raw: Any, where: str) -> PlanEntry:
    p = _only(raw, _PLAN, f"{where} plan")
    keys = _strings(p.get("keys"), f"{where} plan.keys")
    sets = {k: frozenset(_strings(p.get(k, []), f"{where} plan.{k}")) for k in ("path_keys", "tool_keys",
                                                                                  "qualified_keys")}
    paths = p.get("tool_paths", {})
    if not isinstance(paths, dict) or not all(v in ("executable", "directory") for v in paths.values()):
        raise DeclarationError(f"{where} plan.tool_paths must map tool keys to executable or directory")
    for k, vs in (*sets.items(), ("tool_paths", frozenset(paths))):
        if not vs <= set(keys):
            raise DeclarationError(f"{where} plan.{k} names keys not in plan.keys: {', '.join(sorted(vs - set(keys)))}")
    if not sets["qualified_keys"] <= sets["path_keys"] or not set(paths) <= sets["tool_keys"]:
        raise DeclarationError(f"{where} plan: qualified_keys must be path_keys and tool_paths tool_keys")
    return PlanEntry(keys, sets["path_keys"], sets["tool_keys"], sets["qualified_keys"], dict(paths))


def _tool(raw: Any, where: str) -> Tool:
    t = _only(raw, _TOOL, f"{where} tools[]")
    if not isinstance(t.get("name"), str) or ("which" in t) == ("env" in t):
        raise DeclarationError(f"{where} tools[]: a name and exactly one of which, env")
    return Tool(t["name"], t.get("which"), _strings(t["env"], f"{where} tools[].env") if "env" in t else (),
                t.get("version"))


def parse(text: str, name: str, folder: str) -> Declaration:
    """The declaration in ``text`` (YAML) of backend ``name`` in ``folder``.
    Raises :class:`DeclarationError` naming ``folder``'s file and the fault."""
    where = f"rclverify/backends/{folder}/declaration.yaml"
    import yaml  # deferred: start-up (a warm start of the monitor command reads the declarations from its start-up cache)
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # PyYAML's safe loader, libyaml's when PyYAML has it
    try:
        raw = _only(yaml.load(text, Loader=loader), _TOP, where)  # noqa: S506 - a safe loader
    except yaml.YAMLError as exc:
        raise DeclarationError(f"{where}: not YAML: {exc}") from None
    if raw.get("name") != name:
        raise DeclarationError(f"{where}: name {raw.get('name')!r}, but the registry calls it {name!r}")
    for k in ("implementation", "evidence_kind", "strength"):
        if not isinstance(raw.get(k), str) or not raw[k]:
            raise DeclarationError(f"{where}: {k} must be a non-empty string")
    if raw["strength"] not in STRENGTHS:
        raise DeclarationError(f"{where}: strength {raw['strength']!r} is none of {', '.join(STRENGTHS)}")
    if raw["evidence_kind"] not in EVIDENCE_KINDS:  # the report's schema declares these kinds and no other
        raise DeclarationError(f"{where}: evidence_kind {raw['evidence_kind']!r} is none of "
                               f"{', '.join(EVIDENCE_KINDS)} (records/statuses.py, the report's schema)")
    if ":" not in raw["implementation"] or not isinstance(raw.get("whole_contract"), bool):
        raise DeclarationError(f"{where}: implementation is module:Class and whole_contract true or false")
    tools = raw.get("tools", [])
    if not isinstance(tools, list):
        raise DeclarationError(f"{where}: tools must be a list")
    return Declaration(name, folder, raw["implementation"], raw["evidence_kind"], raw["strength"],
                       raw["whole_contract"], _plan(raw.get("plan"), where), tuple(_tool(t, where) for t in tools),
                       raw.get("strength_detail"))


def _read_all() -> dict[str, Declaration]:
    # the package's folder, as core/cache/keys.py's code_stamp reads it: importlib.resources, and the zipfile,
    # tempfile and threading it loads, cost every start of the command about 5 ms for files that are on disk
    # (kept by the monitor command's start-up cache, core/cache/startup.py: its warm start neither imports PyYAML
    # nor parses them; any other process parses them)
    from rclverify.core.cache.startup import read_kept  # deferred: start-up (imported where it is used)
    base = Path(__file__).resolve().parents[2] / "backends"
    out = {}
    for name, folder in REGISTRY.items():
        text = base.joinpath(*folder.split("/"), "declaration.yaml").read_text(encoding="utf-8")
        out[name] = read_kept(f"declaration {name} {folder}", text, lambda t: parse(t, name, folder))
    return out


def declared_in(module_file: str) -> Declaration:
    """The declaration of the backend whose folder holds ``module_file`` (a module's ``__file__``):
    how a backend's own code reads its name and kind.  Raises ``KeyError`` outside every folder."""
    parts = Path(module_file).resolve().parent.parts
    for d in DECLARATIONS.values():
        tail = ("backends", *d.folder.split("/"))
        if parts[-len(tail):] == tail:
            return d
    raise KeyError(module_file)


#: Backend name -> its declaration, in :data:`REGISTRY` order.
DECLARATIONS: Mapping[str, Declaration] = _read_all()

#: The backends a plan may name, in registry order.
BACKEND_NAMES: tuple[str, ...] = tuple(DECLARATIONS)

__all__ = ["BACKEND_NAMES", "DECLARATIONS", "Declaration", "DeclarationError", "PlanEntry", "REGISTRY", "STRENGTHS",
           "Tool", "declared_in", "parse"]
