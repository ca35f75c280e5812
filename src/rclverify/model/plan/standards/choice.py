"""The plan's ``standards:`` entries: which profiles the evidence is mapped onto, at which level.

An entry is ``{profile: NAME, <level key>: LEVEL, strict: BOOL, clauses: {...}}``: ``NAME`` a built-in
profile (:func:`.profiles.builtin_names`) or a workspace-relative YAML file of
the same shape (``*.yaml``/``*.yml``); the level key is the profile's
``level_name`` (``sil``, ``dal``, ``pl``) or ``level``, absent for a profile
without levels; ``strict: true`` makes ``--strict`` fail while an item
recommended HR at that level is not covered (default ``false``: the items
are shown, and named in the summary, without failing it).  ``clauses`` maps a
clause id of the profile to what the plan says of it: ``nodes`` (the nodes
whose guarantees are in its scope, narrowing it) with the ``reason`` for
narrowing it, and a ``justification`` (why the evidence suffices, or why the
clause does not apply) shown in the compliance matrix; neither makes a
clause covered by itself.  Every mistake is one located
:class:`~rclverify.model.plan.errors.PlanError` in the plan (docs/standards.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast
from rclverify.model.plan.document import PlanDocument, plan_document
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import KEY, Path_

if TYPE_CHECKING:
    from rclverify.model.plan.standards.identity import Person
    from rclverify.model.plan.standards.profiles import Profile


#: The fewest words of the justification that narrowing a clause asked at the level needs.
ASKED_WORDS = 8
#: The keys of a clause's entry under ``clauses:``.
CLAUSE_KEYS: tuple[str, ...] = ("nodes", "reason", "justification")


@dataclass(frozen=True)
class ClauseNote:
    """What the plan says of one clause: ``nodes`` the nodes its scope is narrowed to (``None``: not
    narrowed) and the ``reason``, ``justification`` shown beside it (``""``: none), written at ``at``
    (``file:line:col``)."""
    nodes: tuple[str, ...] | None
    reason: str
    justification: str
    at: str


@dataclass(frozen=True)
class StandardChoice:
    """A profile chosen by the plan at ``level`` (``None``: the profile has no levels), written at ``loc``;
    ``strict``: ``--strict`` requires the items it asks covered; ``clauses``: clause id -> what the plan
    says of it; ``people``: the plan's ``people:`` entries, names of one person each (for a review's
    independence)."""
    profile: Profile
    level: str | None
    loc: ast.Loc
    strict: bool = False
    clauses: Mapping[str, ClauseNote] = field(default_factory=dict)
    people: tuple[Person, ...] = ()


def read_people(data: PlanDocument | Mapping[str, Any], locs: Mapping[Path_, ast.Loc], file: str) -> tuple[Person, ...]:
    """The plan's ``people:`` list (``data``: the plan's typed sections, or its schema-checked data) as
    :class:`~.identity.Person` values, in order.  Raises :class:`PlanError` at the entry for a name that names nobody or holds mixed
    scripts or invisible characters (:func:`~.identity.confusable`), and for two entries that name one
    person (their names' keys meet: they would be one entry)."""
    out: list[Person] = []
    for i, entry in enumerate(_document(data).people):
        from rclverify.model.plan.standards.identity import Person, confusable, is_person, person_keys  # deferred: start-up (loaded only by a plan that names people)
        at = locs.get(("people", i), ast.Loc(file, 1, 1))
        p = Person(entry.name, entry.aliases, entry.emails, (at.file, at.line, at.col))
        for n in p.names():
            bad = confusable(n)
            if bad or not is_person(n):
                raise plan_error(at.file, at.line, at.col, f"people: {n!r} " + (
                    bad if bad else "names nobody") + " (docs/plan.md, \"people\")", "E-people")
        keys = person_keys(p.name, p.names()[1:])
        for q in out:
            if keys & person_keys(q.name, q.names()[1:]):
                raise plan_error(at.file, at.line, at.col, f"people: {p.name!r} and {q.name!r} (line {q.loc[1]}) "
                                 "share a name, alias or e-mail: one person is one entry", "E-people")
        out.append(p)
    return tuple(out)


def _profile(root: Path, name: str, at: ast.Loc) -> Profile:
    from rclverify.model.plan.standards.profiles import builtin_names, load_builtin, load_profile_file  # deferred: start-up (loaded only by a plan that names a standard)
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
        if key not in ("profile", "strict", "clauses") and key not in allowed:
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


def _words(value: Any, n: int) -> bool:
    return isinstance(value, str) and len(value.split()) >= n


def _clauses(p: Profile, entry: Mapping[str, Any], base: Path_, locs: Mapping[Path_, ast.Loc],
             file: str, level: str | None = None) -> dict[str, ClauseNote]:
    """The entry's ``clauses:`` read and checked: each id one of the profile's, each key one of
    :data:`CLAUSE_KEYS`, ``nodes`` a non-empty list of names given with a ``reason`` of at least three
    words, a ``justification`` of at least three words; narrowing a clause asked at ``level`` (``HR``,
    or ``required``) also needs a ``justification`` of at least :data:`ASKED_WORDS` words (shown in full
    in the matrix)."""
    from rclverify.model.plan.standards.profiles import ASKED  # deferred: start-up (loaded only by a plan that names a standard)
    def at(*path: Any) -> ast.Loc:
        full = base + ("clauses",) + path
        while full not in locs and len(full) > len(base):
            full = full[:-1]
        return locs.get(full, locs.get(base, ast.Loc(file, 1, 1)))

    def bad(l: ast.Loc, message: str) -> PlanError:
        return plan_error(l.file, l.line, l.col, f"standards: {message}", "E-profile")

    given = entry.get("clauses")
    if given is None:
        return {}
    if not isinstance(given, dict):
        raise bad(at(), "'clauses' maps a clause id of the profile to {nodes, reason, justification}")
    ids = [i.id for i in p.items]
    out: dict[str, ClauseNote] = {}
    for cid, note in given.items():
        cid = str(cid)
        if cid not in ids:
            raise bad(at(cid, KEY), f"{cid!r} is not a clause of profile {p.id!r}; its clauses are {', '.join(ids)}")
        if not isinstance(note, dict) or not note:
            raise bad(at(cid), f"clause {cid!r}: write {{nodes: [...], reason: ..., justification: ...}}")
        for key in note:
            if key not in CLAUSE_KEYS:
                raise bad(at(cid, key, KEY), f"clause {cid!r}: {key!r} is not a key here; the keys are "
                          f"{', '.join(CLAUSE_KEYS)}")
        nodes = note.get("nodes")
        if nodes is not None and not (isinstance(nodes, list) and nodes and all(isinstance(n, str) for n in nodes)):
            raise bad(at(cid, "nodes"), f"clause {cid!r}: 'nodes' is a non-empty list of node names")
        if nodes is not None and not _words(note.get("reason"), 3):
            raise bad(at(cid, "reason") if "reason" in note else at(cid, "nodes"),
                      f"clause {cid!r}: narrowing its scope needs a 'reason' of at least three words, shown with it")
        if "reason" in note and nodes is None:
            raise bad(at(cid, "reason"), f"clause {cid!r}: a 'reason' goes with 'nodes' (the scope it narrows)")
        asked = p.items[ids.index(cid)].at(level) in ASKED
        if nodes is not None and asked and not _words(note.get("justification"), ASKED_WORDS):
            raise bad(at(cid, "justification") if "justification" in note else at(cid, "nodes"),
                      f"clause {cid!r} is asked at this level ({p.items[ids.index(cid)].at(level)}): narrowing its "
                      f"scope needs a 'justification' of at least {ASKED_WORDS} words, shown in full in the matrix")
        if "justification" in note and not _words(note.get("justification"), 3):
            raise bad(at(cid, "justification"), f"clause {cid!r}: a 'justification' is at least three words")
        l = at(cid, KEY)
        out[cid] = ClauseNote(None if nodes is None else tuple(nodes), str(note.get("reason") or ""),
                              str(note.get("justification") or ""), f"{l.file}:{l.line}:{l.col}")
    return out


def _document(data: PlanDocument | Mapping[str, Any]) -> PlanDocument:
    """``data`` as the plan's typed sections (a mapping is converted, :func:`~..document.plan_document`)."""
    return data if isinstance(data, PlanDocument) else plan_document(data)


def read_standards(root: Path, data: PlanDocument | Mapping[str, Any], locs: Mapping[Path_, ast.Loc],
                   file: str) -> tuple[StandardChoice, ...]:
    """The plan's ``standards:`` (``data``: the plan's typed sections, or its schema-checked data;
    ``locs``: its locations, ``file``: the plan's name) as
    :class:`StandardChoice` values, in order.  Raises :class:`PlanError`
    for an unknown profile (naming the profiles there are), a bad profile
    file, a missing or unknown level, a profile chosen twice, or a bad
    ``clauses:`` entry (:func:`_clauses`) or ``people:`` entry (:func:`read_people`).
    Each choice carries the plan's ``people``."""
    out: list[StandardChoice] = []
    doc = _document(data)
    people = read_people(doc, locs, file)
    for i, entry in enumerate(doc.standards):
        base: Path_ = ("standards", i)
        at = locs.get(base + ("profile",), ast.Loc(file, 1, 1))
        p = _profile(root, str(entry["profile"]), at)
        if any(c.profile.id == p.id for c in out):
            raise plan_error(at.file, at.line, at.col, f"standards: profile {p.id!r} is chosen twice", "E-profile")
        level = _level(p, entry, base, locs, file)
        out.append(StandardChoice(p, level, locs.get(base, at), bool(entry.get("strict", False)),
                                  _clauses(p, entry, base, locs, file, level), people))
    return tuple(out)


__all__ = ["ASKED_WORDS", "CLAUSE_KEYS", "ClauseNote", "PlanError", "StandardChoice", "read_people", "read_standards"]
