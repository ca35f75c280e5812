"""The verification environment: which percepts the world may send the agent, and when.

AJPF model checks an agent program against a *verification environment*
that, instead of simulating the world, chooses nondeterministically among
the percepts the world could send (Dennis, Fisher, Lincoln, Lisitsa,
Veres, "Practical verification of decision-making in agent-based autonomous
systems", 2016: the environment explores every combination of percepts;
paper lines 1338-1345 for the case study's use of AJPF).  This module is
that environment as a plain value, built from the plan entry's
``environment`` mapping (docs/model-checking.md, "The verification
environment")::

    environment:
      percepts: ["movebase_result(_, 3)", "movebase_result(_, 2)", danger_red, danger_orange]
      after: [move]          # or "action": after every action (the default)
      at_most: 1             # how many of the percepts at once (default 1)
      at_least: 0            # 1: the environment always sends something (default 0)
      initial: []            # the percepts before the first action (default none)

After each action whose name is in ``after``, the environment *reacts*: it
replaces its percepts by any set of at least ``at_least`` and at most
``at_most`` of the declared percepts (with ``at_least`` 0 the empty set is
among them: nothing is perceived, the previous percepts are retracted).  Each choice is a branch of the explored graph.
``_`` in a declared percept stands for the identifier of the action the
reaction answers, a fresh value at every reaction, so that the result of
the second ``move`` is a new percept even when it equals the first's
(``movebase_result(2, 3)`` after ``movebase_result(1, 3)``: a ``+`` event
again).  How the explorer chooses the values -- 1, 2, 1, 2 ... for a
program that never keeps or tests an identifier, else the smallest number
the state and the program do not hold -- and why that is sound is
:mod:`.identifiers`'s.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from math import comb
from typing import Any, Callable, Mapping

from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.lang.ast import Loc
from rclverify.backends.model_checking.ajpf import psl

KEYS = ("percepts", "after", "at_most", "at_least", "initial")
#: Bound on the branches of one reaction (subsets of the declared percepts).
MAX_CHOICES = 4096

Locate = Callable[..., Loc]


@dataclass(frozen=True)
class Environment:
    """A verification environment (see the module docstring).

    ``percepts`` the declared percepts (ground but for ``_``, the reaction
    number); ``after`` the action names it reacts to, ``None`` for every
    action; ``at_most``/``at_least`` the largest/smallest number of percepts
    at once; ``initial`` the percepts of the initial state (ground).
    """

    percepts: tuple[psl.Term, ...]
    after: tuple[str, ...] | None = None
    at_most: int = 1
    initial: tuple[psl.Term, ...] = ()
    at_least: int = 0

    def reacts_to(self, action: psl.Term) -> bool:
        """Whether the environment reacts after ``action``."""
        name = action.name if isinstance(action, (psl.Sym, psl.Compound)) else None
        return self.after is None or name in self.after

    def choices(self, reaction: int) -> list[tuple[psl.Term, ...]]:
        """The percept sets a reaction with identifier ``reaction`` may choose,
        in a fixed order: nothing first (unless ``at_least`` > 0), then single
        percepts in declared order, then pairs ...; ``_`` replaced by
        ``reaction``."""
        filled = [fill(p, reaction) for p in self.percepts]
        out: list[tuple[psl.Term, ...]] = []
        for k in range(self.at_least, min(self.at_most, len(filled)) + 1):
            out.extend(tuple(c) for c in combinations(filled, k))
        return out

    def describe(self) -> str:
        """One line for reports: ``after move: one of movebase_result(_, 3), ... or nothing``."""
        when = "after every action" if self.after is None else "after " + ", ".join(self.after)
        what = ", ".join(psl.term_text(p) for p in self.percepts)
        nothing = " (or nothing)" if self.at_least == 0 else ""
        return f"{when}: {self.at_least} to {self.at_most} of {what}{nothing}"


def fill(term: psl.Term, reaction: int) -> psl.Term:
    """``term`` with every ``_`` replaced by the number ``reaction``."""
    if isinstance(term, psl.Wild):
        return psl.Num(str(reaction))
    if isinstance(term, psl.Compound):
        return psl.Compound(term.name, tuple(fill(a, reaction) for a in term.args))
    return term


def _has_wild(term: psl.Term) -> bool:
    if isinstance(term, psl.Wild):
        return True
    return isinstance(term, psl.Compound) and any(_has_wild(a) for a in term.args)


def environment_from_plan(raw: Mapping[str, object], locate: Locate | None = None) -> Environment:
    """The :class:`Environment` of a plan entry's ``environment`` mapping.

    ``locate(*path)`` gives the plan location of the value at ``path`` inside
    the mapping (``locate("percepts", 1)``; ``locate()`` the mapping itself);
    without it messages are located at ``<environment>:1:1``.  Raises
    :class:`~rclverify.model.plan.errors.PlanError` (``E-plan``) for an unknown
    key, a missing or empty ``percepts``, a percept that is not a term, a
    variable in a percept, ``_`` in an initial percept, an ``after`` that is
    neither ``"action"`` nor a list of action names, an ``at_most`` that is
    not an integer from 1 to the number of percepts, an ``at_least`` not
    from 0 to ``at_most``, or more than
    :data:`MAX_CHOICES` branches per reaction.
    """
    def err(message: str, *path: Any, col_offset: int = 0) -> PlanError:
        loc = locate(*path) if locate is not None else Loc("<environment>", 1, 1)
        return plan_error(loc.file, loc.line, loc.col + col_offset, f"environment: {message}")

    if not isinstance(raw, Mapping):
        raise err(f"expected a mapping with keys {', '.join(KEYS)}, found {type(raw).__name__}")
    for key in raw:
        if key not in KEYS:
            raise err(f"unknown key {key!r} (known: {', '.join(KEYS)})", key)
    if "percepts" not in raw:
        raise err("'percepts' is required: the percepts the environment may send")
    percepts = _terms(raw["percepts"], "percepts", err, allow_wild=True)
    if not percepts:
        raise err("'percepts' is empty: the environment would never send anything", "percepts")
    initial = _terms(raw.get("initial", []), "initial", err, allow_wild=False)
    after_raw = raw.get("after", "action")
    after: tuple[str, ...] | None
    if after_raw == "action":
        after = None
    elif isinstance(after_raw, str) and after_raw[:1].islower() and after_raw.replace("_", "a").isalnum():
        after = (after_raw,)
    elif isinstance(after_raw, list) and after_raw and all(
            isinstance(a, str) and a[:1].islower() and a.replace("_", "a").isalnum() for a in after_raw):
        after = tuple(after_raw)
    else:
        raise err(f"'after' must be \"action\" (every action) or a list of action names, found {after_raw!r}",
                  "after")
    at_most = raw.get("at_most", 1)
    if isinstance(at_most, bool) or not isinstance(at_most, int) or not 1 <= at_most <= len(percepts):
        raise err(f"'at_most' must be an integer from 1 to {len(percepts)} (the number of percepts), "
                  f"found {at_most!r}", "at_most")
    at_least = raw.get("at_least", 0)
    if isinstance(at_least, bool) or not isinstance(at_least, int) or not 0 <= at_least <= at_most:
        raise err(f"'at_least' must be an integer from 0 to {at_most} ('at_most'), found {at_least!r}", "at_least")
    env = Environment(tuple(percepts), after, at_most, tuple(initial), at_least)
    branches = sum(comb(len(percepts), k) for k in range(at_least, at_most + 1))
    if branches > MAX_CHOICES:
        raise err(f"{branches} choices per reaction exceed the bound of {MAX_CHOICES}; lower 'at_most'",
                  "at_most")
    return env


def _terms(value: Any, key: str, err: Callable[..., PlanError], allow_wild: bool) -> list[psl.Term]:
    if not isinstance(value, list):
        raise err(f"'{key}' must be a list of terms, found {type(value).__name__}", key)
    out: list[psl.Term] = []
    for i, item in enumerate(value):
        if not isinstance(item, str) or not item.strip():
            raise err(f"{key}[{i}] must be a term written as a string (danger_red, \"movebase_result(_, 3)\"), "
                      f"found {item!r}", key, i)
        try:
            formula = psl.parse(f"P({item})")
        except psl.PslSyntaxError as exc:
            raise err(f"{key}[{i}] {item!r} is not a term: {exc.message}", key, i,
                      col_offset=max(exc.col - 3, 0)) from None
        if not isinstance(formula, psl.Percept):  # "a) & P(b" parses, but as two
            raise err(f"{key}[{i}] {item!r} is not one term", key, i)
        term = formula.term
        if not allow_wild and _has_wild(term):
            raise err(f"{key}[{i}] {item!r}: an initial percept must be ground ('_' stands for a reaction's number)",
                      key, i)
        if term in out:
            raise err(f"{key}[{i}] {item!r} is listed twice", key, i)
        out.append(term)
    return out
