"""Who checked a review, as its evidence row says it (docs/standards.md, "Who checked: independence").

A review evidence row (backends/review) carries what its record names in its ``figures`` rows:
``reviewer``, ``author``, ``independence``, ``date``, ``scope`` and the declared ``author aliases``
and ``reviewer aliases``.  :func:`independence_of` decides the independence the row shows, comparing
names with :mod:`.identity`; :func:`review_as_stated` gives what the record states of itself and the
tool does not check (shown in the matrix as stated).  Pure functions of the row; nothing raises.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping

from rclverify.model.plan.standards.identity import Person, is_person, same_person, with_people
from rclverify.model.plan.standards.profiles import INDEPENDENCE
from rclverify.model.plan.standards.report_view import EvidenceView, evidence_view

#: A review evidence row: its view (:mod:`.report_view`), or its JSON object.
Review = EvidenceView | Mapping[str, Any]


def _figures(row: Review) -> tuple[Any, ...]:
    """The row's ``figures`` rows (empty when it has none)."""
    return evidence_view(row).figures or ()


def review_identity(row: Review) -> tuple[str, str, str]:
    """(reviewer, author, independence) a review evidence row names in its ``figures`` rows
    (backends/review: ``reviewer``, ``author``, ``independence``); ``""`` for what it does not name."""
    said = _said(row)

    def named(key: str) -> str:  # "(not named)": the backend's word for a field the record leaves empty
        v = said.get(key, "")
        return "" if v.startswith("(") and v.endswith(")") else v
    return named("reviewer"), named("author"), named("independence")


def _said(row: Review) -> dict[str, str]:
    """A review row's ``figures`` as field -> value (the first of each field)."""
    out: dict[str, str] = {}
    for r in _figures(row):
        if isinstance(r, (list, tuple)) and len(r) == 2:
            out.setdefault(str(r[0]), str(r[1]).strip())
    return out


def _aliases(row: Review, who: str) -> tuple[str, ...]:
    """The aliases the review record declares for its ``who`` (``author`` or ``reviewer``)."""
    text = _said(row).get(f"{who} aliases", "")
    return tuple(a.strip() for a in text.split(";") if a.strip())


def review_as_stated(row: Review) -> str:
    """What a review row states of itself, as the record states it: its independence, date and scope
    (the tool checks none of them) and the files it lists as reviewed (their sha256 is checked, not
    that they are the node's code), ``"; "``-joined (``""`` when it states none)."""
    said = _said(row)
    parts = [f"{label} {said[k]}" for k, label in (("independence", "independence as stated:"),
                                                    ("date", "dated"), ("scope", "scope as stated:"))
             if said.get(k) and not (said[k].startswith("(") and said[k].endswith(")"))]
    files = [str(r[1]).split(" sha256 ", 1)[0] for r in _figures(row)
             if isinstance(r, (list, tuple)) and len(r) == 2 and r[0] == "file"]
    if files:
        parts.append(f"files reviewed: {', '.join(files)}")
    return "; ".join(parts)


def independence_of(row: Review, people: Iterable[Person] = ()) -> tuple[str, str]:
    """(the independence level a review row shows, one of :data:`~.profiles.INDEPENDENCE`; why it is
    ``none`` or ``""``): ``none`` when the record does not name a person as its reviewer and as its author
    (an empty name, ``-``, ``unknown``... names nobody), or they are one person as
    :func:`~.identity.same_person` compares names (NFKC, case, punctuation and spaces aside, e-mail
    addresses, the record's declared aliases and the plan's ``people`` entries resolved,
    :func:`~.identity.with_people`); else the record's stated level, ``person`` when it states none."""
    reviewer, author, stated = review_identity(row)
    known = tuple(people)
    r_alias = with_people(reviewer, _aliases(row, "reviewer"), known)
    a_alias = with_people(author, _aliases(row, "author"), known)
    if not is_person(reviewer, r_alias) or not is_person(author, a_alias):
        missing = [w for w, n, al in (("its reviewer", reviewer, r_alias), ("its author", author, a_alias))
                   if not is_person(n, al)]
        said = [f"{w.removeprefix('its ')} {n!r}" for w, n, al in (("its reviewer", reviewer, r_alias),
                                                                    ("its author", author, a_alias))
                if n and not is_person(n, al)]
        return "none", (f"the record does not name a person as {' or '.join(missing)}"
                        + (f" ({', '.join(said)} names nobody)" if said else "") + ": its independence is not shown")
    if same_person(reviewer, author, r_alias, a_alias):
        return "none", f"self-review: {reviewer} reviewed their own work (author: {author})"
    return (stated if stated in INDEPENDENCE and stated != "none" else "person"), ""


__all__ = ["independence_of", "review_as_stated", "review_identity"]
