"""Standard profiles: a safety standard's clauses or technique-table items as data (docs/standards.md).

A profile is a YAML file checked against ``profile.schema.json`` (JSON Schema
draft 2020-12, the way the plan is checked, model/plan/load.py) and then for
what a schema cannot say: item ids unique, and a per-level recommendation
naming exactly the profile's levels.  The built-in profiles live in
``profiles/`` inside the package; a user's profile is any file of the same
shape.  Every mistake is one :class:`~rclverify.model.plan.errors.PlanError`
at ``file:line:col``.  A profile's ids and titles are a traceability aid,
never the standard's text.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import yaml

from rclverify.lang import ast
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import Path_, load_located, read_yaml_text, schema_error_loc

#: The recommendation codes, strongest first (IEC 61508-3's: highly recommended, recommended, no
#: recommendation, not recommended).
CODES: tuple[str, ...] = ("HR", "R", "---", "NR")
#: Where the built-in profiles are named in messages (package-relative, never a machine path).
BUILTIN_DIR = "rclverify/model/plan/standards/profiles"


@dataclass(frozen=True)
class Item:
    """One clause or technique of a profile: ``evidence`` the evidence kinds
    that can support it, ``strength`` the least strength it asks
    (docs/confidence.md's words), ``recommendation`` one code for every
    level or level -> code."""
    id: str
    title: str
    evidence: tuple[str, ...]
    strength: str
    recommendation: str | Mapping[str, str]

    def at(self, level: str | None) -> str:
        """The recommendation code at ``level`` (``None``: a profile without levels)."""
        if isinstance(self.recommendation, str):
            return self.recommendation
        return self.recommendation.get(str(level), "---")


@dataclass(frozen=True)
class Profile:
    """A loaded profile: ``levels`` empty when the standard has none,
    ``level_name`` the plan key that names the level (``sil``, ``dal``...),
    ``file`` where it was read (package-relative for the built-ins)."""
    id: str
    title: str
    edition: str
    level_name: str
    levels: tuple[str, ...]
    items: tuple[Item, ...]
    file: str


def builtin_names() -> tuple[str, ...]:
    """The ids of the built-in profiles, sorted (the stems of ``profiles/*.yaml``)."""
    folder = resources.files("rclverify.model.plan.standards").joinpath("profiles")
    return tuple(sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".yaml")))


def load_builtin(name: str) -> Profile:
    """The built-in profile ``name`` (one of :func:`builtin_names`).

    Raises ``KeyError`` for an unknown name and :class:`PlanError` for a
    malformed file (a bug of the package, tested)."""
    if name not in builtin_names():
        raise KeyError(name)
    res = resources.files("rclverify.model.plan.standards").joinpath("profiles", f"{name}.yaml")
    return parse_profile(res.read_text(encoding="utf-8"), f"{BUILTIN_DIR}/{name}.yaml")


def load_profile_file(path: Path, file: str) -> Profile:
    """The profile in the YAML file at ``path`` (named ``file`` in messages).
    Raises :class:`PlanError` (unreadable, bad YAML, schema, the checks of
    the module docstring)."""
    return parse_profile(read_yaml_text(path, file), file)


def _schema() -> dict[str, Any]:
    text = resources.files("rclverify.model.plan.standards").joinpath("profile.schema.json").read_text(encoding="utf-8")
    return json.loads(text)  # type: ignore[no-any-return]


def _at(locs: Mapping[Path_, ast.Loc], path: Path_, file: str) -> ast.Loc:
    """The location of ``path``, or of its nearest written ancestor."""
    while path and path not in locs:
        path = path[:-1]
    return locs.get(path, ast.Loc(file, 1, 1))


def _bad(locs: Mapping[Path_, ast.Loc], path: Path_, file: str, message: str) -> PlanError:
    l = _at(locs, path, file)
    return plan_error(l.file, l.line, l.col, message, "E-profile")


def _check_schema(data: object, locs: Mapping[Path_, ast.Loc], file: str) -> None:
    """Raise one located :class:`PlanError` for the first schema violation (by path)."""
    import jsonschema  # deferred: start-up (loads jsonschema only when a profile is read)
    errors = sorted(jsonschema.Draft202012Validator(_schema()).iter_errors(data),
                    key=lambda e: list(map(str, e.absolute_path)))
    if errors:
        e = errors[0]
        l = schema_error_loc(e, locs, file)
        where = ".".join(map(str, e.absolute_path)) or "profile"
        raise plan_error(l.file, l.line, l.col, f"standard profile: {where}: {e.message}", "E-profile")


def parse_profile(text: str, file: str) -> Profile:
    """The profile written in the YAML ``text`` of ``file``.

    Raises :class:`PlanError` at ``file:line:col``: malformed YAML (the
    YAML library's mark), a schema violation, an item id used twice, or a
    per-level recommendation whose levels are not the profile's ``levels``."""
    try:
        data, locs = load_located(text, file)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise plan_error(file, line, col, f"invalid YAML: {getattr(exc, 'problem', exc)}", "E-yaml") from None
    _check_schema(data, locs, file)
    assert isinstance(data, dict)
    levels = tuple(str(x) for x in data.get("levels", []))
    items: list[Item] = []
    seen: dict[str, int] = {}
    for i, it in enumerate(data["items"]):
        iid = str(it["id"])
        if iid in seen:
            raise _bad(locs, ("items", i, "id"), file, f"standard profile: item id {iid!r} is used twice "
                       f"(first at line {_at(locs, ('items', seen[iid], 'id'), file).line})")
        seen[iid] = i
        rec = it["recommendation"]
        if isinstance(rec, dict):
            rec = {str(k): str(v) for k, v in rec.items()}
            if set(rec) != set(levels):
                raise _bad(locs, ("items", i, "recommendation"), file,
                           f"standard profile: item {iid!r}: the recommendation names levels "
                           f"{', '.join(sorted(rec)) or 'none'}; the profile's levels are "
                           f"{', '.join(levels) or 'none (write one code)'}")
        items.append(Item(iid, str(it["title"]), tuple(it["evidence"]), str(it["strength"]), rec))
    return Profile(str(data["id"]), str(data["title"]), str(data["edition"]), str(data.get("level_name", "level")),
                   levels, tuple(items), file)


__all__ = ["BUILTIN_DIR", "CODES", "Item", "Profile", "builtin_names", "load_builtin", "load_profile_file",
           "parse_profile"]
