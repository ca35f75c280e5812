"""Who a review record names, read as an assessor reads it (docs/standards.md, "Who checked: independence").

A name is a person's when, compared as :func:`person_keys` reads it, it
names somebody; two names are one person when their keys meet
(:func:`same_person`).  The reading:

* Unicode NFKC then case folding (Unicode Standard, section 3.13, and
  UAX #15): a full-width ``Ａ``, a ligature or another case reads as the
  plain letter;
* every character that is not a letter or a digit (whitespace,
  punctuation, symbols) removed: ``Ada  Lovelace``, ``ada.lovelace`` and
  ``AdaLovelace`` are one key;
* an e-mail address is read apart from the name beside it
  (``Ada Lovelace <ada@example.org>``): the name, the whole address and
  its local part (without a ``+tag``) are each a key of the person;
* the declared aliases of the record (its ``author_aliases`` and
  ``reviewer_aliases``) are keys of the same person;
* the plan's ``people:`` list (:class:`Person`: a name, its aliases and
  e-mail addresses) makes every name of one entry a key of the person any
  of them names (:func:`with_people`), for every record.

A name that reads as nobody (:data:`NOBODY`: empty, ``-``, ``unknown``,
``n/a``, ``tbd``...) has no key: it is not a person, so nothing is
independent of it.

:func:`confusable` refuses what Unicode Technical Standard #39 (security
mechanisms) calls a mixed-script string and the invisible characters it
warns of: a name whose letters come from more than one script (Latin with
a Cyrillic ``а``; Han with Hiragana, Katakana or Hangul is one writing
system, as UTS #39's "highly restrictive" level allows) or that holds a
format, control or private-use character (a zero-width space, a
right-to-left mark).  The rule of comparison is rclverify's; no standard
prescribes one.  Pure functions of their arguments; nothing raises.
"""
from __future__ import annotations

from dataclasses import dataclass

import re
import unicodedata
from typing import Iterable

#: Names, as :func:`key` reads them, that name nobody.
NOBODY: frozenset[str] = frozenset({
    "", "unknown", "unkown", "na", "none", "nobody", "noone", "anonymous", "anon", "tbd", "tba", "todo",
    "unnamed", "notnamed", "notstated", "notknown", "null", "nil", "xxx", "someone", "somebody", "author",
    "reviewer", "me", "myself", "self"})
#: An e-mail address inside a name.
_EMAIL = re.compile(r"[^\s<>()\[\],;]+@[^\s<>()\[\],;]+")
#: Scripts that write one language together (UTS #39, "highly restrictive": Han with Hiragana and Katakana,
#: Han with Bopomofo, Han with Hangul).
_ONE_SYSTEM = {"HIRAGANA": "CJK", "KATAKANA": "CJK", "HANGUL": "CJK", "BOPOMOFO": "CJK", "CJK": "CJK",
               "HALFWIDTH": "CJK", "IDEOGRAPHIC": "CJK"}


def key(text: str) -> str:
    """``text`` after NFKC, case folding and NFKC again, with every character that is not a letter or a
    digit removed (the module docstring)."""
    folded = unicodedata.normalize("NFKC", unicodedata.normalize("NFKC", text).casefold())
    return "".join(c for c in folded if unicodedata.category(c)[0] in "LN")


def _script(c: str) -> str:
    """The script of the letter ``c`` as the first word of its Unicode name (``LATIN``, ``CYRILLIC``...)."""
    word = unicodedata.name(c, "UNKNOWN").split(" ", 1)[0]
    return _ONE_SYSTEM.get(word, word)


def confusable(name: str) -> str | None:
    """Why ``name`` may be spelt to look like another (the module docstring), or ``None``: the first
    invisible character (its code point and name), or the scripts its letters mix."""
    for c in name:
        cat = unicodedata.category(c)
        if cat in ("Cf", "Cc", "Co", "Cs", "Cn") and c not in "\t\n\r":
            return (f"it holds the invisible character U+{ord(c):04X} "
                    f"{unicodedata.name(c, 'UNNAMED')}")
    scripts = sorted({_script(c) for c in unicodedata.normalize("NFKC", name) if c.isalpha()})
    if len(scripts) > 1:
        return (f"it mixes letters of the scripts {', '.join(s.title() for s in scripts)}, which can spell a "
                "name to look like another (Unicode TR39)")
    return None


def person_keys(name: str, aliases: Iterable[str] = ()) -> frozenset[str]:
    """The keys of the person ``name`` names, with their declared ``aliases`` (the module docstring);
    empty when it names nobody (:data:`NOBODY`)."""
    out: set[str] = set()
    for text in (name, *aliases):
        plain = unicodedata.normalize("NFKC", text)
        for address in _EMAIL.findall(plain):
            local = address.split("@", 1)[0].split("+", 1)[0]
            out.update(k for k in (key(address), key(local)) if k not in NOBODY)
        rest = key(_EMAIL.sub(" ", plain))
        if rest not in NOBODY:
            out.add(rest)
    return frozenset(out)


@dataclass(frozen=True)
class Person:
    """One entry of the plan's ``people:`` list (docs/plan.md): ``name``, its ``aliases`` and ``emails``, all
    names of one person, written at ``loc`` (``file``, ``line``, ``col``)."""
    name: str
    aliases: tuple[str, ...] = ()
    emails: tuple[str, ...] = ()
    loc: tuple[str, int, int] = ("", 0, 0)

    def names(self) -> tuple[str, ...]:
        """Every name the entry gives the person."""
        return (self.name, *self.aliases, *self.emails)


def with_people(name: str, aliases: Iterable[str], people: Iterable[Person]) -> tuple[str, ...]:
    """``aliases`` with every name of each entry of ``people`` whose names' keys meet the keys of ``name``
    with ``aliases`` (:func:`person_keys`); ``aliases`` as given when none does."""
    mine = person_keys(name, aliases)
    out = list(aliases)
    for p in people:
        if mine and mine & person_keys(p.name, p.names()[1:]):
            out += [n for n in p.names() if n not in out]
    return tuple(out)


def is_person(name: str, aliases: Iterable[str] = ()) -> bool:
    """Whether ``name`` (with its ``aliases``) names somebody."""
    return bool(person_keys(name, aliases))


def same_person(a: str, b: str, a_aliases: Iterable[str] = (), b_aliases: Iterable[str] = ()) -> bool:
    """Whether ``a`` and ``b`` (each with its declared aliases) name one person: their keys meet."""
    return bool(person_keys(a, a_aliases) & person_keys(b, b_aliases))


__all__ = ["NOBODY", "Person", "confusable", "is_person", "key", "person_keys", "same_person", "with_people"]
