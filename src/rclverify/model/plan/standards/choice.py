"""The plan's ``standards:`` entries: which profiles the evidence is mapped onto, at which level.

An entry is ``{profile: NAME, <level key>: LEVEL, strict: BOOL}``: ``NAME`` a built-in
profile (:func:`.profiles.builtin_names`) or a workspace-relative YAML file of
the same shape (``*.yaml``/``*.yml``); the level key is the profile's
``level_name`` (``sil``, ``dal``, ``pl``) or ``level``, absent for a profile
without levels; ``strict: true`` makes ``--strict`` fail while an item
recommended HR at that level is not covered (default ``false``: the items
are shown, and named in the summary, without failing it).  Every mistake is one located
:class:`~rclverify.model.plan.errors.PlanError` in the plan (docs/standards.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import KEY, Path_
from rclverify.model.plan.standards.profiles import Profile, builtin_names, load_builtin, load_profile_file


@dataclass(frozen=True)
class StandardChoice:
    """A profile chosen by the plan at ``level`` (``None``: the profile has no levels), written at ``loc``;
    ``strict``: ``--strict`` requires its highly recommended items covered."""
    profile: Profile
    level: str | None
    loc: ast.Loc
    strict: bool = False


def _profile(root: Path, name: str, at: ast.Loc) -> Profile:
    if name.endswith((".yaml", ".yml")):
        if Path(name).is_absolute() or ".." in Path(name).parts:
            raise plan_error(at.file, at.line, at.col, f"standard profile {name!r} must be a path inside the "
                             "workspace", "E-profile")
        return load_profile_file(root / name, name)
    try:
        return load_builtin(name)
    except KeyError:
        raise plan_error(at.file, at.line, at.col, f"unknown standard profile {name!r}; the profiles are: "
                         f"{', '.join(builtin_names())} (or a workspace YAML file, docs/standards.md)",
                         "E-profile") from None


def _level(p: Profile, entry: Mapping[str, Any], base: Path_, locs: Mapping[Path_, ast.Loc], file: str) -> str | None:
    def at(key: str) -> ast.Loc:
        return locs.get(base + (key, KEY), locs.get(base, ast.Loc(file, 1, 1)))

    allowed = {p.level_name, "level"} if p.levels else set()
    for key in entry:
        if key not in ("profile", "strict") and key not in allowed:
            l = at(key)
            say = f"its level key is {p.level_name!r} ({', '.join(p.levels)})" if p.levels else "it has no levels"
            raise plan_error(l.file, l.line, l.col, f"standards: {key!r} is not a key of profile {p.id!r}: {say}",
                             "E-profile")
    if "strict" in entry and not isinstance(entry["strict"], bool):
        l = at("strict")
        raise plan_error(l.file, l.line, l.col, f"standards: 'strict' is true or false, not {entry['strict']!r}",
                         "E-profile")
    given = [k for k in entry if k in allowed]
    if not p.levels:
        return None
    if len(given) != 1:
        l = locs.get(base, ast.Loc(file, 1, 1))
        raise plan_error(l.file, l.line, l.col, f"standards: profile {p.id!r} needs one level, "
                         f"'{p.level_name}: ' one of {', '.join(p.levels)}", "E-profile")
    value = str(entry[given[0]])
    if value not in p.levels:
        l = locs.get(base + (given[0],), at(given[0]))
        raise plan_error(l.file, l.line, l.col, f"standards: {p.level_name} {value!r} is not a level of profile "
                         f"{p.id!r}; the levels are {', '.join(p.levels)}", "E-profile")
    return value


def read_standards(root: Path, data: Mapping[str, Any], locs: Mapping[Path_, ast.Loc],
                   file: str) -> tuple[StandardChoice, ...]:
    """The plan's ``standards:`` (``data``: the schema-checked plan data,
    ``locs``: its locations, ``file``: the plan's name) as
    :class:`StandardChoice` values, in order.  Raises :class:`PlanError`
    for an unknown profile (naming the profiles there are), a bad profile
    file, a missing or unknown level, or a profile chosen twice."""
    out: list[StandardChoice] = []
    for i, entry in enumerate(data.get("standards") or []):
        base: Path_ = ("standards", i)
        at = locs.get(base + ("profile",), ast.Loc(file, 1, 1))
        p = _profile(root, str(entry["profile"]), at)
        if any(c.profile.id == p.id for c in out):
            raise plan_error(at.file, at.line, at.col, f"standards: profile {p.id!r} is chosen twice", "E-profile")
        out.append(StandardChoice(p, _level(p, entry, base, locs, file), locs.get(base, at),
                                  bool(entry.get("strict", False))))
    return tuple(out)


__all__ = ["PlanError", "StandardChoice", "read_standards"]
