"""Which RCL files ``rclverify check FILE...`` checks together.

The rule (docs/rcl-language.md, "Files and scopes"):

* When a verification plan is found, the files it lists under
  ``contracts:`` form one scope, the system, checked together as
  ``doit verify`` checks them.  A file the plan names as a node's
  ``replacement: FILE.rcl:Node`` is a contract offered in place of one of
  the system's: it declares its own context and its own node of the same
  name, so it is checked in a scope of its own (whether it may replace the
  original is the refinement check of ``doit verify``, not a name clash).
  Any other file given is checked alone.
* Without a plan, all the files given form one scope, as before: the files
  of one system may share the context one of them declares.

When the plan's system is given whole (every file of its ``contracts:``),
the plan itself is read and its statements checked against it
(:func:`plan_diagnostics`): requirement ids, ``formal:`` and
``assuming:`` statements, ``deadline:`` paths, ``supported_by``,
connections, environment facts and evidence entries' keys, the checks
``doit verify`` makes before it runs anything (docs/requirements.md).

The plan is ``WORKSPACE/PLAN`` (``-w``, ``--plan``; default
``./contracts/plan.yaml``) when that exists, else ``plan.yaml`` beside the
first file given that has one (its workspace root is then that folder's
parent, the layout ``rclverify init`` writes).  A plan that cannot be read
does not stop the check: the files are then checked as without a plan, and
the reason is returned as a note.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

from rclverify.lang.errors import RclError


@dataclass
class Scope:
    """Files checked together: ``files`` as given on the command line,
    ``why`` a short phrase for the terminal (``""`` for the only scope)."""

    files: list[str]
    why: str = ""


@dataclass
class Scopes:
    """The scopes of one ``check`` run, the plan they come from (its path as
    given, or ``None``) and notes to print (a plan that could not be read)."""

    scopes: list[Scope]
    plan: str | None = None
    notes: list[str] = field(default_factory=list)


def _key(path: Path) -> str:
    return os.path.normcase(os.path.realpath(path))


def find_plan(files: Sequence[str], workspace: str = ".", plan_rel: str = "contracts/plan.yaml") -> tuple[Path, str] | None:
    """``(workspace root, plan path relative to it)`` of the plan that
    groups ``files`` (see the module docstring), or ``None``."""
    root = Path(workspace)
    if (root / plan_rel).is_file():
        return root, plan_rel
    for f in files:
        here = Path(f).parent
        if (here / "plan.yaml").is_file():
            return here.parent, str(Path(here.name) / "plan.yaml")
    return None


def group_files(files: Sequence[str], workspace: str = ".", plan_rel: str = "contracts/plan.yaml") -> Scopes:
    """The scopes ``files`` are checked in (see the module docstring).
    Order: the plan's system first (files in the order given), then the
    others in the order given.  A file given twice is checked once."""
    files = list(dict.fromkeys(files))
    found = find_plan(files, workspace, plan_rel)
    if found is None:
        return Scopes([Scope(files)])
    root, rel = found
    from rclverify.model.plan.load import read_plan_document  # deferred: start-up (loads yaml, rclverify.lang.ast and more only when called)
    shown = str(root / rel)
    try:
        doc, _ = read_plan_document(root, rel)
    except RclError as exc:
        why = exc.diagnostics[0].message if exc.diagnostics else "cannot read it"
        return Scopes([Scope(files)], None, [f"{shown}: note: files checked together, as without a plan: "
                                             f"the plan cannot be read ({why})"])
    system = {_key(root / c) for c in doc.contracts}
    replaced: dict[str, str] = {}
    for node, spec in (doc.nodes or {}).items():
        if spec.replacement is not None:
            replaced[_key(root / spec.replacement.rpartition(":")[0])] = node
    together = [f for f in files if _key(Path(f)) in system]
    scopes = [Scope(together, "the plan's system")] if together else []
    for f in files:
        k = _key(Path(f))
        if k in system:
            continue
        if k in replaced:
            scopes.append(Scope([f], f"the plan's replacement for {replaced[k]}, checked in its own scope"))
        else:
            scopes.append(Scope([f], "not in the plan's contracts, checked alone"))
    return Scopes(scopes, shown)


def plan_diagnostics(files: Sequence[str], checked: object, workspace: str = ".",
                     plan_rel: str = "contracts/plan.yaml",
                     entries: Callable[[Any, Any], list[Any]] | None = None) -> tuple[list[object], str]:
    """The located errors of the plan that groups ``files`` (see
    :func:`find_plan`), read and resolved against ``checked``, the checked
    system of ``files`` (:func:`rclverify.model.plan.load.resolve`: every
    statement of the plan that names the contracts).  Returns
    ``(diagnostics, note)``: ``note`` is ``""`` when the plan was checked,
    else why not (no plan, or ``files`` are not the plan's whole system, so
    its node names could not be checked).  ``entries(plan, checked)``, when
    given, adds the diagnostics of the plan's evidence entries (the
    backends' check-time validation, a layer above this one)."""
    found = find_plan(files, workspace, plan_rel)
    if found is None:
        return [], ""
    root, rel = found
    from rclverify.model.plan.load import load_plan, read_plan_document, resolve  # deferred: start-up (loads yaml, rclverify.lang.ast and more only when called)
    try:
        doc, _ = read_plan_document(root, rel)
    except RclError:
        return [], ""  # group_files said so already
    system = {_key(root / c) for c in doc.contracts}
    given = {_key(Path(f)) for f in files}
    if not system or not system <= given:
        return [], (f"{root / rel}: note: the plan's statements are checked when every file of its contracts: "
                    "is given")
    try:
        plan = load_plan(root, rel)
        resolve(plan, checked)  # type: ignore[arg-type]
    except RclError as exc:
        return list(exc.diagnostics), ""
    return (list(entries(plan, checked)) if entries is not None else []), ""
