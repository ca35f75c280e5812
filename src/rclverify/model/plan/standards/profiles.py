"""Standard profiles: a safety standard's clauses or technique-table items as data (docs/standards.md).

A profile is a YAML file checked against ``profile.schema.json`` (JSON Schema
draft 2020-12, the way the plan is checked, model/plan/load.py) and then for
what a schema cannot say: item ids unique, and a per-level recommendation
naming exactly the profile's levels.  The built-in profiles live in
``profiles/`` inside the package; a user's profile is any file of the same
shape, which may not take a built-in profile's ``id`` or ``edition`` (both
reserved, so a workspace file is never shown as a built-in profile).  Every
mistake is one :class:`~rclverify.model.plan.errors.PlanError` at
``file:line:col``.  A profile's ids and titles are a traceability aid,
never the standard's text.
"""
from __future__ import annotations

import hashlib
import json
import re
import unicodedata
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import msgspec
import yaml

from rclverify.lang import ast
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import Path_, load_located, read_yaml_text, schema_error_loc

#: The recommendation codes: IEC 61508-3's grades (highly recommended, recommended, no recommendation,
#: not recommended), and ``required`` for a standard that does not grade so (the clause is part of what
#: it asks at that level: UL 4600's clauses, ISO 13482's, DO-178C's objectives that apply at a level).
CODES: tuple[str, ...] = ("HR", "R", "---", "NR", "required")
#: The codes ``--strict`` holds a ``strict: true`` standard to (docs/standards.md).
ASKED: tuple[str, ...] = ("HR", "required")
#: What a clause can be about (its scope, docs/standards.md "Scope"): each guarantee of every node, the
#: interfaces between nodes, the requirements, the whole system, field data from operation, trials
#: against a stated target.
ABOUT: tuple[str, ...] = ("guarantees", "interfaces", "requirements", "system", "field-data", "trials")
#: Independence levels, weakest first: rclverify's rule for who checked a review (docs/standards.md), its
#: levels borrowed from IEC 61508-1:2010 clause 8, Tables 4 and 5 (independent person, department,
#: organisation), which grade the functional safety assessment, not a review; DO-178C Annex A's "with
#: independence" is a person other than the author.
INDEPENDENCE: tuple[str, ...] = ("none", "person", "department", "organisation")
#: Where the built-in profiles are named in messages (package-relative, never a machine path).
BUILTIN_DIR = "rclverify/model/plan/standards/profiles"


@dataclass(frozen=True)
class Item:
    """One clause or technique of a profile: ``evidence`` the evidence kinds
    that can support it, ``strength`` the least strength it asks
    (docs/confidence.md's words), ``recommendation`` one code for every
    level or level -> code, ``about`` what it concerns (one of
    :data:`ABOUT`), ``independence`` the reviewer's independence from the
    author it asks (one of :data:`INDEPENDENCE`, for every level or per
    level), ``min_runs`` the fewest independent runs a target in its scope
    must count (0: no minimum), ``safety_case_adds`` what the clause asks
    beyond any evidence rclverify holds (``""``: nothing; else the clause is
    never covered by the tool alone, docs/standards.md)."""
    id: str
    title: str
    evidence: tuple[str, ...]
    strength: str
    recommendation: str | Mapping[str, str]
    about: str = "guarantees"
    independence: str | Mapping[str, str] = "none"
    min_runs: int = 0
    safety_case_adds: str = ""

    def at(self, level: str | None) -> str:
        """The recommendation code at ``level`` (``None``: a profile without levels)."""
        if isinstance(self.recommendation, str):
            return self.recommendation
        return self.recommendation.get(str(level), "---")

    def independence_at(self, level: str | None) -> str:
        """The independence asked at ``level``: one of :data:`INDEPENDENCE`."""
        if isinstance(self.independence, str):
            return self.independence
        return self.independence.get(str(level), "none")


@dataclass(frozen=True)
class Profile:
    """A loaded profile: ``levels`` empty when the standard has none,
    ``level_name`` the plan key that names the level (``sil``, ``dal``...),
    ``file`` where it was read (package-relative for the built-ins),
    ``builtin`` whether it is one of the package's profiles, ``sha256`` the
    hex sha256 of its file's bytes (of the UTF-8 text when parsed from a string), ``left_out`` the standard's clauses it does not
    list, each ``(id, why)``."""
    id: str
    title: str
    edition: str
    level_name: str
    levels: tuple[str, ...]
    items: tuple[Item, ...]
    file: str
    builtin: bool = False
    sha256: str = ""
    left_out: tuple[tuple[str, str], ...] = ()


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
    p = parse_profile(res.read_text(encoding="utf-8"), f"{BUILTIN_DIR}/{name}.yaml", builtin=True)
    return replace(p, sha256=hashlib.sha256(res.read_bytes()).hexdigest())


#: Dashes and hyphens other than '-' (Unicode category Pd and the minus sign), read as '-' in an edition.
_DASHES = dict.fromkeys(map(ord, "\u2010\u2011\u2012\u2013\u2014\u2015\u2212\ufe58\ufe63\uff0d\u2e3a\u2e3b"), "-")


def edition_key(edition: str) -> str:
    """``edition`` as editions are compared: NFKC, case folded, every dash read as '-', spaces around
    ':', '/', '-' and ',' removed and other runs of whitespace read as one space, stripped.  Two editions
    with one key name one standard's edition."""
    text = unicodedata.normalize("NFKC", edition).translate(_DASHES).casefold()
    text = "".join(c for c in text if unicodedata.category(c) not in ("Cf", "Cc") or c.isspace())
    return re.sub(r"\s*([:/,-])\s*", r"\1", " ".join(text.split()))


def _reserved() -> dict[str, tuple[str, str]]:
    """Each built-in profile's id and edition (as :func:`edition_key` reads it) -> (what it is, the built-in id)."""
    out: dict[str, tuple[str, str]] = {}
    for name in builtin_names():
        p = load_builtin(name)
        out[f"id:{p.id}"] = ("id", p.id)
        out[f"edition:{edition_key(p.edition)}"] = ("edition", p.id)
    return out


def load_profile_file(path: Path, file: str) -> Profile:
    """The workspace profile in the YAML file at ``path`` (named ``file`` in
    messages).  Raises :class:`PlanError` (unreadable, bad YAML, schema,
    the checks of the module docstring, and an ``id`` or ``edition`` a
    built-in profile has, located at that key)."""
    text = read_yaml_text(path, file)
    p = parse_profile(text, file)
    reserved = _reserved()
    for key, value, seen in (("id", p.id, p.id), ("edition", p.edition, edition_key(p.edition))):
        if f"{key}:{seen}" in reserved:
            _, locs = load_located(text, file)
            builtin = reserved[f"{key}:{seen}"][1]
            alike = "" if key == "id" else " (editions are compared without case, spacing or the kind of dash)"
            raise _bad(locs, (key,), file, f"standard profile: {key} {value!r} is the built-in profile "
                       f"{builtin!r}'s{alike}; a workspace profile takes its own {key} (choose the "
                       f"built-in one with `profile: {builtin}`)")
    try:
        return replace(p, sha256=hashlib.sha256(path.read_bytes()).hexdigest())
    except OSError:  # read just above; gone since: the text's digest
        return p


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


class _Written(msgspec.Struct, frozen=True, kw_only=True):
    """A part of a profile file as written, once its schema (``profile.schema.json``) has passed."""


class _ItemWritten(_Written, frozen=True, kw_only=True):
    """An ``items[]`` entry; a per-level map's keys as YAML reads them (``1:`` a number)."""

    id: str
    title: str
    evidence: tuple[str, ...]
    strength: str
    recommendation: str | dict[Any, str]
    about: str = "guarantees"
    independence: str | dict[Any, str] = "none"
    min_runs: int = 0
    safety_case_adds: str = ""


class _LeftOutWritten(_Written, frozen=True, kw_only=True):
    """A ``left_out[]`` entry: a clause the profile does not list, and why."""

    id: str
    why: str


class _ProfileWritten(_Written, frozen=True, kw_only=True):
    """A profile file's document."""

    id: str
    title: str
    edition: str
    level_name: str = "level"
    levels: tuple[str, ...] = ()
    items: tuple[_ItemWritten, ...]
    left_out: tuple[_LeftOutWritten, ...] = ()


def _per_level(value: str | dict[Any, str]) -> str | dict[str, str]:
    """One code (or level of independence) for every level, or level -> code with the levels as text."""
    return value if isinstance(value, str) else {str(k): str(v) for k, v in value.items()}


def parse_profile(text: str, file: str, builtin: bool = False) -> Profile:
    """The profile written in the YAML ``text`` of ``file`` (``builtin``: one of the package's).

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
    doc = msgspec.convert(data, _ProfileWritten, strict=False)  # an integer may be written 2.0 (JSON Schema's)
    levels = doc.levels
    items: list[Item] = []
    seen: dict[str, int] = {}
    for i, it in enumerate(doc.items):
        iid = it.id
        if iid in seen:
            raise _bad(locs, ("items", i, "id"), file, f"standard profile: item id {iid!r} is used twice "
                       f"(first at line {_at(locs, ('items', seen[iid], 'id'), file).line})")
        seen[iid] = i
        rec = _per_level(it.recommendation)
        if isinstance(rec, dict):
            if set(rec) != set(levels):
                raise _bad(locs, ("items", i, "recommendation"), file,
                           f"standard profile: item {iid!r}: the recommendation names levels "
                           f"{', '.join(sorted(rec)) or 'none'}; the profile's levels are "
                           f"{', '.join(levels) or 'none (write one code)'}")
        ind = _per_level(it.independence)
        if isinstance(ind, dict):
            if set(ind) != set(levels):
                raise _bad(locs, ("items", i, "independence"), file,
                           f"standard profile: item {iid!r}: the independence names levels "
                           f"{', '.join(sorted(ind)) or 'none'}; the profile's levels are "
                           f"{', '.join(levels) or 'none (write one level of independence)'}")
        items.append(Item(iid, it.title, it.evidence, it.strength, rec, it.about, ind, it.min_runs,
                          it.safety_case_adds.strip()))
    left = tuple((x.id, x.why) for x in doc.left_out)
    return Profile(doc.id, doc.title, doc.edition, doc.level_name, levels, tuple(items), file, builtin,
                   hashlib.sha256(text.encode("utf-8")).hexdigest(), left)


__all__ = ["ABOUT", "ASKED", "BUILTIN_DIR", "CODES", "INDEPENDENCE", "Item", "Profile", "builtin_names", "edition_key",
           "load_builtin", "load_profile_file",
           "parse_profile"]
