"""Review records: the checklist a node's guarantees call for, and the filled-in record.

Record (YAML)::

    node: Localisation
    reviewer: <who reviewed; say so when unknown>
    author: <who wrote what was reviewed>          # optional; needed for independence
    author_aliases: [<other names of the author>]  # optional: e-mail addresses, spellings
    reviewer_aliases: [<other names of the reviewer>]
    independence: person                # optional: person | department | organisation
    date: <YYYY-MM-DD, or text saying it is unknown>
    scope: <what was reviewed, against what>
    files:                              # the reviewed files, workspace-relative
      - {path: src/localisation.py, sha256: <hex>}
    assumption: <the node's assumption, as RCL, when the review was written>
    checklist:                          # one answer per generated question
      - {id: g1.c1, conjunct: <RCL>, answer: yes, note: <why>}   # yes | no | (empty: unanswered)
    verdict: pass                       # pass | fail | (empty: not decided)

``author`` and ``independence`` say who checked what: by rclverify's rule
(docs/standards.md, its levels borrowed from IEC 61508-1:2010 clause 8,
which grades the functional safety assessment; DO-178C Annex A "with
independence"), a review counts for a clause that asks independence only when the record names both its
reviewer and its author, each names a person, they are not one person as
:mod:`rclverify.model.plan.standards.identity` compares names (NFKC, case,
punctuation and spaces aside, e-mail addresses and the declared aliases
resolved), and ``independence`` (``person`` when left out) is at least the
clause's (docs/standards.md).  A record may leave them out: it is still a
review, shown everywhere, never counted as independent.

The checklist has one question per conjunct of each guarantee (top-level
``and`` split), with the conjunct's RCL location, so a reviewer knows what
to check and the record says what was checked.

An answer is bound to the **text** it answered, not to a guarantee's
number: each entry names its conjunct and the record the assumption, both
as :func:`~rclverify.lang.printer.expr_to_rcl` prints them (whitespace
aside).  When either differs from the contract's text now, the review
answered another question and the evidence is ``stale`` (docs/integrity.md,
"What makes evidence stale").
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import yaml

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import CheckedNode
from rclverify.model.plan.yamlguard import safe_load_guarded
from rclverify.backends.shapes import ReviewDetails


class RecordError(ValueError):
    """A malformed review record (message names the field)."""


@dataclass(frozen=True)
class Question:
    """One checklist question: ``id`` ``g<k>.c<j>``, the guarantee index, the
    conjunct as RCL, the question text and the conjunct's location."""

    id: str
    guarantee: int
    conjunct: str
    question: str
    location: str


def _conjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


def checklist(node: CheckedNode) -> list[Question]:
    """The questions a review of ``node`` answers, guarantee by guarantee."""
    out = []
    assume = assumption_text(node)
    for k, g in enumerate(node.node.guarantees, 1):
        for j, c in enumerate(_conjuncts(g.formula), 1):
            text = expr_to_rcl(c)
            loc = c.loc if c.loc.line else g.loc
            out.append(Question(
                f"g{k}.c{j}", k, text,
                f"For every input satisfying the assumption ({assume}), does the reviewed code eventually produce "
                f"outputs satisfying {text}?", f"{loc.file}:{loc.line}:{loc.col}"))
    return out


@dataclass(frozen=True)
class ReviewRecord:
    """A parsed record.  ``answers`` maps question id to ``"yes"``/``"no"``/``None``;
    ``notes`` question id to the reviewer's note; ``verdict`` ``"pass"``/``"fail"``/``None``."""

    node: str
    reviewer: str
    date: str
    scope: str
    files: tuple[tuple[str, str], ...]
    answers: Mapping[str, str | None]
    notes: Mapping[str, str]
    verdict: str | None
    conjuncts: Mapping[str, str] = field(default_factory=dict)
    assumption: str | None = None
    author: str = ""
    independence: str = ""
    author_aliases: tuple[str, ...] = ()
    reviewer_aliases: tuple[str, ...] = ()


def _answer(v: Any, where: str) -> str | None:
    if v is None or v == "":
        return None
    if v is True or str(v).lower() == "yes":
        return "yes"
    if v is False or str(v).lower() == "no":
        return "no"
    raise RecordError(f"{where}: answer must be yes, no or empty, found {v!r}")


def parse_record(text: str, file: str) -> ReviewRecord:
    """Parse and validate a record's text.  Raises :class:`RecordError`."""
    try:
        data = safe_load_guarded(text, file)
    except yaml.YAMLError as exc:
        raise RecordError(f"{file}: invalid YAML: {getattr(exc, 'problem', exc)}") from None
    if not isinstance(data, dict):
        raise RecordError(f"{file}: a review record is a mapping (node, reviewer, date, scope, files, checklist, verdict)")
    missing = [k for k in ("node", "reviewer", "date", "scope", "files", "checklist", "verdict") if k not in data]
    if missing:
        raise RecordError(f"{file}: missing field(s) {', '.join(missing)}")
    files = []
    for i, f in enumerate(data["files"] or []):
        if not isinstance(f, dict) or not isinstance(f.get("path"), str) or not isinstance(f.get("sha256"), str):
            raise RecordError(f"{file}: files[{i}] needs path and sha256")
        files.append((f["path"], f["sha256"].strip().lower()))
    answers: dict[str, str | None] = {}
    notes: dict[str, str] = {}
    conjuncts: dict[str, str] = {}
    for i, q in enumerate(data["checklist"] or []):
        if not isinstance(q, dict) or "id" not in q:
            raise RecordError(f"{file}: checklist[{i}] needs an id")
        answers[str(q["id"])] = _answer(q.get("answer"), f"{file}: checklist {q['id']}")
        notes[str(q["id"])] = str(q.get("note") or "").strip()
        if q.get("conjunct") is not None:
            conjuncts[str(q["id"])] = str(q["conjunct"])
    assumption = data.get("assumption")
    independence = str(data.get("independence") or "").strip()
    if independence not in ("", "person", "department", "organisation"):
        raise RecordError(f"{file}: independence must be person, department or organisation (docs/standards.md), "
                          f"found {independence!r}")
    aliases = {k: _names(data.get(k), f"{file}: {k}") for k in ("author_aliases", "reviewer_aliases")}
    verdict = data["verdict"]
    if verdict not in (None, "", "pass", "fail"):
        raise RecordError(f"{file}: verdict must be pass, fail or empty, found {verdict!r}")
    return ReviewRecord(str(data["node"]), str(data["reviewer"] or "").strip(), str(data["date"] or "").strip(),
                        str(data["scope"] or "").strip(), tuple(files), answers, notes, verdict or None, conjuncts,
                        None if assumption is None else str(assumption), str(data.get("author") or "").strip(),
                        independence, aliases["author_aliases"], aliases["reviewer_aliases"])


def _names(value: Any, where: str) -> tuple[str, ...]:
    """A record's list of aliases (absent: none).  Raises :class:`RecordError` for another shape."""
    if value is None:
        return ()
    if not isinstance(value, list) or not all(isinstance(v, str) and v.strip() for v in value):
        raise RecordError(f"{where}: a list of names (other spellings, e-mail addresses), found {value!r}")
    return tuple(v.strip() for v in value)


def assumption_text(node: CheckedNode) -> str:
    """The node's assumption as one RCL text (``TRUE`` when it has none): what a
    record's ``assumption`` must read."""
    return " and ".join(expr_to_rcl(a.formula) for a in node.node.assumes) or "TRUE"


def _same_text(a: str, b: str) -> bool:
    return " ".join(a.split()) == " ".join(b.split())


def text_drift(record: ReviewRecord, questions: list[Question], assumption: str) -> str | None:
    """Why the record's answers are not about the contract's text now, or
    ``None`` when every answered question names its conjunct as it reads now
    and the record names the assumption as it reads now."""
    answered = [q for q in questions if record.answers.get(q.id) is not None]
    if not answered:
        return None  # nothing answered yet: pending, whatever text the record names
    if record.assumption is None:
        return ("the record does not say which assumption it was reviewed under (no `assumption:`); an answer binds "
                "to the text it answered: regenerate the record with `rclverify review "
                f"{record.node}` and review again")
    if not _same_text(record.assumption, assumption):
        return (f"the review was made under the assumption {record.assumption.strip()!r}; the contract now assumes "
                f"{assumption!r}: review it again")
    for q in answered:
        said = record.conjuncts.get(q.id)
        if said is None:
            return (f"the record's answer to {q.id} does not say which text it answered (no `conjunct:`); "
                    f"{q.location} now reads {q.conjunct!r}: review it again")
        if not _same_text(said, q.conjunct):
            return (f"the review answered {q.id} for {said.strip()!r}; {q.location} now reads {q.conjunct!r}: "
                    "review it again")
    return None


def sha256_of(path: Path) -> str | None:
    """Hex sha256 of a file, ``None`` when it cannot be read."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def judge(record: ReviewRecord, questions: list[Question], root: Path,
          assumption: str | None = None) -> tuple[str, str, ReviewDetails]:
    """(status, explanation, details) of ``record`` for the ``questions`` of one guarantee;
    ``assumption``: the node's assumption text now (:func:`assumption_text`).

    * a listed file missing or with another sha256 -> ``stale``;
    * an answer about another text than the conjunct's or the assumption's
      now (:func:`text_drift`) -> ``stale``;
    * a question the record does not answer (the contract's checklist
      changed) -> ``stale`` (regenerate with ``rclverify review``);
    * an answer ``no`` or verdict ``fail`` -> ``failed`` naming the question;
    * an unanswered question, no verdict, or no reviewed file -> ``pending``;
    * otherwise ``discharged``.
    """
    details: ReviewDetails = {"reviewer": record.reviewer, "author": record.author,
                              "independence": record.independence, "date": record.date, "scope": record.scope,
                               "files": [{"path": p, "sha256": h} for p, h in record.files], "verdict": record.verdict,
                               "checklist": [{"id": q.id, "question": q.question, "location": q.location,
                                              "answer": record.answers.get(q.id), "note": record.notes.get(q.id, "")}
                                             for q in questions]}
    for p, h in record.files:
        now = sha256_of(root / p)
        if now != h:
            what = "is missing" if now is None else f"has sha256 {now[:12]}..., the record lists {h[:12]}..."
            return "stale", f"reviewed file {p} changed since the review: it {what}; review it again", details
    missing = [q for q in questions if q.id not in record.answers]
    if missing:
        return "stale", (f"the record does not answer {', '.join(q.id for q in missing)} ({missing[0].location}: "
                         f"{missing[0].conjunct}); the contract's checklist changed: regenerate it with "
                         f"`rclverify review {record.node}`"), details
    if assumption is not None:
        drift = text_drift(record, questions, assumption)
        if drift is not None:
            return "stale", drift, details
    for q in questions:
        if record.answers.get(q.id) == "no":
            return "failed", (f"the reviewer answered no to {q.id} ({q.location}): {q.question}"
                              + (f" Note: {record.notes[q.id]}" if record.notes.get(q.id) else "")), details
    if record.verdict == "fail":
        return "failed", f"the review's verdict is fail (reviewer: {record.reviewer or 'not named'})", details
    open_q = [q.id for q in questions if record.answers.get(q.id) is None]
    if open_q:
        return "pending", f"checklist question(s) {', '.join(open_q)} not answered yet", details
    if record.verdict is None:
        return "pending", "the review has no verdict yet", details
    if not record.files:
        return "pending", ("the record lists no reviewed file, so the verdict cannot be tied to code in this workspace "
                           "(and no change to that code can make it stale); add the reviewed files with their sha256"), details
    return "discharged", (f"reviewed by {record.reviewer} on {record.date}: every checklist question of the guarantee "
                          f"answered yes, verdict pass, {len(record.files)} file(s) unchanged since"), details

