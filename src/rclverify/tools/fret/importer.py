"""``rclverify import fret EXPORT.json``: a FRET export brought into the workspace, kept in step by ``reqid``.

The workspace keeps its own copy of the export, the one the plan reads
(``requirements_from: {fret: PATH}``; default ``fret/<export's name>``):
the fields rclverify reads of each requirement and variable (FRET's format,
so FRET reads it back), requirements in ``reqid`` order, written by the one
atomic writer (:mod:`rclverify.core.atomic`).  An import compares the new
export with that copy by ``reqid``: *added*, *changed* (any field read,
FRET's formalisations included, differs) and *removed* requirements are
reported, the rest is *unchanged*; importing the same export again writes
nothing.  The plan's own requirements are never touched: the import adds
only the ``requirements_from: fret:`` line when the plan has none.

Each requirement that cannot be translated is reported at its place,
``EXPORT.json:reqid: reason; what would make it importable``, and stays
in the plan as an informal requirement (docs/requirements.md,
"Requirements from FRET").
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import jinja2

from rclverify.core.atomic import atomic_write_text
from rclverify.model.plan.errors import plan_error
from rclverify.model.plan.fret.export import FretExport, digest, read_export
from rclverify.model.plan.fret.requirements import Imported, import_export, options_of, ports_of

#: The fields of a requirement, of its semantics and of a variable that the workspace's copy keeps.
REQUIREMENT_KEYS = ("reqid", "parent_reqid", "project", "rationale", "comments", "fulltext", "status")
SEMANTICS_KEYS = ("type", "scope", "condition", "timing", "response", "variables", "component", "component_name",
                  "pre_condition", "regular_condition", "post_condition", "stop_condition", "duration",
                  "scope_mode", "qualifier_word", "ptExpanded", "ftInfAUExpanded", "ftExpanded")
VARIABLE_KEYS = ("project", "component_name", "variable_name", "idType", "dataType", "assignment",
                 "modeRequirement", "description", "unit")


@dataclass
class ImportResult:
    """What an import did: the copy's ``dest`` (workspace-relative), the
    reqids ``added``/``changed``/``removed``/``unchanged``, each requirement
    as ``imported``, whether the copy and the plan were ``written``/``plan_edited``."""

    source: str
    dest: str
    imported: list[Imported]
    added: list[str] = field(default_factory=list)
    changed: list[str] = field(default_factory=list)
    removed: list[str] = field(default_factory=list)
    unchanged: list[str] = field(default_factory=list)
    written: bool = False
    plan_edited: bool = False


def normalised(data: Any) -> dict[str, Any]:
    """The workspace's copy of export ``data`` (module docstring): FRET's format, the fields read, sorted."""
    reqs = data if isinstance(data, list) else data.get("requirements", [])
    vars_ = [] if isinstance(data, list) else data.get("variables") or []
    out_reqs = []
    for r in sorted(reqs, key=lambda r: str(r.get("reqid"))):
        kept = {k: r[k] for k in REQUIREMENT_KEYS if k in r}
        sem = r.get("semantics")
        if isinstance(sem, dict):
            kept["semantics"] = {k: sem[k] for k in SEMANTICS_KEYS if k in sem}
        out_reqs.append(kept)
    out_vars = [{k: v[k] for k in VARIABLE_KEYS if k in v} for v in vars_ if isinstance(v, dict) and "idType" in v]
    out_vars.sort(key=lambda v: (str(v.get("component_name")), str(v.get("variable_name"))))
    return {"requirements": out_reqs, "variables": out_vars}


def _digests(reqs: list[Mapping[str, Any]]) -> dict[str, str]:
    return {str(r["reqid"]): digest(r) for r in reqs}


def _plan_with_fret(text: str, dest: str) -> str | None:
    """The plan's text with ``requirements_from: {fret: dest}`` added, or ``None`` when its
    ``requirements_from:`` is written in a way a line cannot be added to (flow style)."""
    lines = text.splitlines(keepends=True)
    for k, line in enumerate(lines):
        if re.match(r"requirements_from\s*:\s*(#.*)?$", line.rstrip("\n")):
            nxt = next((l for l in lines[k + 1:] if l.strip() and not l.lstrip().startswith("#")), "")
            indent = re.match(r"\s*", nxt).group(0) if nxt[:1] in (" ", "\t") else "  "  # type: ignore[union-attr]
            lines.insert(k + 1, f"{indent}fret: {dest}\n")
            return "".join(lines)
        if line.startswith("requirements_from"):
            return None
    sep = "" if not text or text.endswith("\n") else "\n"
    return f"{text}{sep}\n# Requirements imported from FRET (rclverify import fret)\nrequirements_from:\n  fret: {dest}\n"


def import_fret(root: Path, plan_rel: str, export: Path, shown: str) -> ImportResult:
    """Import ``export`` (``shown`` its name in messages) into the workspace
    ``root`` whose plan is ``plan_rel`` (module docstring).  Raises
    :class:`~rclverify.model.plan.errors.PlanError` for a malformed export
    or a plan that cannot be read or edited, ``OSError`` when a file cannot
    be written."""
    from rclverify.lang.errors import RclError  # deferred: start-up (loads rclverify.lang only when called)
    from rclverify.lang.parser import parse_file  # deferred: start-up (loads lark only when called)
    from rclverify.model.plan.load import read_plan_document  # deferred: start-up (loads yaml only when called)
    exp = read_export(export, shown)  # a malformed export stops here, before anything is written
    doc, _ = read_plan_document(root, plan_rel)
    dest = doc.fret_export or f"fret/{export.name}"
    raw = json.loads(export.read_text(encoding="utf-8-sig"))
    new = normalised(raw)
    target = root / dest
    old: dict[str, str] = {}
    if target.is_file() and target.resolve() != export.resolve():
        try:
            old = _digests(normalised(json.loads(target.read_text(encoding="utf-8-sig")))["requirements"])
        except (json.JSONDecodeError, AttributeError, TypeError, UnicodeDecodeError):
            old = {}  # a copy that no longer reads: every requirement counts as added
    elif target.is_file():
        old = _digests(new["requirements"])
    now = _digests(new["requirements"])
    res = ImportResult(shown, dest, [])
    res.added = [r for r in now if r not in old]
    res.changed = [r for r in now if r in old and old[r] != now[r]]
    res.removed = [r for r in old if r not in now]
    res.unchanged = [r for r in now if old.get(r) == now[r]]
    plan_path, edited = root / plan_rel, None
    if not doc.fret_export:  # decided before anything is written
        edited = _plan_with_fret(plan_path.read_text(encoding="utf-8"), dest)
        if edited is None:
            raise plan_error(plan_rel, 1, 1, f"requirements_from is written in flow style: add 'fret: {dest}' to it "
                                             "to read the imported requirements", "E-plan")
    if target.resolve() != export.resolve():
        res.written = atomic_write_text(target, json.dumps(new, indent=1, ensure_ascii=False) + "\n", within=root)
    if edited is not None:
        res.plan_edited = atomic_write_text(plan_path, edited, within=root)
    specs = []
    for c in doc.contracts:
        try:
            specs.append(parse_file(root / c))
        except RclError:
            continue
    copy = read_export(target, dest)
    res.imported = import_export(FretExport(shown, copy.requirements, copy.variables), options_of(doc),
                                 ports_of(specs))
    return res


def _env() -> jinja2.Environment:
    return jinja2.Environment(loader=jinja2.PackageLoader("rclverify.tools.fret", "templates"),
                              undefined=jinja2.StrictUndefined, keep_trailing_newline=True, trim_blocks=True,
                              lstrip_blocks=True, autoescape=False)


def render(res: ImportResult) -> str:
    """The import's report (``templates/import.txt.j2``): one line per requirement not imported, then
    what changed and the counts."""
    refused = [i for i in res.imported if i.refusal is not None]
    return _env().get_template("import.txt.j2").render(r=res, refused=refused,
                                                       decided=len(res.imported) - len(refused))
